"""Pure ASGI middlewares, in front of routing:

* `BodySizeLimit` caps request bodies at the admission gate's size (413 naming `body` and the
  allowed [0, cap] bytes): at once from Content-Length (400 when it is malformed), or while a
  chunked body is streamed (counted as it arrives, then handed on unchanged).
* `ReadRateLimit` takes every API read (GET/HEAD under /v1/) from its client's read budget
  (the admission gate's per-client token bucket, `read_rate_hz` / `read_burst`): beyond it 429
  with Retry-After and the limit named, answered before routing, the token check or any
  serialisation, so a read flood costs little. /health and the docs are not counted.

Tokens and setpoint rates are dependencies (service.api.deps); slow clients are the server's
job (service.api.server)."""

from __future__ import annotations

import json
import math
from collections.abc import Awaitable, Callable

from service.core.admission import AdmissionGate

_READ_METHODS = frozenset({"GET", "HEAD", "OPTIONS"})


def error_body(message: str, field: str | None = None, allowed: list | None = None) -> bytes:
    return json.dumps({"detail": [{"field": field, "message": message, "allowed": allowed}]}).encode()


class BodySizeLimit:
    """See the module docstring."""

    def __init__(self, app, *, gate: AdmissionGate):
        self.app = app
        self.gate = gate

    async def __call__(self, scope, receive, send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        method = scope.get("method", "GET").upper()
        headers = _headers(scope)
        length = headers.get(b"content-length")
        if length is not None:
            try:
                declared = int(length)
                if declared < 0:
                    raise ValueError
            except ValueError:
                await _answer(send, 400, error_body("malformed Content-Length header", "Content-Length"))
                return
            refusal = self.gate.check_size(declared, "request body")
            if refusal is not None:
                await _answer(send, 413, error_body(refusal.message, refusal.field, refusal.allowed))
                return
        elif b"transfer-encoding" in headers or method not in _READ_METHODS:
            body, more = bytearray(), True
            while more:
                message = await receive()
                if message["type"] == "http.disconnect":
                    return
                body += message.get("body", b"")
                more = message.get("more_body", False)
                refusal = self.gate.check_size(len(body), "request body")
                if refusal is not None:
                    await _answer(send, 413, error_body(refusal.message, refusal.field, refusal.allowed))
                    return
            receive = _replay(bytes(body), receive)
        await self.app(scope, receive, send)


class ReadRateLimit:
    """See the module docstring."""

    def __init__(self, app, *, gate: AdmissionGate, prefix: str = "/v1/"):
        self.app = app
        self.gate = gate
        self.prefix = prefix

    async def __call__(self, scope, receive, send) -> None:
        if (scope["type"] == "http" and self.gate.read_rate_hz is not None
                and scope.get("method", "GET").upper() in ("GET", "HEAD")
                and scope.get("path", "").startswith(self.prefix)):
            client = scope.get("client")
            refusal = self.gate.take_read(client[0] if client else "unknown")
            if refusal is not None:
                retry = str(max(1, math.ceil(refusal.retry_after_s or 0.0)))
                await _answer(send, 429, error_body(refusal.message, refusal.field, refusal.allowed),
                              [(b"retry-after", retry.encode())])
                return
        await self.app(scope, receive, send)


def _headers(scope) -> dict[bytes, bytes]:
    out: dict[bytes, bytes] = {}
    for name, value in scope.get("headers") or ():
        out.setdefault(name.lower(), value)   # the first of repeated headers
    return out


def _replay(body: bytes, receive: Callable[[], Awaitable[dict]]) -> Callable[[], Awaitable[dict]]:
    sent = False

    async def replay() -> dict:
        nonlocal sent
        if not sent:
            sent = True
            return {"type": "http.request", "body": body, "more_body": False}
        return await receive()
    return replay


async def _answer(send, status: int, body: bytes, headers: list | None = None) -> None:
    await send({"type": "http.response.start", "status": status,
                "headers": [(b"content-type", b"application/json"),
                            (b"content-length", str(len(body)).encode()), *(headers or ())]})
    await send({"type": "http.response.body", "body": body})
