"""fsmbt's BT -> HFSM against boschresearch/bt_tools' ``Bt2FSM`` on the same trees (issue 19).

    .venv/bin/python benchmarks/bench_bt_tools.py [--sizes 100,1000,10000]
        [--bt-tools-python /tmp/bttools-venv/bin/python]

bt_tools is not on PyPI and nothing of it is vendored: fetch the repository, install its
``btlib`` into a separate venv (``python -m venv /tmp/bttools-venv;
/tmp/bttools-venv/bin/pip install <checkout>/btlib networkx``) and pass that interpreter. Without
it the bt_tools column is skipped with a printed note. Trees: ``bench_checker.random_tree`` (plain
Sequence/Fallback, bt_tools' memoryless reading), written as BehaviorTree.CPP XML; bt_tools
runs in its own process (``xml_to_networkx`` + ``Bt2FSM.convert``, timed there, reading the file
excluded); fsmbt's time is ``bt_to_hfsm`` on the read document. Prints figures only.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from bench_checker import random_tree  # noqa: E402
from bench_reactive import leaves_for, node_count  # noqa: E402

from fsmbt import api  # noqa: E402
from fsmbt.convert.bt_to_hfsm import bt_to_hfsm  # noqa: E402

PEER = """
import sys, time
from btlib.bts import xml_to_networkx
from btlib.bt_to_fsm.bt_to_fsm import Bt2FSM
graph = xml_to_networkx(sys.argv[1])
graph = graph[0] if isinstance(graph, tuple) else graph
started = time.perf_counter()
fsm = Bt2FSM(graph).convert()
print(time.perf_counter() - started, fsm.number_of_nodes())
"""


def peer_seconds(python: str, path: Path, timeout: float) -> str:
    try:
        proc = subprocess.run(
            [python, "-c", PEER, str(path)],
            capture_output=True,
            text=True,
            errors="replace",
            timeout=timeout,
        )
    except subprocess.TimeoutExpired:
        return f">{timeout:.0f}s"
    if proc.returncode != 0:
        return "failed: " + (proc.stderr.strip().splitlines() or ["?"])[-1][:60]
    seconds, states = proc.stdout.split()
    return f"{float(seconds):.3f} ({states} st)"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="100,1000,10000")
    parser.add_argument("--bt-tools-python", default="/tmp/bttools-venv/bin/python")
    parser.add_argument("--timeout", type=float, default=300.0)
    args = parser.parse_args(argv)
    have_peer = Path(args.bt_tools_python).exists()
    if not have_peer:
        print(
            f"note: {args.bt_tools_python} not found: the bt_tools column is skipped "
            "(see the module docstring for the install steps)"
        )
    print(f"{'nodes':>6} {'fsmbt s':>9} {'fsmbt st':>8}  bt_tools s")
    with tempfile.TemporaryDirectory(prefix="fsmbt-bttools-") as tmp:
        for size in (int(s) for s in args.sizes.split(",")):
            doc = random_tree(leaves_for(size), size)
            path = api.write(doc, Path(tmp) / f"tree{size}.xml", "btcpp")
            loaded = api.load(path).model
            started = time.perf_counter()
            result = bt_to_hfsm(loaded)
            ours = time.perf_counter() - started
            states = len(result.model.states)
            peer = peer_seconds(args.bt_tools_python, path, args.timeout) if have_peer else "-"
            print(f"{node_count(doc):>6} {ours:>9.3f} {states:>8}  {peer}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
