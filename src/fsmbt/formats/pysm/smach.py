"""SMACH state machines (Python) <-> the hierarchical FSM (docs/formats/smach.md).

Reading is static: the source is parsed with ``ast`` and never imported or executed (a file
whose module-level code would have side effects is safe to read). Containers, ``add`` /
``add_auto`` in positional and keyword forms inside ``with`` blocks, ``Sequence``,
``Concurrence`` (outcome maps), ``Iterator``, ``set_initial_state``, nested containers; the
mapping and the refusals are in ``fsmbt.formats.pysm.build``. When a file builds several
top-level containers the first is read (option ``machine`` names another by its variable) and
the others are named in a warning.

Writing (``fsmbt.formats.pysm.smach_write``) produces a container module with one stub
``smach.State`` class per action.

Costs: O(n) in the size of the source.
"""

from __future__ import annotations

import re

from fsmbt.formats.pysm.analyze import Analysis, Container
from fsmbt.formats.pysm.build import build_fsm
from fsmbt.formats.pysm.smach_write import write_smach
from fsmbt.formats.registry import Format, ReadContext, register
from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM

_SMACH_IMPORT = re.compile(r"^\s*(import\s+smach\b|from\s+smach(_ros)?(\.\w+)*\s+import\b)", re.M)


def read_smach(text: str, ctx: ReadContext) -> FSM:
    """Read a SMACH Python file (see the module docstring)."""
    return build_fsm(text, ctx, choose_machine)


def choose_machine(analysis: Analysis, ctx: ReadContext) -> tuple[Container, str]:
    """The top-level container that is the model (first built, or option ``machine``)."""
    roots = [c for c in analysis.containers if c.parent is None]
    if not roots:
        raise InputError(
            "no state machine is built in this file (no StateMachine, Sequence, "
            "Concurrence or Iterator is constructed)",
            location=ctx.location(),
        )
    wanted = ctx.options.get("machine")
    if wanted is not None:
        chosen = [c for c in roots if c.name == wanted]
        if not chosen:
            raise InputError(
                f"no top-level container '{wanted}' (found: {', '.join(c.name for c in roots)})",
                location=ctx.location(),
            )
        return chosen[0], chosen[0].name
    root = roots[0]
    if len(roots) > 1:
        others = ", ".join(f"'{c.name}' (line {c.line})" for c in roots[1:])
        ctx.warn(
            f"{len(roots)} top-level containers; read '{root.name}' (line {root.line}); "
            f"not read: {others} (choose one with the 'machine' option)"
        )
    return root, root.name


def _sniff(text: str) -> bool:
    head = text[:65536]
    return _SMACH_IMPORT.search(head) is not None and "flexbe_core" not in head


register(
    Format(
        "smach",
        (".py",),
        frozenset({"fsm"}),
        "SMACH state machine (Python; read statically, never run; write stub states)",
        read_smach,
        write_smach,
        _sniff,
        priority=35,
    )
)
