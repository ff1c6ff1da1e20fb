"""Per-client admission: a token bucket per client address (issue 29, item 3; docs/web.md,
'Limits' and 'Behind a reverse proxy').

Why: the worker queue (``fsmbt.web.workers``, ``--max-waiting``) protects the server as a
whole; one client sending without pause could still fill it and make every other client wait
or get 503. So each client address has a bucket of ``burst`` tokens refilled at ``rate`` tokens
a second; a request takes one token, and a client whose bucket is empty gets ``429`` with
``Retry-After`` (whole seconds until its next token) and the API's JSON error shape, at once,
before any work - other clients are not affected.

Rules:

- The client is the connection's peer address. ``X-Forwarded-For`` is read **only** when the
  peer is one of the ``trusted`` proxies the operator named (``--trusted-proxy``): then the
  client is the rightmost address of that header that is not itself a trusted proxy (the one
  the operator's own proxy appended; what a client wrote to the left of it is not believed).
  Without a trusted proxy the header is ignored, so nobody chooses their own bucket by
  writing it.
- Loopback clients (``127.0.0.0/8``, ``::1``) are not limited unless ``limit_loopback``: the
  machine's own users, the benchmarks and tests (a burst of 200 concurrent requests on
  loopback must all succeed). Behind a reverse proxy on the same machine, name it trusted:
  otherwise every client *is* the proxy's loopback address and nobody is limited.
- The page's own files (``/static/``) take no token.
- A refused request's body (at most the body limit, which ``BodyLimit`` outside this
  middleware enforces) is read and dropped before the 429 is sent, so the client sees the
  answer, not a reset.
- At most ``max_clients`` buckets are kept (least recently seen dropped first; a dropped
  client starts again with a full bucket): memory stays bounded whatever the number of
  addresses.

Costs: one dictionary lookup and a few float operations per request.
"""

from __future__ import annotations

import ipaddress
import json
import math
import time
from collections import OrderedDict
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from starlette.types import ASGIApp, Receive, Scope, Send

Network = ipaddress.IPv4Network | ipaddress.IPv6Network

#: Buckets kept at most (one per client address seen recently).
MAX_CLIENTS = 10_000
#: Paths that take no token: the page's own files.
FREE_PREFIXES = ("/static/",)


def parse_networks(values: Iterable[str]) -> tuple[Network, ...]:
    """Addresses or networks (``127.0.0.1``, ``10.0.0.0/8``, ``::1``) as networks.

    Raises:
        ValueError: one line naming the value that is not an address or network.
    """
    networks: list[Network] = []
    for value in values:
        for part in value.replace(",", " ").split():
            try:
                networks.append(ipaddress.ip_network(part, strict=False))
            except ValueError:
                raise ValueError(f"'{part}' is not an IP address or network") from None
    return tuple(networks)


def _address(text: str) -> ipaddress.IPv4Address | ipaddress.IPv6Address | None:
    try:
        return ipaddress.ip_address(text.strip().strip("[]"))
    except ValueError:
        return None


class TokenBuckets:
    """One token bucket per key: ``burst`` tokens, refilled at ``rate`` per second.

    Args:
        rate: tokens added per second (> 0).
        burst: the bucket's size; a new key starts full.
        max_clients: buckets kept at most (least recently used dropped).
        clock: seconds, monotonic (a test passes its own).
    """

    def __init__(
        self,
        rate: float,
        burst: int,
        max_clients: int = MAX_CLIENTS,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.rate = rate
        self.burst = max(1, burst)
        self.max_clients = max(1, max_clients)
        self.clock = clock
        self._buckets: OrderedDict[str, tuple[float, float]] = OrderedDict()  # tokens, when

    def take(self, key: str) -> float:
        """Take one token for ``key``: ``0.0`` when admitted, else the seconds until the next
        token (nothing taken)."""
        now = self.clock()
        tokens, when = self._buckets.pop(key, (float(self.burst), now))
        tokens = min(float(self.burst), tokens + (now - when) * self.rate)
        wait = 0.0
        if tokens >= 1.0:
            tokens -= 1.0
        else:
            wait = (1.0 - tokens) / self.rate
        self._buckets[key] = (tokens, now)
        while len(self._buckets) > self.max_clients:
            self._buckets.popitem(last=False)
        return wait

    def __len__(self) -> int:
        return len(self._buckets)


class ClientRateLimit:
    """ASGI middleware: ``429`` with ``Retry-After`` and ``{"error", "where"}`` for a client
    over its rate (see the module's rules).

    Args:
        app: the application.
        rate: requests per second each client may sustain (``<= 0``: no limit).
        burst: requests a client may send at once.
        trusted: the proxies whose ``X-Forwarded-For`` is believed (addresses or networks).
        limit_loopback: limit loopback clients too.
    """

    def __init__(
        self,
        app: ASGIApp,
        rate: float,
        burst: int,
        trusted: Iterable[str] = (),
        limit_loopback: bool = False,
    ) -> None:
        self.app = app
        self.rate = rate
        self.buckets = TokenBuckets(rate, burst) if rate > 0 else None
        self.trusted = parse_networks(trusted)
        self.limit_loopback = limit_loopback

    def _trusted(self, address: str) -> bool:
        parsed = _address(address)
        return parsed is not None and any(parsed in network for network in self.trusted)

    def client_of(self, scope: Scope) -> str:
        """The client's address: the peer, or through a trusted proxy the rightmost untrusted
        address of ``X-Forwarded-For``."""
        peer = str((scope.get("client") or ("unknown", 0))[0])
        if not self.trusted or not self._trusted(peer):
            return peer
        forwarded = [
            value.decode("latin-1")
            for name, value in scope.get("headers", [])
            if name == b"x-forwarded-for"
        ]
        hops = [hop.strip() for line in forwarded for hop in line.split(",") if hop.strip()]
        for hop in reversed(hops):
            if not self._trusted(hop):
                return hop  # (not an address: its own bucket, never the loopback exemption)
        return hops[0] if hops else peer

    def _exempt(self, client: str) -> bool:
        if self.limit_loopback:
            return False
        parsed = _address(client)
        return parsed is not None and parsed.is_loopback

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if (
            self.buckets is None
            or scope["type"] != "http"
            or str(scope.get("path", "")).startswith(FREE_PREFIXES)
        ):
            await self.app(scope, receive, send)
            return
        client = self.client_of(scope)
        wait = 0.0 if self._exempt(client) else self.buckets.take(client)
        if wait <= 0.0:
            await self.app(scope, receive, send)
            return
        await _drain(receive)
        await _refuse(send, self.rate, self.buckets.burst, max(1, math.ceil(wait)))


async def _drain(receive: Receive) -> None:
    """Read and drop the request's body (its size is bounded by ``BodyLimit`` outside)."""
    while True:
        message = await receive()
        if message["type"] != "http.request" or not message.get("more_body", False):
            return


async def _refuse(send: Send, rate: float, burst: int, retry: int) -> None:
    body = json.dumps(
        {
            "error": f"too many requests from this client (the server's limit: {rate:g} a "
            f"second, bursts of {burst}; --rate-limit, --rate-burst); try again in {retry} s",
            "where": None,
        }
    ).encode()
    headers = [
        (b"content-type", b"application/json"),
        (b"content-length", str(len(body)).encode()),
        (b"retry-after", str(retry).encode()),
    ]
    await send({"type": "http.response.start", "status": 429, "headers": headers})
    await send({"type": "http.response.body", "body": body})
