"""Per-client admission (issue 29, item 3; ``fsmbt.web.admission``; docs/web.md 'Limits'): a
client over its rate gets 429 with ``Retry-After`` and the API's JSON error shape, never a 5xx
or a reset; another client is not affected; ``X-Forwarded-For`` names the client only through
a proxy the operator trusts; loopback is exempt by default (a burst of 200 from loopback is
admitted: tests/web/test_web_abuse.py)."""

from __future__ import annotations

import json
import socket
import urllib.error
import urllib.request
from urllib.parse import urlsplit

import pytest
from fastapi.testclient import TestClient

from fsmbt.web import WebSettings, create_app
from fsmbt.web.admission import ClientRateLimit, TokenBuckets, parse_networks
from support.web_server import REPO, running_server

PAPER = (REPO / "examples" / "paper_fsm.xml").read_text(encoding="utf-8")
BURST = 4
#: A token every 1000 s: nothing refills while a test runs, however slow the machine.
SLOW_RATE = "0.001"


class Clock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def test_a_bucket_admits_its_burst_then_says_when_the_next_token_comes():
    clock = Clock()
    buckets = TokenBuckets(rate=2.0, burst=3, clock=clock)
    assert [buckets.take("a") for _ in range(3)] == [0.0, 0.0, 0.0]
    assert buckets.take("a") == pytest.approx(0.5)  # one token every 0.5 s
    assert buckets.take("b") == 0.0  # another client: its own full bucket
    clock.now += 0.5
    assert buckets.take("a") == 0.0
    assert buckets.take("a") > 0.0
    clock.now += 60.0  # refilled, but never past the burst
    assert [buckets.take("a") for _ in range(4)][-1] > 0.0


def test_buckets_are_bounded_in_number():
    buckets = TokenBuckets(rate=1.0, burst=1, max_clients=50, clock=Clock())
    for index in range(500):
        buckets.take(f"10.0.{index // 250}.{index % 250}")
    assert len(buckets) == 50


def test_forwarded_for_is_believed_only_from_a_trusted_proxy():
    limit = ClientRateLimit(lambda *a: None, rate=1.0, burst=1, trusted=["127.0.0.1", "10.0.0.0/8"])
    header = [(b"x-forwarded-for", b"6.6.6.6, 203.0.113.9, 10.1.2.3")]
    # the rightmost address that is not a trusted proxy; what the client wrote left of it: no
    assert limit.client_of({"client": ("127.0.0.1", 5), "headers": header}) == "203.0.113.9"
    assert limit.client_of({"client": ("198.51.100.1", 5), "headers": header}) == "198.51.100.1"
    untrusting = ClientRateLimit(lambda *a: None, rate=1.0, burst=1)
    assert untrusting.client_of({"client": ("127.0.0.1", 5), "headers": header}) == "127.0.0.1"
    with pytest.raises(ValueError, match="'proxy.example' is not an IP address"):
        parse_networks(["127.0.0.1", "proxy.example"])


def _in_process(client_address: tuple[str, int], **changes: object) -> TestClient:
    settings = WebSettings.default(workers=1, rate_burst=BURST, rate_limit=0.001, **changes)
    return TestClient(create_app(settings), client=client_address)


def _is_429(status: int, headers: dict[str, str], raw: bytes) -> None:
    assert status == 429, (status, raw[:200])
    retry = {k.lower(): v for k, v in headers.items()}.get("retry-after")
    assert retry is not None and int(retry) >= 1
    body = json.loads(raw)
    assert set(body) == {"error", "where"} and "--rate-limit" in body["error"], body


def test_loopback_is_exempt_by_default_and_limited_when_asked():
    with _in_process(("127.0.0.1", 4000)) as client:
        assert {client.get("/api/formats").status_code for _ in range(3 * BURST)} == {200}
    with _in_process(("127.0.0.1", 4000), rate_limit_loopback=True) as client:
        statuses = [client.get("/api/formats").status_code for _ in range(BURST + 2)]
        assert statuses == [200] * BURST + [429, 429]
        # the page's own files take no token
        assert client.get("/static/app.js").status_code == 200


def test_a_remote_client_over_its_limit_gets_429_the_page_files_still_load():
    with _in_process(("198.51.100.7", 4000)) as client:
        statuses = [client.get("/api/formats").status_code for _ in range(BURST)]
        assert statuses == [200] * BURST
        answer = client.post("/api/inspect", json={"text": PAPER})
        _is_429(answer.status_code, dict(answer.headers), answer.content)
        assert answer.headers["x-content-type-options"] == "nosniff"  # the usual headers too


def _request(
    url: str, path: str, forwarded: str | None, body: bytes | None = None
) -> tuple[int, dict[str, str], bytes]:
    headers = {"content-type": "application/json"}
    if forwarded is not None:
        headers["x-forwarded-for"] = forwarded
    request = urllib.request.Request(
        f"{url}{path}", data=body, headers=headers, method="POST" if body else "GET"
    )
    try:
        with urllib.request.urlopen(request, timeout=120) as answer:
            return answer.status, dict(answer.headers), answer.read()
    except urllib.error.HTTPError as error:
        return error.code, dict(error.headers), error.read()


def test_a_real_server_behind_a_trusted_proxy_limits_each_client_alone():
    body = json.dumps({"text": PAPER}).encode()
    with running_server(
        "--workers", "1", "--rate-limit", SLOW_RATE, "--rate-burst", str(BURST),
        "--trusted-proxy", "127.0.0.1",
    ) as url:  # fmt: skip
        first = [_request(url, "/api/inspect", "203.0.113.7", body) for _ in range(BURST + 3)]
        statuses = [status for status, _, _ in first]
        assert statuses == [200] * BURST + [429] * 3
        for status, headers, raw in first[BURST:]:
            _is_429(status, headers, raw)
        # another client behind the same proxy: unaffected
        other = [_request(url, "/api/inspect", "203.0.113.8", body)[0] for _ in range(BURST)]
        assert other == [200] * BURST
        # the proxy itself (loopback, no header) is exempt
        assert _request(url, "/api/formats", None)[0] == 200
        # a refused POST with a body is answered on a connection that stays usable (no reset)
        parts = urlsplit(url)
        payload = b'{"text": "' + b"x" * 60_000 + b'"}'
        head = (
            "POST /api/inspect HTTP/1.1\r\nHost: t\r\nContent-Type: application/json\r\n"
            f"X-Forwarded-For: 203.0.113.7\r\nContent-Length: {len(payload)}\r\n\r\n"
        ).encode()
        with socket.create_connection((parts.hostname, parts.port), timeout=60) as sock:
            for _ in range(2):  # twice on one connection
                sock.sendall(head + payload)
                answer = _read_answer(sock)
                assert answer.startswith(b"HTTP/1.1 429"), answer[:200]
                assert b"connection: close" not in answer.lower()


def _read_answer(sock: socket.socket) -> bytes:
    received = b""
    while True:
        chunk = sock.recv(65536)
        assert chunk, "the connection was closed or reset"
        received += chunk
        end = received.find(b"\r\n\r\n")
        if end >= 0:
            length = next(
                int(line.split(b":", 1)[1])
                for line in received[:end].split(b"\r\n")
                if line.lower().startswith(b"content-length:")
            )
            if len(received) >= end + 4 + length:
                return received


def test_without_a_trusted_proxy_the_header_chooses_no_bucket():
    with running_server(
        "--workers", "1", "--rate-limit", SLOW_RATE, "--rate-burst", str(BURST),
        "--rate-limit-loopback",
    ) as url:  # fmt: skip
        # a new X-Forwarded-For each time: still one client, 127.0.0.1 (whose bucket the
        # fixture's readiness probe has already taken a token from)
        statuses = [
            _request(url, "/api/formats", f"192.0.2.{index}")[0] for index in range(BURST + 2)
        ]
        admitted = statuses.count(200)
        assert 1 <= admitted <= BURST and statuses == [200] * admitted + [429] * (
            BURST + 2 - admitted
        )
