"""Session fixture: a NuSMV binary, built by scripts/build_nusmv.sh when missing.

The agreement test imports the mutation suite's families from ``support.mutation_families``
(tests/support, importable through ``pythonpath`` in pyproject.toml) instead of copying them."""

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
