"""Load test of the web page's API on loopback (issue 16): many concurrent conversions.

    .venv/bin/python benchmarks/bench_web.py [--requests 200] [--concurrency 200]
        [--workers 2] [--deadline 600] [--url http://127.0.0.1:PORT] [--warm]
        [--distinct STATES]

Starts ``fsmbt serve`` as a subprocess on a free 127.0.0.1 port (unless ``--url`` names a
running one), then sends ``--requests`` ``POST /api/convert`` requests cycling over the example
models (JSON bodies), at most ``--concurrency`` at once, through one ``httpx.AsyncClient``. The
run is bounded: each request has a client timeout and the whole run ``--deadline`` seconds.
Prints the count, errors (any answer but 200 with a verdict, or a transport failure: must be
0), throughput and the latency percentiles (p50, p95, max) measured here, per request from send
to full answer, and the load average (the machine may be shared). ``--warm`` sends each example
once first (the server's answer cache is then warm, docs/web.md 'Cache'); ``--distinct 30``
sends a different generated 30-state FSM in every request instead. Exit 1 when any request
failed.
"""

from __future__ import annotations

import argparse
import asyncio
import os
import statistics
import sys
import time
from pathlib import Path

import httpx

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from support.web_server import REPO, running_server  # noqa: E402

#: The examples sent (each converted and verified by the server, both pictures drawn).
EXAMPLES = (
    "paper_fsm.xml",
    "robot_bt.xml",
    "door_hfsm.scxml",
    "game_npc_bt.xml",
    "turnstile.mmd",
    "guard_npc.csv",
    "paper_fsm.json",
)


def percentile(values: list[float], fraction: float) -> float:
    ordered = sorted(values)
    index = min(len(ordered) - 1, max(0, round(fraction * (len(ordered) - 1))))
    return ordered[index]


def example_bodies() -> list[dict[str, str]]:
    return [
        {"text": (REPO / "examples" / name).read_text(encoding="utf-8"), "filename": name}
        for name in EXAMPLES
    ]


def distinct_bodies(count: int, states: int) -> list[dict[str, str]]:
    """``count`` different generated ``states``-state FSMs (SCXML): no cache can help."""
    from fsmbt.formats import dumps
    from fsmbt.generate.generator import random_fsm

    return [
        {
            "text": dumps(
                random_fsm(seed=f"bench-web-{index}", n_states=states, max_states=states),
                "scxml",
            ),
            "filename": f"m{index}.scxml",
        }
        for index in range(count)
    ]


async def warm(url: str, bodies: list[dict[str, str]], timeout: float) -> None:
    """Send each body once (fills the server's answer cache)."""
    async with httpx.AsyncClient(base_url=url, timeout=timeout) as client:
        for body in bodies:
            await client.post("/api/convert", json=body)


async def load(
    url: str,
    requests: int,
    concurrency: int,
    deadline: float,
    timeout: float,
    bodies: list[dict[str, str]],
) -> dict[str, object]:
    latencies: list[float] = []
    errors: list[str] = []
    gate = asyncio.Semaphore(concurrency)
    limits = httpx.Limits(max_connections=concurrency, max_keepalive_connections=concurrency)
    async with httpx.AsyncClient(base_url=url, timeout=timeout, limits=limits) as client:

        async def one(index: int) -> None:
            body = bodies[index % len(bodies)]
            async with gate:
                started = time.perf_counter()
                try:
                    answer = await client.post("/api/convert", json=body)
                    ok = answer.status_code == 200 and "verdict" in answer.json()
                    if not ok:
                        errors.append(
                            f"{body['filename']}: {answer.status_code} {answer.text[:120]}"
                        )
                except httpx.HTTPError as exc:
                    errors.append(f"{body['filename']}: {type(exc).__name__}")
                latencies.append(time.perf_counter() - started)

        started = time.perf_counter()
        try:
            await asyncio.wait_for(asyncio.gather(*(one(i) for i in range(requests))), deadline)
        except TimeoutError:
            errors.append(f"the run passed its deadline of {deadline:g} s")
        elapsed = time.perf_counter() - started
    return {
        "requests": requests,
        "done": len(latencies),
        "errors": errors,
        "elapsed": elapsed,
        "latencies": latencies,
    }


def report(result: dict[str, object], concurrency: int) -> int:
    latencies = result["latencies"]
    errors = result["errors"]
    assert isinstance(latencies, list) and isinstance(errors, list)
    elapsed = float(result["elapsed"])  # type: ignore[arg-type]
    print(
        f"requests: {result['requests']} (concurrency {concurrency}), answered: "
        f"{result['done']}, errors: {len(errors)}"
    )
    if latencies:
        print(f"elapsed: {elapsed:.2f} s, throughput: {len(latencies) / elapsed:.1f} req/s")
        print(
            f"latency p50: {percentile(latencies, 0.5) * 1000:.0f} ms, "
            f"p95: {percentile(latencies, 0.95) * 1000:.0f} ms, "
            f"max: {max(latencies) * 1000:.0f} ms, mean: "
            f"{statistics.fmean(latencies) * 1000:.0f} ms"
        )
    for line in errors[:10]:
        print(f"  error: {line}")
    return 1 if errors else 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--requests", type=int, default=200)
    parser.add_argument("--concurrency", type=int, default=200)
    parser.add_argument("--workers", type=int, default=2, help="server worker processes")
    parser.add_argument("--deadline", type=float, default=600.0, help="seconds for the whole run")
    parser.add_argument("--timeout", type=float, default=300.0, help="seconds per request")
    parser.add_argument("--url", help="a running server instead of starting one")
    parser.add_argument(
        "--warm", action="store_true", help="send each example once before timing (cache warm)"
    )
    parser.add_argument(
        "--distinct",
        type=int,
        default=0,
        metavar="STATES",
        help="every request a different generated FSM of STATES states (no cache hit)",
    )
    parser.add_argument(
        "--no-cache", action="store_true", help="start the server with --cache-bytes 0 (before)"
    )
    args = parser.parse_args(argv)
    bodies = distinct_bodies(args.requests, args.distinct) if args.distinct else example_bodies()

    def run(url: str) -> int:
        if args.warm:
            asyncio.run(warm(url, bodies, args.timeout))
        result = asyncio.run(
            load(url, args.requests, args.concurrency, args.deadline, args.timeout, bodies)
        )
        load1, load5, _ = os.getloadavg()
        mode = f"distinct {args.distinct}-state models" if args.distinct else "examples"
        cache = "off" if args.no_cache else ("warm" if args.warm else "cold")
        print(f"mode: {mode}, cache {cache}")
        print(
            f"load average at the end: {load1:.2f} (1 min), {load5:.2f} (5 min), {os.cpu_count()} cores"
        )
        return report(result, args.concurrency)

    if args.url:
        return run(args.url)
    # the per-conversion limit stays the default; queued requests wait outside it
    extra = ("--cache-bytes", "0") if args.no_cache else ()
    with running_server("--workers", str(args.workers), *extra) as url:
        print(f"server: {url} ({args.workers} worker processes)")
        return run(url)


if __name__ == "__main__":
    sys.exit(main())
