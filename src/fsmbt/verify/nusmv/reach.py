"""Reachability from one listing of the reachable states (docs/nusmv.md, "Fifth round:
reachability from the listed states").

The frozen-copy spec of ``specs.product`` (``EF(alone & s = ts) -> EF(faithful & s = ts)``)
makes NuSMV's backward fixpoint a relation between every state and every frozen value: a
transitive closure, past 60 s from ~100 states on. For a pair whose machines take one step
per input (FSM ~ FSM, FSM ~ dispatch tree: ``check``'s split runs), reachability
(docs/verification.md, section 2: every state a machine reaches on its own occurs in a pair of
the faithful product ``F``) is instead read off the ``REACH`` model (``specs.REACH``: the mode
frozen at the start, so its reachable states are F plus each machine's own states, never their
product): one NuSMV run lists every reachable state (``runner.list_reachable``) with the
variable ``seen`` NuSMV assigns (``fa``: a pair of F; ``sa``/``ra``: that machine alone and
stable). A machine's state is its identity variables' values (``Encoding.id_vars``: an FSM's
``q``, a dispatch tree's written entries and ``fin``); a state listed alone and never in an
``fa`` state is unmatched. Only set membership is computed here; which states are reached,
and which pairs are faithful, is NuSMV's.

When some state is unmatched, one invariant over all of them has a counterexample NuSMV builds
breadth first: a shortest path to an unmatched state in that machine alone; a last run replays
its inputs on both machines, which gives the native checker's kind of witness
(``native._reachability``). So a pair whose reachability holds costs one run, a failing one
three.

(The version before listed nothing: one invariant per state and kind, ``!(faithful & s.q =
v)`` then ``!(alone & s.q = v)``, ~23 ms each on NuSMV's side - 2 000 of them were most of a
1 000-state mutant's 73 s - and only for an FSM's one enumerated ``q``.)
"""

from __future__ import annotations

from fsmbt.verify.nusmv.encode_fsm import Encoding
from fsmbt.verify.nusmv.runner import SpecResult, check_and_list, list_reachable, run_nusmv
from fsmbt.verify.nusmv.smv import all_of, any_of
from fsmbt.verify.nusmv.specs import REACH, SEEN, invariant_specs, mirror_name, product
from fsmbt.verify.nusmv.traces import Context, alone_go, decode_trace
from fsmbt.verify.report import REACHABILITY, PropertyResult, TraceStep

#: The detail of a holding verdict decided from the listing.
STATES_DETAIL = (
    "every state reachable alone is reached with matching behaviour "
    "(NuSMV's listing of the reachable states)"
)
_NAMES_SHOWN = 5

#: A machine's state in the listing: its identity variables' values, in ``id_vars`` order.
Key = tuple[str, ...]


def applies(context: Context) -> bool:
    """Whether both machines name their identity variables. NuSMV's listing prints state
    variables only; an identity read through a DEFINE (the canonical memory of a tree written
    by macro steps, ``encode_macro``: ``cwr_n``, ``cix_n``) is listed through the ``REACH``
    model's copy of it (``specs.listing_mirrors``). ``check`` asks for the split pairs, whose
    modules take one step per input, and for failing structured pairs (their tree takes
    micro-steps; ``_witness`` ends the replay when both machines are stable again)."""
    return all(enc.id_vars for enc in (context[0], context[1]))


def lists_cheaply(context: Context) -> bool:
    """Whether the listing is worth running for every pair, the invariants in the same run
    (``invariants_and_listing``): only when each identity variable is a state variable. A
    tree by macro steps with memory is identified through DEFINEs over raw memories that
    its copies in the listing multiply (many raw states per canonical one): there a holding
    pair's reachability stays implied by the other four properties and the listing runs for a
    failing pair only (``bench_nusmv_macro.py``: the 103-node ``memory`` copy 0.74 s implied,
    past 60 s listed)."""
    return applies(context) and all(
        var in enc.var_order for enc in (context[0], context[1]) for var, _typ in enc.id_vars
    )


def _sides(context: Context) -> list[tuple[str, str, Encoding]]:
    """(prefix, alone mode, encoding) of each machine whose reachability counts: the
    result's not when it follows the environment (its inputs are not the environment's)."""
    src, res = context[0], context[1]
    return [("s", "sa", src)] + ([] if res.follows else [("r", "ra", res)])


def _text(
    context: Context,
    specs: list[tuple[str, str]],
    replay: tuple[str, list[str]] | None = None,
    *,
    listing: bool = False,
) -> tuple[str, str]:
    src, res, inputs = context[0], context[1], context[4]
    prod = product(src, res, inputs, part=REACH, reach_specs=specs, replay=replay, listing=listing)
    return src.text + "\n" + res.text + "\n" + prod.text, prod.order


def _key(state: dict[str, str], side: str, enc: Encoding) -> Key:
    """The listed state's identity for ``side``: a state variable read as listed, a DEFINE
    through its copy (``specs.listing_mirrors``)."""
    return tuple(
        state.get(f"{side}.{var}" if var in enc.var_order else mirror_name(side, var), "?")
        for var, _typ in enc.id_vars
    )


def unmatched_states(context: Context, states: list[dict[str, str]]) -> dict[str, list[Key]]:
    """Per side (``s``, ``r``), the states listed alone (``seen`` = ``sa``/``ra``) that no
    listed pair of F (``seen = fa``) has: the unmatched states. Order: an FSM's by its state
    table (``Encoding.id_values``), any other's as NuSMV listed them. O(listed states)."""
    unmatched: dict[str, list[Key]] = {}
    for side, mode, enc in _sides(context):
        matched = {_key(st, side, enc) for st in states if st.get(SEEN) == "fa"}
        alone: dict[Key, None] = {}
        for st in states:
            if st.get(SEEN) == mode:
                alone.setdefault(_key(st, side, enc), None)
        missing = [key for key in alone if key not in matched]
        if enc.id_values and len(enc.id_vars) == 1:
            rank = {value: i for i, value in enumerate(enc.id_values)}
            missing.sort(key=lambda key: rank.get(key[0], len(rank)))
        if missing:
            unmatched[side] = missing
    return unmatched


def _target(context: Context, unmatched: dict[str, list[Key]]) -> str:
    """``!(alone at an unmatched state)``: its counterexample is the witness."""
    parts = []
    for side, mode, enc in _sides(context):
        keys = unmatched.get(side)
        if not keys:
            continue
        names = [var for var, _typ in enc.id_vars]
        states = any_of(
            all_of(f"{side}.{var} = {value}" for var, value in zip(names, key)) for key in keys
        )
        parts.append(f"(mode = {mode} & {side}.stable & {states})")
    return f"!{any_of(parts)}"


def _detail(context: Context, unmatched: dict[str, list[Key]]) -> str:
    """The native checker's words (``native._reachability``), the states named in the
    order of ``unmatched_states`` (the native checker names them in breadth-first order)."""
    parts = []
    words = {
        "s": "source state(s) never reached with matching behaviour",
        "r": "result state(s) reachable only through behaviour the source does not have",
    }
    for side, _mode, enc in _sides(context):
        keys = unmatched.get(side)
        if not keys:
            continue
        names: dict[str, None] = {}
        for key in keys:
            names.setdefault(enc.decode_state(dict(zip((v for v, _ in enc.id_vars), key))))
        listed = list(names)
        shown = ", ".join(listed[:_NAMES_SHOWN]) + (", ..." if len(listed) > _NAMES_SHOWN else "")
        parts.append(f"{len(keys)} {words[side]}: {shown}")
    return "; ".join(parts)


def check_reachability(
    context: Context, *, timeout: float | None
) -> tuple[PropertyResult, int, float]:
    """Reachability's verdict (with its witness when it fails), the number of NuSMV runs and
    their seconds. ``context`` must satisfy ``applies``. Runs: the listing of the ``REACH``
    model's reachable states (one forward search), then ``verdict``'s."""
    text, order = _text(context, [], listing=True)
    states, seconds = list_reachable(text, order=order, timeout=timeout)
    result, runs, more = verdict(context, states, timeout=timeout)
    return result, runs + 1, seconds + more


def invariants_and_listing(
    context: Context, *, timeout: float | None
) -> tuple[list[str], list[SpecResult], list[dict[str, str]], float]:
    """One NuSMV run on the ``REACH`` model: the three invariants of ``specs.invariant_specs``
    (their names, verdicts and counterexamples: shortest paths in the attached mode, which is
    the ``INVARIANTS`` model's product) and the listing of its reachable states, from one
    build and one forward search (``runner.check_and_list``); and NuSMV's seconds. It replaces
    the separate invariants' run of ``check``'s split pairs: one build and one search fewer
    (docs/nusmv.md, "Fifth round: reachability from the listed states")."""
    src, res, inputs = context[0], context[1], context[4]
    specs = invariant_specs(src, res, list(inputs.to_id.values()))
    text, order = _text(context, specs, listing=True)
    results, states, seconds = check_and_list(text, len(specs), order=order, timeout=timeout)
    return [name for name, _formula in specs], results, states, seconds


def verdict(
    context: Context, states: list[dict[str, str]], *, timeout: float | None
) -> tuple[PropertyResult, int, float]:
    """Reachability's verdict from the listed ``states``, the number of further NuSMV runs and
    their seconds: none when every state reached alone is matched; else the witness, a forward
    search to the nearest unmatched state and its replayed path (two runs)."""
    return judged(context, unmatched_states(context, states), timeout=timeout)


def judged(
    context: Context, unmatched: dict[str, list[Key]], *, timeout: float | None
) -> tuple[PropertyResult, int, float]:
    """``verdict`` from the listing's ``unmatched_states`` already computed (``check`` reads
    them once for deadlock absence, the witness and the verdict)."""
    if not unmatched:
        return PropertyResult(REACHABILITY, True, STATES_DETAIL), 0, 0.0
    trace, seconds = _witness(context, unmatched, timeout=timeout)
    result = PropertyResult(REACHABILITY, False, _detail(context, unmatched), trace or None)
    return result, 2, seconds


def _witness(
    context: Context, unmatched: dict[str, list[Key]], *, timeout: float | None
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
    # the last input taken and both machines stable again: a machine by micro-steps (a
    # structured tree, a tree ``check`` does not split) has finished that input's step
    end = f"k = {len(word)} & both"
    text, order = _text(context, [("replay", f"!({end})")], replay=(mode, word))
    found, more = run_nusmv(text, 1, order=order, timeout=timeout, mono=False)
    return decode_trace(found[0].trace or [], context, alone=True), seconds + more
