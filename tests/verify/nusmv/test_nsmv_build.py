"""The NuSMV build script and binary discovery."""

from __future__ import annotations

import os
import subprocess
import time

from fsmbt.verify.nusmv.binary import BUILD_SCRIPT, ENV_VAR, find_nusmv, nusmv_version


def test_build_script_is_executable_in_git():
    assert BUILD_SCRIPT.exists()
    assert os.access(BUILD_SCRIPT, os.X_OK)
    mode = subprocess.run(
        ["git", "ls-files", "-s", str(BUILD_SCRIPT)],
        capture_output=True,
        text=True,
        cwd=BUILD_SCRIPT.parent,
    ).stdout.split()
    assert mode and mode[0] == "100755"


def test_binary_is_nusmv_2_5_4(nusmv_binary):
    assert nusmv_version(str(nusmv_binary)) == "NuSMV 2.5.4"


def test_second_build_is_a_cached_no_op(nusmv_binary, monkeypatch):
    monkeypatch.delenv(ENV_VAR, raising=False)
    if find_nusmv() is None:
        return  # only a PATH binary: the script would build (not a no-op)
    started = time.perf_counter()
    proc = subprocess.run([str(BUILD_SCRIPT)], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0
    if "already built" in proc.stdout:
        assert time.perf_counter() - started < 30


def test_env_var_pointing_nowhere_is_not_silently_replaced(monkeypatch, tmp_path):
    monkeypatch.setenv(ENV_VAR, str(tmp_path / "no-such-NuSMV"))
    assert find_nusmv() is None


def test_doctor_reports_nusmv_and_fails_when_missing(nusmv_binary, monkeypatch, tmp_path):
    from fsmbt.cli import main

    assert main(["doctor"]) in (0, 1)  # other tools may be missing on a machine
    from fsmbt.cli.cmd_doctor import checks

    assert next(c for c in checks() if c.name == "NuSMV").ok
    monkeypatch.setenv(ENV_VAR, str(tmp_path / "missing"))
    assert not next(c for c in checks() if c.name == "NuSMV").ok
    assert main(["doctor"]) == 1
