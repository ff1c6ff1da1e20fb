"""``fsmbt generate``: write N seeded random models (same seed, same files)."""

from __future__ import annotations

from pathlib import Path

import typer

from fsmbt.formats import get_format, write_model
from fsmbt.generate import SCENARIOS, random_bt, random_fsm
from fsmbt.model.errors import InputError


def model_seed(seed: int, index: int) -> str:
    """The seed of the ``index``-th model of a run: independent of N, so files are stable."""
    return f"{seed}:{index}"


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
        breadth: int | None = typer.Option(None, "--breadth", min=1,
                                           help="BT breadth (default 2-10)"),
        extended: bool = typer.Option(False, "--extended",
                                      help="BTs: add Reactive/WithMemory, Parallel, decorators"),
        force: bool = typer.Option(False, "--force", help="overwrite existing files"),
    ) -> None:
        """Write N random FSMs or BTs within the paper's limits, reproducibly from --seed."""
        if kind not in ("fsm", "bt"):
            raise InputError(f"--kind must be fsm or bt, not {kind!r}")
        if scenario not in SCENARIOS:
            raise InputError(f"--scenario must be one of {', '.join(SCENARIOS)}, not {scenario!r}")
        low, high = _size_range(states)
        chosen = get_format(fmt)
        if chosen.write is None or kind not in chosen.kinds:
            raise InputError(f"format '{chosen.name}' cannot write a {kind.upper()}")
        output.mkdir(parents=True, exist_ok=True)
        extension = chosen.extensions[0] if chosen.extensions else ".txt"
        for index in range(n):
            model_rng = model_seed(seed, index)
            if kind == "fsm":
                model = random_fsm(model_rng, None, scenario, min_states=low, max_states=high)
            else:
                model = random_bt(model_rng, depth, breadth, scenario, extended=extended)
            path = output / f"{kind}_{scenario}_{seed}_{index:04d}{extension}"
            write_model(model, path, chosen.name, overwrite=force)
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
