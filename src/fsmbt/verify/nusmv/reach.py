"""Reachability decided state by state (docs/nusmv.md, "Reachability state by state").

The frozen-copy spec of ``specs.product`` (``EF(alone & s = ts) -> EF(faithful & s = ts)``)
makes NuSMV's backward fixpoint a relation between every state and every frozen value: a
transitive closure, past 60 s from ~300 states on. When each machine's state is one
enumerated variable (an FSM's ``q``), reachability (docs/verification.md, section 2: every
state a machine reaches on its own occurs in a pair of the faithful product ``F``) is instead
decided from two invariants per state on the ``REACH`` model (``specs.state_reach_specs``),
all checked on the reachable states of one forward search (``-dcx``: no traces); a
state whose ``alone`` invariant fails (it is reached alone) and whose ``faithful`` invariant
holds (no pair of ``F`` has it) is unmatched. A second run, only when some state is unmatched,
asks for one invariant over all of them, whose counterexample NuSMV builds breadth first: a
shortest path to an unmatched state in that machine alone; a third replays its inputs on both
machines, which gives the native checker's kind of witness (``native._reachability``).
"""

from __future__ import annotations

from fsmbt.verify.nusmv.runner import SpecResult, run_nusmv
from fsmbt.verify.nusmv.smv import any_of
from fsmbt.verify.nusmv.specs import REACH, enumerated_identity, product, state_reach_specs
from fsmbt.verify.nusmv.traces import Context, alone_go, decode_trace
from fsmbt.verify.report import REACHABILITY, PropertyResult, TraceStep

#: The detail of a holding verdict decided state by state.
STATES_DETAIL = (
    "every state reachable alone is reached with matching behaviour (one NuSMV invariant per state)"
)
_NAMES_SHOWN = 5


def applies(context: Context) -> bool:
    """Whether the pair's reachability can be decided state by state (both identities, or the
    source's for a result that follows the environment, are one enumerated variable)."""
    return state_reach_specs(context[0], context[1]) is not None


def _text(
    context: Context,
    specs: list[tuple[str, str]],
    replay: tuple[str, list[str]] | None = None,
) -> tuple[str, str]:
    src, res, inputs = context[0], context[1], context[4]
    prod = product(src, res, inputs, part=REACH, reach_specs=specs, replay=replay)
    return src.text + "\n" + res.text + "\n" + prod.text, prod.order


def unmatched_states(
    specs: list[tuple[str, str]], results: list[SpecResult]
) -> dict[str, list[str]]:
    """Per side (``s``, ``r``), the identity values reached alone and never in ``F``, in the
    order of the enumeration (the order the encoder declared the states)."""
    verdicts = {name: result.holds for (name, _f), result in zip(specs, results)}
    unmatched: dict[str, list[str]] = {}
    for name, _formula in specs:
        kind, side, value = name.split(":", 2)
        if kind != "alone" or verdicts[name]:
            continue  # not reached alone
        if verdicts[f"faithful:{side}:{value}"]:
            unmatched.setdefault(side, []).append(value)
    return unmatched


def _target(context: Context, unmatched: dict[str, list[str]]) -> str:
    """``!(alone at an unmatched state)``: its counterexample is the witness."""
    parts = []
    for side, mode, enc in (("s", "sa", context[0]), ("r", "ra", context[1])):
        values = unmatched.get(side)
        if not values:
            continue
        ident = enumerated_identity(enc)
        assert ident is not None
        var = ident[0]
        states = any_of(f"{side}.{var} = {v}" for v in values)
        parts.append(f"(mode = {mode} & {side}.stable & {states})")
    return f"!{any_of(parts)}"


def _detail(context: Context, unmatched: dict[str, list[str]]) -> str:
    """The native checker's words (``native._reachability``), the states named in the
    order of the encoding (the native checker names them in breadth-first order)."""
    parts = []
    for side, words in (
        ("s", "source state(s) never reached with matching behaviour"),
        ("r", "result state(s) reachable only through behaviour the source does not have"),
    ):
        values = unmatched.get(side)
        if not values:
            continue
        enc = context[0] if side == "s" else context[1]
        ident = enumerated_identity(enc)
        assert ident is not None
        names = [enc.decode_state({ident[0]: v}) for v in values]
        shown = ", ".join(names[:_NAMES_SHOWN]) + (", ..." if len(names) > _NAMES_SHOWN else "")
        parts.append(f"{len(values)} {words}: {shown}")
    return "; ".join(parts)


def check_reachability(
    context: Context, *, timeout: float | None
) -> tuple[PropertyResult, int, float]:
    """Reachability's verdict (with its witness when it fails), the number of NuSMV runs (1
    or 3) and their seconds. ``context`` must satisfy ``applies``. Cost: one forward search of
    the ``REACH`` model (the faithful product plus each machine's run from the start) and
    2 (S + R) set intersections; the witness: a forward search to the nearest unmatched state and
    one replayed path."""
    specs = state_reach_specs(context[0], context[1])
    assert specs is not None
    text, order = _text(context, specs)
    results, seconds = run_nusmv(
        text, len(specs), order=order, timeout=timeout, options=["-dcx"], mono=False
    )
    unmatched = unmatched_states(specs, results)
    if not unmatched:
        return PropertyResult(REACHABILITY, True, STATES_DETAIL), 1, seconds
    trace, more = _witness(context, unmatched, timeout=timeout)
    result = PropertyResult(REACHABILITY, False, _detail(context, unmatched), trace or None)
    return result, 3, seconds + more


def _witness(
    context: Context, unmatched: dict[str, list[str]], *, timeout: float | None
) -> tuple[list[TraceStep], float]:
    """The witness, in two runs: a shortest path to an unmatched state in the machine that
    reaches it alone (the other frozen at its start: NuSMV's breadth-first counterexample of
    one invariant), then that input sequence replayed on both (``replay``: one path), whose
    trace decodes to the native checker's kind of witness."""
    text, order = _text(context, [("witness", _target(context, unmatched))])
    found, seconds = run_nusmv(text, 1, order=order, timeout=timeout, mono=False)
    path = found[0].trace or []
    mode = path[0].values.get("mode", "sa") if path else "sa"
    word = [
        state.inputs["inp_s"]
        for before, state in zip(path, path[1:])
        if alone_go(before.values, state.inputs)
    ]
    end = f"k = {len(word)}"
    text, order = _text(context, [("replay", f"!({end})")], replay=(mode, word))
    found, more = run_nusmv(text, 1, order=order, timeout=timeout, mono=False)
    return decode_trace(found[0].trace or [], context, alone=True), seconds + more
