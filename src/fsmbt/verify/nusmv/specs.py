"""The product module and the five properties as CTL specifications (docs/nusmv.md).

The product feeds both machine modules the same environment input ``inp_s`` (an IVAR) while it
is *attached*; a BT module first finishes its micro-steps, so inputs are taken only when both
are ``stable``. Steps are taken only from pairs where the two agreed so far (``faithful``),
which makes the attached part exactly the native checker's faithful product P
(docs/verification.md). At any stable pair the environment may *detach* the two: from then on
each machine runs alone on its own input (``inp_s``/``inp_r``), which gives CTL access to what
each machine can do on its own (its reachable states, whether it is dead).

Properties (each one SPEC, all checked in one NuSMV run):
- completeness: ``INVARSPEC(attached & both stable -> source outputs ⊑ result outputs)`` and, unless
  the result follows the environment, every input the source offers in a faithful pair the
  result offers too;
- no additional behaviour: the same with the roles swapped;
- termination consistency: ``INVARSPEC(attached & both stable -> statuses equal)``;
- deadlock absence: ``AG(faithful -> (dead_s <-> dead_r))`` with
  ``dead_x := !x.final & !EX(detached & EF x_obs)`` (no observable step ever, alone);
- reachability: with frozen copies ``ts`` of the source's state variables,
  ``EF(detached & s.stable & s = ts) -> EF(faithful & s = ts)``, and the same for the result
  unless it follows the environment.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

from fsmbt.verify.nusmv.encode_fsm import NONE_OUT, Encoding
from fsmbt.verify.nusmv.smv import Symbols, all_of, any_of, case, enum_type, subsequence
from fsmbt.verify.report import (
    COMPLETENESS,
    DEADLOCK_ABSENCE,
    NO_ADDITIONAL_BEHAVIOR,
    REACHABILITY,
    TERMINATION_CONSISTENCY,
)

EXTRA_CHECKS = ("output_overflow", "sv_livelock")
#: Extra checks read on every state the product reaches, not only where ``ok`` holds: a
#: state-variable tree's livelock (``encode_sv``) is an error wherever the result reaches it
#: alone, as in the native checker, which explores each machine alone before the product (the
#: detached ``ra`` mode reaches every state of the result from the start pair, where ``ok``
#: holds, but a disagreeing step on the way clears ``ok``).
UNGUARDED_CHECKS = frozenset({"sv_livelock"})


@dataclass
class Product:
    text: str
    spec_names: list[str]
    order: str


#: The parts ``check`` runs (docs/nusmv.md, "Two runs"): the invariants on the attached product
#: alone (forward reachability), the CTL specs on the product with detaching (``-df``);
#: ``REACH`` the per-state reachability model (docs/nusmv.md, "Reachability state by state"):
#: the mode is chosen once at the start, so the reachable states are the faithful product plus
#: each machine's run from the start pair (the other replaying its inputs), never their cross
#: product, and no frozen copy makes a fixpoint a transitive closure.
WHOLE, INVARIANTS, CTL, REACH = "whole", "invariants", "ctl", "reach"


class _Terms(NamedTuple):
    """The input type and the agreement terms both product texts (``product``,
    ``_reach_product``) are written with."""

    in_enum: str  # the input type; ``in_pad`` is never offered (no ``offers_in_pad``)
    s_slots: list[str]  # the source's output slots
    r_slots: list[str]  # the result's output slots
    equal_outs: str  # both machines output the same
    joint: str  # the input is offered to the pair (the source alone when the result follows)
    alone_s: str  # the input is offered to the source
    alone_r: str  # the input is offered to the result


def _terms(src: Encoding, res: Encoding, in_ids: list[str]) -> _Terms:
    s_slots = [f"s.{x}" for x in src.slots]
    r_slots = [f"r.{x}" for x in res.slots]
    return _Terms(
        enum_type(in_ids, "in_pad"),
        s_slots,
        r_slots,
        all_of([subsequence(s_slots, r_slots, NONE_OUT), subsequence(r_slots, s_slots, NONE_OUT)]),
        any_of(
            f"(inp_s = {i} & s.offers_{i}" + ("" if res.follows else f" & r.offers_{i}") + ")"
            for i in in_ids
        ),
        any_of(f"(inp_s = {i} & s.offers_{i})" for i in in_ids),
        any_of(f"(inp_s = {i} & r.offers_{i})" for i in in_ids),
    )


def product(
    src: Encoding,
    res: Encoding,
    inputs: Symbols,
    extra_specs: list[tuple[str, str]] | None = None,
    *,
    part: str = WHOLE,
    reach_specs: list[tuple[str, str]] | None = None,
    replay: tuple[str, list[str]] | None = None,
    listing: bool = False,
) -> Product:
    """The ``main`` module and the specs, in the order ``spec_names`` lists them.

    ``part``: ``WHOLE`` every spec on the product with detaching; ``INVARIANTS`` only the
    invariants (completeness, no additional behaviour, termination consistency) on the product
    without detaching - they read attached pairs only, and the detached states (each faithful
    pair times everything one machine reaches alone) are most of a forward search's cost - and
    without the deadlock helpers (``x_obs``, ``x_run``, ``x_st0``) and the frozen copies they
    do not read (a 1 000-state mutant: the forward search 31 -> 9 s, docs/nusmv.md); ``CTL`` the CTL specs (deadlock absence, reachability) and the extra invariants written
    as ``AG``, for a run without the forward search (``-df``); ``REACH`` the product whose
    mode is frozen at the start (``att``: attached; ``sa``: the source runs alone on the
    inputs it offers while the result stays at its start; ``ra``: the roles swapped) with the
    ``INVARSPEC`` s ``reach_specs`` (name, formula) only; ``listing``: with the variable
    ``SEEN`` that classifies each state for ``reach``'s listing of the reachable states; with
    ``replay`` (mode, input ids) the one path that replays a witness (``_reach_product``)."""
    if part == REACH:
        return _reach_product(src, res, inputs, reach_specs or [], replay, listing=listing)
    detach = part != INVARIANTS
    in_ids = list(inputs.to_id.values())
    in_enum, s_slots, r_slots, equal_outs, joint, alone_s, alone_r = _terms(src, res, in_ids)
    follows = res.follows
    lines = [
        "MODULE main",
        "IVAR",
        f"  inp_s : {in_enum};",
        "  ctl : {step, alone_s, alone_r, idle};",
        "VAR",
        "  s : " + src.module + "(go_s, inp_s);",
        "  r : " + res.module + "(go_r, inp_s);",
        "  mode : {att, sa, ra};",
        "  ok : boolean;",
    ]
    if detach:  # the deadlock helpers and the frozen copies: read by the CTL specs only
        lines += [f"  {side}_{v} : boolean;" for v in ("obs", "run", "st0") for side in "sr"]
        lines.append("FROZENVAR")
        for prefix, enc in (("ts", src), ("tr", res)):
            for var, typ in enc.id_vars:
                lines.append(f"  {prefix}_{var} : {typ};")
    lines += [
        "DEFINE",
        "  det := mode != att;",
        "  both := s.stable & r.stable;",
        f"  agree := both & {equal_outs} & (s.final <-> r.final);",
        "  faithful := !det & ok & agree;",
        f"  attached_go := !det & ok & both & ctl = step & {joint};",
        f"  go_s := attached_go | (mode = sa & s.stable & {alone_s});",
        f"  go_r := attached_go | (mode = ra & r.stable & {alone_r});",
    ]
    if detach:
        lines += [
            "  s_out := " + any_of(f"{x} != {NONE_OUT}" for x in s_slots) + ";",
            "  r_out := " + any_of(f"{x} != {NONE_OUT}" for x in r_slots) + ";",
        ]
    lines += [
        "ASSIGN",
        "  init(mode) := att;",
        "  next(mode) := case !det & ok & both & ctl = alone_s : sa; "
        "!det & ok & both & ctl = alone_r : ra; TRUE : mode; esac;"
        if detach
        else "  next(mode) := mode;",
        "  init(ok) := TRUE;",
        "  next(ok) := case !det & both : ok & agree; TRUE : ok; esac;",
    ]
    for side in ("s", "r") if detach else ():
        lines += [
            f"  init({side}_obs) := FALSE;",
            f"  next({side}_obs) := case mode != {side}a : FALSE; "
            f"{side}.stable & {side}_run & ({side}_out | ({side}.final xor {side}_st0)) : TRUE; "
            f"TRUE : {side}_obs; esac;",
            f"  init({side}_run) := FALSE;",
            f"  next({side}_run) := case go_{side} : TRUE; {side}.stable : FALSE; "
            f"TRUE : {side}_run; esac;",
            f"  init({side}_st0) := FALSE;",
            f"  next({side}_st0) := case go_{side} : {side}.final; TRUE : {side}_st0; esac;",
        ]
    # CTL specs first, invariants after: NuSMV checks (and prints) them in that order.
    specs: list[tuple[str, str, str]] = []
    dead_s = "(!s.final & !(EX (mode = sa & EF s_obs)))"
    dead_r = "(!r.final & !(EX (mode = ra & EF r_obs)))"
    specs.append((DEADLOCK_ABSENCE, "SPEC", f"AG (faithful -> ({dead_s} <-> {dead_r}))"))
    same_s = all_of(f"s.{v} = ts_{v}" for v, _ in src.id_vars)
    same_r = all_of(f"r.{v} = tr_{v}" for v, _ in res.id_vars)
    reach = f"((EF (mode = sa & s.stable & {same_s})) -> (EF (faithful & {same_s})))"
    if not follows:
        reach += f" & ((EF (mode = ra & r.stable & {same_r})) -> (EF (faithful & {same_r})))"
    specs.append((REACHABILITY, "SPEC", reach))
    # invariants are checked by forward reachability: much cheaper than AG in CTL
    specs += [(name, "INVARSPEC", formula) for name, formula in invariant_specs(src, res, in_ids)]
    extra_kind = "INVARSPEC" if part == WHOLE else "SPEC AG"
    specs += [
        (name, extra_kind, formula if name in UNGUARDED_CHECKS else f"(ok -> {formula})")
        for name, formula in (extra_specs or [])
    ]
    if part == INVARIANTS:
        specs = [spec for spec in specs if spec[1] == "INVARSPEC"]
    elif part == CTL:
        specs = [spec for spec in specs if spec[1] != "INVARSPEC"]
    for _name, kind, formula in specs:
        lines.append(f"{kind} {formula};")
    order = _order(src, res, copies=detach)
    return Product("\n".join(lines) + "\n", [name for name, _, _ in specs], order)


def invariant_specs(src: Encoding, res: Encoding, in_ids: list[str]) -> list[tuple[str, str]]:
    """Completeness, no additional behaviour and termination consistency as (name, invariant)
    over the product's terms (``det``, ``ok``, ``both``, ``faithful``): true of every attached
    pair (``!det``), so the same text holds on the ``INVARIANTS`` model and on the ``REACH``
    model, whose alone modes are ``det``."""
    s_slots = [f"s.{x}" for x in src.slots]
    r_slots = [f"r.{x}" for x in res.slots]
    compl = f"((!det & ok & both) -> {subsequence(s_slots, r_slots, NONE_OUT)})"
    noadd = f"((!det & ok & both) -> {subsequence(r_slots, s_slots, NONE_OUT)})"
    if not res.follows:
        offers_s_in_r = all_of(f"(s.offers_{i} -> r.offers_{i})" for i in in_ids)
        offers_r_in_s = all_of(f"(r.offers_{i} -> s.offers_{i})" for i in in_ids)
        compl = f"{compl} & (faithful -> {offers_s_in_r})"
        noadd = f"{noadd} & (faithful -> {offers_r_in_s})"
    return [
        (COMPLETENESS, compl),
        (NO_ADDITIONAL_BEHAVIOR, noadd),
        (TERMINATION_CONSISTENCY, "((!det & ok & both) -> (s.final <-> r.final))"),
    ]


def _order(src: Encoding, res: Encoding, *, copies: bool = True, mirrored: bool = False) -> str:
    """A BDD variable order: each identity variable next to its frozen copy (the reachability
    spec compares them), inputs first. Without it NuSMV is 20x slower on small models.
    ``copies=False``: the ``REACH`` model's (no frozen copies, no deadlock helpers);
    ``mirrored``: with its listing's copies of identity DEFINEs (``listing_mirrors``), each
    beside the variable it is read mostly from (``Encoding.id_near``) - at the end of the
    order, a 103-node ``memory`` tree's model was not built in 100 s, beside it in 0.1 s.

    When both modules ask (``Encoding.input_after_source``: two FSMs read by events), the
    input ``inp_s`` comes after the source's variables instead, between the two machines: on
    the random 1 000-state FSM ~ FSM pair of ``bench_nusmv_options.py --random`` (column
    ``input-first`` against ``after``) the mutant's NuSMV CPU fell 30.0 -> 26.8 and 31.4 ->
    28.5 s, the copy's stayed within 1 s (22.1 -> 23.0, 26.4 -> 26.9; docs/nusmv.md, "Sixth
    round"); the other pairs were not measured and keep it first."""
    late = src.input_after_source and res.input_after_source
    order = ["ok", "ctl", "mode"] + ([] if late else ["inp_s"])
    if copies:
        order += ["s_obs", "r_obs", "s_run", "r_run", "s_st0", "r_st0"]
    placed = _interleaved(src, res, copies)
    order += placed
    for side, copy, enc in (("s", "ts", src), ("r", "tr", res)):
        if side == "r" and late:
            order.append("inp_s")
        ids = {v for v, _ in enc.id_vars}
        for var in enc.var_order:
            if placed and (
                (enc.position is not None and var == enc.position[0])
                or var in dict(enc.output_words)
            ):
                continue
            order.append(f"{side}.{var}")
            if var in ids and copies:
                order.append(f"{copy}_{var}")
            if copies:  # identity DEFINEs read mostly from this variable
                order += [f"{copy}_{d}" for d, near in enc.id_near.items() if near == var]
            if mirrored:
                order += [
                    mirror_name(side, d)
                    for d, near in enc.id_near.items()
                    if near == var and d not in enc.var_order
                ]
        if copies:  # DEFINEs
            order += [
                f"{copy}_{v}"
                for v, _ in enc.id_vars
                if v not in enc.var_order and v not in enc.id_near
            ]
        if mirrored:
            order += [
                mirror_name(side, v)
                for v, _ in enc.id_vars
                if v not in enc.var_order and v not in enc.id_near
            ]
    return "\n".join(order) + "\n"


def _interleaved(src: Encoding, res: Encoding, copies: bool) -> list[str]:
    """The two position words bit by bit, most significant first, each beside its frozen
    copy, then both modules' output variables (``Encoding.output_words``) bit by bit, when one
    module asks for it (``Encoding.interleave``) and both have a position; else nothing. Why: in a faithful pair the tree's position and the machine's state determine
    each other, a relation whose BDD is small only with their bits side by side (a 320-node
    tree against its HFSM, by hand: the invariants 11.2 -> 0.66 s, the deadlock spec past
    60 s -> 0.9 s; docs/nusmv.md, "Trees by macro steps")."""
    if not (src.interleave or res.interleave) or src.position is None or res.position is None:
        return []
    ids = {"s": {v for v, _ in src.id_vars}, "r": {v for v, _ in res.id_vars}}
    words = [("s", "ts", *src.position), ("r", "tr", *res.position)]
    order = []
    for bit in reversed(range(max(src.position[1], res.position[1]))):
        for side, copy, var, bits in words:
            if bit < bits:
                order.append(f"{side}.{var}.{bit}")
                if copies and var in ids[side]:
                    order.append(f"{copy}_{var}.{bit}")
    # then the output variables, compared slot against slot by the agreement terms
    outs = [("s", *w) for w in src.output_words] + [("r", *w) for w in res.output_words]
    for bit in reversed(range(max((bits for _s, _v, bits in outs), default=0))):
        order += [f"{side}.{var}.{bit}" for side, var, bits in outs if bit < bits]
    return order


#: The ``REACH`` model's listing variable (``_reach_product(..., listing=True)``): per
#: reachable state, ``fa`` a pair of the faithful product F, ``sa``/``ra`` the source / the
#: result stable while running alone, ``no`` anything else (a disagreeing pair, a micro-step).
SEEN = "seen"


def mirror_name(side: str, var: str) -> str:
    """The ``REACH`` listing's state variable that copies the identity DEFINE ``var`` of the
    machine ``side`` (``listing_mirrors``)."""
    return f"k_{side}_{var}"


def listing_mirrors(src: Encoding, res: Encoding) -> list[tuple[str, str, str]]:
    """(name, the DEFINE it copies, SMV type) for each identity variable (``Encoding.id_vars``)
    that is a DEFINE, not a state variable, of its module: the canonical memories of a tree
    written by macro steps (``encode_macro``'s ``cix_n``, ``cwr_n``; docs/semantics.md §4a).
    NuSMV's listing prints state variables only, so the ``REACH`` model gets one state
    variable per such DEFINE, assigned from it in every state (``name := s.define``, like
    ``seen``): the listed states then carry the canonical identity NuSMV computed, and the
    reader (``reach.unmatched_states``) evaluates nothing. Costs one BDD variable group per
    DEFINE, on the listing's model only."""
    return [
        (mirror_name(side, var), f"{side}.{var}", typ)
        for side, enc in (("s", src), ("r", res))
        for var, typ in enc.id_vars
        if var not in enc.var_order
    ]


def _reach_product(
    src: Encoding,
    res: Encoding,
    inputs: Symbols,
    reach_specs: list[tuple[str, str]],
    replay: tuple[str, list[str]] | None = None,
    *,
    listing: bool = False,
) -> Product:
    """The ``REACH`` model (see ``product``): the attached product of the other parts with
    the mode frozen at the start instead of a detach step. In ``sa`` the source runs alone from
    the start pair on the inputs it offers while the result stays at its start (``ra``: the
    roles swapped), so the reachable states are F plus each machine's own states, never a
    product of the two (the result replaying the source's inputs made NuSMV's forward search
    go past 190 s on a 1 000-state mutant: after the retargeted step the two run apart).

    ``replay`` (mode, input ids): the witness replay instead - the mode fixed, the inputs
    dictated by a step counter ``k`` (``TRANS``), the other machine taking each input it offers
    as the native checker replays its witness; one path, ``k = len(inputs)`` at its end.

    ``listing``: a state variable ``seen`` assigned from the others (``fa`` when ``faithful``,
    ``sa``/``ra`` when that machine runs alone and is stable, else ``no``), so the listed
    reachable states say themselves which set each belongs to: NuSMV evaluates ``faithful``,
    the listing's reader does not (``reach.unmatched_states``)."""
    in_ids = list(inputs.to_id.values())
    in_enum, _, _, equal_outs, joint, alone_s, alone_r = _terms(src, res, in_ids)
    stable_s, stable_r = ("both", "both") if replay is not None else ("s.stable", "r.stable")
    go_s = f"attached_go | (mode = sa & {stable_s} & {alone_s})"
    go_r = f"attached_go | (mode = ra & {stable_r} & {alone_r})"
    if replay is not None:  # the other machine replays the inputs it offers
        go_s += f" | (mode = ra & both & {joint})"
        go_r += f" | (mode = sa & both & {joint})"
    lines = [
        "MODULE main",
        "IVAR",
        f"  inp_s : {in_enum};",
        "  ctl : {step, idle};",
        "VAR",
        "  s : " + src.module + "(go_s, inp_s);",
        "  r : " + res.module + "(go_r, inp_s);",
        "  ok : boolean;",
    ]
    if replay is not None:
        lines.append(f"  k : 0..{max(1, len(replay[1]))};")  # one value: a constant
    mirrors = listing_mirrors(src, res) if listing else []
    if listing:
        lines.append(f"  {SEEN} : {{fa, sa, ra, no}};")
        lines += [f"  {name} : {typ};" for name, _define, typ in mirrors]
    lines += [
        "FROZENVAR",
        "  mode : {att, sa, ra};",
        "DEFINE",
        "  det := mode != att;",
        "  both := s.stable & r.stable;",
        f"  agree := both & {equal_outs} & (s.final <-> r.final);",
        "  faithful := !det & ok & agree;",
        f"  attached_go := !det & ok & both & ctl = step & {joint};",
        f"  go_s := {go_s};",
        f"  go_r := {go_r};",
        "ASSIGN",
        "  init(ok) := TRUE;",
        "  next(ok) := case !det & both : ok & agree; TRUE : ok; esac;",
    ]
    if listing:
        lines.append(
            f"  {SEEN} := case faithful : fa; mode = sa & s.stable : sa; "
            "mode = ra & r.stable : ra; TRUE : no; esac;"
        )
        lines += [f"  {name} := {define};" for name, define, _typ in mirrors]
    if replay is not None:
        mode, word = replay
        last = len(word)
        lines += [
            f"  init(mode) := {mode};",
            "  init(k) := 0;",
            f"  next(k) := case both & k < {last} : k + 1; TRUE : k; esac;",
            "TRANS",
            "  "
            + case([(f"both & k = {j}", f"inp_s = {i}") for j, i in enumerate(word)], "TRUE")
            + ";",
        ]
    lines += [f"INVARSPEC {formula};" for _name, formula in reach_specs]
    order = _order(src, res, copies=False, mirrored=listing) + (f"{SEEN}\n" if listing else "")
    return Product("\n".join(lines) + "\n", [name for name, _ in reach_specs], order)
