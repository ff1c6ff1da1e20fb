"""The ``fsmbt`` command line: one typer app; each command lives in its own ``cmd_*.py`` module.

Every command module defines ``register(app)``; they are discovered here, so adding a command
never edits a shared list. Exit codes: 0 ok (equivalent), 1 not equivalent, 2 bad input,
3 internal error. No traceback reaches the user unless ``FSMBT_DEBUG=1``.
"""

from __future__ import annotations

import importlib
import os
import pkgutil
import sys

import typer

from fsmbt.cli.hints import cli_message
from fsmbt.model.errors import FsmbtError

EXIT_OK = 0
EXIT_NOT_EQUIVALENT = 1
EXIT_BAD_INPUT = 2
EXIT_INTERNAL = 3

app = typer.Typer(
    name="fsmbt",
    help="Convert behavior models between FSMs and behavior trees, and prove the result equivalent.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)


@app.callback()
def _root() -> None:
    """Convert behavior models between FSMs and behavior trees, and prove the result equivalent."""


def _register_commands() -> None:
    package = importlib.import_module("fsmbt.cli")
    for info in sorted(pkgutil.iter_modules(package.__path__), key=lambda i: i.name):
        if info.name.startswith("cmd_"):
            module = importlib.import_module(f"fsmbt.cli.{info.name}")
            module.register(app)


def fail(message: str, code: int = EXIT_BAD_INPUT) -> typer.Exit:
    """Print one line on stderr and return the ``typer.Exit`` to raise."""
    print(f"error: {message}", file=sys.stderr)
    return typer.Exit(code)


def main(argv: list[str] | None = None) -> int:
    """Entry point: run the app, turning every error into one line and an exit code."""
    _register_commands()
    debug = os.environ.get("FSMBT_DEBUG") == "1"
    try:
        # without standalone mode click returns a raised typer.Exit's code instead of exiting
        code = app(args=argv, standalone_mode=False)
    except FsmbtError as exc:
        if debug:
            raise
        print(f"error: {cli_message(exc)}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except typer.Exit as exc:
        return int(exc.exit_code)
    except (RecursionError, MemoryError) as exc:
        if debug:
            raise
        print(f"error: input too large or too deeply nested ({type(exc).__name__})", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        return 130
    except typer.Abort:
        return 130
    except Exception as exc:  # noqa: BLE001 - the last line of defence: never a traceback
        if hasattr(exc, "show") and hasattr(exc, "exit_code"):  # click's usage errors
            exc.show()
            return EXIT_BAD_INPUT
        if debug:
            raise
        print(f"internal error: {type(exc).__name__}: {exc} (FSMBT_DEBUG=1 shows the traceback)",
              file=sys.stderr)
        return EXIT_INTERNAL
    return code if isinstance(code, int) else EXIT_OK


if __name__ == "__main__":
    sys.exit(main())
