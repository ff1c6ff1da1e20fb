"""Where NuSMV's time goes on a structured pair (issue 27, item 2; docs/nusmv.md, "The outcome
pairing (structured trees)").

    .venv/bin/python benchmarks/bench_nusmv_structured_phases.py [--sizes 10,20,50]
        [--seed 27 | --seeds 1,2,3] [--timeout 60]
        [--variants mono,part,dynamic,coi,last,copies,before] [--mutant]

For each size: a seeded outcome-driven machine (``random_outcome_fsm(seed + size, states=size,
containers=0.2)``, the agreement benchmark's family; with ``--seeds``, one machine
``random_outcome_fsm(s, states=size, containers=0.2)`` per listed seed ``s``) against its
structured tree (``--mutant``: the machine with one transition retargeted, as
``bench_nusmv_agreement.retargeted``), the
model ``check`` runs (``build_model``, every spec but reachability, which ``check`` leaves out
at first, and the frozen copies only that spec read, ``without_unread_copies``) run by NuSMV's
interactive shell one phase at a time, each followed by ``time`` (CPU seconds of NuSMV since
the previous ``time``): ``build`` (read, flatten, encode the variables with fsmbt's order,
build the BDD relation), ``reach`` (the forward search), ``invar`` (the
invariants on the reachable states), ``ctl`` (the CTL specs). A phase still running at
``--timeout`` wall seconds is ``-`` and ends the row. Variants: ``mono`` (``check``'s run:
one monolithic relation), ``part`` (NuSMV's partitioned relation), ``dynamic`` (``mono`` and
dynamic reordering by sifting), ``coi`` (``mono`` and the cone of influence per spec),
``last`` (``mono`` with the blackboard entries moved back to the end of the order, where they
were before ``encode_outcome.node_order`` put them after the call stack), ``copies`` (``mono``
with the frozen copies of the reachability spec kept, as before ``without_unread_copies``),
``before`` (both: the run before the eighth round).
Prints the seed, the tree's size, the model's variables and one row per variant.
"""

from __future__ import annotations

import argparse
import random
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from bench_nusmv_agreement import retargeted  # noqa: E402

from fsmbt.convert.structured import fsm_to_structured  # noqa: E402
from fsmbt.generate.outcome_machines import random_outcome_fsm  # noqa: E402
from fsmbt.verify.nusmv import build_model, without_spec, without_unread_copies  # noqa: E402
from fsmbt.verify.nusmv.binary import require_nusmv  # noqa: E402
from fsmbt.verify.nusmv.runner import count_variables  # noqa: E402
from fsmbt.verify.report import REACHABILITY  # noqa: E402

PHASES = ("build", "reach", "invar", "ctl")
_TIME = re.compile(r"elapse:\s*([0-9.]+)")


def commands(variant: str) -> str:
    """The shell script of one variant: each phase then ``time``."""
    build = "build_model" + (" -m Monolithic" if variant != "part" else "")
    lines = [
        "set input_file model.smv",
        "set input_order_file order.txt",
        *(["set cone_of_influence"] if variant == "coi" else []),
        "time",
        "read_model",
        "flatten_hierarchy",
        "encode_variables",
        *(["dynamic_var_ordering -e sift"] if variant == "dynamic" else []),
        build,
        "time",
        "compute_reachable",
        "time",
        "check_invar",
        "time",
        "check_ctlspec",
        "time",
        "quit",
    ]
    return "\n".join(lines) + "\n"


def entries_last(order: str) -> str:
    """``order`` with the tree's blackboard entries (``r.bb_k`` and their frozen copies
    ``tr_bb_k``) moved to its end: the order before this round (variant ``last``)."""
    lines = order.split()
    entries = [v for v in lines if re.fullmatch(r"(r\.|tr_)bb_\d+", v)]
    return "\n".join([v for v in lines if v not in entries] + entries) + "\n"


def run(text: str, order: str, variant: str, timeout: float) -> list[str]:
    """Each phase's CPU seconds (``-`` from the one past ``timeout`` on)."""
    if variant in ("last", "before"):
        order = entries_last(order)
    if variant in ("last", "copies", "before"):
        variant = "mono"
    with tempfile.TemporaryDirectory(prefix="fsmbt-phases-") as tmp:
        Path(tmp, "model.smv").write_text(text)
        Path(tmp, "order.txt").write_text(order)
        Path(tmp, "cmds.txt").write_text(commands(variant))
        binary = str(require_nusmv())
        try:
            done = subprocess.run(
                [binary, "-int", "-source", "cmds.txt"],
                cwd=tmp,
                capture_output=True,
                text=True,
                timeout=timeout,
                errors="replace",
            )
            output = done.stdout
        except subprocess.TimeoutExpired as expired:
            raw = expired.stdout or b""
            output = raw.decode(errors="replace") if isinstance(raw, bytes) else raw
    marks = [float(m) for m in _TIME.findall(output)][1:]  # the first: before any phase
    cells = [f"{m:.2f}" for m in marks[: len(PHASES)]]
    return cells + ["-"] * (len(PHASES) - len(cells))


def rows(seed: int, size: int, args: argparse.Namespace) -> None:
    """One machine's rows, one per variant, printed as each ends."""
    source = random_outcome_fsm(seed, states=size, containers=0.2)
    tree = fsm_to_structured(source).model
    if args.mutant:
        source = retargeted(source, random.Random(args.seed))
    text, names, context = build_model(source, tree, outcome_driven=True)
    lean = without_spec(text, names, REACHABILITY)
    if lean is not None:
        text = lean[0]
    runs = without_unread_copies(text, context[-1])  # check's run
    nodes = sum(1 for _ in tree.nodes())
    for variant in args.variants.split(","):
        started = time.perf_counter()
        model, order = (text, context[-1]) if variant in ("copies", "before") else runs
        cells = run(model, order, variant, args.timeout)
        wall = time.perf_counter() - started
        print(
            f"{seed:>5} {size:>5} {nodes:>5} {count_variables(text):>5} {variant:>8} "
            + " ".join(f"{c:>7}" for c in cells)
            + f"   ({wall:.1f} s wall)",
            flush=True,
        )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="10,20,50")
    parser.add_argument("--seed", type=int, default=27)
    parser.add_argument("--seeds", default="", help="machines of these seeds instead")
    parser.add_argument("--timeout", type=float, default=60.0)
    parser.add_argument("--variants", default="mono,part,dynamic,coi")
    parser.add_argument("--mutant", action="store_true")
    args = parser.parse_args(argv)
    print(
        f"{'seed':>5} {'size':>5} {'nodes':>5} {'vars':>5} {'variant':>8} "
        + " ".join(f"{p:>7}" for p in PHASES)
    )
    seeds = [int(s) for s in args.seeds.split(",") if s]
    for size in (int(s) for s in args.sizes.split(",")):
        for seed in seeds or [args.seed + size]:
            rows(seed, size, args)
    return 0


if __name__ == "__main__":
    sys.exit(main())
