"""Where the whole ``fsmbt convert`` of a large tree spends its time, and what the SCXML load
check costs in its child process (issue 27: a 15 000-node ``mixed`` convert < 30 s on 2 cores).

    .venv/bin/python benchmarks/bench_load_check.py [--families mixed,memory] [--sizes 15000]
        [--limit 120]

Per tree (``bench_reactive.family_tree``, the trees of ``bench_reactive.py --convert``), one row:
the parent's stages, each timed alone in this process - ``read`` (the BT XML), ``convert``
(``convert_model``), ``dumps`` (the SCXML text), ``verify`` (the proof) - then the load check as
``convert`` runs it beside the proof: the child process of
``semantics.engines.load_beside`` (``python -m fsmbt.semantics.engines.scxml_load FILE``), its
wall seconds, CPU seconds (user + system, from ``wait4``) and peak resident memory; and the
same child's work with Python's cyclic garbage collector left on (``gc on``: the check as it
ran before the collector was turned off in the child), so both are measured back to back under
the same load. ``uptime``'s load average is printed before and after: on a shared machine every
wall time grows with it, CPU seconds much less.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from bench_reactive import family_tree, leaves_for, node_count  # noqa: E402

from fsmbt import api  # noqa: E402
from fsmbt.formats import dumps  # noqa: E402
from fsmbt.semantics.engines.load_beside import CHILD_COMMAND  # noqa: E402

#: The child's work with the collector on: the check as ``scxml_load.main`` ran it before.
GC_ON = (
    "-c",
    "import json, sys; from fsmbt.semantics.engines.scxml_load import check_scxml_loads; "
    "answer = check_scxml_loads(open(sys.argv[1], encoding='utf-8').read()); "
    "print(json.dumps(answer.loaded if answer else None))",
)


def _load_average() -> str:
    return "load average " + ", ".join(f"{x:.2f}" for x in os.getloadavg())


def _child(arguments: tuple[str, ...], file: str, limit: int) -> tuple[float, float, int, str]:
    """Wall seconds, CPU seconds (user + system) and peak resident MB of one child run (from
    ``wait4``), and whether it says the chart loaded."""
    started = time.perf_counter()
    with open(os.devnull, "w") as null, tempfile.TemporaryFile("w+") as out:
        child = subprocess.Popen([sys.executable, *arguments, file], stdout=out, stderr=null)
        deadline = started + limit
        while True:
            pid, status, usage = os.wait4(child.pid, os.WNOHANG)
            if pid:
                break
            if time.perf_counter() > deadline:
                child.kill()
                os.wait4(child.pid, 0)
                return float(limit), 0.0, 0, f"over {limit} s"
            time.sleep(0.02)
        child.returncode = os.waitstatus_to_exitcode(status)
        wall = time.perf_counter() - started
        out.seek(0)
        lines = out.read().strip().splitlines()
    try:  # the check's JSON answer, or the gc-on script's printed ``loaded``
        answer = json.loads(lines[-1]) if lines else None
    except json.JSONDecodeError:
        answer = None
    last = str(answer.get("loaded")) if isinstance(answer, dict) else str(answer)
    return wall, usage.ru_utime + usage.ru_stime, usage.ru_maxrss // 1024, last


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--families", default="mixed,memory")
    parser.add_argument("--sizes", default="15000")
    parser.add_argument("--limit", type=int, default=120, help="seconds per child")
    args = parser.parse_args()
    print(_load_average())
    header = (
        f"{'family':<8} {'nodes':>6} {'read s':>7} {'conv s':>7} {'dumps s':>8} {'MB':>5} "
        f"{'verify s':>8} | {'child s':>7} {'cpu s':>6} {'RSS MB':>6} | {'gc on s':>7} "
        f"{'cpu s':>6} {'RSS MB':>6}  answer"
    )
    print(header)
    print("-" * len(header))
    with tempfile.TemporaryDirectory() as folder:
        for family in args.families.split(","):
            for size in (int(s) for s in args.sizes.split(",")):
                doc = family_tree(family, leaves_for(size), size)
                tree = api.write(doc, Path(folder) / f"{family}{size}.xml")
                started = time.perf_counter()
                loaded = api.load(tree)
                read = time.perf_counter() - started
                started = time.perf_counter()
                conversion = api.convert_model(loaded.model, "rules")
                converted = time.perf_counter() - started
                started = time.perf_counter()
                text = dumps(conversion.model, "scxml")
                dumped = time.perf_counter() - started
                started = time.perf_counter()
                api.verify_models(loaded.model, conversion.model, "native")
                verified = time.perf_counter() - started
                scxml = Path(folder) / f"{family}{size}.scxml"
                scxml.write_text(text, encoding="utf-8")
                now = _child(CHILD_COMMAND, str(scxml), args.limit)
                before = _child(GC_ON, str(scxml), args.limit)
                print(
                    f"{family:<8} {node_count(doc):>6} {read:>7.2f} {converted:>7.2f} "
                    f"{dumped:>8.2f} {len(text) / 1e6:>5.1f} {verified:>8.2f} | {now[0]:>7.2f} "
                    f"{now[1]:>6.2f} {now[2]:>6} | {before[0]:>7.2f} {before[1]:>6.2f} "
                    f"{before[2]:>6}  loaded {now[3]} / {before[3]}",
                    flush=True,
                )
    print(_load_average())
    return 0


if __name__ == "__main__":
    sys.exit(main())
