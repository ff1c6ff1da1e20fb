"""``fsmbt serve``: the web page (docs/web.md) on http://HOST:PORT, loopback by default.

Runs ``fsmbt.web.create_app`` under uvicorn. Bound to anything but a loopback address, it
prints a warning first: the page converts whatever anyone who can reach it sends (within the
limits), and it has no login. ``--reports DIR`` lets the page browse the evaluation reports
and batch stores under DIR, read-only. Exit 2 on a bad option (missing folder, busy port).
"""

from __future__ import annotations

import ipaddress
import signal
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from fsmbt.web.admission import parse_networks
from fsmbt.web.answers import DEFAULT_CACHE_BYTES
from fsmbt.web.settings import (
    DEFAULT_CPU_LIMIT_S,
    DEFAULT_MAX_BODY_BYTES,
    DEFAULT_MAX_WAITING,
    DEFAULT_RATE_BURST,
    DEFAULT_RATE_LIMIT,
    DEFAULT_TIMEOUT_S,
    DEFAULT_WORKERS,
)

if TYPE_CHECKING:
    import uvicorn


def is_loopback(host: str) -> bool:
    """Whether ``host`` only listens on this machine (``localhost``, ``127.x``, ``::1``)."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


#: Seconds in-flight requests get to finish after SIGTERM / SIGINT before they are cancelled;
#: the workers then get the rest of the 5 s stop budget (``Workers.close``).
GRACE_S = 2


@contextmanager
def requested_stop_exits_zero(server: uvicorn.Server) -> Iterator[None]:
    """While the server runs, SIGTERM and SIGINT are a requested stop: uvicorn stops accepting,
    lets in-flight requests finish (``GRACE_S``), the app's shutdown stops the workers, and
    uvicorn re-raises the signal into the handlers found here, which note it, so the
    command returns normally and exits 0 (docs/web.md, 'Stopping').

    A signal that arrives before uvicorn has installed its own handlers (while it still starts
    up) lands here too; it also sets ``server.should_exit``, so uvicorn finishes starting, stops
    at once and the workers are stopped. Only noting it would leave a server running that its
    supervisor believes stopped (seen under load: a SIGTERM right after start was ignored)."""
    stopped: list[int] = []

    def note_and_stop(number: int, _frame: object) -> None:
        stopped.append(number)
        server.should_exit = True

    previous = {sig: signal.signal(sig, note_and_stop) for sig in (signal.SIGTERM, signal.SIGINT)}
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        if stopped:
            print("fsmbt serve: stopped", file=sys.stderr)


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
            help="wall seconds one conversion or verification may take (408 past it)",
        ),
        cpu_limit: float = typer.Option(
            DEFAULT_CPU_LIMIT_S,
            "--cpu-limit",
            min=1.0,
            help="CPU seconds one conversion or verification may use (422 past it)",
        ),
        cache_bytes: int = typer.Option(
            DEFAULT_CACHE_BYTES,
            "--cache-bytes",
            min=0,
            help="memory bound of the answer cache, bytes (0: no cache)",
        ),
        cache_dir: Path | None = typer.Option(
            None, "--cache-dir", help="also keep cached answers in this folder"
        ),
        max_waiting: int = typer.Option(
            DEFAULT_MAX_WAITING,
            "--max-waiting",
            min=1,
            help="requests that may wait for a worker (503 with Retry-After beyond)",
        ),
        workers: int = typer.Option(
            DEFAULT_WORKERS, "--workers", min=1, max=64, help="worker processes for conversions"
        ),
        rate_limit: float = typer.Option(
            DEFAULT_RATE_LIMIT,
            "--rate-limit",
            min=0.0,
            envvar="FSMBT_RATE_LIMIT",
            help="requests a second each client may sustain (429 with Retry-After past it; "
            "0: no per-client limit; loopback clients exempt unless --rate-limit-loopback)",
        ),
        rate_burst: int = typer.Option(
            DEFAULT_RATE_BURST,
            "--rate-burst",
            min=1,
            envvar="FSMBT_RATE_BURST",
            help="requests a client may send at once before --rate-limit applies",
        ),
        rate_limit_loopback: bool = typer.Option(
            False,
            "--rate-limit-loopback",
            envvar="FSMBT_RATE_LIMIT_LOOPBACK",
            help="limit loopback clients too (exempt by default)",
        ),
        trusted_proxy: list[str] = typer.Option(
            [],
            "--trusted-proxy",
            envvar="FSMBT_TRUSTED_PROXIES",
            help="address or network of a reverse proxy whose X-Forwarded-For names the "
            "client (repeatable; without it the header is ignored)",
        ),
    ) -> None:
        """Serve the web page: convert, compare both pictures, step through a counterexample."""
        import uvicorn

        from fsmbt.cli import fail
        from fsmbt.web import WebSettings, create_app

        for name, folder in (("--reports", reports), ("--examples", examples)):
            if folder is not None and not folder.is_dir():
                raise fail(f"{name} {folder}: not a folder")
        try:
            parse_networks(trusted_proxy)
        except ValueError as exc:
            raise fail(f"--trusted-proxy: {exc}") from None
        changes: dict[str, object] = {
            "max_body_bytes": max_body,
            "timeout_s": timeout,
            "cpu_limit_s": cpu_limit,
            "max_waiting": max_waiting,
            "cache_bytes": cache_bytes,
            "cache_dir": cache_dir,
            "workers": workers,
            "reports_dir": reports,
            "rate_limit": rate_limit,
            "rate_burst": rate_burst,
            "rate_limit_loopback": rate_limit_loopback,
            "trusted_proxies": tuple(trusted_proxy),
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
        server = uvicorn.Server(
            uvicorn.Config(
                create_app(settings),
                host=host,
                port=port,
                log_level="warning",
                timeout_graceful_shutdown=GRACE_S,
                # X-Forwarded-For is read by fsmbt.web.admission, and only from the proxies
                # named with --trusted-proxy; uvicorn's own handling would believe it from
                # any loopback peer
                proxy_headers=False,
            )
        )
        try:
            with requested_stop_exits_zero(server):
                server.run()
        except OSError as exc:
            raise fail(f"cannot listen on {host}:{port}: {exc.strerror or exc}") from None
        except SystemExit:  # uvicorn's own exit when the port cannot be bound
            raise fail(f"cannot listen on {host}:{port} (address in use or not allowed)") from None
