"""The CLI's human lines about a conversion, in a robotics engineer's words (docs/cli.md,
"Glossary").

An engine's ``stats`` are figures for scripts (``--json`` prints them under their stable keys);
``conversion_summary`` says what they mean in one sentence: what was read, what was built.
Figures an engine adds that this module does not know are appended as ``key=value`` so nothing
is hidden. ``counted`` writes a count with its noun in the right number. Pure string work.
"""

from __future__ import annotations

from collections.abc import Mapping


def counted(n: object, noun: str, plural: str | None = None) -> str:
    """``1 state``, ``2 states``, ``1 branch``/``3 branches`` (``plural`` when irregular).

    Args:
        n: the count (anything ``int()`` accepts; otherwise shown as given).
        noun: the singular noun.
        plural: the plural, when it is not ``noun + "s"``.

    Returns:
        The count and the noun.
    """
    try:
        one = int(n) == 1  # type: ignore[call-overload]
    except (TypeError, ValueError):
        one = False
    return f"{n} {noun if one else (plural or noun + 's')}"


_FSM_TO_BT = ("states", "transitions", "entry", "loop_states", "root_subtrees", "chains",
              "branches", "unreachable_dropped", "flattened", "nodes", "depth")
_BT_TO_FSM = ("k", "units", "explored_regions", "explored_states", "depth_before", "depth_after",
              "merged_nodes", "leaves", "loop")


def _fsm_to_bt(s: Mapping[str, object]) -> list[str]:
    parts = [f"{counted(s['states'], 'FSM state')} and "
             f"{counted(s.get('transitions', '?'), 'transition')} became a loop-execution BT of "
             f"{counted(s.get('nodes', '?'), 'node')} (depth {s.get('depth', '?')})"]
    shape = [f"entry state {s['entry']}"] if s.get("entry") else []
    if "loop_states" in s:
        shape.append(counted(s["loop_states"], "loop state"))
    if "root_subtrees" in s:
        shape.append(f"{counted(s['root_subtrees'], 'selector')} under the root")
    if "chains" in s:
        shape.append(counted(s["chains"], "chain"))
    if "branches" in s:
        shape.append(counted(s["branches"], "branch", "branches"))
    if shape:
        parts.append(", ".join(shape))
    if s.get("unreachable_dropped"):
        parts.append(f"{counted(s['unreachable_dropped'], 'unreachable state')} dropped")
    if s.get("flattened"):
        parts.append("the hierarchy was flattened")
    return parts


def _bt_to_fsm(s: Mapping[str, object]) -> list[str]:
    machines = int(s["k"])  # type: ignore[call-overload]
    subs = machines - 1
    built = "1 state machine" if machines == 1 else (
        f"a state machine with {counted(subs, 'sub-state-machine')}")
    parts = [f"{counted(s.get('leaves', '?'), 'leaf', 'leaves')} became {built}, from "
             f"{counted(s.get('units', '?'), 'conversion unit')} (a control node, its children "
             "and grandchildren)"]
    if s.get("explored_regions"):
        parts.append(f"{counted(s['explored_regions'], 'reactive or stateful subtree')} "
                     f"explored into {counted(s.get('explored_states', '?'), 'state')}")
    if "depth_before" in s:
        merged = s.get("merged_nodes", 0)
        depth = (f"tree depth {s['depth_before']}" if s.get("depth_after") == s["depth_before"]
                 else f"tree depth {s['depth_before']} -> {s.get('depth_after')}")
        if merged:
            depth += f" after merging {counted(merged, 'same-type child node')}"
        parts.append(depth)
    if s.get("loop"):
        parts.append("loop mode (the root is ticked again after it returns)")
    return parts


def conversion_summary(direction: str, stats: Mapping[str, object]) -> str:
    """One readable sentence for a conversion's figures.

    Args:
        direction: ``fsm->bt`` or ``bt->fsm``.
        stats: the engine's figures (``ConversionResult.stats``).

    Returns:
        E.g. ``12 leaves became a state machine with 2 sub-state-machines, from 3 conversion
        units (...); tree depth 7``; unknown figures follow as ``key=value``.
    """
    known: tuple[str, ...] = ()
    parts: list[str] = []
    if direction == "fsm->bt" and "states" in stats:
        parts, known = _fsm_to_bt(stats), _FSM_TO_BT
    elif direction == "bt->fsm" and "k" in stats:
        parts, known = _bt_to_fsm(stats), _BT_TO_FSM
    rest = [f"{k}={v}" for k, v in stats.items() if k not in known]
    return "; ".join(parts + ([", ".join(rest)] if rest else []))


def checked_counts(stats: Mapping[str, object]) -> str:
    """What the checker's state counts count, in one phrase (empty without figures).

    The checker counts *configurations*: an FSM's states plus its start (before the first
    event), a BT's leaves about to be ticked plus its results - so an FSM of 10 states shows
    11 source states.

    Args:
        stats: a verification report's ``stats``.

    Returns:
        E.g. ``11 source and 12 result configurations (states plus the start; for a BT, leaves
        about to tick plus results), 12 pairs of them``.
    """
    if "source_states" not in stats or "result_states" not in stats:
        return ""
    text = (f"{stats['source_states']} source and {stats['result_states']} result "
            "configurations (an FSM's states plus its start; a BT's leaves about to tick plus "
            "its results)")
    if "product_states" in stats:
        text += f", {counted(stats['product_states'], 'pair')} of them explored together"
    return text
