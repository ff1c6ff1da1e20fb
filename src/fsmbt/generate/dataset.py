"""A run of N seeded random models, named and seeded so that each file is stable.

Why a module of its own: ``fsmbt generate``, the evaluation's dataset and the benchmarks all
make "model i of a run with seed S", and each must give the same model for the same (S, i) —
independent of N, so a run of 100 is the first 100 models of a run of 1 000. The ``i``-th model
is drawn from the seed string ``"<S>:<i>"``.

Cost: one model at a time (a generator), O(size of the model) each.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

from fsmbt.generate.generator import FSM_SHAPES, random_bt, random_fsm
from fsmbt.generate.vocab import SCENARIOS
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM

KINDS = ("fsm", "bt")
#: The node budget of a generated BT unless asked otherwise (it keeps depth/breadth 10 trees
#: in the hundreds of nodes, as the paper's dataset is).
DEFAULT_MAX_NODES = 120


def model_seed(seed: int, index: int) -> str:
    """The seed of the ``index``-th model of a run: independent of N, so files are stable."""
    return f"{seed}:{index}"


@dataclass(frozen=True)
class DatasetSpec:
    """What a run generates.

    Attributes:
        kind: ``"fsm"`` or ``"bt"``.
        scenario: ``basic``, ``robot`` or ``game`` (the vocabulary of names).
        seed: the run's base seed.
        min_states, max_states: FSM size range (states).
        depth, breadth: BT shape; ``None`` draws each in [2, 10].
        extended: BTs also use Reactive/WithMemory controls, Parallel and decorators.
        max_nodes: BT node budget (soft: the spine of exactly ``depth`` levels is kept).
        shape: FSM structure (``mixed``, ``chain``, ``tree`` = branches, ``loop``; see
            ``random_fsm``); a run of one shape has the shape in its file stems.
    """

    kind: str
    scenario: str = "basic"
    seed: int = 0
    min_states: int = 2
    max_states: int = 30
    depth: int | None = None
    breadth: int | None = None
    extended: bool = False
    max_nodes: int = DEFAULT_MAX_NODES
    shape: str = "mixed"

    def check(self) -> None:
        """Raise ``InputError`` naming the first setting that is out of range."""
        if self.kind not in KINDS:
            raise InputError(f"the kind must be fsm or bt, not {self.kind!r}")
        if self.scenario not in SCENARIOS:
            raise InputError(
                f"the scenario must be one of {', '.join(SCENARIOS)}, not {self.scenario!r}"
            )
        if not 1 <= self.min_states <= self.max_states:
            raise InputError(
                "the state range must satisfy 1 <= MIN <= MAX, not "
                f"{self.min_states}-{self.max_states}"
            )
        if self.shape not in FSM_SHAPES:
            raise InputError(
                f"the FSM shape must be one of {', '.join(FSM_SHAPES)}, not {self.shape!r}"
            )
        if self.max_nodes < 1:
            raise InputError(f"the node budget must be at least 1, not {self.max_nodes}")

    def model(self, index: int) -> FSM | BTDocument:
        """The ``index``-th model of this run."""
        rng = model_seed(self.seed, index)
        if self.kind == "fsm":
            return random_fsm(
                rng,
                None,
                self.scenario,
                shape=self.shape,
                min_states=self.min_states,
                max_states=self.max_states,
            )
        return random_bt(
            rng,
            self.depth,
            self.breadth,
            self.scenario,
            extended=self.extended,
            max_nodes=self.max_nodes,
        )

    def file_stem(self, index: int) -> str:
        """The file name (without extension) of the ``index``-th model."""
        if self.kind == "fsm" and self.shape != "mixed":
            return f"{self.kind}_{self.scenario}_{self.shape}_{self.seed}_{index:04d}"
        return f"{self.kind}_{self.scenario}_{self.seed}_{index:04d}"


def generate_models(spec: DatasetSpec, n: int) -> Iterator[tuple[str, FSM | BTDocument]]:
    """The first ``n`` models of the run ``spec``, each with its file stem.

    Args:
        spec: what to generate.
        n: how many models.

    Returns:
        An iterator of ``(file stem, model)``.

    Raises:
        InputError: a setting of ``spec`` is out of range.
    """
    spec.check()
    for index in range(n):
        yield spec.file_stem(index), spec.model(index)
