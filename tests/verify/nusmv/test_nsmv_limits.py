"""NuSMV's resource caps (``fsmbt.limits``): memory (RLIMIT_AS in the child) and time, the
``NuSMVLimitError`` that names them, CLI exit code 4, and output decoded with replacement."""

from __future__ import annotations

import stat
from pathlib import Path

import pytest

from fsmbt import limits
from fsmbt.cli import EXIT_LIMIT, main
from fsmbt.model.errors import Hint
from fsmbt.verify.nusmv import build_model
from fsmbt.verify.nusmv.runner import NuSMVLimitError, count_variables, run_nusmv

EXAMPLE = Path(__file__).resolve().parents[3] / "examples" / "paper_fsm.xml"


@pytest.fixture()
def paper_model():
    from fsmbt import api

    fsm = api.load(EXAMPLE).model
    text, names, _context = build_model(fsm, fsm)
    return text, names


def test_memory_cap_is_a_clear_limit_error(nusmv_binary, paper_model, monkeypatch) -> None:
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    text, names = paper_model
    with pytest.raises(NuSMVLimitError) as caught:
        run_nusmv(text, len(names), memory_mb=5)
    error = caught.value
    assert error.resource == "memory" and error.variables == count_variables(text) > 0
    assert f"NuSMV ran out of memory at {error.variables} variables" in str(error)
    assert "FSMBT_MAX_NUSMV_MEMORY_MB" in str(error) and Hint.NUSMV_LIMITS in error.hints


def test_time_cap_is_a_clear_limit_error(nusmv_binary, paper_model, monkeypatch) -> None:
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    text, names = paper_model
    with limits.changed(nusmv_max_seconds=0.001):
        with pytest.raises(NuSMVLimitError) as caught:
            run_nusmv(text, len(names))
    assert caught.value.resource == "time"
    assert "NuSMV ran out of time" in str(caught.value)


def test_within_the_caps_nusmv_answers(nusmv_binary, paper_model, monkeypatch) -> None:
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    text, names = paper_model
    results, _seconds = run_nusmv(text, len(names))
    assert len(results) == len(names) and all(r.holds for r in results)


@pytest.mark.parametrize("flags", [["--nusmv-memory", "5"], ["--timeout", "0.001"]])
def test_cli_exit_code_4(nusmv_binary, monkeypatch, capsys, flags) -> None:
    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    previous = limits.current()
    try:
        code = main(["verify", str(EXAMPLE), str(EXAMPLE), "--engine", "nusmv", "-q", *flags])
    finally:
        limits.use(previous)
    assert code == EXIT_LIMIT == 4
    err = capsys.readouterr().err
    assert "NuSMV ran out of" in err and ("--nusmv-memory" in err or "--timeout" in err)
    assert "Traceback" not in err


def test_output_is_decoded_with_replacement(tmp_path, monkeypatch) -> None:
    """A binary that prints a stray byte next to its verdicts: the verdicts are still read."""
    fake = tmp_path / "NuSMV"
    fake.write_bytes(b"#!/bin/sh\nprintf '*** \\377 garbage\\n-- specification AG x is true\\n'\n")
    fake.chmod(fake.stat().st_mode | stat.S_IEXEC)
    monkeypatch.setenv("FSMBT_NUSMV", str(fake))
    results, _seconds = run_nusmv("MODULE main\nVAR x : boolean;\n", 1)
    assert [r.holds for r in results] == [True]


def test_count_variables() -> None:
    text = (
        "MODULE m\nVAR\n  a : boolean;\n  b : {x, y};\nIVAR i : 0..3;\nDEFINE d := a;\n"
        "ASSIGN init(a) := TRUE;\n"
    )
    assert count_variables(text) == 3


# A model NuSMV needs minutes for: the reachable states of a 2**20 counter, one per iteration.
_ENDLESS = """MODULE main
VAR x : 0..1048575;
ASSIGN init(x) := 0; next(x) := (x + 1) mod 1048576;
SPEC AG (x != 1048575 -> EX TRUE)
"""
_PARENT = """
import sys
from fsmbt.verify.nusmv.runner import run_nusmv
run_nusmv(sys.stdin.read(), 1, timeout=600)
"""


def _children(pid: int) -> list[int]:
    found = []
    for stat_file in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat_file.read_text().rsplit(")", 1)[1].split()
        except (OSError, IndexError):
            continue
        if int(fields[1]) == pid:
            found.append(int(stat_file.parent.name))
    return found


@pytest.mark.skipif(not Path("/proc").is_dir(), reason="needs Linux /proc")
def test_nusmv_dies_with_the_process_that_started_it(nusmv_binary, monkeypatch) -> None:
    """A run killed with SIGKILL (a batch worker, a CLI run) leaves no NuSMV behind."""
    import os
    import signal
    import subprocess
    import sys
    import time

    monkeypatch.setenv("FSMBT_NUSMV", str(nusmv_binary))
    parent = subprocess.Popen([sys.executable, "-c", _PARENT], stdin=subprocess.PIPE, text=True)
    assert parent.stdin is not None
    parent.stdin.write(_ENDLESS)
    parent.stdin.close()
    deadline = time.monotonic() + 60
    children: list[int] = []
    while not children and time.monotonic() < deadline:
        time.sleep(0.1)
        children = _children(parent.pid)
    assert children, "NuSMV did not start"
    (nusmv,) = children
    assert "NuSMV" in Path(f"/proc/{nusmv}/cmdline").read_text(errors="replace")
    os.kill(parent.pid, signal.SIGKILL)
    parent.wait()
    deadline = time.monotonic() + 10
    while Path(f"/proc/{nusmv}").exists() and time.monotonic() < deadline:
        state = Path(f"/proc/{nusmv}/stat").read_text(errors="replace").rsplit(")", 1)[-1].split()
        if state and state[0] == "Z":  # dead, waiting for init to reap it
            break
        time.sleep(0.1)
    alive = (
        Path(f"/proc/{nusmv}").exists()
        and "Z"
        not in Path(f"/proc/{nusmv}/stat")
        .read_text(errors="replace")
        .rsplit(")", 1)[-1]
        .split()[:1]
    )
    if alive:
        os.kill(nusmv, signal.SIGKILL)
    assert not alive, "NuSMV outlived the process that started it"
