"""Certificates: the proof, the certificate's size, the check without search, and the memory of
each proof (issue 27, item 3 "verdicts that say what was proven"). Prints a table.

    .venv/bin/python benchmarks/bench_certificate.py [--sizes 100,1000,10000] [--small 30,100]
        [--memory 30,100,300] [--limit 120]

Rows: BT ~ HFSM for the ``bench_reactive`` families ``plain``, ``reactive`` (static table),
``reactive-plain`` (canonical states; small sizes: their products explode, see
docs/verification.md) and ``memory`` (from 100 nodes proved compositionally: one certificate
unit per region plus the skeleton, ``units``), and FSM ~ LEBT for ``bench_checker.chain_fsm``. Each row runs in a
forked child (so ``peak MiB`` is that proof's own peak resident memory, from ``wait4``):
``prove s`` is ``verify`` (both machines explored and the product), ``cert KiB`` the JSON
certificate, ``check s`` ``fsmbt.verify.certificate.check`` on it (one machine step per
certified edge, no search), ``method`` the report's.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from bench_checker import chain_fsm  # noqa: E402
from bench_reactive import family_tree, leaves_for, node_count  # noqa: E402

from fsmbt.convert.bt_to_hfsm import bt_to_hfsm  # noqa: E402
from fsmbt.convert.lebt import fsm_to_lebt  # noqa: E402
from fsmbt.verify import certificate, verify  # noqa: E402


def _row(kind: str, size: int) -> dict[str, object]:
    if kind == "fsm~lebt":
        source = chain_fsm(size, size)
        result = fsm_to_lebt(source).model
        label = size
    else:
        source = family_tree(kind, leaves_for(size), size)
        label = node_count(source)
        result = bt_to_hfsm(source).model
    started = time.perf_counter()
    with certificate.collecting() as sink:
        report = verify(source, result)
    proved = time.perf_counter() - started
    data = certificate.build(sink, report, source_digest="s", result_digest="r")
    text = json.dumps(data, separators=(",", ":"))
    sink.witness = None
    started = time.perf_counter()
    checked = certificate.check(
        json.loads(text), source, result, source_digest="s", result_digest="r"
    )
    return {
        "size": label,
        "method": report.method,
        "equivalent": report.equivalent and checked.equivalent,
        "pairs": checked.pairs,
        "units": sum(checked.units.values()),
        "prove": proved,
        "cert_kib": len(text) / 1024,
        "check": time.perf_counter() - started,
    }


def _in_child(kind: str, size: int, limit: int) -> tuple[dict[str, object] | None, float]:
    """Run one row in a forked child; its result and its peak resident memory in MiB."""
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child
        os.close(read)
        signal.alarm(limit)
        try:
            payload = json.dumps(_row(kind, size)).encode()
        except BaseException as exc:  # reported by the parent as the row's outcome
            payload = json.dumps({"error": f"{type(exc).__name__}: {exc}"[:120]}).encode()
        os.write(write, payload)
        os._exit(0)
    os.close(write)
    chunks = []
    while chunk := os.read(read, 65536):
        chunks.append(chunk)
    os.close(read)
    _pid, status, usage = os.wait4(pid, 0)
    peak = usage.ru_maxrss / 1024
    if not chunks:
        return {
            "error": f"stopped after {limit} s" if os.WIFSIGNALED(status) else "no result"
        }, peak
    return json.loads(b"".join(chunks)), peak


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="100,1000,10000")
    parser.add_argument("--small", default="30,100", help="sizes for reactive-plain")
    parser.add_argument("--memory", default="30,100,300", help="sizes for memory")
    parser.add_argument("--limit", type=int, default=120, help="seconds per row")
    args = parser.parse_args(argv)
    header = (
        f"{'pair':<15} {'size':>6} {'method':<14} {'units':>5} {'pairs':>7} {'prove s':>8} "
        f"{'cert KiB':>9} {'check s':>8} {'peak MiB':>9}"
    )
    print(header)
    print("-" * len(header))
    plan = [(k, s) for k in ("plain", "reactive", "fsm~lebt") for s in args.sizes.split(",")]
    plan += [("reactive-plain", s) for s in args.small.split(",")]
    plan += [("memory", s) for s in args.memory.split(",")]
    for kind, size in plan:
        row, peak = _in_child(kind, int(size), args.limit)
        pair = kind if kind == "fsm~lebt" else f"bt~hfsm {kind}"
        if row is None or "error" in row:
            print(f"{pair:<15} {size:>6} {(row or {}).get('error', '')}", flush=True)
            continue
        print(
            f"{pair:<15} {row['size']:>6} {row['method']:<14} {row['units']:>5} {row['pairs']:>7} "
            f"{row['prove']:>8.3f} {row['cert_kib']:>9.0f} {row['check']:>8.3f} {peak:>9.0f}",
            flush=True,
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
