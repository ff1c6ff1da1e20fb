"""The NuSMV rules live beside the interpreter's, family by family (issue 25; docs/nusmv.md,
"Where the rules live"): one module of ``fsmbt.verify.nusmv.families`` per module of
``fsmbt.semantics.families``, with the same name and the same rule names, a header that names
the rule it mirrors, and one merged table that covers every kind the registry says is encoded.
"""

from __future__ import annotations

from types import ModuleType

import pytest

from fsmbt.semantics.compiled import CompiledNode
from fsmbt.semantics.families import registry as semantics_registry
from fsmbt.semantics.nodes import all_nodes
from fsmbt.verify.nusmv.families import registry
from fsmbt.verify.nusmv.families.contract import BTCore, Resets


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
