"""The reference paper's (LLMDUCF) numbers, each with its source, for every table of the report.

Only figures the paper states are here, as summarised in issue 15 (the repository holds no copy
of the paper): the element formulas (Tables IV/IX), the edit distances of the six add-behaviour
cases (Tables V/X), and the cost discussion (rules 0.1-0.5 s, LLM 60-70 s and 500-1 000 tokens
per conversion). The paper also reports conversion **accuracy** per scenario and per LLM, with
and without the stepwise conversion procedure (Tables I/VI, II/VII), behavioural consistency
(III/VIII), retries (XII), version sensitivity (XI) and input representations (XIII); those
values are **not recorded in this repository**, and every table says so (``NOT_RECORDED``)
instead of showing a number nobody can check.

Method names: the paper's LLMDUCF is compared with our ``rules`` engine (the deterministic
conversion rules LLMDUCF's prompt describes, docs/conversion.md) and, when an endpoint is
configured, ``llm``; BSD and CHDS are the same baselines (docs/baselines.md).
``M`` = FSM states (FSM -> BT) or BT leaves (BT -> FSM), ``k`` = sub-FSMs.
"""

from __future__ import annotations

NOT_RECORDED = "not recorded in this repository"
#: What the paper reports where its values are not recorded here (one line per table).
NOT_RECORDED_TABLES: dict[str, str] = {
    "accuracy": "the paper reports conversion accuracy per scenario and per LLM, with and "
    "without the stepwise conversion procedure (Tables I/VI)",
    "ablation": "the paper reports accuracy without each SCP module (Tables II/VII), retries "
    "(XII) and version sensitivity (XI)",
    "consistency": "the paper reports the five properties per method (Tables III/VIII)",
    "inputs": "the paper reports conversions from each input representation (Table XIII)",
}
#: Tables for which the paper has no counterpart at all.
NO_PAPER_FIGURE = "the paper has no such figure"

#: (what, the paper's value, where the paper gives it, how ours is computed: a key for
#: ``fsmbt.evaluate.analysis.headline``)
PAPER_NUMBERS: tuple[tuple[str, str, str, tuple[str, ...]], ...] = (
    (
        "conversion accuracy per scenario and LLM, with / without the SCP",
        NOT_RECORDED,
        "Tables I/VI",
        ("accuracy", "llm"),
    ),
    ("conversion accuracy, rule-based engine", NOT_RECORDED, "Tables I/VI", ("accuracy", "rules")),
    ("conversion accuracy, BSD", NOT_RECORDED, "Tables I/VI", ("accuracy", "bsd")),
    ("conversion accuracy, CHDS", NOT_RECORDED, "Tables I/VI", ("accuracy", "chds")),
    (
        "graphical elements, BT->FSM, LLMDUCF",
        "4M+2k+1",
        "Table IV",
        ("elements", "bt->fsm", "rules"),
    ),
    ("graphical elements, BT->FSM, BSD", "≈36M", "Table IV", ("elements", "bt->fsm", "bsd")),
    ("graphical elements, BT->FSM, CHDS", "≈36M", "Table IV", ("elements", "bt->fsm", "chds")),
    ("graphical elements, FSM->BT, LLMDUCF", "≈7M−1", "Table IX", ("elements", "fsm->bt", "rules")),
    ("graphical elements, FSM->BT, BSD", "8M+1", "Table IX", ("elements", "fsm->bt", "bsd")),
    ("graphical elements, FSM->BT, CHDS", "8M+1+6k", "Table IX", ("elements", "fsm->bt", "chds")),
    (
        "edit distance, robot: Tuck Arm / Safe-Move-To / Dock, LLMDUCF",
        "4 / 4 / 4",
        "Table V",
        ("edit", "robot", "rules"),
    ),
    (
        "edit distance, robot: Tuck Arm / Safe-Move-To / Dock, BSD",
        "12 / 4 / 17",
        "Table V",
        ("edit", "robot", "bsd"),
    ),
    (
        "edit distance, robot: Tuck Arm / Safe-Move-To / Dock, CHDS",
        "12 / 4 / 17",
        "Table V",
        ("edit", "robot", "chds"),
    ),
    (
        "edit distance, game: Fire / Gliding / Loading, LLMDUCF",
        "6 / 2 / 8",
        "Table X",
        ("edit", "game", "rules"),
    ),
    (
        "edit distance, game: Fire / Gliding / Loading, BSD",
        "8+k / 2 / 10+k",
        "Table X",
        ("edit", "game", "bsd"),
    ),
    (
        "edit distance, game: Fire / Gliding / Loading, CHDS",
        "8+6k / 2 / 10+6k",
        "Table X",
        ("edit", "game", "chds"),
    ),
    ("time per conversion, rules", "0.1–0.5 s", "cost discussion", ("time", "rules")),
    ("time per conversion, LLM", "60–70 s", "cost discussion", ("time", "llm")),
    ("tokens per conversion, LLM", "500–1 000", "cost discussion", ("tokens", "llm")),
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

#: Tables V/X: (scenario, case) -> method -> (constant, coefficient of k). The paper gives one
#: robot figure for BSD and CHDS together; LLMDUCF is set beside our ``rules``.
PAPER_EDITS: dict[tuple[str, str], dict[str, tuple[int, int]]] = {
    ("robot", "Tuck Arm subtree"): {"rules": (4, 0), "bsd": (12, 0), "chds": (12, 0)},
    ("robot", "Safe-Move-To behaviour"): {"rules": (4, 0), "bsd": (4, 0), "chds": (4, 0)},
    ("robot", "Dock subtree"): {"rules": (4, 0), "bsd": (17, 0), "chds": (17, 0)},
    ("game", "Fire subtree"): {"rules": (6, 0), "bsd": (8, 1), "chds": (8, 6)},
    ("game", "Gliding behaviour"): {"rules": (2, 0), "bsd": (2, 0), "chds": (2, 0)},
    ("game", "Loading subtree"): {"rules": (8, 0), "bsd": (10, 1), "chds": (10, 6)},
}

#: The cost discussion: method -> (seconds per conversion, tokens per conversion).
PAPER_COST: dict[str, tuple[str, str]] = {
    "rules": ("0.1–0.5 s", "–"),
    "llm": ("60–70 s", "500–1 000"),
}


def paper_edit(scenario: str, case: str, method: str, k: int) -> str:
    """The paper's edit distance of one case and method, its ``k`` term evaluated at ours.

    Args:
        scenario: ``robot`` or ``game``.
        case: the case's name (``fsmbt.evaluate.cases.CASES``).
        method: ``rules``, ``bsd`` or ``chds``.
        k: the sub-FSMs of our extended result.

    Returns:
        ``"4"``, or ``"8+6k = 38 at our k = 5"``; ``NOT_RECORDED`` for an unknown case.
    """
    found = PAPER_EDITS.get((scenario, case), {}).get(method)
    if found is None:
        return NOT_RECORDED
    constant, per_k = found
    if per_k == 0:
        return str(constant)
    term = "k" if per_k == 1 else f"{per_k}k"
    return f"{constant}+{term} = {constant + per_k * k} at our k = {k}"


def paper_accuracy(method: str) -> str:
    """The paper's accuracy cell for a method (always ``NOT_RECORDED``: see the module text)."""
    del method  # the same for every method: no value is recorded here
    return NOT_RECORDED


def paper_cost(method: str) -> tuple[str, str]:
    """The paper's (time, tokens) per conversion for a method label (``llm[model]`` -> llm).

    Args:
        method: a method label of the report.

    Returns:
        The two cells; methods the paper gives no cost for read ``NO_PAPER_FIGURE``-style "–".
    """
    base = method.split("[", 1)[0]
    if base in PAPER_COST:
        return PAPER_COST[base]
    return ("none given", "none given")
