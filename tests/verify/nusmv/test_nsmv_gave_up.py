"""``--engine both`` when NuSMV reaches its cap: the native verdict, NuSMV's limit said, exit 0/1
(never only an error); ``--engine nusmv`` alone still exits 4 (test_nsmv_limits.py)."""

from __future__ import annotations

import copy
from pathlib import Path

from fsmbt import api, limits
from fsmbt.cli import main
from fsmbt.verify import verify

EXAMPLE = Path(__file__).resolve().parents[3] / "examples" / "paper_fsm.xml"


def test_both_keeps_the_native_verdict_when_nusmv_runs_out(nusmv_binary, monkeypatch) -> None:
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    fsm = api.load(EXAMPLE).model
    mutated = copy.deepcopy(fsm)
    mutated.transitions[0].target = mutated.transitions[-1].target
    with limits.changed(nusmv_max_seconds=0.001):
        same = verify(fsm, copy.deepcopy(fsm), engine="both")
        other = verify(fsm, mutated, engine="both")
    assert same.equivalent and "NuSMV ran out of time" in same.stats["nusmv_limit"]
    assert same.engine == "native" and "NuSMV" in same.engines
    assert other.equivalent is verify(fsm, mutated).equivalent


def test_cli_both_prints_the_verdict_and_the_limit(nusmv_binary, monkeypatch, capsys) -> None:
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    previous = limits.current()
    try:
        code = main(
            [
                "verify",
                str(EXAMPLE),
                str(EXAMPLE),
                "--engine",
                "both",
                "--no-progress",
                "--timeout",
                "0.001",
            ]
        )
    finally:
        limits.use(previous)
    out = capsys.readouterr().out
    assert code == 0
    assert "EQUIVALENT" in out and "NuSMV gave up" in out and "ran out of time" in out
