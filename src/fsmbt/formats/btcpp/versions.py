"""BehaviorTree.CPP v3 and v4: which built-in nodes each version has, under which names and
ports, and how a v3 node's attributes read in v4 terms (docs/formats/btcpp.md, "Version 3").

The v3 facts are those of BehaviorTree.CPP 3.8 (ROS 2 Humble's ``behaviortree_cpp_v3``): its
``BehaviorTreeFactory`` registers the nodes of ``V3_PORTS`` (``ManualSelector`` only with
ncurses, as in v4), its XML parser refuses an attribute that is not a port of the node's
manifest except ``ID``, ``name`` and ``_description`` (``V3_RESERVED``), and a SubTree is
either ``<SubTree>`` (isolated, its attributes remap a subtree key to a parent key *named
without braces*, or ``__shared_blackboard="true"``: the parent's blackboard) or
``<SubTreePlus>`` (v4's ``SubTree``: ``{key}`` remaps, a literal sets, ``__autoremap``).
Parallel's thresholds are ``success_threshold`` (required) and ``failure_threshold``
(default 1) with v4's meaning of ``success_count`` / ``failure_count`` (negative: all but).

Pure data and dict rewrites; O(attributes) per node.
"""

from __future__ import annotations

#: BehaviorTree.CPP 3.8's built-in nodes (the v3 names) and the ports their manifests list.
V3_PORTS: dict[str, frozenset[str]] = {
    "Fallback": frozenset(),
    "Sequence": frozenset(),
    "SequenceStar": frozenset(),
    "Parallel": frozenset({"success_threshold", "failure_threshold"}),
    "ReactiveSequence": frozenset(),
    "ReactiveFallback": frozenset(),
    "IfThenElse": frozenset(),
    "WhileDoElse": frozenset(),
    "Inverter": frozenset(),
    "RetryUntilSuccessful": frozenset({"num_attempts"}),
    "KeepRunningUntilFailure": frozenset(),
    "Repeat": frozenset({"num_cycles"}),
    "Timeout": frozenset({"msec"}),
    "Delay": frozenset({"delay_msec"}),
    "ForceSuccess": frozenset(),
    "ForceFailure": frozenset(),
    "AlwaysSuccess": frozenset(),
    "AlwaysFailure": frozenset(),
    "SetBlackboard": frozenset({"value", "output_key"}),
    "SubTree": frozenset({"__shared_blackboard"}),  # and remaps: any attribute
    "SubTreePlus": frozenset({"__autoremap"}),  # and remaps: any attribute
    "BlackboardCheckInt": frozenset({"value_A", "value_B", "return_on_mismatch"}),
    "BlackboardCheckDouble": frozenset({"value_A", "value_B", "return_on_mismatch"}),
    "BlackboardCheckString": frozenset({"value_A", "value_B", "return_on_mismatch"}),
    "BlackboardCheckBool": frozenset({"value_A", "value_B", "return_on_mismatch"}),
    "ManualSelector": frozenset({"repeat_last_selection"}),
    **{
        f"Switch{n}": frozenset({"variable", *(f"case_{i}" for i in range(1, n + 1))})
        for n in range(2, 7)
    },
}
#: Attributes BehaviorTree.CPP 3.8 takes on any node without a port of that name.
V3_RESERVED = frozenset({"ID", "name", "_description"})
#: v4 names whose v3 name differs (the migration guide's "SequenceStar -> SequenceWithMemory").
V4_TO_V3_NAMES = {"SequenceWithMemory": "SequenceStar"}
#: v4 port names whose v3 name differs, per node.
V4_TO_V3_PORTS = {
    "Parallel": {"success_count": "success_threshold", "failure_count": "failure_threshold"}
}
#: v4's defaults of ports v3 requires (``success_threshold`` has no default in 3.8).
V3_REQUIRED_DEFAULTS = {"Parallel": {"success_count": "-1", "failure_count": "1"}}
#: v4 pre-conditions: they decide whether a node is ticked, v3 has no way to say it.
PRE_CONDITIONS = ("_skipIf", "_failureIf", "_successIf", "_while")
#: v4 post-conditions: they only write the blackboard (docs/semantics.md, section 2).
POST_CONDITIONS = ("_onSuccess", "_onFailure", "_onHalted", "_post")
#: v4's SubTree attribute that shares every key with the parent.
AUTOREMAP = "_autoremap"


def _truthy(value: str) -> bool:
    return value.strip().lower() in ("true", "1")


def v4_attrs(tag: str, type_name: str, attrs: dict[str, str]) -> dict[str, str]:
    """The v4 meaning of a v3 node's attributes, in their order: Parallel's thresholds under
    v4's port names; ``<SubTreePlus __autoremap>`` as ``_autoremap``; ``<SubTree>`` remaps
    (a parent key named without braces) as ``{key}``, ``__shared_blackboard="true"`` as
    ``_autoremap="true"`` (``"false"`` is the default and dropped).

    Args:
        tag: the element's tag as written (``SubTree``, ``SubTreePlus``, ``Parallel``...).
        type_name: the node's v4 type (after the alias mapping).
        attrs: the attributes other than ``name``.
    """
    if type_name == "Parallel":
        names = {v3: v4 for v4, v3 in V4_TO_V3_PORTS["Parallel"].items()}
        return {names.get(k, k): v for k, v in attrs.items()}
    if type_name != "SubTree":
        return attrs
    out: dict[str, str] = {}
    plus = tag == "SubTreePlus"
    for key, value in attrs.items():
        if key == "ID":
            out[key] = value
        elif plus and key == "__autoremap":
            out[AUTOREMAP] = value
        elif not plus and key == "__shared_blackboard":
            if _truthy(value):
                out[AUTOREMAP] = "true"
        elif not plus and not (value.startswith("{") and value.endswith("}")):
            out[key] = "{" + value + "}"
        else:
            out[key] = value
    return out


def v3_subtree(attrs: dict[str, str]) -> tuple[str, dict[str, str]]:
    """How v3 writes a v4 ``SubTree`` node: ``<SubTree ID>`` when it remaps nothing (both
    isolated), ``<SubTree ID __shared_blackboard="true">`` when it only auto-remaps (every key
    shared with the parent), else ``<SubTreePlus>`` (v4's SubTree under its v3 name,
    ``_autoremap`` as ``__autoremap``).

    Returns:
        The v3 tag and its attributes, in order.
    """
    rest = [k for k in attrs if k not in ("ID", AUTOREMAP) and k not in V3_RESERVED]
    auto = attrs.get(AUTOREMAP)
    if not rest and (auto is None or not _truthy(auto)):
        return "SubTree", {k: v for k, v in attrs.items() if k != AUTOREMAP}
    if not rest:
        return "SubTree", {
            ("__shared_blackboard" if k == AUTOREMAP else k): v for k, v in attrs.items()
        }
    return "SubTreePlus", {("__autoremap" if k == AUTOREMAP else k): v for k, v in attrs.items()}


def v3_name(type_name: str) -> str | None:
    """The v3 name of a v4 built-in, ``None`` when BehaviorTree.CPP 3.8 has no such node."""
    name = V4_TO_V3_NAMES.get(type_name, type_name)
    return name if name in V3_PORTS else None
