"""report.md's prose and layout are a jinja2 template (evaluate/templates/report.md.j2, issue 25):
rendered with no results, every section and figure is there, the run's facts are filled in, no
template syntax is left, and a missing value is an error (StrictUndefined), not a blank."""

from __future__ import annotations

import jinja2
import pytest

from fsmbt.evaluate import report

RUN = {
    "command": "fsmbt evaluate --quick",
    "written_at": "2026-01-01 00:00:00 UTC",
    "batch_runner": "fsmbt.batch",
    "models": 3,
    "jobs": 7,
    "rows_stored": 5,
    "run_seconds": 1.5,
    "versions": {"python": "3.11.7", "fsmbt": "0.1.0"},
    "invocations": [
        {"finished_at": "t", "before": 0, "ran": 5, "after": 5, "jobs": 7, "seconds": 1.5}
    ],
    "llm_models": "not run: no endpoint",
}


def test_report_template_renders_every_section() -> None:
    text = report.markdown_report(RUN, [], [], [], [], [], [], [], [], [], [])
    headings = [line for line in text.splitlines() if line.startswith("#")]
    assert headings == [
        "# fsmbt evaluation report",
        "## Dataset",
        "## Accuracy (Tables I/VI)",
        "## SCP ablations (Tables II/VII), retries (XII), version sensitivity (XI)",
        "## Behavioural consistency (Tables III/VIII)",
        "## Graphical and active elements (Tables IV/IX)",
        "## Edit distance when a behaviour is added (Tables V/X)",
        "## Input representation (Table XIII)",
        "## Cost per conversion",
        "## NuSMV sample",
        "## The paper's headline numbers next to ours",
    ]
    assert "Command: `fsmbt evaluate --quick` — 2026-01-01 00:00:00 UTC;" in text
    assert "3 models, 7 jobs, 5 rows stored; run 1.5 s." in text
    assert "Versions: python 3.11.7, fsmbt 0.1.0" in text
    assert "| t | 0 | 5 | 5 | 7 | 1.5 |" in text
    for figure in ("accuracy", "elements", "time"):
        assert f"![{figure}](plots/{figure}.svg)" in text
    assert "{{" not in text and "{%" not in text and "{#" not in text
    assert text.endswith("|---|---|---|---|\n")  # the headline table, then one newline


def test_report_template_refuses_a_missing_value() -> None:
    incomplete = {k: v for k, v in RUN.items() if k != "batch_runner"}
    with pytest.raises(jinja2.UndefinedError):
        report.markdown_report(incomplete, [], [], [], [], [], [], [], [], [], [])
