"""NuSMV's answers as a ``Report``: one ``PropertyResult`` per property, and each
counterexample decoded (through the symbol tables) into ``TraceStep`` s like the native ones:
one step per input both machines took while attached, the start as step 0."""

from __future__ import annotations

from typing import TYPE_CHECKING, TypeAlias

from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import UnsupportedError
from fsmbt.model.fsm import FSM
from fsmbt.semantics.status import MachineStatus
from fsmbt.verify.nusmv.encode_bt import LeafBTEncoder
from fsmbt.verify.nusmv.encode_fsm import NONE_OUT, Encoding, FSMEncoder
from fsmbt.verify.nusmv.runner import SpecResult, TraceState
from fsmbt.verify.nusmv.smv import Symbols
from fsmbt.verify.report import PROPERTIES, PropertyResult, Report, TraceStep

if TYPE_CHECKING:
    from fsmbt.verify.nusmv.encode_dispatch import DispatchEncoder
    from fsmbt.verify.nusmv.encode_lebt import LebtEncoder
    from fsmbt.verify.nusmv.encode_macro import MacroBTEncoder
    from fsmbt.verify.nusmv.encode_outcome import OutcomeFSMEncoder
    from fsmbt.verify.nusmv.encode_sv import SvEncoder

Encoder: TypeAlias = (
    "FSMEncoder | LeafBTEncoder | LebtEncoder | DispatchEncoder | SvEncoder | OutcomeFSMEncoder"
    " | MacroBTEncoder"
)
# What decoding needs: both encodings, both encoders, the input and output symbol tables, the
# mode ("macro-step" or "leaf-execution") and the BDD variable order.
Context: TypeAlias = tuple[Encoding, Encoding, Encoder, Encoder, Symbols, Symbols, str, str]

_DETAIL_OK = {
    "reachability": "every state reachable alone is reached with matching behaviour (CTL)",
    "completeness": "every source step is matched in the faithful product (CTL)",
    "no_additional_behavior": "the result never does or accepts more than the source (CTL)",
    "deadlock_absence": "no faithful pair where only one side is stuck (CTL)",
    "termination_consistency": "statuses agree in every faithful pair (CTL)",
}
_DETAIL_FAIL = {
    "reachability": "a state reachable alone is never reached with matching behaviour",
    "completeness": "a source step is not matched by the result",
    "no_additional_behavior": "the result does or accepts more than the source",
    "deadlock_absence": "one side is stuck while the other can still act",
    "termination_consistency": "the statuses differ after a step",
}


def _side(values: dict[str, str], prefix: str) -> dict[str, str]:
    cut = len(prefix) + 1
    return {k[cut:]: v for k, v in values.items() if k.startswith(prefix + ".")}


def _attached_go(before: dict[str, str], inputs: dict[str, str], follows: bool) -> bool:
    """The product's ``attached_go`` on a transition (NuSMV does not print defines over both
    state and input variables, so it is evaluated here from the state before and the input)."""
    symbol = inputs.get("inp_s")
    if before.get("faithful") != "TRUE" or inputs.get("ctl") != "step" or symbol is None:
        return False
    return before.get(f"s.offers_{symbol}") == "TRUE" and (
        follows or before.get(f"r.offers_{symbol}") == "TRUE"
    )


def alone_go(before: dict[str, str], inputs: dict[str, str]) -> bool:
    """The ``REACH`` model's step in mode ``sa``/``ra`` (``specs._reach_product``): both
    stable and the machine that runs alone offers the input (the other replays it)."""
    symbol = inputs.get("inp_s")
    driver = {"sa": "s", "ra": "r"}.get(before.get("mode", ""))
    if driver is None or symbol is None or before.get("both") != "TRUE":
        return False
    return before.get(f"{driver}.offers_{symbol}") == "TRUE"


def decode_trace(
    trace: list[TraceState], context: Context, *, alone: bool = False
) -> list[TraceStep]:
    """One step per attached input: a transition taken with ``attached_go`` starts it, the
    next state where both machines are stable ends it (a BT module needs micro-steps).
    ``alone``: a trace of the ``REACH`` model in mode ``sa``/``ra``, one step per input the
    machine running alone takes (``alone_go``), the other's replay shown beside it."""
    src, res, _src_enc, _res_enc, inputs, outputs, _mode, _order = context
    steps: list[TraceStep] = []
    pending: str | None = None
    before: dict[str, str] = {}
    for state in trace:
        went = alone_go(before, state.inputs) if alone else None
        if went or (not alone and _attached_go(before, state.inputs, res.follows)):
            pending = inputs.name(state.inputs["inp_s"]) or "?"
        v = before = state.values
        if v.get("det") == "TRUE" and not alone:
            break
        if v.get("both") != "TRUE" or (steps and pending is None):
            continue  # micro-steps, or an idle step: nothing happened
        s_vals, r_vals = _side(v, "s"), _side(v, "r")

        def outs(vals: dict[str, str], enc: Encoding) -> list[str]:
            return [
                outputs.name(vals[slot]) or vals[slot]
                for slot in enc.slots
                if vals.get(slot, NONE_OUT) != NONE_OUT
            ]

        steps.append(
            TraceStep(
                len(steps),
                pending if steps else None,
                outs(s_vals, src),
                outs(r_vals, res),
                src.decode_state(s_vals),
                res.decode_state(r_vals),
                _status(s_vals),
                _status(r_vals),
            )
        )
        pending = None
    return steps


def build_report(
    names: list[str],
    results: list[SpecResult],
    context: Context,
    source_model: FSM | BTDocument,
    result_model: FSM | BTDocument,
) -> Report:
    src, res, src_enc, res_enc, inputs, outputs, mode, _order = context
    report = Report(
        engine="nusmv", source=_name(source_model), result=_name(result_model), mode=mode
    )
    for name, result in zip(names, results):
        if name in PROPERTIES:
            continue
        if not result.holds:
            # an encoder that adds checks (``extra_specs``) says what each failure means
            failure = getattr(res_enc, "extra_failure", None)
            if failure is not None:
                raise failure(name)
            raise UnsupportedError(f"the NuSMV check {name!r} failed")
    for name, result in zip(names, results):
        if name not in PROPERTIES:
            continue
        if result.holds:
            report.properties[name] = PropertyResult(name, True, _DETAIL_OK[name])
            continue
        trace = decode_trace(result.trace or [], context)
        detail = _DETAIL_FAIL[name]
        if name == "reachability" and result.trace:
            detail += _unmatched(result.trace[0].values, context)
        report.properties[name] = PropertyResult(name, False, detail, trace or None)
    report.properties = {n: report.properties[n] for n in PROPERTIES if n in report.properties}
    report.stats = {"source_smv_id_vars": len(src.id_vars), "result_smv_id_vars": len(res.id_vars)}
    return report


def _unmatched(values: dict[str, str], context: Context) -> str:
    """Name the state the reachability counterexample picked (the frozen copy's value)."""
    src, res = context[0], context[1]
    parts = []
    s_target = {k[3:]: v for k, v in values.items() if k.startswith("ts_")}
    r_target = {k[3:]: v for k, v in values.items() if k.startswith("tr_")}
    if s_target:
        parts.append(f"source {src.decode_state(s_target)}")
    if r_target and not res.follows:
        parts.append(f"result {res.decode_state(r_target)}")
    return f" (candidates: {', '.join(parts)})" if parts else ""


def _name(model: FSM | BTDocument) -> str:
    if isinstance(model, FSM):
        return model.name
    try:
        return model.main.id
    except Exception:  # noqa: BLE001 - a name for the report only
        return "model"


def _status(values: dict[str, str]) -> str:
    """The machine status of a trace state (its ``final`` define), as the native checker says."""
    final = values.get("final") == "TRUE"
    status: MachineStatus = MachineStatus.FINAL if final else MachineStatus.RUNNING
    return str(status.value)
