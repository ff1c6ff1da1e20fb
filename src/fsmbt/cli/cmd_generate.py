"""``fsmbt generate``: write N seeded random models (same seed, same files).

Option parsing and printing around ``fsmbt.generate.generate_models`` (what model i of a run
is) and ``fsmbt.api.write`` (atomic, never overwriting without ``--force``).
"""

from __future__ import annotations

from pathlib import Path

import typer

from fsmbt import api
from fsmbt.formats import get_format
from fsmbt.generate import DatasetSpec, generate_models
from fsmbt.generate.dataset import DEFAULT_MAX_NODES
from fsmbt.model.errors import InputError


def register(app: typer.Typer) -> None:
    @app.command("generate")
    def generate_command(
        kind: str = typer.Option(..., "--kind", help="fsm or bt"),
        output: Path = typer.Option(..., "-o", "--output", help="directory to write into"),
        scenario: str = typer.Option("basic", "--scenario", help="basic, robot or game"),
        n: int = typer.Option(10, "--n", min=1, max=1_000_000, help="how many models"),
        seed: int = typer.Option(0, "--seed", help="base seed; model i uses '<seed>:<i>'"),
        fmt: str = typer.Option("json", "--format", help="output format (see `fsmbt formats`)"),
        states: str = typer.Option("2-30", "--states", help="FSM size: N or MIN-MAX"),
        depth: int | None = typer.Option(None, "--depth", min=2, help="BT depth (default 2-10)"),
        breadth: int | None = typer.Option(
            None, "--breadth", min=1, help="BT breadth (default 2-10)"
        ),
        max_nodes: int = typer.Option(
            DEFAULT_MAX_NODES,
            "--max-nodes",
            min=1,
            help="BT node budget, soft: past it no new control "
            "node is opened, but open ones keep their breadth "
            "and the spine keeps its --depth levels",
        ),
        extended: bool = typer.Option(
            False, "--extended", help="BTs: add Reactive/WithMemory, Parallel, decorators"
        ),
        force: bool = typer.Option(False, "--force", help="overwrite existing files"),
    ) -> None:
        """Write N random FSMs or BTs within the paper's limits, reproducibly from --seed."""
        low, high = _size_range(states)
        spec = DatasetSpec(kind, scenario, seed, low, high, depth, breadth, extended, max_nodes)
        spec.check()
        chosen = get_format(fmt)
        if chosen.write is None or kind not in chosen.kinds:
            raise InputError(f"format '{chosen.name}' cannot write a {kind.upper()}")
        extension = chosen.extensions[0] if chosen.extensions else ".txt"
        output.mkdir(parents=True, exist_ok=True)
        for stem, model in generate_models(spec, n):
            api.write(model, output / f"{stem}{extension}", chosen.name, overwrite=force)
        print(f"wrote {n} {kind.upper()}s ({scenario}, seed {seed}) to {output}")


def _size_range(text: str) -> tuple[int, int]:
    try:
        if "-" in text:
            low_text, high_text = text.split("-", 1)
            low, high = int(low_text), int(high_text)
        else:
            low = high = int(text)
    except ValueError:
        raise InputError(f"--states must be N or MIN-MAX, not {text!r}") from None
    if not 1 <= low <= high:
        raise InputError(f"--states must satisfy 1 <= MIN <= MAX, not {text!r}")
    return low, high
