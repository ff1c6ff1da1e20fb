"""Finding the NuSMV binary: ``FSMBT_NUSMV``, then ``PATH``, then the machine's build cache.

The build cache is where ``scripts/build_nusmv.sh`` puts it, once per machine and keyed by
version: ``${FSMBT_CACHE:-${XDG_CACHE_HOME:-~/.cache}/fsmbt}/nusmv-2.5.4/bin/NuSMV``; the old
per-checkout place ``<repo>/.cache/nusmv/bin/NuSMV`` is still looked at last.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from functools import lru_cache
from pathlib import Path

from fsmbt.cache import cache_root
from fsmbt.install import build_script
from fsmbt.model.errors import FsmbtError

ENV_VAR = "FSMBT_NUSMV"
_REPO_ROOT = Path(__file__).resolve().parents[4]
#: The build script, shipped in the package (``fsmbt doctor --install nusmv`` runs it)
BUILD_SCRIPT = build_script("nusmv")
NUSMV_VERSION = "2.5.4"
LEGACY_BINARY = _REPO_ROOT / ".cache" / "nusmv" / "bin" / "NuSMV"


def cached_binary() -> Path:
    """Where ``scripts/build_nusmv.sh`` installs NuSMV on this machine."""
    return cache_root() / f"nusmv-{NUSMV_VERSION}" / "bin" / "NuSMV"


class NuSMVNotFound(FsmbtError):
    """NuSMV is needed (``--engine nusmv``) but no working binary was found."""


def candidates() -> list[Path]:
    """Where NuSMV is looked for, in order."""
    found: list[Path] = []
    env = os.environ.get(ENV_VAR)
    if env:
        found.append(Path(env))
    on_path = shutil.which("NuSMV") or shutil.which("nusmv")
    if on_path:
        found.append(Path(on_path))
    found.append(cached_binary())
    found.append(LEGACY_BINARY)
    return found


def find_nusmv() -> Path | None:
    """The first candidate that exists and is executable, or ``None``."""
    env = os.environ.get(ENV_VAR)
    if env and not (Path(env).is_file() and os.access(env, os.X_OK)):
        return None  # an explicit setting that is wrong must not be silently replaced
    for path in candidates():
        if path.is_file() and os.access(path, os.X_OK):
            return path
    return None


def require_nusmv() -> Path:
    """The NuSMV binary, or a clear error saying how to get one."""
    path = find_nusmv()
    if path is None:
        env = os.environ.get(ENV_VAR)
        hint = (
            f"{ENV_VAR}={env} is not an executable file"
            if env
            else f"not on PATH and not built at {cached_binary()}"
        )
        raise NuSMVNotFound(
            f"NuSMV not found ({hint}); run fsmbt doctor --install nusmv or set {ENV_VAR}"
        )
    return path


@lru_cache(maxsize=8)
def nusmv_version(path: str) -> str:
    """The version line NuSMV prints (e.g. ``NuSMV 2.5.4``), or ``"unknown"``."""
    try:
        proc = subprocess.run([path, "-h"], capture_output=True, text=True, timeout=20)
    except (OSError, subprocess.TimeoutExpired):
        return "unknown"
    match = re.search(r"This is (NuSMV [\w.\-]+)", proc.stdout + proc.stderr)
    if match:
        return match.group(1)
    match = re.search(r"NuSMV\s+([0-9][\w.\-]*)", proc.stdout + proc.stderr)
    return f"NuSMV {match.group(1)}" if match else "unknown"
