"""A Concurrence read in rounds, in SMV: the FSM side of the outcome pairing when a
SMACH/FlexBE/YASMIN concurrence becomes a ``Parallel``/``ParallelAll`` in the structured tree
(docs/nusmv.md, "The outcome pairing (structured trees)"; docs/semantics.md §11, "Concurrences:
Parallel or product" and "Container children").

Written from the documented round reading and the source decision, never from the native
machine (``OutcomeFSMMachine``) nor from the converter's choice of form:

- per concurrence ``k`` and child ``i`` a variable ``dn<k>_<i>``: ``dnr`` while the child runs,
  else the outcome it ended with (``dv<n>`` symbols); per container child a variable
  ``ps<k>_<i>``: the atomic state it is about to run (a value of the FSM's ``q``). Outside the
  concurrence every ``dn`` is ``dnr`` and every ``ps`` the child's first state (canonical: a
  state is the same whichever way it was reached), so entering it needs no assignment and
  leaving it resets them;
- the FSM's ``q`` is the atomic state about to run: the running child's (its own path for a
  leaf child, its ``ps`` for a container child);
- the *source decision* is the outcome map read as the documented rule: SMACH/YASMIN decide
  only when every child has ended, the *last* entry that holds wins, else the default; FlexBE
  decides at the *first* condition that holds (``decision_rows``);
- the *turn*: after ``running``, after a child ended without a decision, and after a
  container child's outcome that goes round one of its loops (``Region.round_trips``), the
  next child still running in the order they were added, wrapping round (``next_child_rows``).

A ``Row`` is one guarded move: its guard, where ``q`` goes (a state, or a container child's
``ps`` variable) and the round variables it sets. The guards a move produces are disjoint.
Size: per child outcome O(children + map entries x required children) for the decision and
O(children^2) for the turn.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from fsmbt.semantics.outcome_parallel import Concurrence
from fsmbt.verify.nusmv.smv import Symbols, all_of

#: A child that has not ended.
RUNS = "dnr"


@dataclass(frozen=True)
class Target:
    """Where ``q`` goes: the state ``path`` (an atomic path or a result word), or, when
    ``var`` is set, the value of that ``ps`` variable (a container child's position)."""

    path: str = ""
    var: str = ""
    child: int = -1


@dataclass
class Row:
    """One guarded move of the FSM side (the module docstring)."""

    guard: str
    target: Target
    sets: dict[str, str] = field(default_factory=dict)


@dataclass
class Child:
    """One child of a concurrence: its unit's path, whether it is a container, the atomic
    state it starts at (itself for a leaf child) and every atomic state it may be at."""

    index: int
    path: str
    container: bool
    entry: str
    positions: list[str] = field(default_factory=list)

    @property
    def tracked(self) -> bool:
        """Whether it needs a ``ps`` variable: a container child of two states or more
        (one of a single state is always there)."""
        return self.container and len(self.positions) > 1


@dataclass
class RoundTable:
    """One concurrence read in rounds: its region, the recorded concurrence, its children
    and its variables' names."""

    key: int
    region: str
    concurrence: Concurrence
    children: list[Child]

    def done_var(self, i: int) -> str:
        return f"dn{self.key}_{i}"

    def pos_var(self, i: int) -> str:
        return f"ps{self.key}_{i}"

    def variables(self) -> list[str]:
        names = [self.done_var(c.index) for c in self.children]
        return names + [self.pos_var(c.index) for c in self.children if c.tracked]

    def position(self, i: int) -> Target:
        """Where child ``i`` is about to run (not itself moving now)."""
        child = self.children[i]
        if child.tracked:
            return Target(var=self.pos_var(i), child=i)
        return Target(child.entry)

    def entry_target(self) -> Target:
        """The state about to run when the concurrence is entered: the first child's first
        state (every variable is canonical outside it)."""
        return Target(self.children[0].entry)

    def reset(self) -> dict[str, str]:
        """Every variable back to its canonical value (leaving the concurrence)."""
        sets = {self.done_var(c.index): RUNS for c in self.children}
        for c in self.children:
            if c.tracked:
                sets[self.pos_var(c.index)] = c.entry
        return sets

    def next_child_rows(
        self, guard: str, index: int, here: Target | None, sets: dict[str, str]
    ) -> list[Row]:
        """The turn after child ``index`` (the module docstring): the next child still
        running after it, wrapping round; ``here`` is child ``index``'s own position when it
        still runs (it runs again when every other child has ended), ``None`` when it just
        ended (then another child runs: every child ended would have decided)."""
        n = len(self.children)
        order = [(index + step) % n for step in range(1, n)]
        rows: list[Row] = []
        ended: list[str] = []
        for j in order:
            running = f"{self.done_var(j)} = {RUNS}"
            if here is None and j == order[-1]:  # the last candidate: it runs
                rows.append(Row(all_of([guard, *ended]), self.position(j), dict(sets)))
                return rows
            rows.append(Row(all_of([guard, *ended, running]), self.position(j), dict(sets)))
            ended.append(f"{self.done_var(j)} != {RUNS}")
        assert here is not None, "a concurrence of one child decides when it ends"
        rows.append(Row(all_of([guard, *ended]), here, dict(sets)))
        return rows

    def decision_rows(self, index: int, outcome: str, done_ids: Symbols) -> list[tuple[str, str]]:
        """(condition on the other children's ``dn``, container outcome) in priority order,
        when child ``index`` has just ended with ``outcome``: the source decision of
        docs/semantics.md §11 (SMACH/YASMIN: every child ended, the last entry that holds,
        else the default; FlexBE: the first condition that holds)."""
        c = self.concurrence
        others = [ch.index for ch in self.children if ch.index != index]

        def holds(required: dict[str, str]) -> str:
            parts: list[str] = []
            for label, wanted in required.items():
                if label not in c.labels:
                    return "FALSE"
                j = c.labels.index(label)
                if j == index:
                    if wanted != outcome:
                        return "FALSE"
                    continue
                if wanted not in c.outcomes[j]:
                    return "FALSE"
                parts.append(f"{self.done_var(j)} = {done_ids.id(wanted)}")
            return all_of(parts)

        rows: list[tuple[str, str]] = []
        if c.smach:
            every = all_of(f"{self.done_var(j)} != {RUNS}" for j in others)
            for candidate, required in reversed(c.outcome_map):
                rows.append((all_of([every, holds(required)]), candidate))
            if c.default is not None:
                rows.append((every, c.default))
        else:
            rows = [(holds(required), candidate) for candidate, required in c.outcome_map]
        return [(cond, out) for cond, out in rows if cond != "FALSE"]


def negate(expr: str) -> str:
    """``!expr`` (``TRUE``/``FALSE`` folded)."""
    return {"TRUE": "FALSE", "FALSE": "TRUE"}.get(expr, f"!({expr})")


__all__ = ["RUNS", "Child", "RoundTable", "Row", "Target", "negate"]
