"""The conversion engines by name (each returns a ``fsmbt.convert.result.ConversionResult``).

An engine is a pair of callables ``(fsm_to_bt, bt_to_fsm)``, each taking the source model and
keyword options (``style``, ``loop``, ... as the engine understands them) and returning a
``ConversionResult``. ``rules`` (the paper's algorithms done exactly, the default) is
registered here from the converters this module imports; the baselines (``bsd``, ``chds``) and the LLM path (``llm``, ``nllm``, ``hybrid``)
plug in the same way with ``register_engine`` from their own modules, listed in
``_PLUGIN_MODULES`` so that ``get_engine`` finds them without anyone editing this table.
A direction an engine does not offer is ``None``.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from typing import Any

from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.convert.dispatch import fsm_to_dispatch
from fsmbt.convert.dispatch_fsm import dispatch_to_fsm
from fsmbt.convert.hfsm_to_bt import fsm_to_bt
from fsmbt.convert.result import ConversionResult, Converter, Model
from fsmbt.convert.structure import MAX_XML_LEVELS
from fsmbt.convert.structured import structured_result
from fsmbt.convert.structured.style import (
    AUTO,
    DISPATCH,
    STRUCTURED,
    check_style,
    resolve_style,
)
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.fsm import FSM
from fsmbt.semantics.dispatch_memoryless import memory_refusal
from fsmbt.semantics.dispatch_runtime import is_dispatch_bt
from fsmbt.semantics.outcome_blackboard import OutcomeTree
from fsmbt.semantics.outcome_rules import OutcomeRules


@dataclass(frozen=True)
class Engine:
    name: str
    fsm_to_bt: Converter | None
    bt_to_fsm: Converter | None
    description: str = ""


_ENGINES: dict[str, Engine] = {}

#: Option of the rules engine's FSM -> BT: NuSMV will check the result, so ``auto`` writes a
#: form NuSMV encodes (the dispatch form when ``nusmv_refusal`` finds nothing, else the LEBT).
NUSMV_CHECKED = "nusmv_checked"

#: Modules that register further engines when imported (missing ones are skipped). They are
#: plugins: each imports ``register_engine`` from here and registers itself, so this table does
#: not import them statically (that would be a cycle); they are loaded on the first look-up, which
#: also keeps the LLM engine's heavier imports out of every start-up that never asks for it.
_PLUGIN_MODULES = (
    "fsmbt.convert.baselines",
    "fsmbt.llm.engine",
)


def nusmv_refusal(doc: Model) -> str:
    """Why NuSMV's encoding of the dispatch form would refuse the tree ``doc`` (the node and
    the reason, ``fsmbt.semantics.dispatch_memoryless``), or ``""``. O(nodes)."""
    assert isinstance(doc, BTDocument)
    refused = memory_refusal(OutcomeTree(doc))
    if refused is None:
        return ""
    node, why = refused
    return f"<{node.source.type}> '{node.label}': {why}"


def register_engine(
    name: str, fsm_to_bt: Converter | None, bt_to_fsm: Converter | None, description: str = ""
) -> Engine:
    """Add (or replace) an engine under ``name``."""
    engine = Engine(name, fsm_to_bt, bt_to_fsm, description)
    _ENGINES[name] = engine
    return engine


def rules_fsm_to_bt(
    fsm: FSM,
    *,
    style: str = AUTO,
    outcome_driven: bool = False,
    outcomes: str | None = None,
    **options: Any,
) -> ConversionResult:
    """The rules engine's FSM -> BT: the structured tree for an outcome-driven machine, the
    dispatch form otherwise (``fsmbt.convert.structured.style``: ``auto``, ``structured``,
    ``lebt``, ``dispatch``).

    Under ``auto`` an event-driven machine gets the dispatch form (docs/semantics.md §12; a
    hierarchical machine keeps its composite states, §12a, unless the form cannot keep them or
    ``hierarchy="flatten"``: then it is flattened first), or the LEBT with a
    warning naming why when the dispatch form cannot be written (an event a ``Switch`` cannot
    compare, an eventless transition: the dispatch builder's ``InputError``), or when NuSMV is
    to check the result (option ``NUSMV_CHECKED``, set by ``fsmbt.api`` for
    ``--verify-engine nusmv|both``) and the tree holds a node its encoding of the dispatch
    form does not model (``nusmv_refusal``; never for a tree this builder writes, both
    forms are encoded: docs/nusmv.md, "The dispatch form").

    Depth bound (docs/semantics.md §5, "Depth-bounded LEBT"): a structured tree that would nest
    deeper than ``MAX_XML_LEVELS`` XML levels is not written; under ``auto`` the depth-bounded
    LEBT is written instead, with a warning saying why; under ``structured`` it is an error.

    Raises:
        InputError: an unknown style; OutcomeError: ``structured`` on an event-driven machine,
        or a malformed outcome-driven one (state and cause named); UnsupportedError:
        ``structured`` whose tree would nest deeper than the bound.
    """
    rules = OutcomeRules.from_option(outcomes)
    chosen, view = resolve_style(style, fsm, outcome_driven=outcome_driven, rules=rules)
    not_dispatch = ""
    checked_by_nusmv = bool(options.pop(NUSMV_CHECKED, False))
    if chosen == DISPATCH and check_style(style) == AUTO:
        try:
            written = fsm_to_dispatch(fsm, **options)
            refused = nusmv_refusal(written.model) if checked_by_nusmv else ""
            if not refused:
                return written
            not_dispatch = (
                f"NuSMV (--verify-engine nusmv|both) does not encode this dispatch tree "
                f"({refused}): the LEBT was written, which both checkers prove"
            )
        except InputError as exc:  # UnsupportedError too: an event a Switch cannot compare
            where = f" ({exc.element})" if exc.element else ""
            not_dispatch = (
                f"the dispatch form cannot be written{where}: "
                f"{exc.message.split('; use --style lebt')[0]}; the LEBT was written instead"
            )
        chosen = "lebt"
    elif chosen == DISPATCH:
        return fsm_to_dispatch(fsm, **options)
    too_deep = ""
    if view is not None:
        result = structured_result(view)
        result.engine = "rules"
        xml_levels = int(result.stats.get("depth", 0)) + 2  # <root>, <BehaviorTree>
        if xml_levels <= MAX_XML_LEVELS:
            return result
        too_deep = (
            f"the structured tree would nest {xml_levels} XML levels, more than the "
            f"{MAX_XML_LEVELS} BehaviorTree.CPP loads everywhere (4.9+ refuses 256)"
        )
        if check_style(style) == STRUCTURED:
            raise UnsupportedError(f"{too_deep}; --style lebt writes a depth-bounded tree")
        chosen = "lebt"
    result = fsm_to_bt(fsm, style="paper", **options)
    result.stats.setdefault("style", chosen)
    if not_dispatch:
        result.warnings.append(not_dispatch)
    if too_deep:
        result.warnings.append(f"{too_deep}: the depth-bounded LEBT was written instead")
    return result


def rules_bt_to_fsm(doc: BTDocument, *, style: str = AUTO, **options: Any) -> ConversionResult:
    """The rules engine's BT -> FSM (one style; ``structured`` is an FSM -> BT style).

    A dispatch tree (``DispatchEntry`` leaves, docs/semantics.md section 12) becomes the state
    machine of its macro steps (``fsmbt.convert.dispatch_fsm``); any other tree the
    hierarchical FSM of its leaf execution (``fsmbt.convert.bt_to_hfsm``).

    Raises:
        InputError: ``structured``, or ``loop`` on a dispatch tree (it runs by macro steps).
    """
    if check_style(style) == STRUCTURED:
        raise InputError(
            "--style structured converts outcome-driven state machines into behavior trees; "
            "this input is a behavior tree",
            element="--style",
        )
    if is_dispatch_bt(doc):
        if options.get("loop"):
            raise InputError(
                "a dispatch tree runs by macro steps (its root is ticked once per event); "
                "--loop is for trees read by leaf execution",
                element="--loop",
            )
        return dispatch_to_fsm(doc, max_states=options.get("max_states"))
    return bt_to_hfsm(doc, style="paper", **options)


def _register_rules() -> None:
    """The default engine: the structured tree (outcome-driven machines), the dispatch form
    (event-driven ones) or, asked for, the LEBT for FSM -> BT (a SubTree per composite state of
    a hierarchical FSM, option ``hierarchy``); hierarchical conversion units for BT -> FSM (the
    macro-step machine for a dispatch tree)."""
    register_engine(
        "rules",
        rules_fsm_to_bt,
        rules_bt_to_fsm,
        "the paper's algorithms done exactly (LEBT; depth compression + units), the "
        "structured style for outcome-driven machines and the dispatch form for event-driven "
        "ones",
    )


def _load_plugins(until: str | None = None) -> None:
    """Import the plug-in modules in order (all of them, or until ``until`` is registered)."""
    if "rules" not in _ENGINES:
        _register_rules()
    for module in _PLUGIN_MODULES:
        if until is not None and until in _ENGINES:
            return
        try:
            importlib.import_module(module)
        except ModuleNotFoundError as exc:
            if exc.name is None or not module.startswith(exc.name):
                raise  # a real missing dependency inside the plugin, not an absent plugin


def engines() -> dict[str, Engine]:
    """Every registered engine by name."""
    _load_plugins()
    return dict(_ENGINES)


def get_engine(name: str) -> Engine:
    """The engine registered under ``name``.

    The plug-in modules (baselines, LLM engines) are imported only when ``name`` is not
    registered yet: ``rules`` needs none of them, and the LLM engine's client library alone
    costs about half a second to import.

    Raises:
        InputError: no engine has that name (the known ones are listed).
    """
    if "rules" not in _ENGINES:
        _register_rules()
    if name not in _ENGINES:
        _load_plugins(until=name)
    try:
        return _ENGINES[name]
    except KeyError:
        known = ", ".join(sorted(_ENGINES))
        raise InputError(f"unknown engine '{name}' (known: {known})") from None


def converter_for(engine: str, model: Model) -> Converter:
    """The callable converting ``model`` with ``engine`` (direction from the model's kind)."""
    chosen = get_engine(engine)
    if isinstance(model, FSM):
        func, direction = chosen.fsm_to_bt, "FSM -> BT"
    elif isinstance(model, BTDocument):
        func, direction = chosen.bt_to_fsm, "BT -> FSM"
    else:
        raise InputError(f"cannot convert a {type(model).__name__}")
    if func is None:
        raise UnsupportedError(f"engine '{engine}' does not convert {direction}")
    return func
