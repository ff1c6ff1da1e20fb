"""The CLI's human lines about a conversion, in a robotics engineer's words (docs/cli.md,
"Glossary").

An engine's ``stats`` are figures for scripts (``--json`` prints them under their stable keys);
``conversion_summary`` says what they mean in one sentence: what was read, what was built.
Figures an engine adds that this module does not know are appended as ``key=value`` so nothing
is hidden. ``counted`` writes a count with its noun in the right number. Pure string work.
"""

from __future__ import annotations

from collections.abc import Mapping

from fsmbt.semantics.dispatch_runtime import BASE as DISPATCH_BASE


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


def _fsm_to_bt(s: Mapping[str, object], engine: str, used: set[str]) -> list[str]:
    def take(key: str) -> object:
        used.add(key)
        return s[key]

    head = counted(take("states"), "FSM state")
    if "transitions" in s:
        head += f" and {counted(take('transitions'), 'transition')}"
    if s.get("style") == "dispatch" and s.get("form") == "hierarchical":  # §12a
        used.add("form")
        head += (
            " became a hierarchical dispatch BT (a Switch dispatch over each level's child "
            "index on the blackboard, a SubTree per composite state trying the active "
            "child's transitions before the composite's own)"
        )
    elif s.get("style") == "dispatch":  # docs/semantics.md section 12
        digits = (
            counted(take("index_digits"), f"base-{DISPATCH_BASE} digit")
            if "index_digits" in s
            else ""
        )
        index = f" of {digits}" if digits else ""
        head += (
            f" became a dispatch BT (a Switch dispatch over a state index{index} on the "
            "blackboard: a macro step ticks O(log states) nodes)"
        )
    else:
        head += " became " + ("a loop-execution BT" if engine == "rules" else "a BT")
    if "nodes" in s:
        head += f" of {counted(take('nodes'), 'node')}"
    if "depth" in s:
        head += f" (depth {take('depth')})"
    shape: list[str] = []
    if s.get("entry"):
        shape.append(f"entry state {take('entry')}")
    phrases = (
        ("loop_states", "loop state", None, ""),
        ("root_subtrees", "selector", None, " under the root"),
        ("chains", "chain", None, ""),
        ("branches", "branch", "branches", ""),
        ("subtrees", "SubTree", None, " for composite states"),
        ("parallel_subtrees", "SubTree", None, " for parallel states"),
        ("levels", "level", None, " of hierarchy"),
    )
    for key, noun, plural, tail in phrases:
        if key in s and (key != "parallel_subtrees" or s[key]):
            shape.append(counted(take(key), noun, plural) + tail)
        used.add(key)
    parts = [head] + ([", ".join(shape)] if shape else [])
    if s.get("depth_bound_roots"):
        parts.append(
            f"{counted(take('depth_bound_roots'), 'state')} promoted to the root to keep the "
            "tree within 200 XML levels (docs/semantics.md §5, depth-bounded LEBT)"
        )
    if s.get("unreachable_dropped"):
        parts.append(f"{counted(s['unreachable_dropped'], 'unreachable state')} dropped")
    used.add("unreachable_dropped")
    if "hierarchy" in s:
        parts.append(
            "composite states kept as SubTrees"
            if take("hierarchy") == "subtrees"
            else "the hierarchy flattened"
        )
        used.add("flattened")
    elif s.get("flattened"):
        parts.append("the hierarchy flattened")
    used.add("flattened")
    return parts


def _bt_to_fsm(s: Mapping[str, object], used: set[str]) -> list[str]:
    def take(key: str) -> object:
        used.add(key)
        return s[key]

    leaves = counted(take("leaves"), "leaf", "leaves") if "leaves" in s else "the tree"
    if "k" in s:
        machines = int(take("k"))  # type: ignore[call-overload]
        built = (
            "1 state machine"
            if machines == 1
            else (f"a state machine with {counted(machines - 1, 'sub-state-machine')}")
        )
    else:
        built = "an FSM"
        if "states" in s:
            built += f" of {counted(take('states'), 'state')}"
            if "transitions" in s:
                built += f" and {counted(take('transitions'), 'transition')}"
    head = f"{leaves} became {built}"
    if "units" in s:
        head += (
            f", from {counted(take('units'), 'conversion unit')} (a control node, its "
            "children and grandchildren)"
        )
    parts = [head]
    if s.get("explored_regions"):
        parts.append(
            f"{counted(take('explored_regions'), 'reactive or stateful subtree')} "
            f"explored into {counted(s.get('explored_states', '?'), 'state')}"
        )
    used.update(("explored_regions", "explored_states"))
    if "depth_before" in s:
        before, after = take("depth_before"), s.get("depth_after", "?")
        used.add("depth_after")
        depth = f"tree depth {before}" if after == before else f"tree depth {before} -> {after}"
        if s.get("merged_nodes"):
            depth += f" after merging {counted(s['merged_nodes'], 'same-type child node')}"
        used.add("merged_nodes")
        parts.append(depth)
    if s.get("loop"):
        parts.append("loop mode (the root is ticked again after it returns)")
    used.add("loop")
    return parts


def conversion_summary(direction: str, stats: Mapping[str, object], engine: str = "rules") -> str:
    """One readable sentence for a conversion's figures.

    Args:
        direction: ``fsm->bt`` or ``bt->fsm``.
        stats: the engine's figures (``ConversionResult.stats``).
        engine: the engine that made them (only ``rules`` builds a loop-execution BT).

    Returns:
        E.g. ``12 leaves became a state machine with 2 sub-state-machines, from 3 conversion
        units (...); tree depth 7``; figures it has no words for follow as ``key=value``.
    """
    used: set[str] = set()
    parts: list[str] = []
    if stats.get("style") == "structured":
        return f"{stats['summary']}; {stats['nodes']} nodes, depth {stats['depth']}"
    if direction == "fsm->bt" and "states" in stats:
        parts = _fsm_to_bt(stats, engine, used)
    elif direction == "bt->fsm" and stats.get("style") == "dispatch" and "states" in stats:
        used.update(("style", "states", "transitions", "final_states", "configurations"))
        parts = [
            f"a dispatch BT became a state machine of {counted(stats['states'], 'state')} "
            f"({stats.get('final_states', 0)} final) and "
            f"{counted(stats.get('transitions', 0), 'transition')}, read from its "
            f"{counted(stats.get('configurations', 0), 'macro-step configuration')} "
            "(docs/semantics.md section 12)"
        ]
        if "composites" in stats:
            used.add("composites")
            parts.append(
                f"{counted(stats['composites'], 'composite state')} rebuilt from the "
                "configurations' names (docs/semantics.md §12a)"
            )
    elif direction == "bt->fsm" and ("leaves" in stats or "k" in stats):
        parts = _bt_to_fsm(stats, used)
    rest = [f"{k}={v}" for k, v in stats.items() if k not in used]
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
    text = (
        f"{stats['source_states']} source and {stats['result_states']} result "
        "configurations (an FSM's states plus its start; a BT's leaves about to tick plus "
        "its results)"
    )
    if "product_states" in stats:
        text += f", {counted(stats['product_states'], 'pair')} of them explored together"
    return text
