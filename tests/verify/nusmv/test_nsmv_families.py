"""The NuSMV rules live beside the interpreter's, family by family (issue 25; docs/nusmv.md,
"Where the rules live"): one module of ``fsmbt.verify.nusmv.families`` per module of
``fsmbt.semantics.families``, with the same name and the same rule names, a header that names
the rule it mirrors, and one merged table that covers every kind the registry says is encoded.
"""

from __future__ import annotations

import ast
import inspect
from types import ModuleType

import pytest

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.errors import UnsupportedError
from fsmbt.model.kinds import NodeKind
from fsmbt.model.nodes import registered
from fsmbt.semantics.compiled import CompiledNode
from fsmbt.semantics.families import registry as semantics_registry
from fsmbt.semantics.families.contract import FamilyRule
from fsmbt.semantics.families.registry import register_rule, unregister_rule
from fsmbt.semantics.nodes import all_nodes
from fsmbt.verify.nusmv import build_model, encode_bt
from fsmbt.verify.nusmv import check as nusmv_check
from fsmbt.verify.nusmv.families import registry
from fsmbt.verify.nusmv.families.contract import NO_TRAITS, BTCore, Resets
from fsmbt.verify.nusmv.runner import NuSMVError
from support.family_unless import UNLESS, nusmv_unless, tick_unless, unless_installed


def _short(module: ModuleType) -> str:
    return module.__name__.rsplit(".", 1)[-1]


def test_one_nusmv_module_per_interpreter_family_with_the_same_rule_names() -> None:
    interpreter = {_short(m): set(m.RULES) for m in semantics_registry.BUILTIN_FAMILIES}
    nusmv = {_short(m): set(m.RULES) for m in registry.BUILTIN_FAMILIES}
    assert nusmv == interpreter


@pytest.mark.parametrize("module", registry.BUILTIN_FAMILIES, ids=_short)
def test_each_family_module_states_its_rule_in_its_header(module: ModuleType) -> None:
    doc = module.__doc__ or ""
    assert f"fsmbt.semantics.families.{_short(module)}" in doc  # the interpreter rule mirrored
    assert "docs/semantics.md" in doc and "Cost" in doc
    for name in module.RULES:
        assert f"``{name}``" in doc, name  # each rule it serves is described


def test_every_encoded_kind_has_its_rule_in_the_merged_table() -> None:
    rules = registry.nusmv_rules()
    wanted = {n.nusmv for n in all_nodes() if n.nusmv is not None} - {"internal_leaf"}
    assert wanted <= set(rules)


def test_built_in_rules_cannot_be_replaced_or_removed() -> None:
    def rule(core: BTCore, x: CompiledNode, here: str, called: str, resets: Resets) -> None:
        raise AssertionError("never called")

    with pytest.raises(ValueError, match="already registered"):
        registry.register_nusmv_rule("sequence", rule)
    with pytest.raises(ValueError, match="not a registered extra rule"):
        registry.unregister_nusmv_rule("gated")


@pytest.mark.parametrize("module", registry.BUILTIN_FAMILIES, ids=_short)
def test_each_family_states_the_traits_of_its_own_rules_only(module: ModuleType) -> None:
    assert set(module.TRAITS) <= set(module.RULES)
    for name in module.TRAITS:
        assert registry.rule_traits(name) is module.TRAITS[name]


def test_the_encoder_names_no_rule_and_no_kind() -> None:
    # the whole-tree checks (SKIPPED, frame variables, livelock) read the families' traits
    rule_names = set(registry.nusmv_rules())
    kind_names = {n.name for n in all_nodes()}
    literals = {
        node.value
        for node in ast.walk(ast.parse(inspect.getsource(encode_bt)))
        if isinstance(node, ast.Constant) and isinstance(node.value, str)
    }
    assert not literals & (rule_names | kind_names)


def _skipping(decorator: str) -> BTDocument:
    """``Sequence(decorator(RunOnce[then_skip](a)), b)``: the decorator's child may skip."""
    once = BTNode(
        "RunOnce",
        NodeKind.DECORATOR,
        attrs={"then_skip": "true"},
        children=[BTNode("a", NodeKind.ACTION, name="a")],
    )
    dec = BTNode(decorator, NodeKind.DECORATOR, children=[once])
    return BTDocument.single(
        BTNode("Sequence", NodeKind.CONTROL, children=[dec, BTNode("b", NodeKind.ACTION, name="b")])
    )


def test_a_rule_s_traits_decide_whether_a_skipping_child_is_encoded() -> None:
    # the worked example declares its rule skip-aware: the encoder accepts a child that may
    # return SKIPPED under it and the model is the Inverter's, whose traits say the same
    with unless_installed():
        text, _names, _ = build_model(_skipping("Unless"), _skipping("Unless"), loop=False)
        try:
            same = nusmv_check(_skipping("Inverter"), _skipping("Unless"))
            other = nusmv_check(_skipping("ForceFailure"), _skipping("Unless"))
        except NuSMVError as exc:  # no binary on this machine: say so, never pass silently
            pytest.skip(f"NuSMV not available: {exc}")
    assert "sk_" in text  # the Sequence counts the skipped child
    assert same.equivalent and not other.equivalent
    # the same rule registered with the default traits refuses it, naming the parent
    register_rule("unless", FamilyRule(tick_unless))
    registry.register_nusmv_rule("unless", nusmv_unless)
    try:
        with registered(UNLESS), pytest.raises(UnsupportedError, match="SKIPPED under Unless"):
            build_model(_skipping("Unless"), _skipping("Unless"), loop=False)
    finally:
        registry.unregister_nusmv_rule("unless")
        unregister_rule("unless")
    assert registry.rule_traits("unless") is NO_TRAITS  # unregistering drops the traits
