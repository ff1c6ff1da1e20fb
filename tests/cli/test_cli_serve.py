"""``fsmbt serve``: loopback by default, a warning elsewhere, refusals of bad options."""

from __future__ import annotations

import os
import subprocess
import sys

from fsmbt.cli.cmd_serve import is_loopback
from support.web_server import REPO, free_port


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
        process.terminate()
        try:
            process.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            process.kill()  # never leave a server behind; the test still fails
            process.communicate()
            raise
    assert first.startswith("warning: listening on 0.0.0.0, not a loopback address")


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
