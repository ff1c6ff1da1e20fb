"""Certificates: the proof, the certificate's size, the check without search, and the memory of
each proof (issue 27, item 3 "verdicts that say what was proven"). Prints a table.

    .venv/bin/python benchmarks/bench_certificate.py [--sizes 100,1000,10000] [--small 30,100]
        [--memory 30,100,300] [--limit 120]
    .venv/bin/python benchmarks/bench_certificate.py --pernode 1000,10000

``--pernode SIZES``: only the per-node proofs (docs/semantics.md §4d), one row per
``bench_reactive`` family ``mixed``, ``memory``, ``reactive-plain``, ``decorated`` and size
(nodes, seed = size): ``plain s`` is ``verify`` without a certificate, ``prove s`` with one
(each distinct local check's tables numbered from the proof's own steps and kept), ``units`` the certificate's ``pernode`` units (one per distinct local
check) plus its ``region``/``skeleton`` units, ``check s`` the certificate's check, ``plain
MiB``/``peak MiB`` each run's peak resident memory (forked children).

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
from collections.abc import Callable
from functools import partial
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


def _pernode_row(family: str, size: int, with_certificate: bool) -> dict[str, object]:
    """One per-node proof of a ``bench_reactive`` family tree (seed = size), with or without a
    certificate (then also built, serialized and checked)."""
    source = family_tree(family, leaves_for(size), size)
    result = bt_to_hfsm(source).model
    row: dict[str, object] = {"size": node_count(source)}
    started = time.perf_counter()
    with certificate.collecting_if(with_certificate) as sink:
        report = verify(source, result)
    row["prove"], row["method"] = time.perf_counter() - started, report.method
    if not with_certificate:
        return row
    data = certificate.build(sink, report, source_digest="s", result_digest="r")
    text = json.dumps(data, separators=(",", ":"))
    sink.witness = sink.parts = None
    started = time.perf_counter()
    checked = certificate.check(
        json.loads(text), source, result, source_digest="s", result_digest="r"
    )
    row.update(
        equivalent=report.equivalent and checked.equivalent,
        units=", ".join(f"{n} {kind}" for kind, n in checked.units.items()),
        cert_kib=len(text) / 1024,
        check=time.perf_counter() - started,
    )
    return row


def _pernode_table(sizes: list[int], limit: int) -> None:
    header = (
        f"{'family':<15} {'nodes':>6} {'method':<24} {'plain s':>8} {'prove s':>8} "
        f"{'cert KiB':>9} {'check s':>8} {'plain MiB':>9} {'peak MiB':>9}  units"
    )
    print(header)
    print("-" * len(header))
    for family in ("mixed", "memory", "reactive-plain", "decorated"):
        for size in sizes:
            plain, plain_peak = _in_child(partial(_pernode_row, family, size, False), limit)
            row, peak = _in_child(partial(_pernode_row, family, size, True), limit)
            if plain is None or row is None or "error" in plain or "error" in row:
                said = (row or {}).get("error") or (plain or {}).get("error", "")
                print(f"{family:<15} {size:>6} {said}", flush=True)
                continue
            print(
                f"{family:<15} {row['size']:>6} {row['method']:<24} {plain['prove']:>8.2f} "
                f"{row['prove']:>8.2f} {row['cert_kib']:>9.0f} {row['check']:>8.2f} "
                f"{plain_peak:>9.0f} {peak:>9.0f}  {row['units']}"
                + ("" if row["equivalent"] else "  NOT EQUIVALENT"),
                flush=True,
            )


def _in_child(
    run: Callable[[], dict[str, object]], limit: int
) -> tuple[dict[str, object] | None, float]:
    """Run one row in a forked child; its result and its peak resident memory in MiB."""
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child
        os.close(read)
        signal.alarm(limit)
        try:
            payload = json.dumps(run()).encode()
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
    parser.add_argument("--pernode", default="", help="sizes: only the per-node proofs")
    args = parser.parse_args(argv)
    if args.pernode:
        _pernode_table([int(s) for s in args.pernode.split(",")], args.limit)
        return 0
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
        row, peak = _in_child(partial(_row, kind, int(size)), args.limit)
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
