"""HTTP fuzzing of the published API (issue 29, item 3): schemathesis generates requests from
the OpenAPI schema a real ``fsmbt serve`` publishes (``/openapi.json``) and checks that no answer
is a 5xx and every answer matches the schema. Loopback only, bounded in count (``--max-examples``
per operation) and time (the subprocess timeout), seeded so a failure replays."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from support.web_server import running_server

SCHEMATHESIS = Path(sys.executable).parent / "schemathesis"


def test_no_server_error_and_no_schema_violation():
    with running_server("--workers", "2", "--timeout", "20") as url:
        assert url.startswith("http://127.0.0.1:")
        done = subprocess.run(
            [
                str(SCHEMATHESIS),
                "run",
                f"{url}/openapi.json",
                "--checks",
                "not_a_server_error,response_schema_conformance",
                "--max-examples",
                "8",
                "--seed",
                "29",
                "--no-color",
            ],
            capture_output=True,
            text=True,
            timeout=240,
            check=False,
        )
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-2000:]
    assert " passed" in done.stdout and "failed" not in done.stdout.split("SUMMARY")[-1]
