"""The HTTP server around the app: uvicorn configured against slow and greedy clients, and an
access log that never shows a secret.

* `GuardedHttpToolsProtocol`: uvicorn's httptools protocol (the llhttp C parser; the pure-Python
  h11 parser costs about 0.3 ms more per request and lengthens the latency tail of a setpoint,
  docs/performance.md) with two deadlines uvicorn does not have. The
  request line and headers must be complete within `http_header_timeout_s` of the connection
  (or of the first byte of the next request on a kept-alive connection), and a request body
  within `http_body_timeout_s` of its headers. A client that misses one (slowloris: headers or
  body dripped a byte at a time) gets 408 naming `headers` or `body` and the allowed seconds,
  and its connection is closed: a drip does not push the deadline back. uvicorn's own
  `timeout_keep_alive` (`http_keep_alive_s`) closes idle kept-alive connections, and
  `limit_concurrency` (`http_max_connections`) answers 503 beyond that many open connections
  or running requests, so one host cannot hold every socket or task of the service.
* `GuardedHttpToolsProtocol` also notes when a request's headers were read (`request.state`
  `RECEIVED_S`, time.perf_counter): the start of a setpoint's latency, its `http` stage
  (service.core.mailbox.SetpointTiming).
* `RedactAccessLog`: a filter on the `uvicorn.access` logger. In the logged path the value of
  every query parameter whose name says it is a secret (token, key, secret, password, auth,
  credential, signature, ...) becomes `[redacted]`, and so does the service's token wherever it
  appears (the API never reads a token from the query string, but a client may send one there).
* `uvicorn_config(app, settings, ...)`: the uvicorn.Config of `bearing-twin serve` (and of the
  tests' in-process server) with all of the above, on uvloop's event loop.
"""

from __future__ import annotations

import asyncio
import json
import logging
import re
import threading
import time
import urllib.parse
from collections.abc import Iterable

from uvicorn.protocols.http.httptools_impl import HttpToolsProtocol

log = logging.getLogger(__name__)

#: key of `request.state` (the ASGI scope's "state") holding when the request's headers arrived
#: [time.perf_counter() s]: the start of a setpoint's latency (service.core.mailbox.SetpointTiming)
RECEIVED_S = "request_received_s"

REDACTED = "[redacted]"
_SECRET_NAME = re.compile(r"token|key|secret|passw|pwd|auth|credential|signature|sig$|session", re.IGNORECASE)


# ---- slow clients ------------------------------------------------------------------------------
class _Closures:
    """How many connections the deadlines closed (process-wide; logged sparingly)."""

    def __init__(self):
        self._lock = threading.Lock()
        self.headers = 0
        self.body = 0

    def count(self, what: str) -> int:
        with self._lock:
            n = getattr(self, what) + 1
            setattr(self, what, n)
            return n


closures = _Closures()


class GuardedHttpToolsProtocol(HttpToolsProtocol):
    """uvicorn's httptools protocol with header and body deadlines (see the module docstring);
    the deadlines are class attributes, set by `guarded_protocol`. The parser's callbacks give
    where the client is: `headers` from the connection or the first byte of a request
    (`on_message_begin`) to its last header, `body` from there to the request's end, then none."""

    header_timeout_s: float = 10.0
    body_timeout_s: float = 30.0

    def connection_made(self, transport) -> None:
        self._guard: asyncio.TimerHandle | None = None
        self._guarding: str | None = None
        self._phase: str | None = "headers"
        self._received_s = 0.0
        super().connection_made(transport)
        self._follow()

    def data_received(self, data: bytes) -> None:
        self._received_s = time.perf_counter()
        super().data_received(data)
        self._follow()

    def on_message_begin(self) -> None:
        super().on_message_begin()
        self._phase = "headers"

    def on_headers_complete(self) -> None:
        self.scope["state"].setdefault(RECEIVED_S, self._received_s)
        self._phase = "body"
        super().on_headers_complete()

    def on_message_complete(self) -> None:
        self._phase = None
        super().on_message_complete()

    def connection_lost(self, exc: Exception | None) -> None:
        self._disarm()
        super().connection_lost(exc)

    def _follow(self) -> None:
        """Arm, keep or drop the deadline from where the client is in its request."""
        if self.transport is None or self.transport.is_closing() or self._phase is None:
            self._disarm()
        elif self._phase == "headers":
            self._arm("headers", self.header_timeout_s)
        else:
            self._arm("body", self.body_timeout_s)

    def _arm(self, what: str, timeout_s: float) -> None:
        if self._guarding == what:
            return  # a drip does not push the deadline back
        self._disarm()
        self._guarding = what
        self._guard = self.loop.call_later(timeout_s, self._expired, what, timeout_s)

    def _disarm(self) -> None:
        if self._guard is not None:
            self._guard.cancel()
        self._guard, self._guarding = None, None

    def _expired(self, what: str, timeout_s: float) -> None:
        self._guard, self._guarding = None, None
        transport = self.transport
        if transport is None or transport.is_closing():
            return
        if self._phase != what:
            return
        n = closures.count(what)
        if n <= 5 or n % 100 == 0:
            client = f"{self.client[0]}:{self.client[1]}" if self.client else "a client"
            log.warning(
                "closed the connection of %s: request %s not complete within %g s (%d such so far)",
                client,
                what,
                timeout_s,
                n,
            )
        cycle = self.cycle if what == "body" else None
        if cycle is None or not cycle.response_started:
            body = json.dumps(
                {
                    "detail": [
                        {
                            "field": what,
                            "message": f"request {what} not complete within {timeout_s:g} s",
                            "allowed": [0, timeout_s],
                        }
                    ]
                }
            ).encode()
            transport.write(
                b"HTTP/1.1 408 Request Timeout\r\ncontent-type: application/json\r\n"
                b"connection: close\r\ncontent-length: " + str(len(body)).encode() + b"\r\n\r\n" + body
            )
        transport.close()


def guarded_protocol(header_timeout_s: float, body_timeout_s: float) -> type[GuardedHttpToolsProtocol]:
    """A `GuardedHttpToolsProtocol` class with these deadlines [s] (uvicorn instantiates the class)."""
    return type(
        "GuardedHttpToolsProtocol",
        (GuardedHttpToolsProtocol,),
        {"header_timeout_s": float(header_timeout_s), "body_timeout_s": float(body_timeout_s)},
    )


# ---- the access log ----------------------------------------------------------------------------
def redact_path(path: str, secrets: Iterable[str] = ()) -> str:
    """`path` (with its query string) with the values of secret-looking query parameters and
    every occurrence of each of `secrets` (raw or percent-encoded) replaced by `[redacted]`."""
    base, sep, query = path.partition("?")
    if sep:
        parts = []
        for part in query.split("&"):
            name, eq, _ = part.partition("=")
            if eq and _SECRET_NAME.search(urllib.parse.unquote_plus(name)):
                part = f"{name}={REDACTED}"
            parts.append(part)
        path = f"{base}?{'&'.join(parts)}"
    for secret in secrets:
        if not secret:
            continue
        for form in {
            secret,
            urllib.parse.quote(secret, safe=""),
            urllib.parse.quote_plus(secret),
            urllib.parse.quote(secret),
        }:
            path = path.replace(form, REDACTED)
    return path


class RedactAccessLog(logging.Filter):
    """Redacts the path of uvicorn's access-log records (`redact_path`)."""

    def __init__(self, secrets: Iterable[str] = ()):
        super().__init__()
        self.secrets = tuple(s for s in secrets if s)

    def filter(self, record: logging.LogRecord) -> bool:
        args = record.args
        if isinstance(args, tuple) and len(args) >= 3 and isinstance(args[2], str):
            record.args = (*args[:2], redact_path(args[2], self.secrets), *args[3:])
        elif self.secrets:
            record.msg = redact_path(record.getMessage(), self.secrets)
            record.args = ()
        return True


def install_access_log_redaction(token: str | None) -> RedactAccessLog:
    """Put a `RedactAccessLog` (knowing `token`) on the `uvicorn.access` logger, replacing an
    earlier one."""
    logger = logging.getLogger("uvicorn.access")
    for old in [f for f in logger.filters if isinstance(f, RedactAccessLog)]:
        logger.removeFilter(old)
    redactor = RedactAccessLog([token] if token else [])
    logger.addFilter(redactor)
    return redactor


# ---- uvicorn -----------------------------------------------------------------------------------
def uvicorn_config(
    app, settings, *, host: str | None = None, port: int | None = None, log_level: str = "info", **extra
):
    """The uvicorn.Config serving `app` with the settings' slow-client limits (one worker,
    httptools with deadlines, keep-alive, concurrency) on uvloop's event loop, and the access-log
    redaction installed."""
    import uvicorn

    config = uvicorn.Config(
        app,
        host=settings.http.host if host is None else host,
        port=settings.http.port if port is None else port,
        workers=1,
        loop="uvloop",
        log_level=log_level,
        lifespan="on",
        http=guarded_protocol(settings.http.header_timeout_s, settings.http.body_timeout_s),
        timeout_keep_alive=settings.http.keep_alive_s,
        limit_concurrency=settings.http.max_connections,
        **extra,
    )
    install_access_log_redaction(settings.security.token_value)  # after uvicorn configured its loggers
    return config
