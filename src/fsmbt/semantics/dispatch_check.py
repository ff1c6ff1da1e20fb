"""Load-time check of a dispatch tree's annotations (docs/semantics.md section 12, "Checked at
load time"): the rule the C++ runtime (``fsmbt/lebt.hpp``, ``LebtRunner::checkDispatch``) and the
Python runtime (``fsmbt.runtime.dispatch_run``) apply before the first tick, so that a hand edit
(a digit mistyped, a transition pointed at an index no state has) is a located error, not a
machine that silently stops. It covers the flat form (§12) and the hierarchical form (§12a).

Rules, over the compiled tree of a ``DispatchMachine`` (SubTrees expanded):

- a digit entry is ``fsm_dJ`` (the top level) or ``fsm_d_<level>_J`` (a composite's level),
  the grammar of ``dispatch_runtime.digit_key``; the index switches are the ``Switch`` nodes
  whose variable is a digit entry (there is at least one); each case is one digit ``a``..``g``;
  a level has as many digits as the highest ``J`` its switches read, plus one;
- a ``DispatchEntry``'s ``_onSuccess`` (already refused elsewhere when not ``KEY:='literal'``
  assignments) writes only digit entries that some level's switches read, values one digit
  each;
- the **index** is the joint valuation of every level's digits. It resolves from the root:
  an index ``Switch`` takes the case of its digit's value (its default when none equals it), a
  ``SubTree`` its tree, and a control node that is not a ``Switch`` and whose first child is
  (through SubTrees) an index ``Switch`` - a composite's ``ReactiveFallback`` - its first child;
  its other children hold that composite's own transitions. The node reached is the state's
  case; the state's transitions are the ``DispatchEntry`` leaves in its case and in the own
  transitions of every composite passed on the way (the flat form has none of those);
- from the start (no digit set) every ``DispatchEntry`` of each reached state writes an index
  (the state's index with its assignments applied) that sets every digit and leads to a
  state's case - not back to the start case and not to a leaf whose result is fixed at FAILURE
  (``AlwaysFailure``: a padding case, an unused default), except, inside a composite (below an
  index switch of a ``fsm_d_<level>_`` digit), an ``AlwaysFailure`` named as the state the leaf
  enters: a final sub-state's case (§12a) - and the leaves writing one index name the same
  ``state``.

Cost: O(nodes + reachable configurations x (digits + nesting) + transitions x digits).
"""

from __future__ import annotations

from fsmbt.model.errors import InputError
from fsmbt.model.kinds import NodeKind
from fsmbt.semantics.compiled import CompiledNode
from fsmbt.semantics.dispatch_runtime import (
    DIGIT_PREFIX,
    DIGITS,
    ON_SUCCESS,
    DispatchMachine,
    digit_key,
)
from fsmbt.semantics.outcome_blackboard import SWITCH
from fsmbt.semantics.status import NodeStatus

DISAGREE = "dispatch annotations disagree"

Index = tuple[str | None, ...]


def _error(node: CompiledNode, text: str) -> InputError:
    return InputError(
        f"{DISAGREE}: {text}",
        location=node.source.location,
        element=f"<{node.source.type}> '{node.label}'",
    )


def _is_digit(value: str) -> bool:
    return len(value) == 1 and value in DIGITS


class _Layout:
    """Where each digit entry sits in a joint index: the top level's digits first, then each
    composite level's (by prefix), each level least significant digit first."""

    def __init__(self, widths: dict[str, int]) -> None:
        self.widths = widths
        prefixes = sorted(widths, key=lambda p: (p != DIGIT_PREFIX, p))
        self.keys = [(p, j) for p in prefixes for j in range(widths[p])]
        self.slot = {key: k for k, key in enumerate(self.keys)}

    def name(self, slot: int) -> str:
        prefix, j = self.keys[slot]
        return f"{prefix}{j}"

    def shown(self, index: Index) -> str:
        """Most significant digit first (``-`` unset); the top level alone as ``'ba'``, else
        each level as ``<prefix>='..'``."""
        parts: dict[str, str] = {}
        for (prefix, _j), value in zip(self.keys, index, strict=True):
            parts[prefix] = (value or "-") + parts.get(prefix, "")
        if list(parts) == [DIGIT_PREFIX]:
            return f"'{parts[DIGIT_PREFIX]}'"
        return ", ".join(f"{prefix}='{digits}'" for prefix, digits in parts.items())


def check_dispatch_annotations(machine: DispatchMachine) -> None:
    """Check the annotations of ``machine``'s tree (see the module doc).

    Raises:
        InputError: the first node that breaks a rule, with its location.
    """
    nodes = machine.tree.nodes
    switches: dict[int, tuple[tuple[str, int], tuple[str, ...]]] = {}
    widths: dict[str, int] = {}
    for node in nodes:
        if node.type != SWITCH:
            continue
        key, cases = node.params
        digit = digit_key(key)
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
        widths[digit[0]] = max(widths.get(digit[0], 0), digit[1] + 1)
    if not switches and machine.entries:
        leaf = nodes[min(machine.entries)]
        raise _error(
            leaf,
            f"no Switch reads a state index digit ({{{DIGIT_PREFIX}0}}, ...): a tree of "
            f"{leaf.source.type} leaves is the dispatch form, a Switch dispatch over the index",
        )
    layout = _Layout(widths)
    writes = {nid: _writes(nodes[nid], pairs, layout) for nid, pairs in machine.on_success.items()}

    def is_index(nid: int) -> bool:
        while nid not in switches and nodes[nid].kind is NodeKind.SUBTREE and nodes[nid].children:
            nid = nodes[nid].children[0]
        return nid in switches

    def resolve(index: Index) -> tuple[int, list[int], bool]:
        """(the state's case, the own-transition subtrees passed, whether inside a composite)."""
        nid, inside = 0, False
        own: list[int] = []
        while True:
            node = nodes[nid]
            found = switches.get(nid)
            if found is not None:
                digit, cases = found
                value = index[layout.slot[digit]]
                k = cases.index(value) if value in cases else len(cases)
                inside = inside or digit[0] != DIGIT_PREFIX
                nid = node.children[k]
            elif node.kind is NodeKind.SUBTREE and node.children:
                nid = node.children[0]
            elif (
                node.kind is NodeKind.CONTROL
                and node.type != SWITCH
                and len(node.children) > 1
                and is_index(node.children[0])
            ):
                own.extend(node.children[1:])
                nid = node.children[0]
            else:
                return nid, own, inside

    start: Index = (None,) * len(layout.keys)
    start_case = resolve(start)[0]
    named: dict[Index, int] = {}  # index -> the first entry writing it
    queue: list[tuple[Index, list[int]]] = [(start, [start_case])]
    for source, roots in queue:
        stack = list(reversed(roots))
        while stack:
            nid = stack.pop()
            stack.extend(reversed(nodes[nid].children))
            if nid not in machine.entries:
                continue
            state = machine.entries[nid][0]
            target = list(source)
            for slot, value in writes.get(nid, ()):
                target[slot] = value
            index = tuple(target)
            if None in index:
                raise _error(
                    nodes[nid],
                    f"entering {state!r} from the start, {ON_SUCCESS} leaves "
                    f"{layout.name(index.index(None))} unset (from the start every index "
                    "digit is written)",
                )
            first = named.get(index)
            if first is not None:
                if machine.entries[first][0] != state:
                    other = nodes[first]
                    raise _error(
                        nodes[nid],
                        f"it enters {state!r} but writes the state index "
                        f"{layout.shown(index)} of {machine.entries[first][0]!r} "
                        f"(<{other.source.type}> '{other.label}', line "
                        f"{other.source.location.line if other.source.location else '?'})",
                    )
                continue
            found, own, inside = resolve(index)
            case = nodes[found]
            final_inside = inside and case.source.name == state
            if found == start_case or (
                case.internal_status == NodeStatus.FAILURE.value and not final_inside
            ):
                where = (
                    "the start case"
                    if found == start_case
                    else f"<{case.source.type}> '{case.label}'"
                )
                raise _error(
                    nodes[nid],
                    f"entering {state!r}, {ON_SUCCESS} writes the state index "
                    f"{layout.shown(index)}, which no state has (the index Switches lead it "
                    f"to {where})",
                )
            named[index] = nid
            queue.append((index, [found, *own]))


def _writes(
    node: CompiledNode, pairs: tuple[tuple[str, str], ...], layout: _Layout
) -> list[tuple[int, str]]:
    """The (slot, letter) pairs of ``node``'s ``_onSuccess``, each key a digit some index
    ``Switch`` reads and each value one digit.

    Raises:
        InputError: the first assignment that is not such a pair, naming ``node``.
    """
    items: list[tuple[int, str]] = []
    for key, value in pairs:
        digit = digit_key(key)
        if digit is None:
            raise _error(
                node,
                f"{ON_SUCCESS} writes {key!r}, which is no state index digit "
                f"({DIGIT_PREFIX}0, {DIGIT_PREFIX}1, ...)",
            )
        if not _is_digit(value):
            raise _error(
                node,
                f"{ON_SUCCESS} writes the malformed index digit {value!r} (a digit is one "
                f"of the letters {DIGITS})",
            )
        prefix, j = digit
        width = layout.widths.get(prefix, 0)
        if j >= width:
            if prefix == DIGIT_PREFIX:
                has = f"the index has {width}"
            elif width:
                has = f"the level {prefix}.. has {width}"
            else:
                has = f"no Switch reads a digit of the level {prefix}.."
            raise _error(node, f"{ON_SUCCESS} writes {key}, but no Switch reads that digit ({has})")
        items.append((layout.slot[digit], value))
    return items
