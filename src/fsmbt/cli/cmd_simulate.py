"""``fsmbt simulate WORLD MODEL [--against OTHER]``: run a model and another one (by default its
conversion) in the same seeded world and compare their trajectories step by step.

Prints one row per engine (episodes, steps, identical episodes, steps per second, the first
divergence), then the first divergence's report (the step, both sides' behaviour and world
state); with ``-o DIR`` writes ``DIR/simulation.gif`` (one episode side by side: the first
divergent one, else the first) and ``DIR/trajectories.png``. Exit 0 only when every row that ran
is identical in every episode; 1 when one diverges; 2 on bad input (docs/simulation.md).
"""

from __future__ import annotations

from pathlib import Path

import typer

from fsmbt.api_types import ReadOptions
from fsmbt.cli import EXIT_NOT_EQUIVALENT
from fsmbt.cli.options import reads_models


def register(app: typer.Typer) -> None:
    @app.command("simulate")
    @reads_models
    def simulate_command(
        world: str = typer.Argument(..., help="robot or predator-prey."),
        model: Path = typer.Argument(..., help="The model (BT, FSM, or a conversion)."),
        against: Path | None = typer.Option(
            None, "--against", help="The model to compare with (default: MODEL's conversion)."
        ),
        episodes: int = typer.Option(100, "--episodes", "-n", min=1, help="Seeded episodes."),
        seed: int = typer.Option(0, "--seed", help="The first episode's seed."),
        engine: list[str] = typer.Option(
            [],
            "--engine",
            help="fsmbt, btcpp, py_trees, python-statemachine (repeatable; default: all).",
        ),
        convert_engine: str = typer.Option(
            "rules", "--convert-engine", help="Engine of the default conversion (rules, bsd, chds)."
        ),
        role: str | None = typer.Option(
            None, "--role", help="predator-prey: predator or prey (default: from the names)."
        ),
        max_steps: int | None = typer.Option(
            None, "--max-steps", min=1, help="Step limit per episode."
        ),
        output: Path | None = typer.Option(
            None, "-o", "--output", help="Folder for the GIF and the PNG."
        ),
        force: bool = typer.Option(False, "--force", help="Replace existing pictures."),
        show: int | None = typer.Option(
            None,
            "--show",
            min=0,
            help="Episode (0-based) drawn in the pictures (default: the "
            "first divergent one, else the first).",
        ),
        *,
        read: ReadOptions,
    ) -> None:
        """Run MODEL and OTHER (or MODEL's conversion) in the same seeded world; compare the
        trajectories step by step."""
        from fsmbt import api
        from fsmbt.cli import fail
        from fsmbt.sim.agents import ENGINES
        from fsmbt.sim.simulate import simulate

        if show is not None and show >= episodes:
            raise fail(f"--show {show}: there are only {episodes} episodes (0 to {episodes - 1})")
        gif = png = None
        if output is not None:
            if output.exists() and not output.is_dir():
                raise fail(f"{output} exists and is not a directory")
            gif = api.check_destination(output / "simulation.gif", overwrite=force)
            png = api.check_destination(output / "trajectories.png", overwrite=force)
        source = api.load(model, options=read).model
        if against is not None:
            other = api.load(against, options=read.model_copy(update={"format": None})).model
            names = (model.name, against.name)
        else:
            other = api.convert_model(source, convert_engine).model
            names = (model.name, f"conversion ({convert_engine})")
        result = simulate(
            world,
            source,
            other,
            engines=engine or ENGINES,
            episodes=episodes,
            seed=seed,
            role=role,
            names=names,
            max_steps=max_steps,
            keep=show,
        )
        _print(result, names)
        kept = next(
            (
                r.comparison
                for r in result.ran
                if r.comparison is not None and not r.comparison.all_identical
            ),
            None,
        )
        kept = kept or (result.ran[0].comparison if result.ran else None)
        if gif is not None and png is not None and kept is not None and kept.first is not None:
            from fsmbt.sim.pictures import write_gif, write_plot
            from fsmbt.sim.run import worlds
            from fsmbt.sim.world import first_divergence

            left, right = kept.first
            shown = worlds()[world]()
            output.mkdir(parents=True, exist_ok=True)  # type: ignore[union-attr]
            write_plot(left, right, shown, png, names, first_divergence(left, right))
            write_gif(left, right, shown, gif, names)
            print(f"wrote {gif} and {png} (episode seed {left.seed})")
        if not result.all_identical:
            raise typer.Exit(EXIT_NOT_EQUIVALENT)


def _print(result, names: tuple[str, str]) -> None:  # type: ignore[no-untyped-def]
    print(f"world {result.world}, role {result.role}: {names[0]} vs {names[1]}")
    header = (
        f"{'engine':<22} {'runs on (model / other)':<32} {'episodes':>8} {'steps':>8} "
        f"{'identical':>9} {'steps/s':>8}  first divergence"
    )
    print(header)
    print("-" * len(header))
    for row in result.rows:
        if row.comparison is None:
            print(f"{row.engine:<22} {row.note}")
            continue
        c = row.comparison
        first = c.first_divergence
        where = "-" if first is None else f"episode seed {first.seed}, step {first.divergence.step}"
        rate = c.steps / c.seconds if c.seconds > 0 else float("inf")
        runs = f"{row.left_engine} / {row.right_engine}"
        print(
            f"{row.engine:<22} {runs:<32} {len(c.episodes):>8} {c.steps:>8} "
            f"{c.identical:>5}/{len(c.episodes):<3} {rate:>8.0f}  {where}"
        )
    for row in result.ran:
        first = row.comparison.first_divergence if row.comparison else None
        if first is not None and first.divergence is not None:
            print(
                f"\nfirst divergence ({row.engine}), episode seed {first.seed}, "
                + first.divergence.describe(*names)
            )
            break
    if not result.ran:
        print(
            "\nNOT RUN: no engine asked for runs either model (a skipped engine is never "
            "counted as identical)"
        )
        return
    verdict = "IDENTICAL" if result.all_identical else "DIVERGENT"
    print(
        f"\n{verdict}: {sum(r.comparison.identical for r in result.ran if r.comparison)} of "
        f"{sum(len(r.comparison.episodes) for r in result.ran if r.comparison)} episodes "
        "identical"
    )
