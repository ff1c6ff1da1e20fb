"""``fsmbt formats``: list the formats fsmbt reads and writes."""

from __future__ import annotations

import typer
from rich.console import Console
from rich.table import Table

from fsmbt.formats import formats


def register(app: typer.Typer) -> None:
    @app.command("formats")
    def formats_command() -> None:
        """List the file formats, what they hold, and whether fsmbt reads and writes them."""
        table = Table("format", "extensions", "models", "read", "write")
        # wide enough for its header on an 80-column terminal, next to long extension lists
        table.add_column("cannot hold", min_width=len("cannot hold"))
        table.add_column("description")
        for fmt in formats():
            table.add_row(
                fmt.name,
                " ".join(fmt.extensions),
                ", ".join(sorted(fmt.kinds)),
                "yes" if fmt.read else "-",
                "yes" if fmt.write else "-",
                fmt.cannot_hold or "-",
                fmt.description,
            )
        Console().print(table)
