"""Pure ASGI middlewares, in front of routing:

* `BodySizeLimit` caps request bodies at the admission gate's size (413 naming `body` and the
  allowed [0, cap] bytes): at once from Content-Length (400 when it is malformed), or while a
  chunked body is streamed (counted as it arrives, then handed on unchanged).
* `ReadRateLimit` takes every API read (GET/HEAD under /v1/) from its client's read budget
  (the admission gate's per-client token bucket, `read_rate_hz` / `read_burst`): beyond it 429
  with Retry-After and the limit named, answered before routing, the token check or any
  serialisation, so a read flood costs little. /health and the docs are not counted.

* `TokenGate` refuses an API write (POST/PUT/PATCH/DELETE under /v1/; reads too with
  read_requires_token) without the service's token: 401 with WWW-Authenticate, answered before
  routing, the body or any validation (the cheapest refusal of the commonest hostile request).
  The routers keep their token dependency (service.api.deps), which also documents it in OpenAPI.
* `Tarpit` (outermost) holds the refusals of a client over its error budget: every 4xx answer
  takes one from its address's budget (the admission gate's `take_error`, `client_error_rate_hz`
  / `client_error_burst`); once that is empty, each further 4xx answer is sent `tarpit_delay_s`
  after it was decided, with Retry-After. The wait is an asyncio timer: no thread, no CPU. A
  flood that waits for its answers before sending more (any closed-loop client: 32 requests in
  flight make at most 32 / delay refusals a second) slows itself down, and its CPU, which on a
  shared host is taken from the twins, falls with its rate. At most `tarpit_max_held` refusals
  are held at once (beyond: answered at once, counted), so the tarpit cannot hold every
  connection the server allows. /health is never counted nor held; a client within its budget
  (a few mistakes a second) is never held.

* `NoSniff` (outside all of them) marks every answer `X-Content-Type-Options: nosniff`: an error
  that quotes the request (an unknown twin id, an unknown field's name) is JSON, and a browser
  is told never to take it for HTML.

Setpoint rates are a dependency (service.api.deps); slow clients are the server's job
(service.api.server)."""

from __future__ import annotations

import asyncio
import json
import math
from collections.abc import Awaitable, Callable
from dataclasses import dataclass

from service.core.admission import AdmissionGate, bearer_token

_READ_METHODS = frozenset({"GET", "HEAD", "OPTIONS"})


def error_body(message: str, field: str | None = None, allowed: list | None = None) -> bytes:
    return json.dumps({"detail": [{"field": field, "message": message, "allowed": allowed}]}).encode()


class NoSniff:
    """See the module docstring."""

    HEADER = (b"x-content-type-options", b"nosniff")

    def __init__(self, app):
        self.app = app

    async def __call__(self, scope, receive, send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return

        async def marked(message) -> None:
            if message["type"] == "http.response.start":
                message = {**message, "headers": [*message.get("headers", ()), self.HEADER]}
            await send(message)

        await self.app(scope, receive, marked)


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
        if (
            scope["type"] == "http"
            and self.gate.read_rate_hz is not None
            and scope.get("method", "GET").upper() in ("GET", "HEAD")
            and scope.get("path", "").startswith(self.prefix)
        ):
            client = scope.get("client")
            refusal = self.gate.take_read(client[0] if client else "unknown")
            if refusal is not None:
                retry = str(max(1, math.ceil(refusal.retry_after_s or 0.0)))
                await _answer(
                    send,
                    429,
                    error_body(refusal.message, refusal.field, refusal.allowed),
                    [(b"retry-after", retry.encode())],
                )
                return
        await self.app(scope, receive, send)


_WRITE_METHODS = frozenset({"POST", "PUT", "PATCH", "DELETE"})
_MISSING_TOKEN = "missing bearer token: send 'Authorization: Bearer <token>'"


class TokenGate:
    """See the module docstring."""

    def __init__(self, app, *, gate: AdmissionGate, reads: bool = False, prefix: str = "/v1/"):
        self.app = app
        self.gate = gate
        self.methods = _WRITE_METHODS | ({"GET", "HEAD"} if reads else frozenset())
        self.prefix = prefix

    async def __call__(self, scope, receive, send) -> None:
        if (
            scope["type"] == "http"
            and self.gate.requires_token
            and scope.get("method", "GET").upper() in self.methods
            and scope.get("path", "").startswith(self.prefix)
        ):
            given = bearer_token(_headers(scope).get(b"authorization"))
            refusal = self.gate.check_token(given, missing=_MISSING_TOKEN, field="Authorization")
            if refusal is not None:
                await _answer(
                    send,
                    401,
                    error_body(refusal.message, refusal.field, refusal.allowed),
                    [(b"www-authenticate", b'Bearer realm="bearing-twin"')],
                )
                return
        await self.app(scope, receive, send)


@dataclass
class TarpitStats:
    """What the tarpit did (one event loop: no lock): for /health `http_tarpit`."""

    delay_s: float = 0.0
    max_held: int = 0
    held_now: int = 0  # refusals being held now
    held: int = 0  # refusals held so far
    answered_at_once: int = 0  # over budget, but max_held were held already

    def record(self) -> dict:
        return {
            "active": self.delay_s > 0,
            "delay_s": self.delay_s,
            "max_held": self.max_held,
            "held_now": self.held_now,
            "held": self.held,
            "answered_at_once": self.answered_at_once,
        }


class Tarpit:
    """See the module docstring. `stats`: shared with /health."""

    def __init__(
        self,
        app,
        *,
        gate: AdmissionGate,
        delay_s: float,
        max_held: int,
        stats: TarpitStats | None = None,
        exempt: frozenset[str] = frozenset({"/health"}),
    ):
        self.app = app
        self.gate = gate
        self.delay_s = float(delay_s)
        self.max_held = int(max_held)
        self.exempt = exempt
        self.active = self.delay_s > 0 and gate.error_rate_hz is not None
        self.stats = stats if stats is not None else TarpitStats()
        self.stats.delay_s = self.delay_s if self.active else 0.0  # record(): active = delay_s > 0
        self.stats.max_held = self.max_held

    async def __call__(self, scope, receive, send) -> None:
        if not self.active or scope["type"] != "http" or scope.get("path") in self.exempt:
            await self.app(scope, receive, send)
            return
        client = scope.get("client")
        address = client[0] if client else "unknown"
        stats = self.stats

        async def send_held(message) -> None:
            if (
                message["type"] == "http.response.start"
                and 400 <= message.get("status", 200) < 500
                and not self.gate.take_error(address)
            ):
                if stats.held_now < self.max_held:
                    message = _with_retry_after(message, self.delay_s)
                    stats.held_now += 1
                    stats.held += 1
                    try:
                        await asyncio.sleep(self.delay_s)
                    finally:
                        stats.held_now -= 1
                else:
                    stats.answered_at_once += 1
            await send(message)

        await self.app(scope, receive, send_held)


def _with_retry_after(message: dict, delay_s: float) -> dict:
    """The response start with a Retry-After of at least `delay_s` (whole seconds)."""
    headers = list(message.get("headers") or ())
    wait = max(1, math.ceil(delay_s))
    for i, (name, value) in enumerate(headers):
        if name.lower() == b"retry-after":
            try:
                wait = max(wait, int(value))
            except ValueError:
                pass
            headers[i] = (b"retry-after", str(wait).encode())
            break
    else:
        headers.append((b"retry-after", str(wait).encode()))
    return {**message, "headers": headers}


def _headers(scope) -> dict[bytes, bytes]:
    out: dict[bytes, bytes] = {}
    for name, value in scope.get("headers") or ():
        out.setdefault(name.lower(), value)  # the first of repeated headers
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
    await send(
        {
            "type": "http.response.start",
            "status": status,
            "headers": [
                (b"content-type", b"application/json"),
                (b"content-length", str(len(body)).encode()),
                *(headers or ()),
            ],
        }
    )
    await send({"type": "http.response.body", "body": body})
