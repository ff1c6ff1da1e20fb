"""A smaller run of the load benchmark (benchmarks/bench_web.py) in CI: concurrent conversions
of the examples on loopback, bounded in count and time, and none may fail."""

from __future__ import annotations

import subprocess
import sys

from support.web_server import REPO


def test_concurrent_conversions_all_succeed():
    done = subprocess.run(
        [
            sys.executable,
            str(REPO / "benchmarks" / "bench_web.py"),
            "--requests",
            "30",
            "--concurrency",
            "30",
            "--deadline",
            "240",
            "--timeout",
            "240",
        ],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "answered: 30, errors: 0" in done.stdout
    assert "latency p50:" in done.stdout
