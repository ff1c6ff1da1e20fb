"""``fsmbt testgen SPEC --tree TREE -o DIR``: a behaviour test suite for TREE from SPEC.

Exit 0 written (the suite passes on TREE when TREE behaves like SPEC), 2 bad input (SPEC or
TREE does not load, TREE is not a behavior tree, DIR is not empty without ``--force``). The
work is ``fsmbt.testgen`` (docs/testgen.md).
"""

from __future__ import annotations

from pathlib import Path

import typer

from fsmbt import api, testgen
from fsmbt.api_types import ReadOptions
from fsmbt.cli.options import reads_models
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import InputError, SourceLocation


def register(app: typer.Typer) -> None:
    @app.command("testgen")
    @reads_models
    def testgen_command(
        spec: Path = typer.Argument(..., help="The specification (FSM or BT)."),
        tree: Path = typer.Option(..., "--tree", help="The behavior tree under test."),
        output: Path = typer.Option(..., "-o", "--output", help="The folder to write."),
        force: bool = typer.Option(False, "--force", help="Write into a non-empty folder."),
        score: bool = typer.Option(
            True, "--score/--no-score", help="Compute the mutation score (mutants of TREE)."
        ),
        *,
        read: ReadOptions,
    ) -> None:
        """Generate input sequences covering every transition of SPEC, with the expected
        observations, as pytest files running TREE on py_trees and BehaviorTree.CPP."""
        loaded_spec = api.load(spec, options=read)
        loaded_tree = api.load(tree, options=read.model_copy(update={"format": None}))
        if not isinstance(loaded_tree.model, BTDocument):
            raise InputError("--tree must be a behavior tree", location=SourceLocation(str(tree)))
        suite = testgen.generate(loaded_spec.model)
        files = testgen.write_suite(
            output,
            suite,
            tree=tree,
            spec_name=spec.name,
            overwrite=force,
            tree_model=loaded_tree.model,
        )
        print(
            f"suite: {len(suite.cases)} cases, {suite.steps} scripted leaf ticks; "
            f"covers {suite.covered}/{suite.targets} transitions of {spec.name}"
        )
        if score:
            killed, mutants = testgen.mutation_score(loaded_tree.model, suite)
            share = f"{100 * killed / len(mutants):.0f}%" if mutants else "n/a"
            print(
                f"mutation score: {killed}/{len(mutants)} mutants of {tree.name} killed ({share})"
            )
        for path in files:
            print(f"wrote {path}")
