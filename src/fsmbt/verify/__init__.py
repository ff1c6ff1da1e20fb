"""Equivalence checking of a source model and its conversion (docs/verification.md).

``verify(source, result)`` gives a ``Report``: the verdict and the five properties, each with a
shortest counterexample when it fails. Two engines: ``native`` (explicit-state product, the
default) and ``nusmv``; ``both`` runs the two and raises ``EngineDisagreement`` if any property
verdict differs, since then one of them is wrong; when NuSMV reaches its time or memory cap, ``both``
returns the native verdict with ``stats["nusmv_limit"]`` saying so, and the same when the outcome
pairing's encoding refuses a construct by name (docs/nusmv.md, "The outcome pairing"). Every report names its
``method``, ``engines`` and ``abstractions`` (``fsmbt.verify.method``); inside
``certificate.collecting()`` the native check's witness (or, for a compositional proof, each
part's) is kept for a certificate.
"""

from __future__ import annotations

from typing import Any

from fsmbt import __version__
from fsmbt.convert.perf import gc_paused
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import Hint, InputError, UnsupportedError
from fsmbt.model.fsm import FSM
from fsmbt.semantics.dispatch_runtime import is_dispatch_bt
from fsmbt.semantics.execution import Flavour, flavour_of
from fsmbt.semantics.machine import FSMLeafMachine, Machine
from fsmbt.semantics.outcome_machine import OutcomeFSMMachine
from fsmbt.semantics.outcome_rules import OutcomeRules
from fsmbt.verify import certificate
from fsmbt.verify.compositional import (
    FAILED_PART,
    CheckPlan,
    Parts,
    attempt_seconds,
    compositional_report,
)
from fsmbt.verify.method import SYMBOLIC_PER_NODE_SENTENCE, describe_method, nusmv_engine
from fsmbt.verify.native import DEFAULT_MAX_STATES, Replay, check, check_witnessed, replay
from fsmbt.verify.outcome_pairing import is_outcome_pair, outcome_abstractions
from fsmbt.verify.pairing import machines_for
from fsmbt.verify.report import (
    LIFTED,
    PER_NODE,
    PER_NODE_LIFTED,
    PROPERTIES,
    SYMBOLIC,
    SYMBOLIC_PER_NODE,
    PropertyResult,
    Report,
    TraceStep,
)

ENGINES = ("native", "nusmv", "both")


class EngineDisagreement(RuntimeError):
    """The native checker and NuSMV disagree on a property, or on a local check of the
    per-node decomposition (``detail`` says which): a bug in one of them (exit 3)."""

    def __init__(self, native: Report, nusmv: Report, detail: str | None = None) -> None:
        differing = [
            name for name in PROPERTIES if native.verdicts().get(name) != nusmv.verdicts().get(name)
        ]
        shown = ", ".join(
            f"{name} (native {_word(native.verdicts().get(name))}, "
            f"NuSMV {_word(nusmv.verdicts().get(name))})"
            for name in differing
        )
        super().__init__(f"the engines disagree on {detail or shown}")
        self.native = native
        self.nusmv = nusmv
        self.differing = differing


def verify(
    source: FSM | BTDocument,
    result: FSM | BTDocument,
    *,
    engine: str = "native",
    loop: bool = False,
    max_states: int = DEFAULT_MAX_STATES,
    outcomes: OutcomeRules | None = None,
    outcome_driven: bool = False,
) -> Report:
    """Check that ``result`` behaves exactly like ``source`` (see ``fsmbt.verify.pairing``).

    Args:
        source: The model that was converted.
        result: Its conversion.
        engine: ``native`` (explicit-state product), ``nusmv``, or ``both`` (must agree).
        loop: BT source: the root is ticked again after it finishes (leaf-execution mode).
        max_states: Bound on the states the native checker explores per machine.
        outcomes: FSM source, structured BT result: the outcome rules (docs/semantics.md §11).
        outcome_driven: the FSM's events are outcomes even where no state declares them.

    Returns:
        The report: the verdict and the five properties, each with a shortest
        counterexample when it fails.

    Raises:
        InputError: Unknown engine, a pair of models that cannot be compared, NuSMV
            missing when it is asked for, or a machine with more than ``max_states``
            reachable states.
        UnsupportedError: A construct the chosen engine does not model (located).
        EngineDisagreement: With ``both``, the engines differ on some property.
        NuSMVLimitError: With ``nusmv``, NuSMV reached its cap (with ``both`` the native
            verdict is returned instead, ``stats["nusmv_limit"]`` naming the cap).
    """
    if engine not in ENGINES:
        raise InputError(f"unknown verification engine '{engine}' (known: {', '.join(ENGINES)})")
    pairing = (outcomes, outcome_driven)  # the outcome pairing's reading, for both engines
    outcome_pair = (
        isinstance(source, FSM)
        and isinstance(result, BTDocument)
        and is_outcome_pair(source, result, outcome_driven=outcome_driven)
    )
    if engine != "native" and dispatch_beside_bt(source, result):
        raise UnsupportedError(
            "NuSMV encodes the dispatch form (docs/semantics.md section 12) against a state "
            "machine only, by macro steps; not against another tree",
            hints=(Hint.NATIVE_VERIFIER,),
        )
    sink = certificate.active_sink()
    fell_back = ""
    if not loop:
        # one compositional attempt serves every engine (docs/verification.md, "What a verdict
        # says"): native keeps it; NuSMV decides its per-node checks again, or, with ``both``,
        # the whole pair beside its verdict - the native verdict is never computed twice
        plan = CheckPlan() if engine != "native" else None
        proved, fell_back = _compositional(source, result, max_states, sink, plan)
        if proved is not None and engine == "native":
            return proved
        if proved is not None and plan is not None:
            decided = _per_node_nusmv(proved, plan, engine)
            if decided is not None:
                return decided
            if engine == "both":
                return _beside_nusmv(proved, source, result, pairing, outcome_pair)
        if sink is not None and engine == "nusmv":  # NuSMV's whole encodings decide
            sink.witness, sink.parts = None, None
    if engine == "nusmv":
        report = _nusmv(source, result, loop, pairing, fallback=False)
        report.method = SYMBOLIC
        report.engines = nusmv_engine()
        return report
    with gc_paused():  # a data machine's expansion allocates its flat machine (acyclic)
        source_machine, result_machine, mode = machines_for(
            source, result, loop=loop, outcomes=outcomes, outcome_driven=outcome_driven
        )
    native = _native(source_machine, result_machine, max_states, mode, sink, loop, False)
    if isinstance(source_machine, OutcomeFSMMachine):
        native.stats["abstractions"] = outcome_abstractions(source_machine.view)
    native.source = _model_name(source, native.source)
    native.result = _model_name(result, native.result)
    if fell_back:  # the verdict says the compositional check did not decide it, and why
        native.stats["compositional"] = fell_back
    if engine == "native":
        return native
    try:
        other = _nusmv(source, result, loop, pairing)
    except (NuSMVGaveUp, UnsupportedError) as exc:
        return _nusmv_limited(native, exc, outcome_pair)
    if _reachability_only(native, other):
        # Reachability compares states: a leaf machine on reduced states (docs/semantics.md
        # §4a) may merge a state reached only outside the agreeing pairs with one reached in
        # them. The faithful machines decide the state-based property the way NuSMV does.
        source_machine, result_machine, mode = machines_for(
            source,
            result,
            loop=loop,
            faithful=True,
            outcomes=outcomes,
            outcome_driven=outcome_driven,
        )
        faithful = _native(source_machine, result_machine, max_states, mode, sink, loop, True)
        faithful.source, faithful.result = native.source, native.result
        native = faithful
    if native.verdicts() != other.verdicts():
        raise EngineDisagreement(native, other)
    return _joined(native, other)


def _beside_nusmv(
    native: Report,
    source: FSM | BTDocument,
    result: FSM | BTDocument,
    pairing: tuple[OutcomeRules | None, bool],
    outcome_pair: bool,
) -> Report:
    """``both`` on a pair the compositional check decided but not node by node (a proof by
    regions, or a region's counterexample lifted): NuSMV's whole encodings decide the pair
    beside that verdict. A proof must meet NuSMV's on all five properties; a lifted
    counterexample lists only the properties its replay shows failing (docs/verification.md
    §3), and each of them must fail in NuSMV too, whose verdict must be NOT EQUIVALENT. A NuSMV
    cap keeps the native verdict and says so, as for the whole product."""
    try:
        other = _nusmv(source, result, False, pairing)
    except (NuSMVGaveUp, UnsupportedError) as exc:
        return _nusmv_limited(native, exc, outcome_pair)
    if native.method in LIFTED:
        theirs = other.verdicts()
        shown = [name for name, holds in native.verdicts().items() if not holds]
        if other.equivalent or any(theirs.get(name) is not False for name in shown):
            raise EngineDisagreement(
                native,
                other,
                "the lifted counterexample's properties "
                + ", ".join(f"{name} (NuSMV {_word(theirs.get(name))})" for name in shown),
            )
    elif native.verdicts() != other.verdicts():
        raise EngineDisagreement(native, other)
    return _joined(native, other)


def _nusmv_limited(native: Report, exc: Exception, outcome_pair: bool) -> Report:
    """The native verdict when NuSMV gave up (its time or memory cap) or, on an outcome pair,
    refused a construct by name (docs/nusmv.md, "The outcome pairing"): the verdict stands and
    the report says NuSMV could not confirm it (docs/verification.md, "What a verdict says").
    Any other refusal is the user's answer and is raised again."""
    if isinstance(exc, UnsupportedError):
        if not outcome_pair:
            raise exc
        native.stats["nusmv_limit"] = f"NuSMV does not encode this pair: {exc}"
    else:
        native.stats["nusmv_limit"] = str(exc)
    native.engines.update(nusmv_engine())
    return native


def _joined(native: Report, other: Report) -> Report:
    """The native verdict confirmed by NuSMV's: both engines and methods named."""
    native.engine = "native+nusmv"
    native.method = f"{native.method}+{SYMBOLIC}"
    native.engines.update(nusmv_engine())
    native.stats["nusmv"] = dict(other.stats)
    return native


def _native(
    source_machine: Machine[Any],
    result_machine: Machine[Any],
    max_states: int,
    mode: str,
    sink: certificate.WitnessSink | None,
    loop: bool,
    faithful: bool,
) -> Report:
    """The native check, its method and abstractions named; its witness left in ``sink``."""
    report, witness = check_witnessed(
        source_machine, result_machine, max_states=max_states, mode=mode
    )
    report.method, report.abstractions = describe_method(source_machine, result_machine)
    report.engines = {"fsmbt native checker": __version__}
    if sink is not None:
        sink.witness, sink.loop, sink.faithful = witness, loop, faithful
    return report


def _per_node_nusmv(report: Report, plan: CheckPlan, engine: str) -> Report | None:
    """``both``/``nusmv`` on a pair the native checker decided node by node (``report``, with
    the local checks it made in ``plan``; docs/nusmv.md, "Trees node by node"): NuSMV decides
    the same distinct local checks (its own encoding of each node's tick rules) and the parts
    checked whole; ``None`` when the native verdict is not per node (``nusmv`` also when the
    native per-node check refuted the pair): the caller decides then. With ``both``, a NuSMV
    limit or a unit it does not encode keeps the native verdict and says so
    (``stats["nusmv_limit"]``); any disagreement on a unit raises ``EngineDisagreement``.

    Raises:
        NuSMVLimitError, UnsupportedError: with ``nusmv``, NuSMV past a cap or a unit it
            does not encode.
    """
    if report.method not in (PER_NODE, PER_NODE_LIFTED):
        return None
    if engine == "nusmv" and report.method != PER_NODE:
        return None
    try:
        from fsmbt.verify.nusmv import NuSMVLimitError
        from fsmbt.verify.nusmv.pernode import check_plan
    except ImportError as exc:
        raise InputError(
            f"the NuSMV engine is not available ({exc})", hints=(Hint.NATIVE_VERIFIER,)
        ) from None
    try:
        found = check_plan(plan.units, plan.wholes)
    except NuSMVLimitError as exc:
        if engine == "nusmv":
            raise
        report.engines.update(nusmv_engine())
        report.stats["nusmv_limit"] = str(exc)
        return report
    if found.limits:
        if engine == "nusmv":
            raise UnsupportedError(
                "NuSMV's per-node check does not encode " + "; ".join(found.limits[:3]),
                hints=(Hint.NATIVE_VERIFIER,),
            )
        report.engines.update(nusmv_engine())
        report.stats["nusmv_limit"] = "; ".join(found.limits[:3])
        return report
    stats = found.stats()
    if report.method == PER_NODE:
        if not found.holds:
            failing = found.local.failed
            steps = "; ".join(failing[0].steps) if failing else "a part checked whole differs"
            raise EngineDisagreement(
                report,
                report,
                f"the local check of {found.first_failure()} (native holds, NuSMV fails: {steps})",
            )
        report.method = f"{PER_NODE}+{SYMBOLIC_PER_NODE}" if engine == "both" else SYMBOLIC_PER_NODE
        confirmed = (
            f"; NuSMV: every one of the {len(found.local.verdicts)} distinct local checks holds "
            f"({found.local.runs} runs) and the {len(found.wholes)} part(s) checked whole"
        )
        for prop in report.properties.values():
            prop.detail += confirmed
        report.engine = "native+nusmv" if engine == "both" else "nusmv"
    else:  # refuted per node and lifted: NuSMV must fail the same unit, and that one only
        native_failed = report.stats.get("per_node_failed", "")
        verdicts = found.local.verdicts
        same = (
            bool(verdicts)
            and all(v.holds for v in verdicts[:-1])
            and not verdicts[-1].holds
            and all(equivalent for _n, equivalent in found.wholes)
        )
        if not same:
            raise EngineDisagreement(
                report,
                report,
                f"the per-node check of {native_failed} (native fails there, NuSMV: "
                f"{found.first_failure() or 'every local check holds'})",
            )
        report.engine = "native+nusmv"
    report.abstractions.append(SYMBOLIC_PER_NODE_SENTENCE)
    report.engines.update(nusmv_engine())
    report.stats["nusmv"] = stats
    return report


def _compositional(
    source: FSM | BTDocument,
    result: FSM | BTDocument,
    max_states: int,
    sink: certificate.WitnessSink | None,
    plan: CheckPlan | None = None,
) -> tuple[Report | None, str]:
    """The compositional proof of a BT against a hierarchical FSM (``fsmbt.verify.
    compositional``) when the pair decomposes into regions and every local check holds within
    its budget (``attempt_seconds``); ``None`` otherwise, and the whole product decides (and
    explains a difference). A pair with a single region is left to the whole product before
    any part is checked (the same product, done once), unless that region was written per node
    (its per-node check, ``verify/pernode.py``, is not the whole product). The
    string says why a local check failed (the whole product then gives the verdict), else
    ``""``. Inside ``certificate.collecting()`` the parts' witnesses are left in ``sink``."""
    if not (isinstance(source, BTDocument) and isinstance(result, FSM)):
        return None, ""
    if is_dispatch_bt(source) or flavour_of(source) is not Flavour.PLAIN:
        return None, ""
    parts = Parts() if sink is not None else None
    with gc_paused():  # one region is the whole product again: give way before any part
        report, why = compositional_report(
            source,
            result,
            max_states=max_states,
            keep=parts,
            min_regions=2,
            max_seconds=attempt_seconds(),
            plan=plan,
        )
    if report is None:
        # a part failed: the whole product decides and explains; the verdict says so
        return None, why if why.startswith(FAILED_PART) else ""
    if report.stats["regions"] < 2 and not report.stats.get("per_node_regions"):
        return None, ""  # one region: its check is the whole product again; let that decide
    report.engines = {"fsmbt native checker": __version__}
    if sink is not None:
        sink.witness, sink.parts, sink.loop, sink.faithful = None, parts, False, False
    report.source = _model_name(source, report.source)
    report.result = _model_name(result, report.result)
    return report, ""


def _reachability_only(native: Report, other: Report) -> bool:
    """The two reports differ in the reachability property alone, on a failing pair."""
    mine, theirs = native.verdicts(), other.verdicts()
    differing = {name for name in mine if mine[name] != theirs.get(name)}
    return differing == {"reachability"} and not native.equivalent


class NuSMVGaveUp(RuntimeError):
    """NuSMV reached its time or memory cap (``fsmbt.limits``) on a pair."""


def _nusmv(
    source: FSM | BTDocument,
    result: FSM | BTDocument,
    loop: bool,
    pairing: tuple[OutcomeRules | None, bool] = (None, False),
    *,
    fallback: bool = True,
) -> Report:
    try:
        from fsmbt.verify import nusmv
    except ImportError as exc:
        raise InputError(
            f"the NuSMV engine is not available ({exc})", hints=(Hint.NATIVE_VERIFIER,)
        ) from None
    checker = getattr(nusmv, "check", None)
    if checker is None:
        raise InputError(
            "the NuSMV engine is not available (fsmbt.verify.nusmv has no check)",
            hints=(Hint.NATIVE_VERIFIER,),
        )
    try:
        outcomes, outcome_driven = pairing
        report: Report = checker(
            source, result, loop=loop, outcomes=outcomes, outcome_driven=outcome_driven
        )
        return report
    except nusmv.NuSMVLimitError as exc:
        if fallback:
            raise NuSMVGaveUp(str(exc)) from None
        raise
    except FileNotFoundError as exc:
        raise InputError(
            f"the NuSMV binary is not installed ({exc}); scripts/setup.sh builds it",
            hints=(Hint.NATIVE_VERIFIER,),
        ) from None


def _model_name(model: FSM | BTDocument, fallback: str) -> str:
    if isinstance(model, FSM):
        return model.name
    try:
        return model.main.id
    except KeyError:
        return fallback


def _word(verdict: bool | None) -> str:
    return {True: "holds", False: "fails", None: "missing"}[verdict]


__all__ = [
    "verify",
    "check",
    "replay",
    "Replay",
    "Report",
    "PropertyResult",
    "TraceStep",
    "PROPERTIES",
    "EngineDisagreement",
    "FSMLeafMachine",
    "machines_for",
    "ENGINES",
]


def dispatch_beside_bt(source: FSM | BTDocument, result: FSM | BTDocument) -> bool:
    """Whether a dispatch tree is paired with a tree: NuSMV encodes the dispatch form only
    against a state machine (``fsmbt.verify.nusmv.encode_dispatch``; the native pairing then
    compares leaf-execution machines, whose Switch blackboard NuSMV does not model)."""
    trees = [m for m in (source, result) if isinstance(m, BTDocument)]
    return any(is_dispatch_bt(t) for t in trees) and len(trees) == 2
