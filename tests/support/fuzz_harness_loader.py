"""Load ``fuzz/fuzz_readers.py`` (a script, not a package) for the tests that share its rule."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "fuzz" / "fuzz_readers.py"
REGRESSIONS = ROOT / "tests" / "fuzz" / "regressions"


def harness() -> ModuleType:
    """The fuzz script as a module (imported once)."""
    name = "fsmbt_fuzz_readers"
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, SCRIPT)
        assert spec is not None and spec.loader is not None
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
    return sys.modules[name]
