"""Small one-file C++ programs compiled against the cached BehaviorTree.CPP build.

Why: the load check (``btcpp_load.cpp``) and the XSD writer (``runtime/cpp/xsd/
fsmbt_btcpp_xsd.cpp``) are each one source file linked with ``libbehaviortree_cpp``. Both are
compiled on first use into ``bin/<stem>-<sha256 of the source, 16 hex>`` under the build's
prefix, so a changed source is rebuilt and a stale binary is never run; this module is that one
rule, written once.

Costs: the first call per source compiles it (about 10 s on one core); later calls are one
``stat``. Concurrent first calls each compile to a private temporary name and rename it into
place (atomic; they write the same bytes).
"""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
from pathlib import Path

from fsmbt.cache import btcpp_prefix


class ToolBuildError(Exception):
    """The compiler refused the source (the message is the start of its error output)."""


def tool_path(source: Path, stem: str) -> Path:
    """Where the program built from ``source`` is kept (may not exist yet)."""
    digest = hashlib.sha256(source.read_bytes()).hexdigest()[:16]
    return btcpp_prefix() / "bin" / f"{stem}-{digest}"


def library_built() -> bool:
    """The cached BehaviorTree.CPP build has its shared library and headers."""
    prefix = btcpp_prefix()
    return (prefix / "lib" / "libbehaviortree_cpp.so").is_file() and (
        prefix / "include" / "behaviortree_cpp" / "bt_factory.h"
    ).is_file()


def build_tool(source: Path, stem: str, *, build: bool = True) -> Path | None:
    """The program for ``source``, compiled first when ``build`` and the library is there.

    Returns ``None`` when the program is missing and cannot be built here (``build`` false, no
    library, no C++ compiler). Raises ``ToolBuildError`` when the compiler refuses the source,
    ``OSError`` when the cache cannot be written and ``subprocess.TimeoutExpired`` when the
    compiler takes over 10 minutes: each caller decides whether that is an error or a fallback.
    """
    path = tool_path(source, stem)
    if path.is_file() and os.access(path, os.X_OK):
        return path
    if not build or not library_built():
        return None
    compiler = os.environ.get("CXX") or shutil.which("g++") or shutil.which("clang++")
    if compiler is None:
        return None
    prefix = btcpp_prefix()
    path.parent.mkdir(parents=True, exist_ok=True)
    partial = path.with_name(f"{path.name}.{os.getpid()}.tmp")
    done = subprocess.run(
        [compiler, "-std=c++17", "-O1", "-o", str(partial), str(source)]
        + [f"-I{prefix / 'include'}", f"-L{prefix / 'lib'}", f"-Wl,-rpath,{prefix / 'lib'}"]
        + ["-lbehaviortree_cpp", "-lpthread", "-ldl"],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    if done.returncode != 0:
        partial.unlink(missing_ok=True)
        raise ToolBuildError(f"cannot compile {source.name}: {done.stderr.strip()[:400]}")
    partial.replace(path)  # atomic: a concurrent build writes the same bytes
    return path
