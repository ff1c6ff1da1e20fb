"""Honest answers to abuse against a real ``fsmbt serve`` (issue 29, item 3; docs/web.md,
'Limits'): an over-limit body gets a 413 with the API's JSON error whether or not the client
sends ``Expect: 100-continue`` (never a reset); a burst of 200 concurrent requests is admitted
and answered; past the admission limit a request gets 503 with ``Retry-After``."""

from __future__ import annotations

import json
import socket
import urllib.error
import urllib.request
from concurrent.futures import ThreadPoolExecutor
from urllib.parse import urlsplit

import pytest

from support.web_server import REPO, running_server

PAPER = (REPO / "examples" / "paper_fsm.xml").read_text(encoding="utf-8")
LIMIT = 64 * 1024


@pytest.fixture(scope="module")
def server_url():
    with running_server("--workers", "2", "--max-body", str(LIMIT)) as url:
        yield url


def _post(url: str, body: bytes, timeout: float = 120.0) -> tuple[int, dict[str, str], bytes]:
    request = urllib.request.Request(
        url, data=body, headers={"content-type": "application/json"}, method="POST"
    )
    try:
        with urllib.request.urlopen(request, timeout=timeout) as answer:
            return answer.status, dict(answer.headers), answer.read()
    except urllib.error.HTTPError as error:
        return error.code, dict(error.headers), error.read()


def _is_error_json(raw: bytes, *words: str) -> None:
    body = json.loads(raw)
    assert set(body) == {"error", "where"}, body
    for word in words:
        assert word in body["error"], body


def test_urllib_without_expect_gets_a_json_413_not_a_reset(server_url):
    # 8 MiB from a client that sends everything and never asks 'Expect: 100-continue'
    status, _, raw = _post(f"{server_url}/api/convert", b"x" * (8 * 1024 * 1024))
    assert status == 413
    _is_error_json(raw, "larger than", str(LIMIT))
    # the server still answers on a fresh request
    status, _, raw = _post(f"{server_url}/api/inspect", json.dumps({"text": PAPER}).encode())
    assert status == 200 and json.loads(raw)["kind"] == "fsm"


def _raw_exchange(url: str, head: str, body: bytes | None) -> bytes:
    parts = urlsplit(url)
    with socket.create_connection((parts.hostname, parts.port), timeout=60) as sock:
        sock.sendall(head.encode())
        if body is not None:
            sock.sendall(body)
        received = b""
        while True:
            chunk = sock.recv(65536)
            if not chunk:
                break
            received += chunk
            header_end = received.find(b"\r\n\r\n")
            if header_end >= 0:
                length = next(
                    (
                        int(line.split(b":", 1)[1])
                        for line in received[:header_end].split(b"\r\n")
                        if line.lower().startswith(b"content-length:")
                    ),
                    None,
                )
                if length is not None and len(received) >= header_end + 4 + length:
                    break
        return received


def test_raw_socket_without_expect_gets_413_json_on_a_kept_connection(server_url):
    size = 4 * 1024 * 1024
    head = (
        "POST /api/convert HTTP/1.1\r\nHost: t\r\nContent-Type: application/json\r\n"
        f"Content-Length: {size}\r\n\r\n"
    )
    answer = _raw_exchange(server_url, head, b"y" * size)
    status_line, _, rest = answer.partition(b"\r\n")
    assert status_line.startswith(b"HTTP/1.1 413"), answer[:200]
    headers, _, body = rest.partition(b"\r\n\r\n")
    assert b"connection: close" not in headers.lower()  # drained: the connection stays usable
    _is_error_json(body, "larger than")


def test_expect_100_continue_gets_the_413_before_any_body_is_sent(server_url):
    head = (
        "POST /api/convert HTTP/1.1\r\nHost: t\r\nContent-Type: application/json\r\n"
        f"Content-Length: {64 * 1024 * 1024}\r\nExpect: 100-continue\r\n\r\n"
    )
    answer = _raw_exchange(server_url, head, None)  # not one byte of the body
    assert answer.startswith(b"HTTP/1.1 413"), answer[:200]
    assert b"100 Continue" not in answer
    _is_error_json(answer.partition(b"\r\n\r\n")[2], "larger than")


def test_a_burst_of_200_concurrent_requests_all_succeed(server_url):
    body = json.dumps({"text": PAPER}).encode()
    with ThreadPoolExecutor(max_workers=200) as pool:
        answers = list(
            pool.map(lambda _: _post(f"{server_url}/api/inspect", body, 240), range(200))
        )
    statuses = [status for status, _, _ in answers]
    assert statuses == [200] * 200, sorted(set(statuses))


def test_past_the_admission_limit_503_with_retry_after():
    from fsmbt.formats import dumps
    from fsmbt.generate.generator import random_fsm

    big = dumps(random_fsm(seed="web-busy", n_states=3000, max_states=3000), "scxml")
    body = json.dumps({"text": big}).encode()
    with running_server(
        "--workers", "1", "--max-waiting", "1", "--max-body", str(8 * 1024 * 1024)
    ) as url:
        with ThreadPoolExecutor(max_workers=6) as pool:
            answers = list(pool.map(lambda _: _post(f"{url}/api/convert", body, 240), range(6)))
    busy = [(headers, raw) for status, headers, raw in answers if status == 503]
    assert busy, [status for status, _, _ in answers]
    assert all(status in (200, 503) for status, _, _ in answers)
    for headers, raw in busy:
        retry = {k.lower(): v for k, v in headers.items()}.get("retry-after")
        assert retry is not None and int(retry) > 0
        _is_error_json(raw, "busy", "--max-waiting")
