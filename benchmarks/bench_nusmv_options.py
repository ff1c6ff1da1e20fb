"""NuSMV options and runs, measured (issue 27, item 2). Prints a table of NuSMV CPU seconds.

    .venv/bin/python benchmarks/bench_nusmv_options.py [--sizes 100,300,1000]
        [--timeout 60] [--columns whole,coi,dynamic,split-mono,frozen,unshared,after,beside,
        input-first]
        [--random] [--wall]

Pairs: ``bench_checker.chain_fsm(n, n)`` against its renamed copy (``copy``: equivalent), and
the same with one transition retargeted (``mutant``: not equivalent), FSM ~ FSM by macro
steps; ``--random``: ``generate.random_fsm`` of n states instead (the agreement benchmark's
FSMs; seed n), its mutant one random transition retargeted. Each cell is NuSMV's CPU seconds (user + system of the NuSMV children, from
``RUSAGE_CHILDREN``: independent of the load of this shared machine; wall seconds vary 2-10x
with it), ``-`` past ``--timeout`` wall seconds in one run:

- ``whole``: every spec in one model and one run, ``-mono`` and fsmbt's variable order, the
  reachability spec left out when the other four hold (``check(..., split=False)``: the runs
  of the previous version, on today's product);
- ``-coi``, ``-dynamic``: the whole model, every spec, with NuSMV's cone of influence /
  dynamic reordering;
- ``split-mono``: ``check``'s two runs (invariants on the product without detaching; CTL
  specs with ``-df``) but each with ``-mono``;
- ``frozen``: ``check``'s two runs, a failing pair's reachability by the frozen-copy spec
  (``check(..., state_reach=False)``: the default before "Reachability state by state");
- ``unshared``: ``check(..., shared_search=False)``: the invariants' own run, the CTL run,
  and for a failing pair the listing of the reachable states (``fsmbt.verify.nusmv.reach``);
- ``after``: ``check``'s default: the invariants and the listing in one run (one build, one
  forward search), the CTL run, the witness's two runs when reachability fails;
- ``beside``: ``check(..., beside=True)``: the same runs, the CTL run in a second process
  beside the shared run (docs/nusmv.md, "Sixth round");
- ``input-first``: ``after`` with the input ``inp_s`` first in the BDD order of an FSM ~ FSM
  pair (the order before the sixth round; ``after`` puts it after the source's variables).

``--wall``: each cell is ``CPU/wall`` seconds (the wall of the whole ``check``, on the loaded
machine).

``agree`` compares the five verdicts of ``after``, ``beside`` and ``input-first`` (each run)
with the native checker's; ``native`` is the native checker's CPU seconds.
"""

from __future__ import annotations

import argparse
import copy
import random
import resource
import sys
import time
from collections.abc import Callable
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from bench_checker import chain_fsm, renamed  # noqa: E402

from fsmbt import limits  # noqa: E402
from fsmbt.generate.generator import random_fsm  # noqa: E402
from fsmbt.model.fsm import FSM  # noqa: E402
from fsmbt.verify import nusmv, verify  # noqa: E402
from fsmbt.verify.nusmv.encode_fsm import Encoding, FSMEncoder  # noqa: E402
from fsmbt.verify.nusmv.runner import NuSMVLimitError, run_nusmv  # noqa: E402


def child_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def cpu_of(run: Callable[[], object], wall: bool = False) -> tuple[str, object]:
    """NuSMV CPU seconds of ``run()`` (``-`` past the cap) and its value; with ``wall``,
    ``CPU/wall`` (the wall seconds of the whole call: two runs side by side share it)."""
    before, begun = child_cpu(), time.perf_counter()
    try:
        value = run()
    except NuSMVLimitError:
        return "-", None
    cell = f"{child_cpu() - before:.2f}"
    return (f"{cell}/{time.perf_counter() - begun:.1f}" if wall else cell), value


def _runs(
    source: FSM, result: FSM, text: str, names: list[str], order: str
) -> dict[str, Callable[[], object]]:
    """The measured ways to run NuSMV on one pair, by column name."""
    return {
        "whole": lambda: nusmv.check(source, result, split=False),
        "coi": lambda: run_nusmv(text, len(names), order=order, options=["-coi"]),
        "dynamic": lambda: run_nusmv(text, len(names), order=order, options=["-dynamic"]),
        "split-mono": lambda: nusmv.check(source, result, split=True, mono=True),
        "frozen": lambda: nusmv.check(source, result, state_reach=False),
        "unshared": lambda: nusmv.check(source, result, shared_search=False),
        "after": lambda: nusmv.check(source, result),
        "beside": lambda: nusmv.check(source, result, beside=True),
        "input-first": lambda: _input_first(lambda: nusmv.check(source, result)),
    }


def _input_first(run: Callable[[], object]) -> object:
    """``run()`` with every FSM module's ``Encoding.input_after_source`` off: the input
    ``inp_s`` first in the BDD order, as before the sixth round (docs/nusmv.md)."""
    original = FSMEncoder.encode

    def encode(self: FSMEncoder) -> Encoding:
        encoding = original(self)
        encoding.input_after_source = False
        return encoding

    FSMEncoder.encode = encode  # type: ignore[method-assign]
    try:
        return run()
    finally:
        FSMEncoder.encode = original  # type: ignore[method-assign]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="100,300,1000")
    parser.add_argument("--timeout", type=float, default=60.0)
    parser.add_argument("--columns", default="whole,coi,dynamic,split-mono,frozen,after")
    parser.add_argument("--random", action="store_true", help="random_fsm pairs (seed = size)")
    parser.add_argument("--wall", action="store_true", help="cells CPU/wall seconds")
    args = parser.parse_args(argv)
    limits.use(limits.current().with_changes(nusmv_max_seconds=args.timeout))
    columns = args.columns.split(",")
    header = f"{'pair':<7} {'states':>6} {'native':>7} " + " ".join(f"{c:>10}" for c in columns)
    print(header + "  agree")
    print("-" * (len(header) + 7))
    gave_up: set[str] = set()  # a column past the cap is not run on larger sizes
    for n in [int(x) for x in args.sizes.split(",")]:
        if args.random:
            rng = random.Random(n)
            source = random_fsm(rng.randrange(10**9), n_states=n)
            mutant = copy.deepcopy(source)
            moved = mutant.transitions[rng.randrange(len(mutant.transitions))]
            moved.target = rng.choice([x for x in mutant.states if x != moved.target])
        else:
            source = chain_fsm(n, n)
            mutant = copy.deepcopy(source)
            mutant.transitions[0].target = mutant.transitions[-1].target
        same = renamed(source)
        for label, result in (("copy", same), ("mutant", mutant)):
            started = time.process_time()
            native = verify(source, result)
            native_s = time.process_time() - started
            text, names, context = nusmv.build_model(source, result)
            order = context[-1]
            runs = _runs(source, result, text, names, order)
            cells, agree = [], "-"
            for column in columns:
                key = f"{column}/{label}"
                if key in gave_up:
                    cells.append("-")
                    continue
                cell, value = cpu_of(runs[column], args.wall)
                if cell == "-":
                    gave_up.add(key)
                cells.append(cell)
                if column in ("after", "beside", "input-first") and value is not None:
                    same_verdicts = value.verdicts() == native.verdicts()  # type: ignore[attr-defined]
                    agree = "NO" if agree == "NO" or not same_verdicts else "yes"
            print(
                f"{label:<7} {n:>6} {native_s:>7.3f} "
                + " ".join(f"{c:>10}" for c in cells)
                + f"  {agree}",
                flush=True,
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
