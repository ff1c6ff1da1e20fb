"""Load-time check of a dispatch tree's annotations (docs/semantics.md section 12, "Checked at
load time"): the rule the C++ runtime (``fsmbt/lebt.hpp``, ``LebtRunner::checkDispatch``) and the
Python runtime (``fsmbt.runtime.dispatch_run``) apply before the first tick, so that a hand edit
(a digit mistyped, a transition pointed at an index no state has) is a located error, not a
machine that silently stops.

Rules, over the compiled tree of a ``DispatchMachine`` (SubTrees expanded):

- the index switches are the ``Switch`` nodes whose variable is ``fsm_dJ`` (there is at least
  one); each case is one digit ``a``..``g``;
- a ``DispatchEntry``'s ``_onSuccess`` (already refused elsewhere when not ``KEY:='literal'``
  assignments) writes only index digits: keys ``fsm_dJ`` with ``J`` below the number of digits
  the switches read, values one digit each;
- from the start (no digit set) the index switches lead each reached index to its state's case;
  every ``DispatchEntry`` in that case writes an index (the state's digits with its assignments
  applied) that sets every digit and leads to a state's case - not to a leaf whose result is
  fixed at FAILURE (``AlwaysFailure``: a padding case, an unused default) and not back to the
  start case - and the leaves writing one index name the same ``state``.

Cost: O(nodes + reachable states x digits + transitions x digits).
"""

from __future__ import annotations

import re

from fsmbt.model.errors import InputError
from fsmbt.model.kinds import NodeKind
from fsmbt.semantics.compiled import CompiledNode
from fsmbt.semantics.dispatch_runtime import DIGIT_PREFIX, DIGITS, ON_SUCCESS, DispatchMachine
from fsmbt.semantics.outcome_blackboard import SWITCH
from fsmbt.semantics.status import NodeStatus

_DIGIT_KEY = re.compile(re.escape(DIGIT_PREFIX) + r"(\d{1,4})")
DISAGREE = "dispatch annotations disagree"


def digit_number(key: str) -> int | None:
    """``J`` for the blackboard key ``fsm_dJ``, else ``None``."""
    match = _DIGIT_KEY.fullmatch(key)
    return int(match.group(1)) if match else None


def _error(node: CompiledNode, text: str) -> InputError:
    return InputError(
        f"{DISAGREE}: {text}",
        location=node.source.location,
        element=f"<{node.source.type}> '{node.label}'",
    )


def _is_digit(value: str) -> bool:
    return len(value) == 1 and value in DIGITS


def _shown(index: tuple[str | None, ...]) -> str:
    return "'" + "".join(d or "-" for d in reversed(index)) + "'"


def check_dispatch_annotations(machine: DispatchMachine) -> None:
    """Check the annotations of ``machine``'s tree (see the module doc).

    Raises:
        InputError: the first node that breaks a rule, with its location.
    """
    nodes = machine.tree.nodes
    switches: dict[int, tuple[int, tuple[str, ...]]] = {}
    levels = 0
    for node in nodes:
        if node.type != SWITCH:
            continue
        key, cases = node.params
        digit = digit_number(key)
        if digit is None:
            continue  # a Switch on {event}
        for k, value in enumerate(cases, 1):
            if not _is_digit(value):
                raise _error(
                    node,
                    f"case_{k} is the malformed index digit {value!r} (a digit is one of the "
                    f"letters {DIGITS})",
                )
        switches[node.id] = (digit, cases)
        levels = max(levels, digit + 1)
    if not switches and machine.entries:
        leaf = nodes[min(machine.entries)]
        raise _error(
            leaf,
            f"no Switch reads a state index digit ({{{DIGIT_PREFIX}0}}, ...): a tree of "
            f"{leaf.source.type} leaves is the dispatch form, a Switch dispatch over the index",
        )
    writes: dict[int, list[tuple[int, str]]] = {}
    for nid, pairs in machine.on_success.items():
        items: list[tuple[int, str]] = []
        for key, value in pairs:
            digit = digit_number(key)
            if digit is None:
                raise _error(
                    nodes[nid],
                    f"{ON_SUCCESS} writes {key!r}, which is no state index digit "
                    f"({DIGIT_PREFIX}0, {DIGIT_PREFIX}1, ...)",
                )
            if not _is_digit(value):
                raise _error(
                    nodes[nid],
                    f"{ON_SUCCESS} writes the malformed index digit {value!r} (a digit is one "
                    f"of the letters {DIGITS})",
                )
            if digit >= levels:
                raise _error(
                    nodes[nid],
                    f"{ON_SUCCESS} writes {key}, but no Switch reads that digit (the index has "
                    f"{levels})",
                )
            items.append((digit, value))
        writes[nid] = items

    def resolve(index: tuple[str | None, ...]) -> int:
        nid = 0
        while True:
            node = nodes[nid]
            found = switches.get(nid)
            if found is not None:
                digit, cases = found
                value = index[digit]
                k = cases.index(value) if value in cases else len(cases)
                nid = node.children[k]
            elif node.kind is NodeKind.SUBTREE and node.children:
                nid = node.children[0]
            else:
                return nid

    start: tuple[str | None, ...] = (None,) * levels
    start_case = resolve(start)
    named: dict[tuple[str | None, ...], int] = {}  # index -> the first entry writing it
    queue = [(start, start_case)]
    for source, case in queue:
        stack = [case]
        while stack:
            nid = stack.pop()
            stack.extend(reversed(nodes[nid].children))
            if nid not in machine.entries:
                continue
            state = machine.entries[nid][0]
            target = list(source)
            for digit, value in writes.get(nid, ()):
                target[digit] = value
            index = tuple(target)
            if None in index:
                raise _error(
                    nodes[nid],
                    f"entering {state!r} from the start, {ON_SUCCESS} leaves "
                    f"{DIGIT_PREFIX}{index.index(None)} unset (from the start every index "
                    "digit is written)",
                )
            first = named.get(index)
            if first is not None:
                if machine.entries[first][0] != state:
                    other = nodes[first]
                    raise _error(
                        nodes[nid],
                        f"it enters {state!r} but writes the state index {_shown(index)} of "
                        f"{machine.entries[first][0]!r} (<{other.source.type}> "
                        f"'{other.label}', line "
                        f"{other.source.location.line if other.source.location else '?'})",
                    )
                continue
            found = resolve(index)
            if found == start_case or nodes[found].internal_status == NodeStatus.FAILURE.value:
                where = (
                    "the start case"
                    if found == start_case
                    else f"<{nodes[found].source.type}> '{nodes[found].label}'"
                )
                raise _error(
                    nodes[nid],
                    f"entering {state!r}, {ON_SUCCESS} writes the state index {_shown(index)}, "
                    f"which no state has (the index Switches lead it to {where})",
                )
            named[index] = nid
            queue.append((index, found))
