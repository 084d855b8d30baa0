"""The admission gate: ONE check of who may send setpoints and how many, for every transport.

* `token_matches(given, expected)`: constant-time comparison (hmac.compare_digest on UTF-8
  bytes), so the time an answer takes does not tell how much of a guessed token was right.
* `TokenBucket`: a rate limit (sustained `rate_hz`, bursts of `burst`).
* `AdmissionGate`: the service's HTTP token, body/payload size cap, per-twin setpoint rate (one
  token bucket per twin, shared by HTTP and zenoh), per-client read rate and per-client error
  budget (one token bucket per client address each, the most recently seen `MAX_READ_CLIENTS`
  kept) and whether setpoints from the bus are taken at all. Each check returns None (admitted) or a `Refusal` with the
  status the transport
  answers with (401, 403, 413, 429), the field and a message; the HTTP layer turns it into its
  error answer (service.api.deps), the zenoh intake into a refusal on the result key
  (service.core.intake).

The HTTP token is for HTTP only: it never travels on zenoh (any subscriber could read it there).
Who may put a setpoint on zenoh is decided by zenoh's own authentication and access-control
rules (service.bus.access); the gate only knows the outcome of the settings (`bus_writes`):
"authorized" (zenoh access control on: what arrives was allowed by the rules), "open" (no
access control and no HTTP token: an open service, as on loopback by default) or "closed" (an
HTTP token but no zenoh access control: zenoh setpoints are refused with 403, since anyone could
send them).

No transport here: no fastapi, no zenoh.
"""

from __future__ import annotations

import collections
import hmac
import math
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass


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


@dataclass(frozen=True)
class Refusal:
    """Why the gate refused: the status to answer with, the field at fault and a message."""

    status: int  # 401, 403, 413 or 429
    field: str | None
    message: str
    allowed: list | None = None
    retry_after_s: float | None = None  # 429: when a setpoint will be admitted again [s]


class AdmissionGate:
    """Token, size and per-twin setpoint rate for every transport (see the module docstring).

    `token` None: no authentication. `setpoint_rate_hz` None or 0: no rate limit.
    `max_payload_bytes` None: no size cap. `bus_writes`: "open", "authorized" or "closed"
    (module docstring); default "closed" when a token is given, else "open"."""

    BUS_WRITES = ("open", "authorized", "closed")
    MAX_READ_CLIENTS = 10_000  # read budgets kept (least recently seen client dropped first)

    def __init__(
        self,
        *,
        token: str | None = None,
        setpoint_rate_hz: float | None = None,
        setpoint_burst: int = 100,
        max_payload_bytes: int | None = None,
        bus_writes: str | None = None,
        read_rate_hz: float | None = None,
        read_burst: int = 200,
        error_rate_hz: float | None = None,
        error_burst: int = 20,
        clock: Callable[[], float] = time.monotonic,
    ):
        self.token = token
        if bus_writes is None:
            bus_writes = "closed" if token is not None else "open"
        if bus_writes not in self.BUS_WRITES:
            raise ValueError(f"bus_writes = {bus_writes!r}: one of {', '.join(self.BUS_WRITES)}")
        self.bus_writes = bus_writes
        self.setpoint_rate_hz = float(setpoint_rate_hz) if setpoint_rate_hz else None
        self.setpoint_burst = int(setpoint_burst)
        if self.setpoint_rate_hz is not None:
            TokenBucket(self.setpoint_rate_hz, self.setpoint_burst)  # ValueError on bad settings
        self.read_rate_hz = float(read_rate_hz) if read_rate_hz else None
        self.read_burst = int(read_burst)
        if self.read_rate_hz is not None:
            TokenBucket(self.read_rate_hz, self.read_burst)  # ValueError on bad settings
        self._readers: collections.OrderedDict[str, TokenBucket] = collections.OrderedDict()
        self.reads_limited = 0
        self.error_rate_hz = float(error_rate_hz) if error_rate_hz else None
        self.error_burst = int(error_burst)
        if self.error_rate_hz is not None:
            TokenBucket(self.error_rate_hz, self.error_burst)  # ValueError on bad settings
        self._failing: collections.OrderedDict[str, TokenBucket] = collections.OrderedDict()
        self.errors_over_budget = 0
        self.max_payload_bytes = max_payload_bytes
        self._clock = clock
        self._buckets: dict[str, TokenBucket] = {}
        self._lock = threading.Lock()
        self.unauthorized = 0
        self.too_large = 0

    @property
    def requires_token(self) -> bool:
        return self.token is not None

    def check_token(
        self, given: str | bytes | None, *, missing: str = "missing token", field: str | None = "token"
    ) -> Refusal | None:
        """None if `given` is the token (or none is configured), else a 401 Refusal; `missing`
        is the message when nothing was given (it says how to send it on that transport)."""
        if self.token is None:
            return None
        if given is not None and token_matches(given, self.token):
            return None
        with self._lock:
            self.unauthorized += 1
        return Refusal(401, field, missing if given is None else "invalid token")

    def check_bus_writer(self) -> Refusal | None:
        """None if setpoints from the bus are taken, else a 403 Refusal saying how to allow them."""
        if self.bus_writes != "closed":
            return None
        with self._lock:
            self.unauthorized += 1
        return Refusal(
            403,
            None,
            "zenoh setpoints are refused: the HTTP API of this service needs a "
            "token, and zenoh access control is off, so anyone could send them; configure "
            "zenoh access control (BEARING_TWIN_ZENOH_USERSFILE and BEARING_TWIN_ZENOH_WRITERS, "
            "or join a secured router) or send the setpoint over HTTP",
        )

    def check_size(self, size: int, what: str = "payload") -> Refusal | None:
        """None if `size` [bytes] is within the cap, else a 413 Refusal."""
        cap = self.max_payload_bytes
        if cap is None or size <= cap:
            return None
        with self._lock:
            self.too_large += 1
        return Refusal(413, "body", f"{what} of {size} bytes is larger than the limit of {cap} bytes", [0, cap])

    def take_setpoint(self, bearing_id: str) -> Refusal | None:
        """Take one setpoint from the twin's budget: None, or a 429 Refusal with retry_after_s."""
        if self.setpoint_rate_hz is None:
            return None
        with self._lock:
            bucket = self._buckets.get(bearing_id)
            if bucket is None:
                bucket = self._buckets[bearing_id] = TokenBucket(
                    self.setpoint_rate_hz, self.setpoint_burst, clock=self._clock
                )
        ok, retry_after = bucket.take()
        if ok:
            return None
        return Refusal(
            429,
            None,
            f"too many setpoints for twin {bearing_id!r}: at most "
            f"{self.setpoint_rate_hz:g} per second (bursts of {self.setpoint_burst}); "
            f"retry after {retry_after:.3f} s",
            retry_after_s=retry_after,
        )

    def take_read(self, client: str) -> Refusal | None:
        """Take one read from the budget of `client` (its address): None, or a 429 Refusal naming
        the limit, with retry_after_s."""
        if self.read_rate_hz is None:
            return None
        ok, retry_after = self._client_bucket(self._readers, client, self.read_rate_hz, self.read_burst).take()
        if ok:
            return None
        with self._lock:
            self.reads_limited += 1
        return Refusal(
            429,
            None,
            f"too many reads from {client}: at most {self.read_rate_hz:g} per "
            f"second per client (read_rate_hz, bursts of {self.read_burst}: read_burst); "
            f"retry after {retry_after:.3f} s",
            [0, self.read_rate_hz],
            retry_after_s=retry_after,
        )

    def take_error(self, client: str) -> bool:
        """Count one refused request (an HTTP 4xx answer) of `client` (its address) against its
        error budget (`error_rate_hz`, bursts of `error_burst`): True while within it, False for
        a client over it (the HTTP layer holds its refusals: service.api.middleware.Tarpit). No
        budget configured: always True."""
        if self.error_rate_hz is None:
            return True
        ok, _ = self._client_bucket(self._failing, client, self.error_rate_hz, self.error_burst).take()
        if not ok:
            with self._lock:
                self.errors_over_budget += 1
        return ok

    def _client_bucket(
        self, buckets: collections.OrderedDict[str, TokenBucket], client: str, rate_hz: float, burst: int
    ) -> TokenBucket:
        """The bucket of `client` in `buckets` (made on first sight; the least recently seen of
        more than MAX_READ_CLIENTS dropped)."""
        with self._lock:
            bucket = buckets.get(client)
            if bucket is None:
                bucket = buckets[client] = TokenBucket(rate_hz, burst, clock=self._clock)
                if len(buckets) > self.MAX_READ_CLIENTS:
                    buckets.popitem(last=False)
            else:
                buckets.move_to_end(client)
            return bucket

    def rate_limited(self, bearing_id: str) -> int:
        """Setpoints of this twin refused by the rate limit so far."""
        with self._lock:
            bucket = self._buckets.get(bearing_id)
        return bucket.refused if bucket is not None else 0

    def forget(self, bearing_id: str) -> None:
        """Drop a removed twin's budget."""
        with self._lock:
            self._buckets.pop(bearing_id, None)
