"""Reachability decided state by state (docs/nusmv.md, "Reachability state by state").

The frozen-copy spec of ``specs.product`` (``EF(alone & s = ts) -> EF(faithful & s = ts)``)
makes NuSMV's backward fixpoint a relation between every state and every frozen value: a
transitive closure, past 60 s from ~300 states on. When each machine's state is one
enumerated variable (an FSM's ``q``), reachability (docs/verification.md, section 2: every
state a machine reaches on its own occurs in a pair of the faithful product ``F``) is instead
decided by invariants per state on the ``REACH`` model (``specs.state_reach_specs``), each
run checking them on the reachable states of one forward search (``-dcx``: no traces):
first ``!(faithful & q = v)`` for every state ``v`` (it holds iff no pair of F has ``v``);
then, only for those states, ``!(alone & q = v)`` (it fails iff the machine reaches ``v`` on
its own: ``v`` is unmatched). States of F are always reached alone, so an equivalent pair's
states, and a failing pair's whose reachability holds, need no second run. When some state is
unmatched, one invariant over all of them has a counterexample NuSMV builds breadth first: a
shortest path to an unmatched state in that machine alone; a last run replays its inputs on
both machines, which gives the native checker's kind of witness (``native._reachability``).
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
    source's for a result that follows the environment, are one variable whose values the
    encoder lists: an FSM's ``q``)."""
    return state_reach_specs(context[0], context[1]) is not None


def _text(
    context: Context,
    specs: list[tuple[str, str]],
    replay: tuple[str, list[str]] | None = None,
) -> tuple[str, str]:
    src, res, inputs = context[0], context[1], context[4]
    prod = product(src, res, inputs, part=REACH, reach_specs=specs, replay=replay)
    return src.text + "\n" + res.text + "\n" + prod.text, prod.order


def holding(specs: list[tuple[str, str]], results: list[SpecResult]) -> dict[str, list[str]]:
    """Per side (``s``, ``r``), the states whose invariant in ``specs`` holds (for the
    ``faithful`` ones: the states no pair of F has; for the ``alone`` ones: the states the
    machine never reaches alone), in the order of the enumeration."""
    found: dict[str, list[str]] = {}
    for (name, _formula), result in zip(specs, results):
        _kind, side, value = name.split(":", 2)
        if result.holds:
            found.setdefault(side, []).append(value)
    return found


def unmatched_states(
    candidates: dict[str, list[str]], specs: list[tuple[str, str]], results: list[SpecResult]
) -> dict[str, list[str]]:
    """The ``candidates`` (states no pair of F has) that the ``alone`` invariants ``specs``
    show reached alone: the unmatched states, per side, in the order of the enumeration."""
    unreached = holding(specs, results)
    unmatched: dict[str, list[str]] = {}
    for side, values in candidates.items():
        never = set(unreached.get(side, ()))
        missing = [v for v in values if v not in never]
        if missing:
            unmatched[side] = missing
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
    """Reachability's verdict (with its witness when it fails), the number of NuSMV runs and
    their seconds. ``context`` must satisfy ``applies``. Runs: the ``faithful`` invariant of
    every state (a forward search of the ``REACH`` model - F plus each machine's own states -
    and S + R checks); when some states are not in F, their ``alone`` invariants (a second
    run); when some of those are reached alone (reachability fails), the witness: a forward
    search to the nearest one and its replayed path (two more runs)."""
    src, res = context[0], context[1]
    specs = state_reach_specs(src, res, "faithful")
    assert specs is not None
    text, order = _text(context, specs)
    results, seconds = run_nusmv(
        text, len(specs), order=order, timeout=timeout, options=["-dcx"], mono=False
    )
    candidates = holding(specs, results)  # never in F: unmatched if reached alone
    if not candidates:
        return PropertyResult(REACHABILITY, True, STATES_DETAIL), 1, seconds
    specs = state_reach_specs(src, res, "alone", only=candidates)
    assert specs is not None
    text, order = _text(context, specs)
    results, more = run_nusmv(
        text, len(specs), order=order, timeout=timeout, options=["-dcx"], mono=False
    )
    seconds += more
    unmatched = unmatched_states(candidates, specs, results)
    if not unmatched:
        return PropertyResult(REACHABILITY, True, STATES_DETAIL), 2, seconds
    trace, more = _witness(context, unmatched, timeout=timeout)
    result = PropertyResult(REACHABILITY, False, _detail(context, unmatched), trace or None)
    return result, 4, seconds + more


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
