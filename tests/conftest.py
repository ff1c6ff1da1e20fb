"""Session fixtures shared by every test folder: ``nusmv_binary``, the NuSMV binary, built by
scripts/build_nusmv.sh when missing (the NuSMV agreement, CLI and encoding tests of
tests/verify/nusmv, and the semantics tests that encode their node families for NuSMV)."""

from __future__ import annotations

import subprocess

import pytest

from fsmbt.verify.nusmv.binary import BUILD_SCRIPT, find_nusmv


@pytest.fixture(scope="session")
def nusmv_binary():
    path = find_nusmv()
    if path is None and BUILD_SCRIPT.exists():
        proc = subprocess.run([str(BUILD_SCRIPT)], capture_output=True, text=True, timeout=1800)
        path = find_nusmv()
        if path is None:
            pytest.skip(f"NuSMV could not be built: {proc.stderr.strip()[-300:]}")
    if path is None:
        pytest.skip("NuSMV is not available and scripts/build_nusmv.sh is missing")
    return path
