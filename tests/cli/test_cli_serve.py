"""``fsmbt serve``: loopback by default, a warning elsewhere, refusals of bad options."""

from __future__ import annotations

import os
import signal
import subprocess
import sys

from fsmbt.cli.cmd_serve import is_loopback, requested_stop_exits_zero
from support.web_server import REPO, free_port, stop_leaving_nothing


def test_loopback_addresses():
    assert is_loopback("127.0.0.1") and is_loopback("localhost") and is_loopback("::1")
    assert not is_loopback("0.0.0.0") and not is_loopback("192.168.1.5")
    assert not is_loopback("example.org")


def _serve(*args: str) -> subprocess.Popen[str]:
    env = dict(os.environ, PYTHONPATH=str(REPO / "src"))
    return subprocess.Popen(
        [sys.executable, "-m", "fsmbt.cli", "serve", *args],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def test_a_non_loopback_address_prints_a_warning():
    process = _serve("--host", "0.0.0.0", "--port", str(free_port()))
    try:
        assert process.stderr is not None
        first = process.stderr.readline()  # printed before the server starts listening
    finally:
        # SIGTERM, then SIGKILL of the server and its workers if needed: a plain kill of the
        # server alone leaves workers holding its pipes, and reading them would never end
        stop_leaving_nothing(process, seconds=60.0)
    assert first.startswith("warning: listening on 0.0.0.0, not a loopback address")


def test_a_stop_requested_while_the_server_starts_is_obeyed():
    """SIGTERM right after the first line (uvicorn not yet listening) stops the server and its
    workers by themselves, exit 0, nothing left to kill."""
    process = _serve("--host", "127.0.0.1", "--port", str(free_port()), "--workers", "1")
    assert process.stderr is not None
    process.stderr.readline()
    process.send_signal(signal.SIGTERM)
    try:
        returncode = process.wait(timeout=60)
    finally:
        killed = stop_leaving_nothing(process, seconds=1.0)
    assert returncode == 0
    assert killed == []


def test_a_stop_noted_before_uvicorn_listens_still_stops_the_server():
    """The window the subprocess test rarely hits: our handler is installed, uvicorn's are not
    yet. The signal must still make the server exit (it used to be noted and ignored, and under
    load a server kept running after SIGTERM)."""
    import uvicorn

    server = uvicorn.Server(uvicorn.Config(app=None))
    with requested_stop_exits_zero(server):
        signal.raise_signal(signal.SIGTERM)
        assert server.should_exit


def test_loopback_has_no_warning_and_a_missing_reports_folder_is_refused():
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "fsmbt.cli",
            "serve",
            "--reports",
            "/nonexistent/reports",
            "--port",
            str(free_port()),
        ],
        env=dict(os.environ, PYTHONPATH=str(REPO / "src")),
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert done.returncode == 2
    assert "--reports /nonexistent/reports: not a folder" in done.stderr
    assert "Traceback" not in done.stderr
