"""A diff's result and its three written forms: a Markdown review comment, a JUnit XML file for
CI, and a plain dict (JSON) (docs/diff.md, 'Outputs').

Model text (names, labels, inputs) is escaped for each form: Markdown table cells have ``|`` and
back-ticks neutralised, JUnit goes through ``xml.etree`` (never string-built). Costs: linear in
the groups shown and their witnesses.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import Any

from fsmbt.diff.behaviour import BehaviourDiff, Divergence
from fsmbt.diff.structure import EditOp

#: Witness traces shown in full in the Markdown comment (the rest are listed by their inputs).
MARKDOWN_TRACES = 5


@dataclass
class DiffReport:
    """Everything ``fsmbt diff`` found.

    Attributes:
        old, new: the names the models are shown by (their files).
        old_kind, new_kind: ``"fsm"`` or ``"bt"``.
        behaviour: the behavioural differences.
        script: the structural edit script, ``None`` for models of two kinds.
    """

    old: str
    new: str
    old_kind: str
    new_kind: str
    behaviour: BehaviourDiff
    script: list[EditOp] | None

    @property
    def same(self) -> bool:
        """Same behaviour (the exit code's 0)."""
        return self.behaviour.same

    def summary(self) -> str:
        """One line: the verdict and the counts."""
        b = self.behaviour
        edits = "" if self.script is None else f"; {len(self.script)} structural edit(s)"
        if b.same:
            return f"same behaviour ({b.rule}){edits}"
        return (
            f"behaviour differs: {b.total_groups} group(s) of distinguishing runs "
            f"({b.total_points} frontier point(s); {b.rule}){edits}"
        )

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict."""
        return {
            "old": self.old,
            "new": self.new,
            "same": self.same,
            "rule": self.behaviour.rule,
            "total_groups": self.behaviour.total_groups,
            "total_points": self.behaviour.total_points,
            "groups": [
                {
                    "old_state": g.old_state,
                    "new_state": g.new_state,
                    "input": g.input,
                    "old_does": g.old_does,
                    "new_does": g.new_does,
                    "old_next": g.old_next,
                    "new_next": g.new_next,
                    "witness": list(g.witness),
                    "points": g.points,
                }
                for g in self.behaviour.groups
            ],
            "edits": None
            if self.script is None
            else [
                {
                    "op": e.op,
                    "what": e.what,
                    "old": e.old,
                    "new": e.new,
                    "label": e.label,
                    "detail": e.detail,
                }
                for e in self.script
            ],
            "stats": self.behaviour.stats,
        }


def _cell(text: object) -> str:
    """A Markdown table cell: code-quoted, pipes escaped, one line."""
    value = " ".join(str(text).split()).replace("`", "'").replace("|", "\\|")
    return f"`{value}`" if value else ""


def _on(group: Divergence) -> str:
    return "(start)" if group.input is None and not group.witness else (group.input or "—")


def divergence_text(index: int, group: Divergence) -> str:
    """One line for a terminal: where, on what, OLD vs NEW, the witness."""
    where = (
        group.old_state
        if group.old_state == group.new_state
        else (f"{group.old_state} / {group.new_state}")
    )
    on = f" on {group.input!r}" if group.input is not None else ""
    more = f" [{group.points} product states]" if group.points > 1 else ""
    return (
        f"{index}. at {where}{on}: OLD {group.old_does}; NEW {group.new_does}{more}; "
        f"witness: {' '.join(group.witness) or '(start)'}"
    )


def to_markdown(report: DiffReport, *, picture: str | None = None) -> str:
    """The review comment (GitHub-flavoured Markdown).

    Args:
        report: the diff.
        picture: a link or relative path to the picture, shown when given.
    """
    b = report.behaviour
    lines = [f"### fsmbt diff: {_cell(report.old)} → {_cell(report.new)}", ""]
    verdict = "✅ **same behaviour**" if b.same else "❌ **behaviour changed**"
    lines.append(f"{verdict} — {report.summary()}")
    lines.append("")
    if not b.same:
        shown = len(b.groups)
        extra = f" (first {shown} of {b.total_groups})" if shown < b.total_groups else ""
        lines += [
            f"#### Where the runs part{extra}",
            "",
            "| # | OLD at | NEW at | input | OLD does | NEW does | shortest witness |",
            "|---|---|---|---|---|---|---|",
        ]
        for k, g in enumerate(b.groups, start=1):
            lines.append(
                f"| {k} | {_cell(g.old_state)} | {_cell(g.new_state)} | {_cell(_on(g))} | "
                f"{_cell(g.old_does)} | {_cell(g.new_does)} | "
                f"{_cell(' '.join(g.witness) or '(start)')} |"
            )
        lines.append("")
        for k, g in enumerate(b.groups[:MARKDOWN_TRACES], start=1):
            lines += [
                f"<details><summary>Witness {k}: {len(g.witness)} input(s)</summary>",
                "",
                "| step | input | OLD outputs | NEW outputs | OLD state | NEW state |",
                "|---|---|---|---|---|---|",
            ]
            for st in g.trace:
                lines.append(
                    f"| {st.step} | {_cell(st.input or '(start)')} | "
                    f"{_cell(', '.join(st.source_outputs))} | "
                    f"{_cell(', '.join(st.result_outputs))} | {_cell(st.source_state)} | "
                    f"{_cell(st.result_state)} |"
                )
            lines += ["", "</details>", ""]
    if report.script is None:
        lines += [
            f"#### Structure: OLD is {report.old_kind.upper()}, NEW is "
            f"{report.new_kind.upper()} (no edit script across kinds)",
            "",
        ]
    else:
        lines += [f"#### Edit script ({len(report.script)} edit(s))", ""]
        if not report.script:
            lines.append("No structural change.")
        for e in report.script:
            place = e.new or e.old or ""
            if e.old is not None and e.new is not None and e.old != e.new:
                place = f"{e.old} → {e.new}"
            detail = f" — {e.detail}" if e.detail else ""
            lines.append(f"- **{e.op}** {e.what} {_cell(e.label)} ({_cell(place)}){detail}")
        lines.append("")
    if picture:
        lines += [f"![NEW with the changes highlighted]({picture})", ""]
    return "\n".join(lines)


def to_junit(report: DiffReport) -> str:
    """A JUnit XML document: one test case per group of distinguishing runs (each a failure),
    or one passing case when the behaviour is the same; the edit script as system-out."""
    b = report.behaviour
    suite = ET.Element(
        "testsuite",
        name=f"fsmbt diff {report.old} -> {report.new}",
        tests=str(max(len(b.groups), 1)),
        failures=str(len(b.groups)),
        errors="0",
        time=f"{b.stats.get('seconds', 0.0):.6f}",
    )
    if b.same:
        ET.SubElement(suite, "testcase", classname="fsmbt.diff", name="same behaviour")
    for k, g in enumerate(b.groups, start=1):
        case = ET.SubElement(
            suite,
            "testcase",
            classname="fsmbt.diff",
            name=f"divergence {k} at {g.new_state}" + (f" on {g.input}" if g.input else ""),
        )
        failure = ET.SubElement(case, "failure", message=f"OLD {g.old_does}; NEW {g.new_does}")
        failure.text = divergence_text(k, g)
    out = ET.SubElement(suite, "system-out")
    out.text = "\n".join(e.text() for e in report.script or [])
    suites = ET.Element("testsuites")
    suites.append(suite)
    ET.indent(suites)
    return ET.tostring(suites, encoding="unicode", xml_declaration=True) + "\n"
