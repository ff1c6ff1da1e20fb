"""Session fixture: a NuSMV binary, built by scripts/build_nusmv.sh when missing.

tests/verify is put on ``sys.path`` so the agreement test imports the mutation suite's families
(``mutation_families``) instead of copying them; pytest's default import mode adds only each
test file's own directory."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from fsmbt.verify.nusmv.binary import BUILD_SCRIPT, find_nusmv

VERIFY_TESTS = str(Path(__file__).resolve().parents[1] / "verify")
if VERIFY_TESTS not in sys.path:
    sys.path.append(VERIFY_TESTS)


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
