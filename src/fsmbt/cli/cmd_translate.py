"""``fsmbt translate``: the same model in another format, with every loss named.

``fsmbt translate IN -o OUT [--to FMT] [--from FMT] [--force] [--flatten] [-O KEY=VALUE]``:
reads IN (``-O`` passes reader options, e.g. ``machine=NAME`` for SMACH), writes
OUT in FMT (default: from OUT's extension; stdout when there is no ``-o``, then ``--to`` is
needed). The reader's warnings and one ``warning:`` line per thing the target cannot hold go
to stderr; a loss that changes the model's behaviour is an error (exit 2) and nothing is
written. The logic is ``fsmbt.api.translate``; this module parses options and prints.
Exit codes: 0 translated, 2 bad input or a refused translation.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import typer

from fsmbt import api
from fsmbt.api_types import ReadOptions, read_options
from fsmbt.cli.options import reads_models


def register(app: typer.Typer) -> None:
    @app.command("translate")
    @reads_models
    def translate_command(
        source: Path = typer.Argument(..., help="the model to translate (any readable format)"),
        output: Path | None = typer.Option(
            None, "-o", "--output", help="write here (default: stdout)"
        ),
        to: str | None = typer.Option(
            None, "--to", help="target format (default: from -o's extension)"
        ),
        force: bool = typer.Option(False, "--force", help="overwrite an existing output file"),
        flatten: bool = typer.Option(
            False,
            "--flatten",
            help="write a hierarchical FSM as its flat machine (named as a loss)",
        ),
        as_json: bool = typer.Option(False, "--json", help="print a JSON summary on stdout"),
        option: list[str] = typer.Option(
            [],
            "--option",
            "-O",
            help="a reader option "
            "KEY=VALUE, e.g. machine=sm_top (SMACH: which "
            "top-level container), behaviour=MySM (FlexBE)",
        ),
        *,
        read: ReadOptions,
    ) -> None:
        """Write the same model in another format; name whatever the target cannot hold."""
        if output is None and to is None:
            print("error: name the target format with --to (or give -o FILE)", file=sys.stderr)
            raise typer.Exit(2)
        options: dict[str, object] = {}
        for item in option:
            key, sep, value = item.partition("=")
            if not sep or not key:
                print(f"error: --option takes KEY=VALUE, not {item!r}", file=sys.stderr)
                raise typer.Exit(2)
            options[key.strip()] = value.strip()
        if options:
            read = read_options(read, **options)
        _loaded, result, _report = api.translate(
            source, output, to=to, read=read, flatten=flatten, overwrite=force
        )
        summary = {
            "source": str(source),
            "from": result.source_format,
            "to": result.target_format,
            "output": str(output) if output is not None else None,
            "warnings": result.warnings,
            "losses": result.losses,
            "verified_equivalent": result.verified,
        }
        if as_json:
            if output is None:
                summary["model"] = result.text
            print(json.dumps(summary, indent=2))
            return
        if output is None:
            sys.stdout.write(result.text)
        for warning in result.warnings:
            print(f"warning: {warning}", file=sys.stderr)
        for loss in result.losses:
            print(f"warning: {result.target_format}: {loss}", file=sys.stderr)
        check = "read back and verified equivalent" if result.verified else "not read back"
        print(
            f"translated {source} ({result.source_format or '?'}) -> "
            f"{output or 'stdout'} ({result.target_format}): {len(result.losses)} "
            f"loss(es), {check}",
            file=sys.stderr,
        )
