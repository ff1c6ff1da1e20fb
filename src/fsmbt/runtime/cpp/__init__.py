"""The C++ runtime of fsmbt's LEBTs for BehaviorTree.CPP v4: shipped files, cache, driver.

Shipped with the package (written out by ``fsmbt runtime cpp DIR``):
- ``include/fsmbt/lebt.hpp``: the header-only runtime (``LebtGuard``, ``LebtState``,
  ``registerLebtNodes``, ``ActionRegistry``, ``LebtRunner``), docs/runtime.md;
- ``example/CMakeLists.txt`` and ``example/main.cpp``: the minimal CMake project a ROS 2 package
  can copy;
- ``driver/fsmbt_lebt_driver.cpp``: the driver the differential test and the benchmark run (not
  written out; ``scripts/build_btcpp.sh`` compiles it).

The build cache lives outside the checkout, keyed by the BehaviorTree.CPP version:
``${FSMBT_CACHE:-${XDG_CACHE_HOME:-~/.cache}/fsmbt}/btcpp-4.8.2-sqlite/`` holds the installed library
and ``bin/fsmbt_lebt_driver`` with, next to it, the sha256 of the header and driver sources it
was built from. ``find_driver()`` is the one way Python finds the driver: it returns it only when
that hash matches this package's sources (a stale driver would test old code).

``DriverSession`` runs one driver process per tree and feeds it many event sequences (a
``%reset`` line between them): one process start per model, not per sequence.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from fsmbt.cache import BTCPP_VERSION, btcpp_prefix
from fsmbt.install import build_script as install_script
from fsmbt.model.errors import FsmbtError

PACKAGE_DIR = Path(__file__).resolve().parent
HEADER = PACKAGE_DIR / "include" / "fsmbt" / "lebt.hpp"
DRIVER_SOURCE = PACKAGE_DIR / "driver" / "fsmbt_lebt_driver.cpp"
EXAMPLE_DIR = PACKAGE_DIR / "example"
DRIVER_NAME = "fsmbt_lebt_driver"
RESET = "%reset"
#: Files ``fsmbt runtime cpp DIR`` writes: (path inside the package, path inside DIR).
WRITTEN_FILES: tuple[tuple[Path, str], ...] = (
    (HEADER, "include/fsmbt/lebt.hpp"),
    (EXAMPLE_DIR / "CMakeLists.txt", "CMakeLists.txt"),
    (EXAMPLE_DIR / "main.cpp", "main.cpp"),
)


class CppRuntimeError(FsmbtError):
    """The C++ driver is missing, stale, or failed on a tree."""


def build_script() -> Path:
    """The build script of BehaviorTree.CPP and the driver, shipped in the package
    (``fsmbt doctor --install btcpp`` runs it; a checkout's ``scripts/build_btcpp.sh`` too)."""
    return install_script("btcpp")


def library_prefix() -> Path:
    """Where BehaviorTree.CPP is installed by the build script (may not exist)."""
    return btcpp_prefix()


def library_built() -> bool:
    """The installed CMake package and shared library are there."""
    prefix = library_prefix()
    return (
        prefix / "lib" / "cmake" / "behaviortree_cpp" / "behaviortree_cppConfig.cmake"
    ).is_file() and (prefix / "lib" / "libbehaviortree_cpp.so").is_file()


def sources_hash() -> str:
    """sha256 of the header followed by the driver source (what the build script records)."""
    digest = hashlib.sha256()
    digest.update(HEADER.read_bytes())
    digest.update(DRIVER_SOURCE.read_bytes())
    return digest.hexdigest()


def driver_path() -> Path:
    return library_prefix() / "bin" / DRIVER_NAME


@dataclass(frozen=True)
class RuntimeStatus:
    """What ``fsmbt doctor`` reports about the C++ runtime."""

    library: Path | None  # the install prefix when the library is built
    driver: Path | None  # the driver when built from the current sources
    problem: str  # "" when both are there, else what is missing


def status() -> RuntimeStatus:
    """Library and driver, found or not, with the reason when not."""
    prefix = library_prefix()
    library = prefix if library_built() else None
    driver = find_driver()
    if library is None:
        return RuntimeStatus(None, None, f"BehaviorTree.CPP {BTCPP_VERSION} not built at {prefix}")
    if driver is None:
        path = driver_path()
        what = "stale (built from other sources)" if path.exists() else "not built"
        return RuntimeStatus(library, None, f"driver {what}: {path}")
    return RuntimeStatus(library, driver, "")


def find_driver() -> Path | None:
    """The driver built from this package's header and driver sources, or ``None``."""
    path = driver_path()
    stamp = path.with_name(DRIVER_NAME + ".sources")
    if not (path.is_file() and os.access(path, os.X_OK) and stamp.is_file()):
        return None
    if stamp.read_text(encoding="utf-8").strip() != sources_hash():
        return None
    return path


def require_driver() -> Path:
    """The driver, or a ``CppRuntimeError`` that says how to build it."""
    path = find_driver()
    if path is None:
        raise CppRuntimeError(
            f"the C++ LEBT driver is not built ({status().problem}); "
            "run fsmbt doctor --install btcpp (needs cmake and g++)"
        )
    return path


# -- writing the runtime out ---------------------------------------------------------------------
def write_files(directory: Path, *, overwrite: bool) -> list[Path]:
    """Write the header and the CMake example into ``directory``.

    Args:
        directory: where to write (created when missing).
        overwrite: replace existing files; without it nothing is written when any exists.

    Returns:
        The files written, in order.

    Raises:
        FileExistsError: a target exists and ``overwrite`` is false (nothing was written).
    """
    targets = [(source, directory / relative) for source, relative in WRITTEN_FILES]
    existing = [target for _, target in targets if target.exists()]
    if existing and not overwrite:
        raise FileExistsError(", ".join(str(p) for p in existing))
    written: list[Path] = []
    for source, target in targets:
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(source, target)
        written.append(target)
    return written


# -- running the driver ----------------------------------------------------------------------------
@dataclass(frozen=True)
class DriverStep:
    """One line of the driver's output: the start (``event`` None) or one macro step."""

    event: str | None
    actions: tuple[str, ...]
    terminated: bool
    state: str


class DriverSession:
    """One driver process per tree file, fed every event sequence at once."""

    def __init__(
        self,
        tree_file: Path,
        *,
        driver: Path | None = None,
        table: bool = False,
        dispatch: bool = False,
        start: str | None = None,
        tick: str | None = None,
        timeout: float = 120.0,
    ) -> None:
        self.tree_file = tree_file
        self.tick = tick  # "once", "exactly-once", "auto" (the driver's default) or None
        self.driver = driver or require_driver()
        self.table = table
        self.dispatch = dispatch  # the tree is the dispatch form (docs/semantics.md section 12)
        self.start = start
        self.timeout = timeout

    def _command(self, extra: Sequence[str] = ()) -> list[str]:
        command = [str(self.driver), str(self.tree_file)]
        if self.table:
            command.append("--table")
        if self.dispatch:
            command.append("--dispatch")
        if self.start is not None:
            command += ["--start", self.start]
        if self.tick is not None:
            command += ["--tick", self.tick]
        return command + list(extra)

    def run(self, sequences: Sequence[Sequence[str]]) -> list[list[DriverStep]]:
        """Each sequence from a fresh start; per sequence: the start step, then one per event.

        Raises:
            CppRuntimeError: the driver failed (its one-line error is in the message) or an
                event contains a line break.
        """
        lines: list[str] = []
        for index, events in enumerate(sequences):
            if index:
                lines.append(RESET)
            for event in events:
                if "\n" in event or "\r" in event or not event or event == RESET:
                    raise CppRuntimeError(f"event {event!r} cannot be sent to the driver")
                lines.append(event)
        out = self._call(lines)
        runs: list[list[DriverStep]] = []
        for raw in out.splitlines():
            record = json.loads(raw)
            step = DriverStep(
                record["event"],
                tuple(record["actions"]),
                bool(record["terminated"]),
                record["state"],
            )
            if step.event is None:
                runs.append([])
            runs[-1].append(step)
        if len(runs) != max(1, len(sequences)):
            raise CppRuntimeError(f"driver printed {len(runs)} runs for {len(sequences)} sequences")
        return runs

    def bench(self, sequences: Sequence[Sequence[str]], repeat: int) -> dict[str, float]:
        """The driver's ``--bench`` figures (only the macro steps are timed, in C++)."""
        lines: list[str] = []
        for index, events in enumerate(sequences):
            if index:
                lines.append(RESET)
            lines.extend(events)
        out = self._call(lines, ["--bench", str(repeat)])
        return dict(json.loads(out))

    def _call(self, lines: list[str], extra: Sequence[str] = ()) -> str:
        try:
            proc = subprocess.run(
                self._command(extra),
                input="\n".join(lines) + "\n",
                capture_output=True,
                text=True,
                encoding="utf-8",
                timeout=self.timeout,
            )
        except subprocess.TimeoutExpired:
            raise CppRuntimeError(
                f"driver timed out after {self.timeout} s on {self.tree_file}"
            ) from None
        if proc.returncode != 0:
            message = (
                proc.stderr.strip().splitlines()[-1]
                if proc.stderr.strip()
                else (f"exit status {proc.returncode}")
            )
            raise CppRuntimeError(f"driver failed on {self.tree_file}: {message}")
        return proc.stdout
