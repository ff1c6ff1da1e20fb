"""``LEBTMachine``: an LEBT's macro steps as a ``Machine`` (inputs = events, outputs = actions).

A tree of the strict LEBT grammar (``fsmbt.semantics.lebt.fast.strict_lebt_sels``) runs on
``FastLEBTRuntime`` (O(1) per macro step for a deterministic LEBT); any other tree, or
``generic=True``, on the interpreter (``LEBTRuntime``, O(root-level guards) per step). Both are
``MacroStepDriver`` s (docs/semantics.md §5, "The LEBT protocol"), so they take the same
steps; ``fast`` says which one was chosen. Choosing costs one O(N) pass over the tree.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from typing import Any

from fsmbt.model.bt import BTDocument
from fsmbt.semantics.bt_interpreter import CompiledTree
from fsmbt.semantics.lebt.fast import FastLEBTRuntime, strict_lebt_sels
from fsmbt.semantics.lebt.interpreted import LEBTRuntime
from fsmbt.semantics.lebt.leaves import LebtLeaves
from fsmbt.semantics.machine import FINAL, RUNNING, Outputs


class LEBTMachine:
    """``Machine`` of an LEBT's macro steps.

    Args:
        doc: the tree (compiled or not).
        alphabet: the events offered in every state.
        start: the start pseudo-state; ``None`` infers it (``LebtLeaves.of``).
        name: the machine's name in reports; the main tree's id by default.
        generic: run on the interpreter even when the tree has the strict grammar.
    """

    def __init__(
        self,
        doc: BTDocument | CompiledTree,
        alphabet: Sequence[str],
        *,
        start: str | None = None,
        name: str | None = None,
        generic: bool = False,
    ) -> None:
        tree = doc if isinstance(doc, CompiledTree) else CompiledTree(doc)
        body_state = None if generic else strict_lebt_sels(tree)
        self.runtime: LEBTRuntime | FastLEBTRuntime
        if body_state is None:
            self.runtime = LEBTRuntime(tree, start=start)
        else:
            self.runtime = FastLEBTRuntime(tree, body_state, LebtLeaves.of(tree, start))
        self.fast = body_state is not None
        self.alphabet = tuple(alphabet)
        self.name = name or self.runtime.tree.doc.main.id

    @property
    def leaves(self) -> LebtLeaves:
        """The tree's parsed LEBT leaves."""
        return self.runtime.leaves

    def start(self) -> tuple[Any, Outputs]:
        """The state before any event and the actions run to reach it."""
        return self.runtime.initial()

    def inputs(self, state: Any) -> Sequence[str]:
        """Every event of the alphabet (``active_inputs`` is the checker wrapper's)."""
        return self.alphabet

    def step(self, state: Any, symbol: str) -> tuple[Any, Outputs]:
        """One macro step on event ``symbol``."""
        return self.runtime.macro_step(state, symbol)

    def status(self, state: Any) -> str:
        """``final`` once the tree has terminated, else ``running``."""
        return FINAL if self.runtime.terminated(state) else RUNNING

    def describe(self, state: Any) -> str:
        """The FSM state the tree is in."""
        return str(state.bb_state)

    def running_leaves(self, state: Any) -> Iterator[int]:
        """The compiled ids of the state leaves running in ``state``."""
        return self.runtime.running_leaves(state)
