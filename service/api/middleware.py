"""`BodySizeLimit`: a pure ASGI middleware capping request bodies at the admission gate's size
(413 naming `body` and the allowed [0, cap] bytes): at once from Content-Length (400 when it is
malformed), or while a chunked body is streamed (counted as it arrives, then handed on unchanged).
It knows nothing of routes; tokens and rates are dependencies (service.api.deps)."""

from __future__ import annotations

import json
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


async def _answer(send, status: int, body: bytes) -> None:
    await send({"type": "http.response.start", "status": status,
                "headers": [(b"content-type", b"application/json"),
                            (b"content-length", str(len(body)).encode())]})
    await send({"type": "http.response.body", "body": body})
