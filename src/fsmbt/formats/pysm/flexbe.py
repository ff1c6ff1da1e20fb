"""FlexBE behaviours (Python, as the FlexBE editor writes them) -> the hierarchical FSM.

Read statically (docs/formats/flexbe.md): the source is parsed with ``ast`` and never imported
or executed. The model is the state machine that a ``Behavior`` subclass's ``create()``
returns: ``OperatableStateMachine`` (and ``PriorityContainer``, read as a plain machine),
``ConcurrencyContainer`` with its ``conditions`` (a product of its leaf children, the first
satisfied condition ending it), states added with ``OperatableStateMachine.add(label, state,
transitions=..., autonomy=..., remapping=...)`` inside ``with`` blocks, and embedded
behaviours (``self.use_behavior(Class, ...)``) read from their file in their own ROS package
(an opaque state with a warning when it is not found). Python 2 era files (ROS 1) are read
through a token-level normaliser (``fsmbt.formats.pysm.py2``), never run. Rules and refusals
are those of ``fsmbt.formats.pysm.build``; autonomy levels are kept as the ``autonomy``
attribute of each transition; parameters, userdata keys, remappings and editor positions as
``fsmbt.model.state_info`` annotations of the states (they do not change the machine).

Option ``behaviour`` (``ReadContext.options``) picks a Behavior class when a file has several.
Costs: O(n) in the size of the source (plus the embedded files).
"""

from __future__ import annotations

import re

from fsmbt.formats.pysm.analyze import Analysis, Container
from fsmbt.formats.pysm.build import build_fsm
from fsmbt.formats.pysm.smach import choose_machine
from fsmbt.formats.registry import Format, ReadContext, register
from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM

_FLEXBE_IMPORT = re.compile(
    r"^\s*(from\s+flexbe_core(\.\w+)*\s+import\b|import\s+flexbe_core\b)", re.M
)


def read_flexbe(text: str, ctx: ReadContext) -> FSM:
    """Read a FlexBE behaviour file (see the module docstring)."""
    return build_fsm(text, ctx, choose_behaviour)


def choose_behaviour(analysis: Analysis, ctx: ReadContext) -> tuple[Container, str]:
    """The state machine of the chosen Behavior class (``create()``'s return value)."""
    wanted = ctx.options.get("behaviour")
    readable = {name: c for name, c in analysis.behaviours.items() if c is not None}
    if wanted is not None:
        if wanted not in analysis.behaviours:
            raise InputError(
                f"no Behavior class '{wanted}' in this file (found: "
                f"{', '.join(analysis.behaviours) or 'none'})",
                location=ctx.location(),
            )
        found = analysis.behaviours[str(wanted)]
        if found is None:
            raise InputError(
                f"Behavior '{wanted}': create() does not return a state machine",
                location=ctx.location(),
            )
        return found, str(wanted)
    if readable:
        name, container = next(iter(readable.items()))
        if len(readable) > 1:
            ctx.warn(
                f"{len(readable)} Behavior classes; read '{name}' (others: "
                f"{', '.join(list(readable)[1:])}; choose one with the 'behaviour' option)"
            )
        return container, name
    if analysis.behaviours:
        raise InputError(
            "the Behavior's create() does not return a state machine built in "
            "it (return _state_machine)",
            location=ctx.location(),
        )
    return choose_machine(analysis, ctx)


def _sniff(text: str) -> bool:
    return _FLEXBE_IMPORT.search(text[:65536]) is not None


register(
    Format(
        "flexbe",
        (".py",),
        frozenset({"fsm"}),
        "FlexBE behaviour (Python, read statically, never run)",
        read_flexbe,
        None,
        _sniff,
        priority=34,
    )
)
