"""One vocabulary across commands: every command that reads a model offers every reader option
under the same flag, and the checker's options have one name everywhere."""

from typing import Any

import pytest
import typer.main

from fsmbt.cli import _register_commands, app, main
from fsmbt.cli.options import READ_FLAGS

#: The commands that read a user's model file.
READING_COMMANDS = (
    "diff",
    "conform",
    "testgen",
    "convert",
    "verify",
    "info",
    "render",
    "validate",
    "metrics",
    "translate",
    "batch",
    "simulate",
)


def _commands() -> dict[str, Any]:
    _register_commands()
    group = typer.main.get_command(app)
    return dict(group.commands)  # type: ignore[attr-defined]


def _flags(command: Any) -> set[str]:
    return {flag for param in command.params for flag in getattr(param, "opts", [])}


@pytest.mark.parametrize("name", READING_COMMANDS)
def test_every_reading_command_offers_every_reader_option(name: str) -> None:
    command = _commands()[name]
    missing = [flag for flag in READ_FLAGS if flag not in _flags(command)]
    assert not missing, f"fsmbt {name} lacks {missing}"


@pytest.mark.parametrize("name", ["convert", "verify", "batch"])
def test_the_checker_is_chosen_with_one_flag(name: str) -> None:
    assert "--verify-engine" in _flags(_commands()[name])


def test_version(capsys: pytest.CaptureFixture[str]) -> None:
    from fsmbt import __version__

    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"fsmbt {__version__}"
