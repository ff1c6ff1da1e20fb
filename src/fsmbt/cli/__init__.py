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

from fsmbt.cli import stopping
from fsmbt.cli.hints import cli_message
from fsmbt.model.errors import FsmbtError

EXIT_OK = 0
EXIT_NOT_EQUIVALENT = 1
EXIT_BAD_INPUT = 2
EXIT_INTERNAL = 3
#: A resource cap of a verification engine was reached (NuSMV's memory or time, the native
#: checker's time; docs/cli.md).
EXIT_LIMIT = 4

app = typer.Typer(
    name="fsmbt",
    help="Convert behavior models between FSMs and behavior trees, and prove the result equivalent.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    # plain click help: paragraphs re-wrapped to the terminal, flags without a "<bool>" type,
    # choices shown as <a|b>
    rich_markup_mode=None,
)


def sub_app(help_text: str) -> typer.Typer:
    """A command group (``fsmbt llm ...``) with the same help style as the main app."""
    return typer.Typer(help=help_text, no_args_is_help=True, rich_markup_mode=None)


def _print_version(asked: bool) -> None:
    """``--version``: the package's version, then exit 0."""
    if asked:
        from fsmbt import __version__

        print(f"fsmbt {__version__}")
        raise typer.Exit(EXIT_OK)


@app.callback()
def _root(
    version: bool = typer.Option(
        False,
        "--version",
        is_eager=True,
        callback=_print_version,
        help="print fsmbt's version and exit",
    ),
) -> None:
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


def _silence_stdout() -> None:
    """Point stdout at /dev/null so the interpreter's final flush cannot fail again."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass


def _is_engine_limit(exc: FsmbtError) -> bool:
    """Whether ``exc`` is a verification engine's resource cap (exit ``EXIT_LIMIT``)."""
    from fsmbt.verify.native import CheckerTimeLimitError
    from fsmbt.verify.nusmv.runner import NuSMVLimitError

    return isinstance(exc, NuSMVLimitError | CheckerTimeLimitError)


def main(argv: list[str] | None = None) -> int:
    """Entry point: run the app, turning every error into one line and an exit code; SIGTERM
    and SIGINT are a requested stop (exit 0, ``fsmbt.cli.stopping``)."""
    _register_commands()
    with stopping.installed():
        return _run(argv)


def _run(argv: list[str] | None) -> int:
    debug = os.environ.get("FSMBT_DEBUG") == "1"
    try:
        # without standalone mode click returns a raised typer.Exit's code instead of exiting
        code = app(args=argv, standalone_mode=False)
        if code == 130 and stopping.stop_was_requested():  # typer's code for an interruption
            print("fsmbt: stopped on request", file=sys.stderr)
            return EXIT_OK
    except FsmbtError as exc:
        if debug:
            raise
        print(f"error: {cli_message(exc)}", file=sys.stderr)
        return EXIT_LIMIT if _is_engine_limit(exc) else EXIT_BAD_INPUT
    except typer.Exit as exc:
        return int(exc.exit_code)
    except (RecursionError, MemoryError) as exc:
        if debug:
            raise
        print(
            f"error: input too large or too deeply nested ({type(exc).__name__})", file=sys.stderr
        )
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print("fsmbt: stopped on request", file=sys.stderr)
        return EXIT_OK
    except BrokenPipeError:
        # the reader went away (``fsmbt llm prompt x | head``): what it wanted, it got
        _silence_stdout()
        return EXIT_OK
    except SystemExit as exc:
        # click turns a closed pipe into exit 1 after wrapping stdout; that is not a failure
        if type(sys.stdout).__name__ == "PacifyFlushWrapper":
            _silence_stdout()
            return EXIT_OK
        raise exc
    except typer.Abort as exc:
        if stopping.requested_stop(exc):
            print("fsmbt: stopped on request", file=sys.stderr)
            return EXIT_OK
        return 130
    except Exception as exc:  # noqa: BLE001 - the last line of defence: never a traceback
        if hasattr(exc, "show") and hasattr(exc, "exit_code"):  # click's usage errors
            exc.show()
            return EXIT_BAD_INPUT
        if debug:
            raise
        print(
            f"internal error: {type(exc).__name__}: {exc} (FSMBT_DEBUG=1 shows the traceback)",
            file=sys.stderr,
        )
        return EXIT_INTERNAL
    return code if isinstance(code, int) else EXIT_OK


if __name__ == "__main__":
    sys.exit(main())
