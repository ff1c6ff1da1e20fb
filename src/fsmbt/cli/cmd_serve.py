"""``fsmbt serve``: the web page (docs/web.md) on http://HOST:PORT, loopback by default.

Runs ``fsmbt.web.create_app`` under uvicorn. Bound to anything but a loopback address, it
prints a warning first: the page converts whatever anyone who can reach it sends (within the
limits), and it has no login. ``--reports DIR`` lets the page browse the evaluation reports
and batch stores under DIR, read-only. Exit 2 on a bad option (missing folder, busy port).
"""

from __future__ import annotations

import ipaddress
import sys
from pathlib import Path

import typer

from fsmbt.web.settings import DEFAULT_MAX_BODY_BYTES, DEFAULT_TIMEOUT_S, DEFAULT_WORKERS


def is_loopback(host: str) -> bool:
    """Whether ``host`` only listens on this machine (``localhost``, ``127.x``, ``::1``)."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def register(app: typer.Typer) -> None:
    @app.command("serve")
    def serve_command(
        host: str = typer.Option("127.0.0.1", "--host", help="address to listen on"),
        port: int = typer.Option(8000, "--port", min=0, max=65535, help="port to listen on"),
        reports: Path | None = typer.Option(
            None,
            "--reports",
            help="browse evaluation reports and batch stores under this folder (read-only)",
        ),
        examples: Path | None = typer.Option(
            None,
            "--examples",
            help="offer the model files of this folder as "
            "examples (default: the checkout's examples/)",
        ),
        max_body: int = typer.Option(
            DEFAULT_MAX_BODY_BYTES, "--max-body", min=1024, help="largest request body, bytes"
        ),
        timeout: float = typer.Option(
            DEFAULT_TIMEOUT_S,
            "--timeout",
            min=0.1,
            help="seconds one conversion or verification may take",
        ),
        workers: int = typer.Option(
            DEFAULT_WORKERS, "--workers", min=1, max=64, help="worker processes for conversions"
        ),
    ) -> None:
        """Serve the web page: convert, compare both pictures, step through a counterexample."""
        import uvicorn

        from fsmbt.cli import fail
        from fsmbt.web import WebSettings, create_app

        for name, folder in (("--reports", reports), ("--examples", examples)):
            if folder is not None and not folder.is_dir():
                raise fail(f"{name} {folder}: not a folder")
        changes: dict[str, object] = {
            "max_body_bytes": max_body,
            "timeout_s": timeout,
            "workers": workers,
            "reports_dir": reports,
        }
        if examples is not None:
            changes["examples_dir"] = examples
        settings = WebSettings.default(**changes)
        if not is_loopback(host):
            print(
                f"warning: listening on {host}, not a loopback address: anyone who can reach "
                "this machine can use the page (there is no login); use --host 127.0.0.1 "
                "to keep it local",
                file=sys.stderr,
            )
        print(
            f"fsmbt web page on http://{host}:{port}/  (API documentation: /docs)", file=sys.stderr
        )
        try:
            uvicorn.run(create_app(settings), host=host, port=port, log_level="warning")
        except OSError as exc:
            raise fail(f"cannot listen on {host}:{port}: {exc.strerror or exc}") from None
