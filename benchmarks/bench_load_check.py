"""Where the whole ``fsmbt convert`` of a large tree spends its time, and what the SCXML load
check costs in its child process (issue 27: a 15 000-node ``mixed`` convert < 30 s on 2 cores).

    .venv/bin/python benchmarks/bench_load_check.py [--families mixed,memory] [--sizes 15000]
        [--limit 120] [--profile]

Per tree (``bench_reactive.family_tree``, the trees of ``bench_reactive.py --convert``), one row:
the parent's stages, each timed alone in this process - ``read`` (the BT XML), ``convert``
(``convert_model``), ``dumps`` (the SCXML text), ``verify`` (the proof) - then the load check as
``convert`` runs it beside the proof: the child process of
``semantics.engines.load_beside`` (``python -m fsmbt.semantics.engines.scxml_load FILE``), its
wall seconds (with a small launcher's start, about 0.05 s), CPU seconds (user + system) and
peak resident memory (the child's own, ``getrusage`` in the launcher); and the
same child's work with Python's cyclic garbage collector left on (``gc on``: the check as it
ran before the collector was turned off in the child), so both are measured back to back under
the same load. Before the table, the child's start (Python, its imports, a 3-state chart) on
its own. ``--profile``: after each row, cProfile's cumulative seconds of the engine's phases in
this process, collector off as in the child (its parse: ``SCXMLReader.read``; its class
creation: ``create_machine_class_from_definition``; one instance: ``StateChart.__init__``; the
profiler's own cost inflates all three alike). ``uptime``'s load average is printed before and
after: on a shared machine every wall time grows with it, CPU seconds much less.
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
from bench_reactive import node_count, written_trees  # noqa: E402

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


#: Runs the child and reports its resources: a small process starts it, so the child's peak
#: memory is its own (a child forked from this large process would count this one's pages: on
#: Linux the peak survives ``exec``). Its first argument is the time limit: past it the child
#: is killed by the launcher (``subprocess.run``), so none is left behind.
LAUNCHER = (
    "import json, resource, subprocess, sys; "
    "subprocess.run(sys.argv[2:], stderr=subprocess.DEVNULL, timeout=float(sys.argv[1])); "
    "u = resource.getrusage(resource.RUSAGE_CHILDREN); "
    "sys.stderr.write(json.dumps([u.ru_utime + u.ru_stime, u.ru_maxrss]))"
)


def _child(arguments: tuple[str, ...], file: str, limit: int) -> tuple[float, float, int, str]:
    """Wall seconds, CPU seconds (user + system) and peak resident MB of one child run (its
    ``getrusage``, through ``LAUNCHER``), and whether it says the chart loaded."""
    started = time.perf_counter()
    command = [sys.executable, "-c", LAUNCHER, str(limit), sys.executable, *arguments, file]
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    wall = time.perf_counter() - started
    if wall >= limit or done.returncode != 0:
        return wall, 0.0, 0, f"over {limit} s or failed ({done.returncode})"
    cpu, peak_kb = json.loads(done.stderr.strip().splitlines()[-1])
    lines = done.stdout.strip().splitlines()
    try:  # the check's JSON answer, or the gc-on script's printed ``loaded``
        answer = json.loads(lines[-1]) if lines else None
    except json.JSONDecodeError:
        answer = None
    last = str(answer.get("loaded")) if isinstance(answer, dict) else str(answer)
    return wall, float(cpu), int(peak_kb) // 1024, last


#: A 3-state chart: what the child's start costs without a document to speak of.
TINY_SCXML = (
    '<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0" initial="a">'
    '<state id="a"><transition event="e" target="b"/></state><state id="b"/><final id="c"/>'
    "</scxml>"
)
#: The engine's phases reported by ``--profile`` (cProfile's ``file:line(function)`` suffixes).
PHASES = {
    "parse": "reader.py:495(read)",
    "class": "(create_machine_class_from_definition)",
    "instance": "statemachine.py:142(__init__)",
}


def _profile(text: str) -> str:
    """cProfile's cumulative seconds of the engine's phases on ``text`` (collector off)."""
    import cProfile
    import gc
    import pstats

    from fsmbt.semantics.engines.scxml_load import check_scxml_loads

    profiler = cProfile.Profile()
    gc.disable()
    try:
        profiler.runcall(check_scxml_loads, text)
    finally:
        gc.enable()
        gc.collect()  # the chart's cycles, freed here rather than in the next row's ``read``
    stats = pstats.Stats(profiler).stats
    found = dict.fromkeys(PHASES, 0.0)
    for (file, line, function), (_cc, _nc, _tt, cumulative, _callers) in stats.items():
        where = f"{Path(file).name}:{line}({function})"
        for phase, suffix in PHASES.items():
            if where.endswith(suffix):
                found[phase] = max(found[phase], cumulative)
    return ", ".join(f"{phase} {seconds:.2f} s" for phase, seconds in found.items())


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--families", default="mixed,memory")
    parser.add_argument("--sizes", default="15000")
    parser.add_argument("--limit", type=int, default=120, help="seconds per child")
    parser.add_argument("--profile", action="store_true", help="the engine's phases (cProfile)")
    args = parser.parse_args()
    print(_load_average())
    with tempfile.TemporaryDirectory() as folder:
        tiny = Path(folder) / "tiny.scxml"
        tiny.write_text(TINY_SCXML, encoding="utf-8")
        start = _child(CHILD_COMMAND, str(tiny), args.limit)
        print(
            f"child start (3-state chart): {start[0]:.2f} s wall, {start[1]:.2f} s CPU, loaded {start[3]}"
        )
    header = (
        f"{'family':<8} {'nodes':>6} {'read s':>7} {'conv s':>7} {'dumps s':>8} {'MB':>5} "
        f"{'verify s':>8} | {'child s':>7} {'cpu s':>6} {'RSS MB':>6} | {'gc on s':>7} "
        f"{'cpu s':>6} {'RSS MB':>6}  answer"
    )
    with tempfile.TemporaryDirectory() as folder:
        for family, size, doc, tree in written_trees(args, header, Path(folder)):
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
            if args.profile:
                print(f"  profile ({family} {node_count(doc)}): {_profile(text)}", flush=True)
    print(_load_average())
    return 0


if __name__ == "__main__":
    sys.exit(main())
