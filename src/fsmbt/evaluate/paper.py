"""The reference paper's (LLMDUCF) headline numbers, in one table, each with its source.

Only figures the paper states are here (as summarised in issue 15); every report prints them
next to ours. ``M`` = FSM states (FSM -> BT) or BT leaves (BT -> FSM), ``k`` = sub-FSMs.
"""

from __future__ import annotations

#: (what, the paper's value, where the paper gives it)
PAPER_NUMBERS: tuple[tuple[str, str, str], ...] = (
    ("graphical elements, BT->FSM, LLMDUCF", "4M+2k+1", "Table IV"),
    ("graphical elements, BT->FSM, BSD/CHDS", "≈36M", "Table IV"),
    ("graphical elements, FSM->BT, LLMDUCF", "≈7M−1", "Table IX"),
    ("graphical elements, FSM->BT, BSD", "8M+1", "Table IX"),
    ("graphical elements, FSM->BT, CHDS", "8M+1+6k", "Table IX"),
    ("edit distance, robot: Tuck Arm / Safe-Move-To / Dock, LLMDUCF", "4 / 4 / 4", "Table V"),
    ("edit distance, robot: Tuck Arm / Safe-Move-To / Dock, BSD/CHDS", "12 / 4 / 17", "Table V"),
    ("edit distance, game: Fire / Gliding / Loading, LLMDUCF", "6 / 2 / 8", "Table X"),
    ("edit distance, game: Fire / Gliding / Loading, BSD", "8+k / 2 / 10+k", "Table X"),
    ("edit distance, game: Fire / Gliding / Loading, CHDS", "8+6k / 2 / 10+6k", "Table X"),
    ("time per conversion, rules", "0.1–0.5 s", "cost discussion"),
    ("time per conversion, LLM", "60–70 s", "cost discussion"),
    ("tokens per conversion, LLM", "500–1 000", "cost discussion"),
)

#: The paper's coefficient of M for each (direction, method), for the fitted-slope table.
PAPER_SLOPES: dict[tuple[str, str], float] = {
    ("bt->fsm", "rules"): 4.0,
    ("bt->fsm", "bsd"): 36.0,
    ("bt->fsm", "chds"): 36.0,
    ("fsm->bt", "rules"): 7.0,
    ("fsm->bt", "bsd"): 8.0,
    ("fsm->bt", "chds"): 8.0,
}
#: The paper's formula text per (direction, method).
PAPER_FORMULAS: dict[tuple[str, str], str] = {
    ("bt->fsm", "rules"): "4M+2k+1",
    ("bt->fsm", "bsd"): "≈36M",
    ("bt->fsm", "chds"): "≈36M",
    ("fsm->bt", "rules"): "7M−1",
    ("fsm->bt", "bsd"): "8M+1",
    ("fsm->bt", "chds"): "8M+1+6k",
}
