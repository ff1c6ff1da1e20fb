"""Session fixture: the C++ LEBT driver built by scripts/build_btcpp.sh.

A machine without cmake or a C++ compiler skips the C++ tests (saying which tool is missing); a
machine that has them but no driver built from the current sources FAILS (run the build script:
scripts/setup.sh does), so CI cannot pass by skipping.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from fsmbt.runtime.cpp import build_script, find_driver, status


def missing_tools() -> list[str]:
    """The build tools this machine lacks (empty: the C++ runtime can be built here)."""
    missing = [tool for tool in ("cmake",) if shutil.which(tool) is None]
    if not any(shutil.which(cxx) for cxx in ("g++", "c++", "clang++")):
        missing.append("a C++ compiler")
    return missing


@pytest.fixture(scope="session")
def driver() -> Path:
    path = find_driver()
    if path is not None:
        return path
    missing = missing_tools()
    if missing:
        pytest.skip(f"C++ runtime cannot be built on this machine: missing {', '.join(missing)}")
    pytest.fail(f"C++ runtime not built ({status().problem}): run {build_script()}")
