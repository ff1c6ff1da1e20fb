"""The input-representation table (the paper's Table XIII): one model, five representations.

The predator FSM (``examples/predator_fsm.csv``) is written as a paper-style text file, a CSV
table, a Markdown table, a PNG image (``fsmbt.render``) and an unseen notation (arrows in a
made-up ``.fsmnote`` file no reader knows). Each goes through the real input path:
``fsmbt.llm.extract.needs_llm`` decides whether a parser reads it (``fsmbt.formats``) or an LLM
must extract it. Each cell names the reader or says "not run: no endpoint", the engine that
converted it and the verdict of the native checker. Cost: five small conversions per method.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from fsmbt import api
from fsmbt.evaluate.plan import NOT_RUN, RULE_ENGINES, method_style
from fsmbt.formats import dumps
from fsmbt.llm.extract import needs_llm
from fsmbt.model.fsm import FSM


def write_representations(examples: Path, outdir: Path) -> list[tuple[str, Path]]:
    """Write the five representations of the predator FSM; return (name, file)."""
    outdir.mkdir(parents=True, exist_ok=True)
    model = api.load(examples / "predator_fsm.csv").model
    if not isinstance(model, FSM):
        raise ValueError("examples/predator_fsm.csv must hold an FSM")
    files = [
        ("text file (paper text)", outdir / "predator.txt", dumps(model, "paper-text")),
        ("table (CSV)", outdir / "predator.csv", dumps(model, "csv")),
        ("table (Markdown)", outdir / "predator.md", dumps(model, "md")),
    ]
    for _name, path, text in files:
        api.write_text(text, path, overwrite=True)
    picked = [(name, path) for name, path, _text in files]
    image = outdir / "predator.png"
    from fsmbt.render import render_model

    if image.exists():
        image.unlink()
    render_model(model, image, overwrite=True)
    picked.append(("image (PNG)", image))
    unseen = outdir / "predator.fsmnote"
    lines = [f"{t.source} ={t.event}=> {t.target}" for t in model.transitions]
    api.write_text(
        "predator machine, starts in Patrol\n" + "\n".join(lines) + "\n", unseen, overwrite=True
    )
    picked.append(("unseen encoding", unseen))
    return picked


def table(examples: Path, outdir: Path, llm_methods: list[str]) -> list[dict[str, Any]]:
    """One row per representation and method (see the module text)."""
    out = []
    for name, path in write_representations(examples, outdir):
        llm_needed = needs_llm(path)
        for method in (*RULE_ENGINES, *llm_methods):
            cell: dict[str, Any] = {"representation": name, "file": path.name, "method": method}
            if llm_needed:
                cell.update(reader="LLM extraction (fsmbt.llm.extract.read_input)", text=NOT_RUN)
                out.append(cell)
                continue
            if method not in RULE_ENGINES:  # a parser reads it; the LLM converts it
                cell.update(reader=f"{api.load(path).format} reader", text=NOT_RUN)
                out.append(cell)
                continue
            try:
                outcome = api.convert_file(path, engine=method, **method_style(method))
                cell.update(
                    reader=f"{outcome.source.format} reader",
                    engine=method,
                    verdict=outcome.verdict,
                    text=f"converted by {method}, native check: {outcome.verdict}",
                )
            except Exception as exc:  # noqa: BLE001 - a cell that fails says why
                cell.update(reader="?", text=f"error: {type(exc).__name__}: {exc}")
            out.append(cell)
    return out
