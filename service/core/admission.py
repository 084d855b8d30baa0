"""Access and abuse limits of the service: bearer token, setpoint rate, request body size.

* `token_matches(given, expected)`: constant-time comparison (hmac.compare_digest on UTF-8
  bytes), so the time an answer takes does not tell how much of a guessed token was right.
* `TokenBucket`: the per-twin setpoint rate limit (sustained `rate_hz`, bursts of `burst`),
  shared by HTTP and zenoh (`TwinRunner.admit_setpoint`).
* `HardeningMiddleware`: a pure ASGI middleware in front of the FastAPI app. For each HTTP
  request, in this order:

  1. token: when a token is configured, POST/PUT/PATCH/DELETE (and every method other than
     GET/HEAD/OPTIONS) need `Authorization: Bearer <token>`; GET/HEAD too when
     `read_requires_token` (GET /health stays open: it is the liveness probe). 401 otherwise,
     with `WWW-Authenticate: Bearer`.
  2. size: a `Content-Length` above `max_body_bytes` -> 413 at once (nothing is read); a
     malformed one -> 400.
  3. rate: `PUT /v1/bearings/{id}/setpoint` takes one token from that twin's bucket -> 429 with
     `Retry-After` (whole seconds) when empty. Answered here, before the body is read or a
     worker thread is taken, so a burst of setpoints cannot starve reads.
  4. body: a body without Content-Length (chunked) is read here while counting; above the cap
     -> 413, else it is handed to the app unchanged.

Every refusal has the service's error body {"detail": [{"field", "message", "allowed"}]}.
"""

from __future__ import annotations

import hmac
import json
import math
import re
import threading
import time
from collections.abc import Awaitable, Callable
from typing import Any

_SETPOINT_PATH = re.compile(r"^/v1/bearings/([^/]+)/setpoint/?$")
_READ_METHODS = frozenset({"GET", "HEAD", "OPTIONS"})
_OPEN_PATHS = frozenset({"/health"})


def token_matches(given: str | bytes | None, expected: str | None) -> bool:
    """Whether `given` is the configured token (constant time in the content of `given`)."""
    if expected is None:
        return True
    if given is None:
        return False
    if isinstance(given, str):
        given = given.encode("utf-8", "surrogateescape")
    return hmac.compare_digest(given, expected.encode("utf-8"))


def bearer_token(header: bytes | None) -> bytes | None:
    """The credentials of an `Authorization: Bearer <token>` header value (None if absent or
    another scheme)."""
    if not header:
        return None
    scheme, _, credentials = header.strip().partition(b" ")
    if scheme.lower() != b"bearer":
        return None
    credentials = credentials.strip()
    return credentials or None


class TokenBucket:
    """Thread-safe token bucket: `burst` tokens, refilled at `rate_hz` per second."""

    def __init__(self, rate_hz: float, burst: int, clock: Callable[[], float] = time.monotonic):
        if not (rate_hz > 0 and math.isfinite(rate_hz)):
            raise ValueError(f"rate_hz = {rate_hz!r}: must be finite and > 0")
        if burst < 1:
            raise ValueError(f"burst = {burst!r}: must be >= 1")
        self.rate_hz = float(rate_hz)
        self.burst = int(burst)
        self._clock = clock
        self._tokens = float(burst)
        self._last = clock()
        self._lock = threading.Lock()
        self.refused = 0

    def take(self) -> tuple[bool, float]:
        """Take one token: (True, 0.0), or (False, seconds until one is available)."""
        with self._lock:
            now = self._clock()
            self._tokens = min(self.burst, self._tokens + (now - self._last) * self.rate_hz)
            self._last = now
            if self._tokens >= 1.0:
                self._tokens -= 1.0
                return True, 0.0
            self.refused += 1
            return False, (1.0 - self._tokens) / self.rate_hz


def error_body(message: str, field: str | None = None, allowed: list | None = None) -> bytes:
    return json.dumps({"detail": [{"field": field, "message": message, "allowed": allowed}]}).encode()


class HardeningMiddleware:
    """See the module docstring. `get_service()` returns the running TwinService (or None)."""

    def __init__(self, app, *, token: str | None, read_requires_token: bool, max_body_bytes: int,
                 get_service: Callable[[], Any]):
        self.app = app
        self.token = token
        self.read_requires_token = bool(read_requires_token)
        self.max_body_bytes = int(max_body_bytes)
        self.get_service = get_service
        self.unauthorized = 0
        self.too_large = 0
        self.rate_limited = 0

    async def __call__(self, scope, receive, send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        method = scope.get("method", "GET").upper()
        path = scope.get("path", "")
        headers = _headers(scope)

        # 1. token
        if self.token is not None and self._needs_token(method, path):
            given = bearer_token(headers.get(b"authorization"))
            if not token_matches(given, self.token):
                self.unauthorized += 1
                message = ("missing bearer token: send 'Authorization: Bearer <token>'"
                           if given is None else "invalid bearer token")
                await _answer(send, 401, error_body(message, "Authorization"),
                              [(b"www-authenticate", b'Bearer realm="bearing-twin"')])
                return

        # 2. declared size
        length = headers.get(b"content-length")
        if length is not None:
            try:
                declared = int(length)
                if declared < 0:
                    raise ValueError
            except ValueError:
                await _answer(send, 400, error_body("malformed Content-Length header", "Content-Length"))
                return
            if declared > self.max_body_bytes:
                self.too_large += 1
                await _answer(send, 413, error_body(
                    f"request body of {declared} bytes is larger than the limit of "
                    f"{self.max_body_bytes} bytes", "body", [0, self.max_body_bytes]))
                return

        # 3. setpoint rate, per twin
        if method == "PUT":
            m = _SETPOINT_PATH.match(path)
            if m is not None:
                refused = self._rate_limit(m.group(1))
                if refused is not None:
                    self.rate_limited += 1
                    await _answer(send, 429, error_body(
                        f"too many setpoints for twin {m.group(1)!r}: at most "
                        f"{refused[1]:g} per second (bursts of {refused[2]}); retry after "
                        f"{refused[0]:.3f} s", None),
                        [(b"retry-after", str(max(1, math.ceil(refused[0]))).encode())])
                    return

        # 4. body without a declared length (chunked): read it while counting
        if length is None and (b"transfer-encoding" in headers or method not in _READ_METHODS):
            body, more, disconnected = bytearray(), True, False
            while more:
                message = await receive()
                if message["type"] == "http.disconnect":
                    disconnected = True
                    break
                body += message.get("body", b"")
                more = message.get("more_body", False)
                if len(body) > self.max_body_bytes:
                    self.too_large += 1
                    await _answer(send, 413, error_body(
                        f"request body is larger than the limit of {self.max_body_bytes} bytes",
                        "body", [0, self.max_body_bytes]))
                    return
            if disconnected:
                return
            receive = _replay(bytes(body), receive)
        await self.app(scope, receive, send)

    def _needs_token(self, method: str, path: str) -> bool:
        if method not in _READ_METHODS:
            return True
        return self.read_requires_token and path not in _OPEN_PATHS

    def _rate_limit(self, bearing_id: str) -> tuple[float, float, int] | None:
        """None when admitted, else (retry after [s], rate [1/s], burst)."""
        try:
            service = self.get_service()
            entry = service.get(bearing_id) if service is not None else None
        except Exception:  # noqa: BLE001 - unknown twin: the app answers 404
            return None
        runner = getattr(entry, "runner", None)
        if runner is None:
            return None
        ok, retry_after = runner.admit_setpoint()
        if ok:
            return None
        bucket = runner.setpoint_bucket
        return retry_after, bucket.rate_hz, bucket.burst


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


async def _answer(send, status: int, body: bytes, headers: list[tuple[bytes, bytes]] = ()) -> None:
    await send({"type": "http.response.start", "status": status,
                "headers": [(b"content-type", b"application/json"),
                            (b"content-length", str(len(body)).encode()), *headers]})
    await send({"type": "http.response.body", "body": body})
