"""Build fsmbt's optional engines into the machine's cache (``fsmbt doctor --install``).

NuSMV 2.5.4 (the second verification engine, docs/nusmv.md) and BehaviorTree.CPP 4.8.2 with the
LEBT driver (the C++ runtime, docs/runtime.md) are not Python packages: they are compiled from
source into ``fsmbt.cache.cache_root()`` (``~/.cache/fsmbt``), once per machine. Their build
scripts ship inside this package (``build_nusmv.sh``, ``build_btcpp.sh``), so an installed
fsmbt builds them with ``fsmbt doctor --install nusmv|btcpp`` exactly as a checkout's
``scripts/setup.sh`` does (``scripts/build_*.sh`` run these same files). Nothing is fetched when
fsmbt is installed; the builds download their sources when asked to (NuSMV's from the pynusmv
sdist on PyPI, BehaviorTree.CPP's release archive) and need a C/C++ tool chain (the scripts say
which tool is missing, in one line).

Cost: minutes for a first build (NuSMV about 2, BehaviorTree.CPP about 5 on 2 cores); a second
run returns at once.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent

#: Engine name -> its build script in this package.
SCRIPTS: dict[str, Path] = {
    "nusmv": HERE / "build_nusmv.sh",
    "btcpp": HERE / "build_btcpp.sh",
}


def build_script(engine: str) -> Path:
    """The build script of ``engine`` (``nusmv`` or ``btcpp``).

    Raises:
        KeyError: an engine this module does not build.
    """
    return SCRIPTS[engine]


def install(engine: str, *, python: str | None = None) -> int:
    """Build ``engine`` into the cache, its progress on this process's stdout/stderr.

    Args:
        engine: ``nusmv`` or ``btcpp``.
        python: The interpreter whose ``pip download`` fetches sources (default: this one).

    Returns:
        The build script's exit status (0 built or already there; 2 a missing tool chain).
    """
    env = dict(os.environ)
    env.setdefault("PYTHON", python or sys.executable)
    done = subprocess.run(["bash", str(build_script(engine))], env=env, check=False)
    return done.returncode
