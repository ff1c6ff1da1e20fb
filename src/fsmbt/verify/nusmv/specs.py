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

from fsmbt.verify.nusmv.encode_fsm import NONE_OUT, Encoding
from fsmbt.verify.nusmv.smv import Symbols, all_of, any_of, enum_type, subsequence
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
#: alone (forward reachability), the CTL specs on the product with detaching (``-df``).
WHOLE, INVARIANTS, CTL = "whole", "invariants", "ctl"


def product(
    src: Encoding,
    res: Encoding,
    inputs: Symbols,
    extra_specs: list[tuple[str, str]] | None = None,
    *,
    part: str = WHOLE,
) -> Product:
    """The ``main`` module and the specs, in the order ``spec_names`` lists them.

    ``part``: ``WHOLE`` every spec on the product with detaching; ``INVARIANTS`` only the
    invariants (completeness, no additional behaviour, termination consistency) on the product
    without detaching - they read attached pairs only, and the detached states (each faithful
    pair times everything one machine reaches alone) are most of a forward search's cost;
    ``CTL`` the CTL specs (deadlock absence, reachability) and the extra invariants written
    as ``AG``, for a run without the forward search (``-df``)."""
    detach = part != INVARIANTS
    in_ids = list(inputs.to_id.values())
    in_enum = enum_type(in_ids, "in_pad")  # never offered: no machine defines offers_in_pad
    follows = res.follows
    s_slots = [f"s.{x}" for x in src.slots]
    r_slots = [f"r.{x}" for x in res.slots]
    equal_outs = all_of(
        [subsequence(s_slots, r_slots, NONE_OUT), subsequence(r_slots, s_slots, NONE_OUT)]
    )
    joint = any_of(
        f"(inp_s = {i} & s.offers_{i}" + ("" if follows else f" & r.offers_{i}") + ")"
        for i in in_ids
    )
    alone_s = any_of(f"(inp_s = {i} & s.offers_{i})" for i in in_ids)
    alone_r = any_of(f"(inp_s = {i} & r.offers_{i})" for i in in_ids)
    lines = [
        "MODULE main",
        "IVAR",
        f"  inp_s : {in_enum};",
        "  ctl : {step, alone_s, alone_r, idle};",
        "VAR",
        "  s : " + src.module + "(go_s, inp_s);",
        "  r : " + res.module + "(go_r, inp_s);",
        "  mode : {att, sa, ra};",
        "  s_obs : boolean;",
        "  r_obs : boolean;",
        "  s_run : boolean;",
        "  r_run : boolean;",
        "  s_st0 : boolean;",
        "  r_st0 : boolean;",
        "  ok : boolean;",
        "FROZENVAR",
    ]
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
        "  s_out := " + any_of(f"{x} != {NONE_OUT}" for x in s_slots) + ";",
        "  r_out := " + any_of(f"{x} != {NONE_OUT}" for x in r_slots) + ";",
        "ASSIGN",
        "  init(mode) := att;",
        "  next(mode) := case !det & ok & both & ctl = alone_s : sa; "
        "!det & ok & both & ctl = alone_r : ra; TRUE : mode; esac;"
        if detach
        else "  next(mode) := mode;",
        "  init(ok) := TRUE;",
        "  next(ok) := case !det & both : ok & agree; TRUE : ok; esac;",
    ]
    for side in ("s", "r"):
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
    offers_s_in_r = all_of(f"(s.offers_{i} -> r.offers_{i})" for i in in_ids)
    offers_r_in_s = all_of(f"(r.offers_{i} -> s.offers_{i})" for i in in_ids)
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
    compl = f"((!det & ok & both) -> {subsequence(s_slots, r_slots, NONE_OUT)})"
    noadd = f"((!det & ok & both) -> {subsequence(r_slots, s_slots, NONE_OUT)})"
    if not follows:
        compl = f"{compl} & (faithful -> {offers_s_in_r})"
        noadd = f"{noadd} & (faithful -> {offers_r_in_s})"
    specs.append((COMPLETENESS, "INVARSPEC", compl))
    specs.append((NO_ADDITIONAL_BEHAVIOR, "INVARSPEC", noadd))
    specs.append(
        (TERMINATION_CONSISTENCY, "INVARSPEC", "((!det & ok & both) -> (s.final <-> r.final))")
    )
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
    order = _order(src, res)
    return Product("\n".join(lines) + "\n", [name for name, _, _ in specs], order)


def _order(src: Encoding, res: Encoding) -> str:
    """A BDD variable order: each identity variable next to its frozen copy (the reachability
    spec compares them), inputs first. Without it NuSMV is 20x slower on small models."""
    order = ["ok", "ctl", "mode", "inp_s", "s_obs", "r_obs", "s_run", "r_run", "s_st0", "r_st0"]
    for side, copy, enc in (("s", "ts", src), ("r", "tr", res)):
        ids = {v for v, _ in enc.id_vars}
        for var in enc.var_order:
            order.append(f"{side}.{var}")
            if var in ids:
                order.append(f"{copy}_{var}")
        order += [f"{copy}_{v}" for v, _ in enc.id_vars if v not in enc.var_order]  # DEFINEs
    return "\n".join(order) + "\n"
