"""``fsmbt runtime cpp DIR`` / ``fsmbt runtime python DIR``: write a runtime for converted trees.

- ``cpp``: the header-only BehaviorTree.CPP v4 runtime (``include/fsmbt/lebt.hpp``) and the
  minimal CMake example (``CMakeLists.txt``, ``main.cpp``) - docs/runtime.md;
- ``python``: a runnable Python example over the Python runtime
  (``fsmbt.runtime.python_runtime.write_files``) - docs/runtime-python.md.

Both refuse to replace an existing file unless ``--force`` is given (nothing is written then),
and list the files they wrote. Exit 2 on a refusal or a missing runtime.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import typer

from fsmbt.cli import sub_app

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


def register(app: typer.Typer) -> None:
    runtime_app = sub_app("Write a runtime that runs converted trees with your actions.")
    app.add_typer(runtime_app, name="runtime")

    @runtime_app.command("cpp")
    def cpp_command(
        directory: Path = typer.Argument(..., help="where to write (created when missing)"),
        force: bool = typer.Option(False, "--force", help="replace existing files"),
    ) -> None:
        """Write the BehaviorTree.CPP v4 runtime header and a minimal CMake example."""
        from fsmbt.runtime.cpp import write_files

        _write(directory, force, write_files, "C++ (BehaviorTree.CPP v4)")
        print(
            "build: cmake -S DIR -B DIR/build -DCMAKE_PREFIX_PATH=<behaviortree_cpp prefix> "
            "(docs/runtime.md)"
        )

    @runtime_app.command("python")
    def python_command(
        directory: Path = typer.Argument(..., help="where to write (created when missing)"),
        force: bool = typer.Option(False, "--force", help="replace existing files"),
    ) -> None:
        """Write a runnable Python example over the runtime (py_trees and behaviortreepy)."""
        from fsmbt.runtime.python_runtime import write_files

        _write(directory, force, write_files, "Python")
