"""A verification report for people: the verdict, the five properties, and for each failure its
shortest counterexample as a table (step, input, what the source did, what the result did)."""

from __future__ import annotations

from rich.console import Console, Group, RenderableType
from rich.table import Table
from rich.text import Text

from fsmbt.verify.report import LIFTED, PROPERTIES, PropertyResult, Report, TraceStep

_TITLES = {
    "reachability": "reachability",
    "completeness": "completeness",
    "no_additional_behavior": "no additional behaviour",
    "deadlock_absence": "deadlock absence",
    "termination_consistency": "termination consistency",
}


def render(report: Report) -> RenderableType:
    """The whole report as one rich renderable."""
    parts: list[RenderableType] = []
    verdict = (
        Text("EQUIVALENT", style="bold green")
        if report.equivalent
        else Text("NOT EQUIVALENT", style="bold red")
    )
    header = Text.assemble(
        verdict,
        f"  {report.source} -> {report.result}",
        f"  ({report.mode}, engine {report.engine})",
    )
    parts.append(header)
    if report.method:
        engines = ", ".join(f"{name} {version}" for name, version in report.engines.items())
        parts.append(Text(f"proven by: {report.method} ({engines})", style="dim"))
        for sentence in report.abstractions:
            parts.append(Text(f"under the abstraction: {sentence}", style="dim"))
    if report.stats.get("compositional"):
        parts.append(
            Text(
                f"compositional check: {report.stats['compositional']}; the whole product "
                "decided (docs/verification.md §5)",
                style="dim",
            )
        )
    if report.stats.get("nusmv_limit"):
        parts.append(
            Text(
                f"NuSMV gave up (native verdict only): {report.stats['nusmv_limit']}",
                style="yellow",
            )
        )
    table = Table("property", "verdict", "detail", show_lines=False)
    for name in PROPERTIES:
        prop = report.properties.get(name)
        if prop is None:
            table.add_row(_TITLES[name], Text("MISSING", style="yellow"), "not checked")
            continue
        mark = Text("PASS", style="green") if prop.holds else Text("FAIL", style="bold red")
        table.add_row(_TITLES[name], mark, Text(prop.detail))
    parts.append(table)
    groups: dict[tuple[str | None, ...], list[PropertyResult]] = {}
    for name in PROPERTIES:
        prop = report.properties.get(name)
        if prop is not None and not prop.holds and prop.counterexample:
            key = tuple(step.input for step in prop.counterexample)
            groups.setdefault(key, []).append(prop)
    for props in groups.values():  # properties failing on the same trace share one table
        parts.append(
            counterexample_table(
                props[0],
                [p.name for p in props],
                leaf_execution=report.mode == "leaf-execution",
                shortest=report.method not in LIFTED,
            )
        )
    stats = report.stats
    if stats:
        parts.append(Text(_stats_line(stats), style="dim"))
    return Group(*parts)


def counterexample_table(
    prop: PropertyResult,
    names: list[str] | None = None,
    leaf_execution: bool | None = None,
    shortest: bool = True,
) -> Table:
    """The shortest counterexample of one failed property (or several sharing it); with
    ``shortest`` false, a lifted one (docs/verification.md §3: real, not always shortest).

    Args:
        prop: the failed property.
        names: the properties sharing this trace (default: ``prop``'s).
        leaf_execution: the inputs are leaf outcomes (shown as "previous leaf returned
            FAILURE"); default: guessed from the inputs.

    Returns:
        The table.
    """
    titles = ", ".join(_TITLES.get(n, n) for n in (names or [prop.name]))
    steps = len(prop.counterexample or []) - 1
    leaf_mode = leaf_execution if leaf_execution is not None else _leaf_outcomes(prop)
    unit = "leaf outcome" if leaf_mode else "input"
    table = Table(
        "step",
        "previous leaf returned" if leaf_mode else "input",
        "source did",
        "result did",
        "states",
        "note",
        title=(
            f"{titles}: {'shortest' if shortest else 'lifted (not always shortest)'} "
            f"counterexample ({steps} {unit}{'' if steps == 1 else 's'})"
        ),
        title_justify="left",
    )
    for step in prop.counterexample or []:
        style = "red" if step.note else None
        given = step.input.upper() if leaf_mode and step.input is not None else step.input
        cells = [
            str(step.step),
            "(start)" if given is None else given,
            _did(step.source_outputs, step.source_status),
            _did(step.result_outputs, step.result_status),
            f"{step.source_state} / {step.result_state}",
            step.note,
        ]
        table.add_row(*(Text(cell) for cell in cells), style=style)
    return table


def _leaf_outcomes(prop: PropertyResult) -> bool:
    inputs = {s.input for s in prop.counterexample or [] if s.input is not None}
    return bool(inputs) and inputs <= {"success", "failure", "running"}


def _did(outputs: list[str], status: str) -> str:
    text = ", ".join(outputs) if outputs else "-"
    return text if status == "running" else f"{text} [{status}]"


def _seconds(value: object) -> str:
    """A duration from the stats as ``1.234 s`` (``-`` when it is not a number)."""
    return f"{value:.3f} s" if isinstance(value, (int, float)) else "-"


def _stats_line(stats: dict[str, object]) -> str:
    keys = ("source_states", "result_states", "product_states", "product_edges")
    shown = [f"{k.replace('_', ' ')} {stats[k]}" for k in keys if k in stats]
    nusmv = stats.get("nusmv")
    if isinstance(nusmv, dict) and "seconds" in nusmv:  # --engine both: each engine's time
        shown.append(f"native {_seconds(stats.get('seconds'))}")
        shown.append(f"NuSMV {_seconds(nusmv['seconds'])}")
    elif "seconds" in stats:
        shown.append(_seconds(stats["seconds"]))
    return ", ".join(shown)


def print_report(report: Report, console: Console | None = None) -> None:
    (console or Console()).print(render(report))


def trace_rows(trace: list[TraceStep]) -> list[dict[str, object]]:
    """Plain rows of a counterexample (for JSON or other front ends)."""
    return [
        {
            "step": s.step,
            "input": s.input,
            "source": s.source_outputs,
            "result": s.result_outputs,
            "note": s.note,
        }
        for s in trace
    ]
