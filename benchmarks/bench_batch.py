"""Throughput, scaling and memory of ``fsmbt batch`` (issue 14, item 6). Prints a table.

    nice -n 10 .venv/bin/python benchmarks/bench_batch.py [--n 10000] [--big 100000]
        [--workers 1,2] [--executors local,ray] [--big-workers 2] [--folder DIR]
    .venv/bin/python benchmarks/bench_batch.py --n 600 --repeat 3 [--executors local]

``--repeat R`` (issue 29, item 4) is the scaling measure: each configuration runs ``R`` times,
interleaved (1 worker, 2 workers, 1 worker, ...: a change in the machine's load hits both), and
each run is the whole ``fsmbt batch IN -o OUT -j W --quiet`` command, timed from its start to
its exit: the interpreter's start, the imports, the job list, the pool's start and the store's
close are all inside the figure. Every run is printed, then per configuration the median
models/s and the scaling (median of ``W`` workers over the median of the first worker count).
``--via library`` times ``make_jobs`` + ``run_jobs`` in a fresh interpreter instead.

The models: ``n`` generated models, half FSMs (2-30 states) and half BTs (depth 2-10, the
generator's default draw), from ``fsmbt.generate`` with seed 14, written as JSON (FSMs) and
BehaviorTree.CPP XML (BTs) into a folder (reused when it already holds them). Every
configuration runs the whole folder through ``make_jobs`` and ``run_jobs`` with the rules
engine and the native checker, into a fresh output folder with its own store, exactly as
``fsmbt batch IN -o OUT -j W [--executor ray]`` does.

Figures per configuration:
- ``models/s``: inputs over wall time (job creation, hashing and sniffing included; Ray's
  start included);
- ``scaling``: models/s over the same executor's 1-worker models/s;
- ``driver MB``: the driver's peak RSS (``ru_maxrss``);
- ``worker MB``: the largest peak RSS of one worker process (sampled every 0.2 s through
  psutil over the driver's descendants: pool workers, or Ray's workers and its raylet/GCS);
- ``all MB``: the peak of the driver plus all its descendants, sampled alike;
- ``store MB``: the SQLite store (with its WAL) at the end; ``statuses``: the row counts.
The ``--big`` run repeats this for ``big`` models with the local executor and ``--big-workers``.
The machine's core count and load are printed: figures on a shared machine are lower bounds.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from collections import Counter
from pathlib import Path

import psutil

from fsmbt import api
from fsmbt.batch import ResultStore, make_jobs, run_jobs
from fsmbt.generate import DatasetSpec, generate_models

MB = 1024 * 1024
#: Every this many results, a progress line goes to ``progress-<executor>-<workers>-<folder>.txt``
#: in the scratch folder (figures of a run that is stopped before its end).
PROGRESS_EVERY = 5000


def build_folder(folder: Path, n: int) -> None:
    """``n`` mixed models in ``folder`` (skipped when the folder already holds them)."""
    marker = folder / f".complete-{n}"
    if marker.exists():
        return
    if folder.exists():
        shutil.rmtree(folder)
    fsms = DatasetSpec("fsm", scenario="robot", seed=14, min_states=2, max_states=30)
    bts = DatasetSpec("bt", scenario="game", seed=14)
    half = n // 2
    for index, (stem, model) in enumerate(generate_models(fsms, n - half)):
        api.write(model, folder / "fsm" / f"{index // 1000:03d}" / f"{stem}.json", "json")
    for index, (stem, model) in enumerate(generate_models(bts, half)):
        api.write(model, folder / "bt" / f"{index // 1000:03d}" / f"{stem}.xml", "btcpp")
    marker.write_text("", encoding="utf-8")


class MemorySampler:
    """Peak RSS of the driver's descendants (one worker's peak, and the whole tree's)."""

    def __init__(self, interval: float = 0.2) -> None:
        self.interval = interval
        self.worker_peak = 0
        self.total_peak = 0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def _run(self) -> None:
        me = psutil.Process()
        while not self._stop.is_set():
            total = me.memory_info().rss
            for child in me.children(recursive=True):
                try:
                    rss = child.memory_info().rss
                except psutil.Error:
                    continue
                total += rss
                self.worker_peak = max(self.worker_peak, rss)
            self.total_peak = max(self.total_peak, total)
            self._stop.wait(self.interval)

    def __enter__(self) -> MemorySampler:
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._stop.set()
        self._thread.join()


def run_one(folder: Path, workers: int, executor: str, scratch: Path) -> dict[str, object]:
    """One configuration over the whole folder; its figures."""
    out = scratch / f"out-{executor}-{workers}"
    if out.exists():
        shutil.rmtree(out)
    started = time.perf_counter()
    progress_file = scratch / f"progress-{executor}-{workers}-{folder.name}.txt"
    with MemorySampler() as memory, progress_file.open("w", encoding="utf-8") as progress:
        jobs = make_jobs([folder], out)
        done = [0]

        def report(_result: object) -> None:
            done[0] += 1
            if done[0] % PROGRESS_EVERY == 0 or done[0] == len(jobs):
                elapsed = time.perf_counter() - started
                progress.write(
                    f"{done[0]} of {len(jobs)} in {elapsed:.1f} s: "
                    f"{done[0] / elapsed:.1f} models/s, driver "
                    f"{driver_peak_mb():.0f} MB, worker {memory.worker_peak / MB:.0f}"
                    f" MB, all {memory.total_peak / MB:.0f} MB\n"
                )
                progress.flush()

        with ResultStore(out) as store:
            run_jobs(
                jobs,
                store=store,
                executor=executor,
                workers=workers,
                collect=False,
                on_result=report,
            )
            statuses = Counter({k: v for k, v in store.summary()["statuses"].items() if v})
        store_bytes = ResultStore(out).size_bytes()
    seconds = time.perf_counter() - started
    shutil.rmtree(out, ignore_errors=True)
    return {
        "executor": executor,
        "workers": workers,
        "models": len(jobs),
        "seconds": seconds,
        "rate": len(jobs) / seconds,
        "driver_mb": driver_peak_mb(),
        "worker_mb": memory.worker_peak / MB,
        "all_mb": memory.total_peak / MB,
        "store_mb": store_bytes / MB,
        "statuses": dict(statuses),
    }


def driver_peak_mb() -> float:
    """This process's peak RSS so far (Linux reports ``ru_maxrss`` in KiB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def run_isolated(folder: Path, workers: int, executor: str, scratch: Path) -> dict[str, object]:
    """``run_one`` in a fresh interpreter, so each driver's peak RSS is its own."""
    command = [
        sys.executable,
        __file__,
        "--one",
        f"{executor}:{workers}",
        "--models",
        str(folder),
        "--folder",
        str(scratch),
    ]
    done = subprocess.run(command, check=True, capture_output=True, text=True)
    return json.loads(done.stdout.strip().splitlines()[-1])  # type: ignore[no-any-return]


def run_cli(folder: Path, workers: int, executor: str, scratch: Path) -> dict[str, object]:
    """The whole ``fsmbt batch`` command over ``folder`` (a fresh output folder), timed from
    the process's start to its exit; its figures (store read after the exit)."""
    out = scratch / f"out-cli-{executor}-{workers}"
    if out.exists():
        shutil.rmtree(out)
    command = [sys.executable, "-m", "fsmbt.cli", "batch", str(folder), "-o", str(out)]
    command += ["-j", str(workers), "--executor", executor, "--quiet"]
    started = time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True)
    seconds = time.perf_counter() - started
    if done.returncode not in (0, 1, 2) or not (out / "fsmbt-batch.sqlite").exists():
        raise SystemExit(f"fsmbt batch failed ({done.returncode}): {done.stderr[-2000:]}")
    with ResultStore(out) as store:
        summary = store.summary()
    shutil.rmtree(out, ignore_errors=True)
    if summary["pending"]:
        raise SystemExit(f"fsmbt batch left {summary['pending']} rows pending")
    models = sum(summary["statuses"].values())
    return {
        "executor": executor,
        "workers": workers,
        "models": models,
        "seconds": seconds,
        "rate": models / seconds,
        "statuses": {k: v for k, v in summary["statuses"].items() if v},
        "pending": summary["pending"],
    }


def load_average() -> str:
    return ", ".join(f"{x:.2f}" for x in os.getloadavg())


def repeated(args: argparse.Namespace, folder: Path, scratch: Path) -> None:
    """``--repeat``: every run printed, then the medians and the scaling (see the module text)."""
    counts = [int(w) for w in args.workers.split(",")]
    print(f"# load average before: {load_average()}", flush=True)
    print("| run | executor | workers | models | seconds | models/s | load (1 min) | statuses |")
    print("|---|---|---|---|---|---|---|---|", flush=True)
    rates: dict[tuple[str, int], list[float]] = {}
    for executor in args.executors.split(","):
        for run in range(1, args.repeat + 1):
            for workers in counts:
                if args.via == "cli":
                    row = run_cli(folder, workers, executor, scratch)
                else:
                    row = run_isolated(folder, workers, executor, scratch)
                rate = float(row["rate"])  # type: ignore[arg-type]
                rates.setdefault((executor, workers), []).append(rate)
                statuses = ", ".join(f"{k} {v}" for k, v in row["statuses"].items())  # type: ignore[attr-defined]
                print(
                    f"| {run} | {executor} | {workers} | {row['models']} | "
                    f"{row['seconds']:.2f} | {rate:.1f} | {os.getloadavg()[0]:.2f} | "
                    f"{statuses} |",
                    flush=True,
                )
    print(f"# load average after: {load_average()}", flush=True)
    print()
    print(f"| executor | workers | median models/s (of {args.repeat}) | scaling |")
    print("|---|---|---|---|")
    for executor in args.executors.split(","):
        base = statistics.median(rates[(executor, counts[0])])
        for workers in counts:
            median = statistics.median(rates[(executor, workers)])
            print(f"| {executor} | {workers} | {median:.1f} | {median / base:.2f} |", flush=True)


def print_row(row: dict[str, object], base: dict[str, float]) -> None:
    rate = float(row["rate"])  # type: ignore[arg-type]
    key = str(row["executor"])
    scaling = rate / base[key] if key in base else 1.0
    statuses = ", ".join(f"{k} {v}" for k, v in row["statuses"].items())  # type: ignore[attr-defined]
    print(
        f"| {row['executor']} | {row['workers']} | {row['models']} | {row['seconds']:.1f} | "
        f"{rate:.1f} | {scaling:.2f} | {row['driver_mb']:.0f} | {row['worker_mb']:.0f} | "
        f"{row['all_mb']:.0f} | {row['store_mb']:.1f} | {statuses} |",
        flush=True,
    )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=10_000)
    parser.add_argument("--big", type=int, default=100_000, help="0 skips the big run")
    parser.add_argument("--workers", default="1,2")
    parser.add_argument("--executors", default=None, help="default: local,ray (--repeat: local)")
    parser.add_argument("--big-workers", type=int, default=2)
    parser.add_argument(
        "--folder",
        type=Path,
        default=None,
        help="where the generated models are kept (default: a temp folder)",
    )
    parser.add_argument(
        "--repeat",
        type=int,
        default=0,
        help="the scaling measure: each configuration this many times, medians printed",
    )
    parser.add_argument(
        "--via",
        choices=("cli", "library"),
        default="cli",
        help="--repeat: time the whole fsmbt batch command (cli) or make_jobs + run_jobs",
    )
    parser.add_argument("--one", default=None, help=argparse.SUPPRESS)  # EXECUTOR:WORKERS
    parser.add_argument("--models", type=Path, default=None, help=argparse.SUPPRESS)
    args = parser.parse_args()
    scratch = args.folder or Path(tempfile.mkdtemp(prefix="fsmbt-bench-batch-"))
    if args.executors is None:
        args.executors = "local" if args.repeat else "local,ray"
    if args.one:
        executor, workers = args.one.split(":")
        print(json.dumps(run_one(args.models, int(workers), executor, scratch)))
        return 0
    print(
        f"# fsmbt batch benchmark: {os.cpu_count()} cores, load average "
        f"{', '.join(f'{x:.1f}' for x in os.getloadavg())}, python "
        f"{sys.version.split()[0]}",
        flush=True,
    )
    print(
        "# the cores are shared with other work: absolute figures are lower bounds, compare "
        "ratios of interleaved runs",
        flush=True,
    )
    started = time.perf_counter()
    build_folder(scratch / f"models-{args.n}", args.n)
    print(f"# generated {args.n} models in {time.perf_counter() - started:.1f} s", flush=True)
    if args.repeat:
        repeated(args, scratch / f"models-{args.n}", scratch)
        return 0
    print(
        "| executor | workers | models | seconds | models/s | scaling | driver MB | "
        "worker MB | all MB | store MB | statuses |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|", flush=True)
    base: dict[str, float] = {}
    for executor in args.executors.split(","):
        for workers in (int(w) for w in args.workers.split(",")):
            row = run_isolated(scratch / f"models-{args.n}", workers, executor, scratch)
            base.setdefault(executor, float(row["rate"]))  # type: ignore[arg-type]
            print_row(row, base)
    if args.big:
        started = time.perf_counter()
        build_folder(scratch / f"models-{args.big}", args.big)
        print(f"# generated {args.big} models in {time.perf_counter() - started:.1f} s", flush=True)
        row = run_isolated(scratch / f"models-{args.big}", args.big_workers, "local", scratch)
        print_row(row, {})
    print(
        f"# load average at the end: {', '.join(f'{x:.1f}' for x in os.getloadavg())}", flush=True
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
