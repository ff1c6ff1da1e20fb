"""``fsmbt runtime cpp DIR [MODEL]`` / ``fsmbt runtime python DIR [MODEL]``.

Without MODEL: the LEBT runtime for converted trees -

- ``cpp``: the header-only BehaviorTree.CPP v4 runtime (``include/fsmbt/lebt.hpp``) and the
  minimal CMake example (``CMakeLists.txt``, ``main.cpp``) - docs/runtime.md;
- ``python``: a runnable Python example over the Python runtime
  (``fsmbt.runtime.python_runtime.write_files``) - docs/runtime-python.md.

Both refuse to replace an existing file unless ``--force`` is given (nothing is written then),
and list the files they wrote.

With MODEL (a BehaviorTree.CPP v4 tree): the migration path's skeleton
(``fsmbt.runtime.skeleton``) - the tree's leaf classes for the user to fill in, their
registration or tree builder, and a main; for the tree of an event-driven machine (the
dispatch form or an LEBT, ``cpp`` only) the runtime header, one method per state action and a
main that posts events (``fsmbt.runtime.skeleton.machine``). Generated files are rewritten on every run; the
user's files (``nodes/``, ``main``, ``CMakeLists.txt``) are written once and never replaced
(``--force`` only replaces files at generated paths that fsmbt did not write); a changed port
list is printed. Exit 2 on bad input or a refusal, with one line naming the cause.
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


def _skeleton(directory: Path, model: Path, force: bool, language: str) -> None:
    from fsmbt.cli import fail
    from fsmbt.model.errors import FsmbtError
    from fsmbt.runtime.skeleton import write_skeleton

    try:
        report = write_skeleton(model, directory, language, force=force)
    except FsmbtError as exc:
        raise fail(str(exc)) from None
    except OSError as exc:
        raise fail(f"cannot write into {directory}: {exc.strerror or exc}") from None
    what = "C++ (BehaviorTree.CPP v4)" if language == "cpp" else "Python (py_trees)"
    print(f"wrote the {what} skeleton of {model} into {directory}:")
    for path in report.written:
        print(f"  {path}")
    for path in report.kept:
        print(f"  {path} (yours: kept)")
    for line in report.changes:
        print(f"changed: {line}")


def register(app: typer.Typer) -> None:
    runtime_app = sub_app("Write a runtime that runs converted trees with your actions.")
    app.add_typer(runtime_app, name="runtime")

    @runtime_app.command("cpp")
    def cpp_command(
        directory: Path = typer.Argument(..., help="where to write (created when missing)"),
        model: Path | None = typer.Argument(
            None,
            help="a BehaviorTree.CPP v4 tree: write its leaf classes (the skeleton); for a "
            "dispatch or LEBT tree, one method per state action and a main",
        ),
        force: bool = typer.Option(False, "--force", help="replace existing files"),
    ) -> None:
        """Write the C++ runtime and a CMake example, or with MODEL the tree's C++ skeleton."""
        if model is not None:
            _skeleton(directory, model, force, "cpp")
            print("build: cmake -S DIR -B DIR/build -DCMAKE_PREFIX_PATH=<behaviortree_cpp prefix>")
            return
        from fsmbt.runtime.cpp import write_files

        _write(directory, force, write_files, "C++ (BehaviorTree.CPP v4)")
        print(
            "build: cmake -S DIR -B DIR/build -DCMAKE_PREFIX_PATH=<behaviortree_cpp prefix> "
            "(docs/runtime.md)"
        )

    @runtime_app.command("python")
    def python_command(
        directory: Path = typer.Argument(..., help="where to write (created when missing)"),
        model: Path | None = typer.Argument(
            None, help="a BehaviorTree.CPP v4 tree: write its py_trees leaf classes (skeleton)"
        ),
        force: bool = typer.Option(False, "--force", help="replace existing files"),
    ) -> None:
        """Write a runnable LEBT example, or with MODEL the tree's py_trees skeleton."""
        if model is not None:
            _skeleton(directory, model, force, "python")
            print(f"run: cd {directory} && python main.py")
            return
        from fsmbt.runtime.python_runtime import write_files

        _write(directory, force, write_files, "Python")
