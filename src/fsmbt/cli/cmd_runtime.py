"""``fsmbt runtime cpp DIR`` / ``fsmbt runtime python DIR``: write a runtime for converted trees.

- ``cpp``: the header-only BehaviorTree.CPP v4 runtime (``include/fsmbt/lebt.hpp``) and the
  minimal CMake example (``CMakeLists.txt``, ``main.cpp``) - docs/runtime.md;
- ``python``: the Python runtime module (``fsmbt.runtime.python_runtime.write_files``).

Both refuse to replace an existing file unless ``--force`` is given (nothing is written then),
and list the files they wrote. Exit 2 on a refusal or a missing runtime.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from pathlib import Path

import typer

WriteFiles = Callable[..., list[Path]]


def _write(directory: Path, force: bool, write_files: WriteFiles, what: str) -> None:
    from fsmbt.cli import fail

    if directory.exists() and not directory.is_dir():
        raise fail(f"{directory} exists and is not a directory")
    try:
        written = write_files(directory, overwrite=force)
    except FileExistsError as exc:
        raise fail(f"not overwriting existing file(s): {exc} (use --force)") from None
    except OSError as exc:
        raise fail(f"cannot write into {directory}: {exc.strerror or exc}") from None
    print(f"wrote the {what} runtime into {directory}:")
    for path in written:
        print(f"  {path}")


def _python_writer() -> WriteFiles | None:
    """``fsmbt.runtime.python_runtime.write_files`` when that module is installed."""
    try:
        module = importlib.import_module("fsmbt.runtime.python_runtime")
    except ModuleNotFoundError as exc:
        if exc.name in ("fsmbt.runtime.python_runtime", "fsmbt.runtime"):
            return None
        raise
    writer = getattr(module, "write_files", None)
    return writer if callable(writer) else None


def register(app: typer.Typer) -> None:
    runtime_app = typer.Typer(help="Write a runtime that runs converted trees with your actions.",
                              no_args_is_help=True)
    app.add_typer(runtime_app, name="runtime")

    @runtime_app.command("cpp")
    def cpp_command(
        directory: Path = typer.Argument(..., help="where to write (created when missing)"),
        force: bool = typer.Option(False, "--force", help="replace existing files"),
    ) -> None:
        """Write the BehaviorTree.CPP v4 runtime header and a minimal CMake example."""
        from fsmbt.runtime.cpp import write_files

        _write(directory, force, write_files, "C++ (BehaviorTree.CPP v4)")
        print("build: cmake -S DIR -B DIR/build -DCMAKE_PREFIX_PATH=<behaviortree_cpp prefix> "
              "(docs/runtime.md)")

    @runtime_app.command("python")
    def python_command(
        directory: Path = typer.Argument(..., help="where to write (created when missing)"),
        force: bool = typer.Option(False, "--force", help="replace existing files"),
    ) -> None:
        """Write the Python runtime module (py_trees and behaviortreepy)."""
        from fsmbt.cli import fail

        writer = _python_writer()
        if writer is None:
            raise fail("the Python runtime (fsmbt.runtime.python_runtime) is not installed in "
                       "this fsmbt")
        _write(directory, force, writer, "Python")
