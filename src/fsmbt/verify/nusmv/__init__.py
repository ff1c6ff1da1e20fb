"""NuSMV as the second, independent verification engine (docs/verification.md, docs/nusmv.md).

``check(source, result, loop=False)`` encodes both models as SMV modules from their structure
(the BT's tick rules as transition relations, never the native interpreter's explored graph),
builds the product and the five properties as CTL specs, runs NuSMV (twice: the invariants,
then the CTL specs; docs/nusmv.md, "Two runs") and returns the same
``Report`` the native checker gives, counterexamples decoded to ``TraceStep`` s.
"""

from __future__ import annotations

import re
import time
from collections.abc import Iterable
from concurrent.futures import Future, ThreadPoolExecutor
from typing import TYPE_CHECKING, TypeAlias

from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM
from fsmbt.semantics.outcome_rules import OutcomeRules
from fsmbt.verify.nusmv import encode_macro, reach
from fsmbt.verify.nusmv.binary import NuSMVNotFound, find_nusmv, require_nusmv
from fsmbt.verify.nusmv.encode_bt import LeafBTEncoder
from fsmbt.verify.nusmv.encode_dispatch import encode_dispatch_pair, one_step_per_input
from fsmbt.verify.nusmv.encode_fsm import FSMEncoder
from fsmbt.verify.nusmv.encode_outcome import OutcomeBTEncoder
from fsmbt.verify.nusmv.runner import NuSMVError, NuSMVLimitError, SpecResult, run_nusmv
from fsmbt.verify.nusmv.smv import Symbols
from fsmbt.verify.nusmv.specs import CTL, INVARIANTS, WHOLE, product
from fsmbt.verify.nusmv.traces import Context, Encoder, build_report
from fsmbt.verify.report import (
    DEADLOCK_ABSENCE,
    PROPERTIES,
    REACHABILITY,
    PropertyResult,
    Report,
)

if TYPE_CHECKING:
    from fsmbt.verify.nusmv.encode_lebt import LebtEncoder  # noqa: F401 - in Encoder
    from fsmbt.verify.nusmv.encode_outcome import OutcomeFSMEncoder  # noqa: F401 - in Encoder
    from fsmbt.verify.nusmv.encode_sv import SvEncoder  # noqa: F401 - in Encoder

Encoders: TypeAlias = tuple[Encoder, Encoder, Symbols, Symbols, str]

MACRO_STEP = "macro-step"
LEAF_EXECUTION = "leaf-execution"

#: How a BT ~ FSM pair's tree is written (``check(tree_encoding=...)``): ``MICRO`` one
#: micro-step per node visit (``encode_bt``), ``MACRO`` one step per leaf outcome
#: (``encode_macro``, its node class only), ``AUTO`` the macro steps wherever they apply.
AUTO, MICRO, MACRO = "auto", "micro", "macro"


def _union(*groups: Iterable[str]) -> list[str]:
    seen: dict[str, None] = {}
    for group in groups:
        for item in group:
            seen.setdefault(item, None)
    return list(seen)


def encode(
    source: FSM | BTDocument,
    result: FSM | BTDocument,
    *,
    loop: bool = False,
    outcomes: OutcomeRules | None = None,
    outcome_driven: bool = False,
    tree_encoding: str = AUTO,
) -> Encoders:
    """The two machine encoders, the shared symbol tables and the mode for a pair of models
    (the same pairing as ``fsmbt.verify.pairing.machines_for``; ``outcomes`` and
    ``outcome_driven`` as there: an outcome-driven FSM and its structured tree are the outcome
    pairing, ``encode_outcome``). ``tree_encoding`` (``AUTO``/``MICRO``/``MACRO``): how the
    tree of a BT ~ FSM pair is written; ``MACRO`` on a tree outside ``encode_macro``'s class
    raises its ``UnsupportedError``."""
    from fsmbt.verify.outcome_pairing import OUTCOME_EXECUTION, is_outcome_pair
    from fsmbt.verify.pairing import lebt_guard_events, sub_machine_events

    inputs, outputs = Symbols("in_"), Symbols("out_")
    if (
        isinstance(source, FSM)
        and isinstance(result, BTDocument)
        and is_outcome_pair(source, result, outcome_driven=outcome_driven)
    ):
        from fsmbt.verify.nusmv.encode_outcome import encode_outcome_pair

        pair = encode_outcome_pair(source, result, inputs, outputs, outcomes)
        return (*pair, inputs, outputs, OUTCOME_EXECUTION)
    if isinstance(source, FSM) and isinstance(result, FSM):
        alphabet = _union(source.events(), result.events(), *sub_machine_events(source, result))
        return (
            FSMEncoder(source, "source", inputs, outputs, alphabet=alphabet),
            FSMEncoder(result, "result", inputs, outputs, alphabet=alphabet),
            inputs,
            outputs,
            MACRO_STEP,
        )
    dispatch = encode_dispatch_pair(source, result, inputs, outputs)
    if dispatch is not None:  # the dispatch form, by macro steps (docs/nusmv.md)
        return (*dispatch, inputs, outputs, MACRO_STEP)
    if isinstance(source, FSM) and isinstance(result, BTDocument):
        from fsmbt.model.flatten import flatten
        from fsmbt.semantics.execution import Flavour, flavour_of
        from fsmbt.verify.nusmv.encode_lebt import LebtEncoder

        if flavour_of(result) is Flavour.STATE_VARIABLE:  # BSD, CHDS: Sv* leaves
            from fsmbt.semantics.state_variable_runtime import StateVariableMachine
            from fsmbt.verify.nusmv.encode_sv import SvEncoder

            # the native pairing's alphabet (machines_for_state_variable): the FSM's events,
            # then every event a leaf names
            machine = StateVariableMachine(result, ())  # parsed once, for both uses
            alphabet = _union(flatten(source).events(), machine.events())
            return (
                FSMEncoder(source, "source", inputs, outputs, alphabet=alphabet),
                SvEncoder(result, "result", inputs, outputs, alphabet=alphabet, machine=machine),
                inputs,
                outputs,
                MACRO_STEP,
            )

        alphabet = _union(flatten(source).events(), lebt_guard_events(result))
        return (
            FSMEncoder(source, "source", inputs, outputs, alphabet=alphabet),
            LebtEncoder(result, "result", inputs, outputs, alphabet=alphabet),
            inputs,
            outputs,
            MACRO_STEP,
        )
    if isinstance(source, BTDocument) and isinstance(result, FSM):
        if uses_macro_steps(source, result, tree_encoding):
            return (
                encode_macro.MacroBTEncoder(source, "source", inputs, outputs, loop=loop),
                FSMEncoder(result, "result", inputs, outputs, alphabet=(), leaf=True, loop=loop),
                inputs,
                outputs,
                LEAF_EXECUTION,
            )
        return (
            LeafBTEncoder(source, "source", inputs, outputs, loop=loop),
            FSMEncoder(result, "result", inputs, outputs, alphabet=(), leaf=True, loop=loop),
            inputs,
            outputs,
            LEAF_EXECUTION,
        )
    if isinstance(source, BTDocument) and isinstance(result, BTDocument):
        return (
            LeafBTEncoder(source, "source", inputs, outputs, loop=loop),
            LeafBTEncoder(result, "result", inputs, outputs, loop=loop),
            inputs,
            outputs,
            LEAF_EXECUTION,
        )
    raise InputError(f"cannot compare a {type(source).__name__} with a {type(result).__name__}")


def uses_macro_steps(
    source: FSM | BTDocument, result: FSM | BTDocument, tree_encoding: str = AUTO
) -> bool:
    """Whether ``encode`` writes the pair's tree by macro steps (``encode_macro``): a BT
    source against an FSM, ``MACRO`` asked or ``AUTO`` and the tree in its class (measured:
    it agrees with the micro-step encoding and is faster from 5 leaves on, docs/nusmv.md,
    "Trees by macro steps"). The outcome and dispatch pairings have an FSM source."""
    if not (isinstance(source, BTDocument) and isinstance(result, FSM)):
        return False
    if tree_encoding not in (AUTO, MICRO, MACRO):
        raise InputError(f"unknown tree encoding {tree_encoding!r} (auto, micro or macro)")
    return tree_encoding == MACRO or (tree_encoding == AUTO and encode_macro.applies(source))


def build_model(
    source: FSM | BTDocument,
    result: FSM | BTDocument,
    *,
    loop: bool = False,
    part: str = WHOLE,
    outcomes: OutcomeRules | None = None,
    outcome_driven: bool = False,
    tree_encoding: str = AUTO,
) -> tuple[str, list[str], Context]:
    """The SMV text of the product, the spec names and what is needed to decode traces.

    ``part`` (``specs.WHOLE``, ``INVARIANTS``, ``CTL``): which model - every spec on one
    product (the single model of earlier versions, kept for the benchmarks and
    ``scripts/smv_snapshot.py``) or one of the two that ``check`` runs."""
    return build_models(
        source,
        result,
        loop=loop,
        parts=(part,),
        outcomes=outcomes,
        outcome_driven=outcome_driven,
        tree_encoding=tree_encoding,
    )[0]


def build_models(
    source: FSM | BTDocument,
    result: FSM | BTDocument,
    *,
    loop: bool = False,
    parts: tuple[str, ...] = (INVARIANTS, CTL),
    outcomes: OutcomeRules | None = None,
    outcome_driven: bool = False,
    tree_encoding: str = AUTO,
) -> list[tuple[str, list[str], Context]]:
    """``build_model`` for several parts, encoding the two machines once."""
    src_enc, res_enc, inputs, outputs, mode = encode(
        source,
        result,
        loop=loop,
        outcomes=outcomes,
        outcome_driven=outcome_driven,
        tree_encoding=tree_encoding,
    )
    src, res = src_enc.encode(), res_enc.encode()
    extra: list[tuple[str, str]] = getattr(res_enc, "extra_specs", lambda: [])()
    models = []
    for part in parts:
        prod = product(src, res, inputs, extra, part=part)
        text = src.text + "\n" + res.text + "\n" + prod.text
        context = (src, res, src_enc, res_enc, inputs, outputs, mode, prod.order)
        models.append((text, prod.spec_names, context))
    return models


def check(
    source_model: FSM | BTDocument,
    result_model: FSM | BTDocument,
    *,
    loop: bool = False,
    timeout: float | None = None,
    implied_reachability: bool = True,
    split: bool | None = None,
    mono: bool | None = None,
    outcomes: OutcomeRules | None = None,
    outcome_driven: bool = False,
    state_reach: bool = True,
    shared_search: bool = True,
    beside: bool = False,
    tree_encoding: str = AUTO,
    implied_deadlock: bool = True,
) -> Report:
    """Verify ``result_model`` against ``source_model`` with NuSMV; see the module docstring.

    ``outcomes``, ``outcome_driven``: an FSM and a structured tree are compared by the outcome
    pairing (``encode_outcome``; ``fsmbt.verify.outcome_pairing``) under these rules.

    ``split`` (docs/nusmv.md, "Two runs"): the invariants run on the product without
    detaching (NuSMV's forward search then visits the faithful product only), the CTL specs on
    the product with detaching under ``-df`` (no forward search: the backward fixpoints of the
    specs alone). ``False``: one run of one model holding every spec. ``None`` (default): split
    for an FSM ~ FSM pair, an FSM ~ dispatch tree pair and a tree written by macro steps
    beside an FSM (``tree_encoding``; both modules take one step per input; a 100-state equivalent dispatch pair: 0.6 s split, 11.6 s single) - there it wins by
    orders of magnitude, while on a BT's
    micro-step product the unrestricted backward fixpoints of ``-df`` cost far more than the
    forward search saves (measured: benchmarks/bench_nusmv_options.py, docs/nusmv.md). ``mono``: NuSMV's ``-mono`` (one monolithic transition relation); ``None``: only
    for the single model (the two runs are 4-7x cheaper on the partitioned relation;
    benchmarks/bench_nusmv_options.py).

    ``implied_reachability``: the reachability spec (its frozen copies make it a transitive
    closure, the costliest spec) is left out at first; when the other four properties hold,
    reachability follows from them (docs/nusmv.md, "Reachability implied") and is reported as
    such; otherwise it is run too, so a failing pair gets reachability's own verdict and
    counterexample. ``state_reach`` (default): on the split runs (FSM ~ FSM, FSM ~ dispatch
    tree) that run is ``reach.check_reachability``'s listing of the reachable states instead
    of the frozen-copy spec (docs/nusmv.md, "Fifth round: reachability from the listed
    states": a 1 000-state mutant in one forward search where the frozen copies gave up at ~100
    states); ``False``: the frozen-copy spec (kept for the benchmarks and the tests that
    compare the two). ``shared_search`` (default, with ``state_reach`` on the split runs):
    the invariants are checked on that listing's model in the same NuSMV run
    (``reach.invariants_and_listing``: one build and one forward search for both, and
    reachability decided directly rather than implied; docs/nusmv.md); ``False``: the
    invariants' own run first, the listing only for a failing pair. ``beside`` (with the shared
    run): the CTL run is started in a second NuSMV process beside it (a thread waits on it),
    since neither reads the other's result - the same runs and report, the wall time the
    longer run's rather than their sum when a core is free, at the cost of two processes'
    memory (each under ``nusmv_max_memory_mb``). Not the default: on the random 1 000-state
    pair, four measured runs at load 1.3-4.9 gave 9 % less wall in total but a loss in three of
    eight pairs (copy 23.3 -> 13.4 s at load 1.9, 27.7 -> 32.4 s at load 1.3-2.2;
    docs/nusmv.md, "Sixth round"). ``False``: one after the other.

    ``implied_deadlock`` (default): on the shared run's split pairs, when the three invariants
    hold and the listing leaves no state unmatched (reachability holds), deadlock absence is
    implied (``deadlock_implied``) and the CTL run is not made; ``False``: it always runs.

    ``tree_encoding`` (``AUTO``, ``MICRO``, ``MACRO``): how a BT ~ FSM pair's tree is written
    (``uses_macro_steps``; docs/nusmv.md, "Trees by macro steps"); the report's
    ``stats["nusmv_tree_encoding"]`` names the one used.

    ``timeout`` defaults to ``fsmbt.limits.current().nusmv_max_seconds`` (per NuSMV run); the
    memory cap is ``nusmv_max_memory_mb``. Raises ``UnsupportedError`` for BT node types the
    encoding does not model (docs/nusmv.md), ``NuSMVLimitError`` past a cap and
    ``NuSMVNotFound`` when no binary is available; for a state-variable (BSD/CHDS) tree whose
    macro step never settles, the native checker's livelock ``InputError`` (``encode_sv``).
    """
    started = time.perf_counter()
    macro = uses_macro_steps(source_model, result_model, tree_encoding)
    if split is None:  # a tree by macro steps takes one step per input, like an FSM
        split = macro or one_step_per_input(source_model, result_model)
    parts = (INVARIANTS, CTL) if split else (WHOLE,)
    mono = not split if mono is None else mono
    # the encoding decided once above: ``encode`` does not compile and scan the tree again
    models = build_models(
        source_model,
        result_model,
        loop=loop,
        parts=parts,
        outcomes=outcomes,
        outcome_driven=outcome_driven,
        tree_encoding=MACRO if macro else MICRO,
    )
    encoded = time.perf_counter()
    context = models[0][2]
    names: list[str] = []
    results: list[SpecResult] = []
    runs, nusmv_seconds = 0, 0.0
    # the reachability run, if needed: text, spec names, options, variable order
    deferred: tuple[str, list[str], list[str], str] | None = None
    # the split pairs' invariants and reachability listing in one run (``reach``)
    listed: list[dict[str, str]] | None = None
    # the listing's unmatched states per side (``reach.unmatched_states``), read once
    unmatched: dict[str, list[reach.Key]] = {}
    shared = split and state_reach and shared_search and reach.lists_cheaply(context)
    drop_reach = implied_reachability or shared
    pool = ThreadPoolExecutor(max_workers=1) if shared and beside and CTL in parts else None
    ctl_run: Future[tuple[list[SpecResult], float]] | None = None
    # reachability's verdict from the listing when decided beside the CTL run
    reach_found: tuple[PropertyResult, int, float] | None = None
    deadlock_follows = False  # deadlock absence implied, its spec not run (``deadlock_implied``)
    try:
        for part, (text, part_names, part_context) in zip(parts, models):
            if shared and part == INVARIANTS:
                if pool is not None:  # the CTL run does not read this one's result: beside it
                    ctl_text, ctl_names, ctl_context = models[parts.index(CTL)]
                    ctl_text, ctl_names, ctl_options, ctl_order, _kept = _lean_part(
                        CTL, ctl_text, ctl_names, ctl_context[-1], drop_reach
                    )
                    if ctl_names:
                        ctl_run = pool.submit(
                            run_nusmv,
                            ctl_text,
                            len(ctl_names),
                            order=ctl_order,
                            timeout=timeout,
                            options=ctl_options,
                            mono=mono,
                        )
                part_names, found, listed, seconds = reach.invariants_and_listing(
                    context, timeout=timeout
                )
                unmatched = reach.unmatched_states(context, listed)
                names += part_names
                results += found
                runs += 1
                nusmv_seconds += seconds
                continue
            text, part_names, options, order, lean = _lean_part(
                part, text, part_names, part_context[-1], drop_reach
            )
            deferred = lean or deferred
            if (
                part == CTL
                and ctl_run is None
                and implied_deadlock
                and listed is not None
                and deadlock_implied(context, results, unmatched)
            ):
                dropped = without_spec(text, part_names, DEADLOCK_ABSENCE)
                if dropped is not None:
                    text, part_names = dropped
                    deadlock_follows = True
            if not part_names:
                continue
            if part == CTL and ctl_run is not None:
                found, seconds = ctl_run.result()  # started beside the shared run
            elif part == CTL and unmatched:
                # reachability fails: its witness runs go beside the CTL run (neither reads
                # the other's result), so the pair's wall is the longer of the two
                with ThreadPoolExecutor(max_workers=1) as beside_pool:
                    ctl_future = beside_pool.submit(
                        run_nusmv,
                        text,
                        len(part_names),
                        order=order,
                        timeout=timeout,
                        options=options,
                        mono=mono,
                    )
                    try:
                        reach_found = reach.judged(context, unmatched, timeout=timeout)
                    finally:  # past its cap: the CTL run ends by its own cap, waited for
                        found, seconds = ctl_future.result()
            else:
                found, seconds = run_nusmv(
                    text, len(part_names), order=order, timeout=timeout, options=options, mono=mono
                )
            names += part_names
            results += found
            runs += 1
            nusmv_seconds += seconds
    finally:  # a run past its cap raised: the other process ends by its own cap, waited for
        if pool is not None:
            pool.shutdown(wait=True)
    report = build_report(names, results, context, source_model, result_model)
    tree = context[3]
    if isinstance(tree, OutcomeBTEncoder):  # the outcome pairing's livelock check, on its own
        checked = tree.livelock_model(context[1])
        if checked is not None:
            # one monolithic relation: the partitioned one passed 200 s on the 125-node tree
            # of a corpus FlexBE machine, -mono takes 1.4 s (docs/nusmv.md, "Eighth round")
            found, seconds = run_nusmv(checked[0], 1, order=checked[1], timeout=timeout, mono=True)
            runs += 1
            nusmv_seconds += seconds
            if not found[0].holds:
                raise tree.livelock_failure()
    if deadlock_follows:
        report.properties[DEADLOCK_ABSENCE] = PropertyResult(
            DEADLOCK_ABSENCE, True, DEADLOCK_IMPLIED_DETAIL
        )
    if listed is not None:  # reachability from the shared run's listing
        verdict, more_runs, seconds = reach_found or reach.judged(
            context, unmatched, timeout=timeout
        )
        runs += more_runs
        nusmv_seconds += seconds
        report.properties[REACHABILITY] = verdict
        report.properties = {n: report.properties[n] for n in PROPERTIES}
    elif deferred is not None:
        if all(p.holds for p in report.properties.values()):
            report.properties[REACHABILITY] = PropertyResult(REACHABILITY, True, IMPLIED_DETAIL)
        elif (
            state_reach
            and reach.applies(context)
            and (split or isinstance(context[3], OutcomeBTEncoder))
        ):  # a failing split or structured pair: from the listed reachable states
            verdict, more_runs, seconds = reach.check_reachability(context, timeout=timeout)
            runs += more_runs
            nusmv_seconds += seconds
            report.properties[REACHABILITY] = verdict
        else:  # a failing pair: reachability is decided by its own spec (its counterexample)
            text, part_names, options, order = deferred
            only = _only_spec(text, part_names, REACHABILITY)
            if split:  # the closure over the frozen copies: forward-restricted, reordered
                options = ["-dynamic"]  # (CPU s on a 100-state mutant: 17.6 -df, 6.2 here)
            found, seconds = run_nusmv(
                only, 1, order=order, timeout=timeout, options=options, mono=mono
            )
            runs += 1
            nusmv_seconds += seconds
            report = build_report(
                names + [REACHABILITY], results + found, context, source_model, result_model
            )
        report.properties = {n: report.properties[n] for n in PROPERTIES}
    report.stats.update(
        {
            "smv_lines": sum(text.count("\n") for text, _n, _c in models),
            "encode_seconds": round(encoded - started, 6),
            "nusmv_seconds": round(nusmv_seconds, 6),
            "nusmv_runs": runs,
            "seconds": round(time.perf_counter() - started, 6),
        }
    )
    if isinstance(source_model, BTDocument) and isinstance(result_model, FSM):
        report.stats["nusmv_tree_encoding"] = (
            encode_macro.ENCODING_NAME if macro else "micro-step tree (encode_bt)"
        )
    return report


def _lean_part(
    part: str, text: str, names: list[str], order: str, drop_reach: bool
) -> tuple[str, list[str], list[str], str, tuple[str, list[str], list[str], str] | None]:
    """One part's run as ``check`` makes it: (text, spec names, NuSMV options, variable
    order, the run kept for reachability or ``None``). ``-df`` for the CTL part; with
    ``drop_reach`` the reachability spec is left out, with the frozen copies only it read
    (``without_unread_copies``), and the whole part is kept to run it later if needed."""
    options = ["-df"] if part == CTL else []
    lean = without_spec(text, names, REACHABILITY) if drop_reach else None
    if lean is None:
        return text, names, options, order, None
    lean_text, lean_order = without_unread_copies(lean[0], order)
    return lean_text, lean[1], options, lean_order, (text, names, options, order)


#: A declaration line of ``MODULE main`` (``  name : type;``).
_DECLARED = re.compile(r"^  ([A-Za-z_][A-Za-z0-9_]*) : ")
_IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_.]*")


def without_unread_copies(text: str, order: str) -> tuple[str, str]:
    """``text`` without the ``FROZENVAR`` declarations of ``MODULE main`` that no other line
    reads, and ``order`` without them (a name or one of its bits, ``name.k``). A copy whose
    enumerated type is the only declaration of one of its symbols is kept (a DEFINE may
    evaluate to that symbol: a tree's ``runl`` to ``rl_4``, declared by ``tr_runl`` alone).

    Why: the frozen copies of the identity variables (``ts_*``, ``tr_*``; ``specs.product``)
    are read by the reachability spec alone; once ``without_spec`` has left it out they are
    free variables that change no verdict but make every counterexample costly, NuSMV picking
    and printing a value of each at every step: on a 125-node structured tree's mutant (a
    corpus FlexBE machine) the two failing invariants' traces took 49.4 s with the copies and
    6.4 s without (docs/nusmv.md, "The outcome pairing", "Eighth round"). O(size of the
    text)."""
    lines = text.split("\n")
    try:
        main = lines.index("MODULE main")
    except ValueError:
        return text, order
    frozen: dict[str, int] = {}  # name -> its declaration's line
    heads: dict[int, list[int]] = {}  # a FROZENVAR header's line -> its declarations' lines
    head = None
    for i in range(main + 1, len(lines)):
        line = lines[i]
        if line.startswith("MODULE "):
            break  # main's sections end at the next module
        if line and not line.startswith(" "):
            head = i if line.strip() == "FROZENVAR" else None
            if head is not None:
                heads[head] = []
            continue
        found = _DECLARED.match(line)
        if head is not None and found:
            frozen[found.group(1)] = i
            heads[head].append(i)
    declared_at = set(frozen.values())
    read: set[str] = set()
    for i, line in enumerate(lines):
        if i not in declared_at:
            read.update(name.split(".")[0] for name in _IDENTIFIER.findall(line))
    unread = [name for name in frozen if name not in read]
    # the enumerated symbols declared by the declarations that stay (symbols are global)
    candidates = {frozen[name] for name in unread}
    symbols = {
        symbol
        for i, line in enumerate(lines)
        if i not in candidates and _ENUM_DECLARED.match(line)
        for symbol in _symbols(line)
    }
    dropped: set[str] = set()
    for name in unread:
        own = _symbols(lines[frozen[name]])
        if own <= symbols:
            dropped.add(name)
        else:  # the only declaration of a symbol: kept
            symbols |= own
    if not dropped:
        return text, order
    drop = {frozen[name] for name in dropped}
    drop.update(h for h, declared in heads.items() if drop.issuperset(declared))  # now empty
    kept_lines = [line for i, line in enumerate(lines) if i not in drop]
    kept_order = [entry for entry in order.split("\n") if entry.split(".")[0] not in dropped]
    return "\n".join(kept_lines), "\n".join(kept_order)


_ENUMERATION = re.compile(r"\{([^}]*)\}")
#: A declaration of an enumerated type, in any module.
_ENUM_DECLARED = re.compile(r"^\s+[A-Za-z_][A-Za-z0-9_.]*\s*:\s*\{")


def _symbols(line: str) -> set[str]:
    """The symbols of the enumerated types written on ``line`` (``x : {a, b};`` -> a, b)."""
    return {
        symbol.strip()
        for found in _ENUMERATION.findall(line)
        for symbol in found.split(",")
        if symbol.strip()
    }


def _only_spec(text: str, names: list[str], kept: str) -> str:
    """The model with only the spec named ``kept`` (see ``without_spec``)."""
    for name in names:
        if name != kept:
            dropped = without_spec(text, names, name)
            assert dropped is not None
            text, names = dropped
    return text


#: The reachability verdict when the other four hold (docs/nusmv.md, "Reachability implied").
IMPLIED_DETAIL = (
    "implied by the other four (every faithful pair steps on every input the source offers "
    "to an agreeing pair, so every state either side reaches is reached faithfully)"
)

#: The deadlock verdict when the three invariants and reachability hold (``deadlock_implied``).
DEADLOCK_IMPLIED_DETAIL = (
    "implied by the other four (neither machine follows the environment, so in every faithful "
    "pair both offer the same inputs and every common step agrees: what one side can still "
    "do observably the other can, docs/verification.md §2)"
)


def deadlock_implied(
    context: Context, invariants: list[SpecResult], unmatched: dict[str, list[reach.Key]]
) -> bool:
    """Whether deadlock absence follows from the shared run (docs/nusmv.md, "Deadlock
    implied"): its three invariants hold (completeness, no additional behaviour, termination
    consistency: from a faithful pair the two machines offer the same inputs - neither follows
    the environment, so neither exception of docs/verification.md §2 applies - and each common
    step has equal outputs and statuses, so it leads to a faithful pair) and reachability holds
    on its listing. Then from any pair of F every input sequence one side offers the other offers
    too, with the same outputs and statuses, so an observable step one side can still reach the
    other reaches: a side is dead exactly when the other is. (A result that follows the
    environment may offer inputs the source refuses: not implied there.) ``unmatched``: the
    listing's unmatched states (``reach.unmatched_states``). Cost: O(1)."""
    src, res = context[0], context[1]
    return (
        not src.follows
        and not res.follows
        and bool(invariants)
        and all(found.holds for found in invariants)
        and not unmatched
    )


_SPEC_PREFIXES = ("SPEC ", "INVARSPEC ", "LTLSPEC ")


def without_spec(text: str, names: list[str], dropped: str) -> tuple[str, list[str]] | None:
    """The model without the spec named ``dropped`` (specs are the lines starting with
    ``SPEC``/``INVARSPEC``/``LTLSPEC``, in ``names`` order), or ``None`` when the text does not
    have one spec line per name (then nothing is dropped)."""
    lines = text.split("\n")
    spec_lines = [i for i, line in enumerate(lines) if line.startswith(_SPEC_PREFIXES)]
    if len(spec_lines) != len(names) or dropped not in names:
        return None
    skip = spec_lines[names.index(dropped)]
    kept = [line for i, line in enumerate(lines) if i != skip]
    return "\n".join(kept), [n for n in names if n != dropped]


__all__ = [
    "check",
    "build_model",
    "find_nusmv",
    "require_nusmv",
    "NuSMVNotFound",
    "NuSMVError",
    "NuSMVLimitError",
]
