"""Shared helpers of the simulation tests (tests/sim): models, mutants, divergence checks."""

from __future__ import annotations

from pathlib import Path

from fsmbt import api
from fsmbt.model.bt import BTDocument
from fsmbt.model.fsm import FSM
from fsmbt.sim.run import Comparison, Side, run_episode, worlds
from fsmbt.verify.mutations import mutants

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def example(name: str) -> FSM | BTDocument:
    """A model of examples/, read by fsmbt."""
    return api.load(EXAMPLES / name).model


def mutant(model: FSM | BTDocument, operator: str, description: str) -> FSM | BTDocument:
    """The first mutant of ``model`` by ``operator`` whose description starts with
    ``description`` (fsmbt.verify.mutations, every candidate enumerated)."""
    for candidate in mutants(model, per_operator=None):
        if candidate.operator == operator and candidate.description.startswith(description):
            return candidate.model
    raise AssertionError(f"no {operator} mutant '{description}'")


def assert_first_divergence_is_real(world_name: str, comparison: Comparison) -> int:
    """The comparison's first divergent episode, re-run: every record before the reported step
    is equal on both sides and the reported step differs. Returns that step."""
    first = comparison.first_divergence
    assert first is not None and first.divergence is not None
    make = worlds()[world_name]
    left = run_episode(make(), comparison.left, first.seed)
    right = run_episode(make(), comparison.right, first.seed)
    step = first.divergence.step
    assert left.records[:step] == right.records[:step]
    a = left.records[step] if step < len(left.records) else None
    b = right.records[step] if step < len(right.records) else None
    assert a != b
    assert a == first.divergence.left and b == first.divergence.right
    return step


def side(label: str, models: dict[str, FSM | BTDocument], engine: str = "fsmbt") -> Side:
    """A side whose every role runs on ``engine``."""
    return Side(label, models, dict.fromkeys(models, engine))
