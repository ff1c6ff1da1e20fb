"""Start ``fsmbt serve`` as a real subprocess on a free loopback port, for the web tests and the
load benchmark (the same command a user runs; nothing mocked)."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import time
import urllib.request
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


@contextmanager
def running_server(*args: str, ready_seconds: float = 60.0) -> Iterator[str]:
    """``fsmbt serve --port N *args`` running; yields its base URL; stopped afterwards."""
    port = free_port()
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(REPO / "src"), env.get("PYTHONPATH", "")])
    process = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "fsmbt.cli",
            "serve",
            "--host",
            "127.0.0.1",
            "--port",
            str(port),
            *args,
        ],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    url = f"http://127.0.0.1:{port}"
    try:
        deadline = time.monotonic() + ready_seconds
        while True:
            if process.poll() is not None:
                raise RuntimeError(
                    f"fsmbt serve exited: {process.stderr.read() if process.stderr else ''}"
                )
            try:
                with urllib.request.urlopen(f"{url}/api/formats", timeout=2):
                    break
            except OSError:
                if time.monotonic() > deadline:
                    raise RuntimeError("fsmbt serve did not answer in time") from None
                time.sleep(0.2)
        yield url
    finally:
        stop_leaving_nothing(process)


def stop_leaving_nothing(process: subprocess.Popen[str], seconds: float = 15.0) -> list[int]:
    """SIGTERM ``process``, wait, then SIGKILL whatever of it and its descendants is still
    alive, so a test never leaves a worker behind. Returns the pids that had to be killed
    (the stop tests assert it is empty; fixtures just clean up)."""
    import psutil

    try:
        descendants = psutil.Process(process.pid).children(recursive=True)
    except psutil.NoSuchProcess:
        descendants = []
    process.terminate()
    try:
        process.wait(timeout=seconds)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()
    _, alive = psutil.wait_procs(descendants, timeout=1.0)
    for child in alive:
        try:
            child.kill()
        except psutil.NoSuchProcess:
            pass
    return [child.pid for child in alive]
