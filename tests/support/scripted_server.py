"""A local OpenAI-compatible chat server that replays scripted responses (tests only).

It listens on 127.0.0.1 on a free port, answers ``POST .../chat/completions`` with the next
scripted step and records every request (headers and JSON body) so tests can assert what the
client sent (and when: ``time``, ``time.monotonic()`` on arrival). It checks plumbing only; nothing it returns says anything about a real model.

A step is a dict: ``{"content": "..."}`` (a normal answer), ``{"status": 429, "headers":
{...}}`` (an HTTP error), ``{"delay": 2.0, ...}`` (wait first), ``{"usage": False}`` (no usage
block). When the script runs out, the last step repeats.

Fault steps (for the fault-injection tests): ``{"raw": "..."}`` sends that body as-is with
status 200 (``"content_type"`` to change its type: another format, or truncated JSON);
``{"trickle": 0.05, "chunk": 1}`` sends the body ``chunk`` bytes at a time, ``trickle`` seconds
apart; ``{"reset_after": 100}`` sends the first 100 bytes of the body and then resets the
connection (TCP RST).
"""

from __future__ import annotations

import json
import socket
import struct
import threading
import time
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any


class ScriptedServer:
    def __init__(self, steps: list[dict[str, Any]]) -> None:
        self.steps = list(steps)
        self.requests: list[dict[str, Any]] = []
        self._lock = threading.Lock()
        self._stop = threading.Event()
        server = self

        class Handler(BaseHTTPRequestHandler):
            def log_message(self, *args: Any) -> None:  # keep test output clean
                pass

            def do_POST(self) -> None:  # noqa: N802 - http.server's naming
                length = int(self.headers.get("Content-Length", "0"))
                raw = self.rfile.read(length)
                try:
                    body = json.loads(raw)
                except json.JSONDecodeError:
                    body = None
                with server._lock:
                    server.requests.append(
                        {
                            "path": self.path,
                            "headers": dict(self.headers),
                            "body": body,
                            "time": time.monotonic(),
                        }
                    )
                    index = min(len(server.requests) - 1, len(server.steps) - 1)
                    step = server.steps[index]
                deadline = time.monotonic() + float(step.get("delay", 0))
                while time.monotonic() < deadline and not server._stop.is_set():
                    time.sleep(0.02)
                if server._stop.is_set():
                    return
                if not self.path.endswith("/chat/completions"):
                    self._send(404, {"error": {"message": f"no route {self.path}"}})
                    return
                if "raw" in step:
                    raw_body = step["raw"]
                    self._send_bytes(
                        200,
                        raw_body.encode() if isinstance(raw_body, str) else raw_body,
                        step,
                        step.get("content_type", "application/json"),
                    )
                    return
                status = int(step.get("status", 200))
                if status != 200:
                    self._send(
                        status,
                        {
                            "error": {
                                "message": step.get("message", f"scripted {status}"),
                                "type": "scripted",
                            }
                        },
                        step.get("headers", {}),
                    )
                    return
                content = step.get("content", "")
                reply: dict[str, Any] = {
                    "id": f"chatcmpl-{len(server.requests)}",
                    "object": "chat.completion",
                    "created": 0,
                    "model": (body or {}).get("model", "scripted"),
                    "choices": [
                        {
                            "index": 0,
                            "finish_reason": "stop",
                            "message": {"role": "assistant", "content": content},
                        }
                    ],
                }
                if step.get("usage", True):
                    reply["usage"] = {
                        "prompt_tokens": 100 + len(server.requests),
                        "completion_tokens": max(1, len(content) // 4),
                        "total_tokens": 0,
                    }
                self._send_bytes(200, json.dumps(reply).encode(), step, "application/json")

            def _send_bytes(
                self, status: int, data: bytes, step: dict[str, Any], content_type: str
            ) -> None:
                try:
                    self.send_response(status)
                    self.send_header("Content-Type", content_type)
                    self.send_header("Content-Length", str(len(data)))
                    self.end_headers()
                    if "reset_after" in step:
                        self.wfile.write(data[: int(step["reset_after"])])
                        self.wfile.flush()
                        # SO_LINGER 0: close() sends a TCP RST instead of a clean FIN
                        self.connection.setsockopt(
                            socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0)
                        )
                        self.connection.close()
                        self.close_connection = True
                        return
                    if "trickle" in step:
                        chunk = int(step.get("chunk", 1))
                        for start in range(0, len(data), chunk):
                            if server._stop.is_set():
                                return
                            self.wfile.write(data[start : start + chunk])
                            self.wfile.flush()
                            time.sleep(float(step["trickle"]))
                        return
                    self.wfile.write(data)
                except (BrokenPipeError, ConnectionResetError, OSError):
                    pass  # the client gave up (a guard or timeout test)

            def finish(self) -> None:
                try:
                    super().finish()
                except OSError:
                    pass  # the connection was reset on purpose

            def _send(
                self, status: int, payload: dict[str, Any], headers: dict[str, str] | None = None
            ) -> None:
                data = json.dumps(payload).encode()
                try:
                    self.send_response(status)
                    self.send_header("Content-Type", "application/json")
                    self.send_header("Content-Length", str(len(data)))
                    for key, value in (headers or {}).items():
                        self.send_header(key, value)
                    self.end_headers()
                    self.wfile.write(data)
                except (BrokenPipeError, ConnectionResetError):
                    pass  # the client gave up (a timeout test)

        self._httpd = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self._httpd.daemon_threads = True
        self._thread = threading.Thread(target=self._httpd.serve_forever, daemon=True)

    @property
    def base_url(self) -> str:
        host, port = self._httpd.server_address[:2]
        return f"http://{host}:{port}/v1"

    def __enter__(self) -> ScriptedServer:
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._stop.set()
        self._httpd.shutdown()
        self._httpd.server_close()
        self._thread.join(timeout=5)

    def user_texts(self, index: int) -> str:
        """All user-message text of request ``index`` joined (for assertions)."""
        body = self.requests[index]["body"]
        texts = []
        for message in body["messages"]:
            content = message["content"]
            if isinstance(content, str):
                texts.append(content)
            else:
                texts.extend(part.get("text", "") for part in content if part.get("type") == "text")
        return "\n".join(texts)


def closed_port() -> int:
    """A port on 127.0.0.1 nothing listens on (bound then released)."""
    import socket

    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])
