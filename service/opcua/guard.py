"""What one OPC UA client may take from the server, so that no client takes real time from the twins.

`OpcUaGuard` holds the limits (settings `opcua_max_sessions`, `opcua_max_subscriptions_per_session`,
`opcua_max_monitored_items_per_session`, `opcua_max_notifications_per_s`, `opcua_min_publishing_interval_ms`,
`opcua_max_queue_size`, `opcua_login_*`) and `GuardedSession`, asyncua's InternalSession with them
enforced, is what the facade's server creates for every client session (`OpcUaGuard.install`).

* Sessions: at most `max_sessions` open at once (created and not closed); one more is refused at
  CreateSession with BadTooManySessions.
* Subscriptions: at most `max_subscriptions_per_session` per session (BadTooManySubscriptions);
  the publishing interval is revised up to `min_publishing_interval_ms` (OPC UA Part 4 5.13.2: the
  server revises the requested interval to one it supports; 0 would publish at every change).
* Notifications: each monitored item may send, per second, at most
  min(publish_rate_hz, queue_size x 1000 / publishing_interval_ms) notifications: its variable
  changes at most once per twin snapshot, and between two publishes its queue holds at most
  `queue_size` values (a requested 0 is 1, the latest value only, as OPC UA Part 4 7.16 says of
  0 and 1; asyncua would make it its cap; at most `max_queue_size`). A session's items together may send at
  most `max_notifications_per_s`, and there are at most `max_monitored_items_per_session` of them;
  an item beyond either is refused with BadTooManyMonitoredItems (the others of the request are
  created). A ModifyMonitoredItems may not enlarge an item's queue. So one session costs the
  server at most `max_notifications_per_s` notifications and 1000 / interval publish cycles per
  subscription per second, and all sessions at most `max_sessions` times that.
* Failed logins (`LoginThrottle`): per client address, the first `login_free_failures` failures
  are answered at once; after them, for `login_backoff_s` x 2^k (k = failures beyond the free
  ones, at most `login_backoff_max_s`) after the last failure, every password from that address
  is refused with BadUserAccessDenied at ActivateSession WITHOUT being tried, so guessing is
  slowed to one try per backoff; anonymous sessions (read-only, they guess nothing) still open.
  Each burst is logged twice: at its first failure and, once it stops
  (a success, or `login_backoff_max_s` without a failure), a summary with the counts. asyncua's
  own ERROR line per refusal is filtered out (`QuietRefusals`).
"""

from __future__ import annotations

import collections
import logging
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from asyncua import ua
from asyncua.common.utils import ServiceError
from asyncua.server.internal_session import InternalSession

log = logging.getLogger(__name__)

MAX_TRACKED_ADDRESSES = 4096  # client addresses the login throttle remembers (oldest dropped)
_REFUSALS = {"BadUserAccessDenied", "BadTooManySessions", "BadTooManySubscriptions", "BadTooManyMonitoredItems"}


@dataclass
class _Burst:
    """Failed logins from one address since its last success or quiet spell."""

    first_s: float
    last_s: float
    failures: int = 0
    refused: int = 0  # refused during the backoff, password not tried


class LoginThrottle:
    """Backoff of failed logins per client address (see the module docstring). `clock`: monotonic
    seconds (injectable for tests)."""

    def __init__(
        self,
        free_failures: int = 3,
        backoff_s: float = 1.0,
        backoff_max_s: float = 60.0,
        clock: Callable[[], float] = time.monotonic,
    ):
        self.free_failures = int(free_failures)
        self.backoff_s, self.backoff_max_s = float(backoff_s), float(backoff_max_s)
        self.clock = clock
        self._bursts: collections.OrderedDict[str, _Burst] = collections.OrderedDict()
        self.failures = 0  # since start, all addresses
        self.refused = 0

    def wait_s(self, address: str) -> float:
        """How long `address` must still wait before a password of it is tried again [s] (0: now)."""
        burst = self._bursts.get(address)
        if burst is None:
            return 0.0
        beyond = burst.failures - self.free_failures
        if beyond < 0:
            return 0.0
        backoff = min(self.backoff_max_s, self.backoff_s * 2.0 ** min(beyond, 60))
        return max(0.0, burst.last_s + backoff - self.clock())

    def refuse(self, address: str) -> None:
        """An activation refused during the backoff (the password was not tried)."""
        self.refused += 1
        burst = self._bursts.get(address)
        if burst is not None:
            burst.refused += 1

    def failed(self, address: str) -> None:
        """A login from `address` failed (wrong password, or anonymous where a token is needed)."""
        now = self.clock()
        self.failures += 1
        self.sweep()
        burst = self._bursts.get(address)
        if burst is None:
            burst = self._bursts[address] = _Burst(now, now)
            while len(self._bursts) > MAX_TRACKED_ADDRESSES:
                self._end(*self._bursts.popitem(last=False))
            log.warning(
                "OPC UA: failed login from %s; after %d failures its logins wait %g s, doubling up to %g s "
                "(password not tried meanwhile); the burst is summarised when it stops",
                address,
                self.free_failures,
                self.backoff_s,
                self.backoff_max_s,
            )
        self._bursts.move_to_end(address)
        burst.failures += 1
        burst.last_s = now

    def succeeded(self, address: str) -> None:
        """A login from `address` succeeded: its burst ends."""
        burst = self._bursts.pop(address, None)
        if burst is not None:
            self._end(address, burst)

    def sweep(self) -> None:
        """End the bursts with no failure for `backoff_max_s` (their summary is logged)."""
        now = self.clock()
        for address in [a for a, b in self._bursts.items() if now - b.last_s >= self.backoff_max_s]:
            self._end(address, self._bursts.pop(address))

    def _end(self, address: str, burst: _Burst) -> None:
        log.warning(
            "OPC UA: %d failed login(s) from %s in %.1f s (%d more refused during the backoff, password not tried)",
            burst.failures,
            address,
            burst.last_s - burst.first_s,
            burst.refused,
        )

    def figures(self) -> dict:
        """Counts since start (any thread: reads a copy of the addresses)."""
        return {
            "failed_logins": self.failures,
            "refused_in_backoff": self.refused,
            "addresses_in_backoff": sum(1 for a in list(self._bursts) if self.wait_s(a) > 0),
        }


class QuietRefusals(logging.Filter):
    """Drops asyncua's one ERROR line per service fault for the refusals the guard logs itself."""

    def filter(self, record: logging.LogRecord) -> bool:
        if record.getMessage().startswith("sending service fault response"):
            return not any(name in record.getMessage() for name in _REFUSALS)
        return True


@dataclass(frozen=True)
class GuardLimits:
    """The limits of `OpcUaGuard` (the settings of the same names without `opcua_`)."""

    max_sessions: int = 16
    max_subscriptions_per_session: int = 8
    max_monitored_items_per_session: int = 500
    max_notifications_per_s: float = 1000.0
    min_publishing_interval_ms: float = 50.0
    max_queue_size: int = 10
    publish_rate_hz: float = 50.0  # how often a variable changes at most (the twins' publish rate) [1/s]

    @classmethod
    def from_settings(cls, s: Any) -> GuardLimits:
        return cls(
            max_sessions=s.opcua.max_sessions,
            max_subscriptions_per_session=s.opcua.max_subscriptions_per_session,
            max_monitored_items_per_session=s.opcua.max_monitored_items_per_session,
            max_notifications_per_s=s.opcua.max_notifications_per_s,
            min_publishing_interval_ms=s.opcua.min_publishing_interval_ms,
            max_queue_size=s.opcua.max_queue_size,
            publish_rate_hz=s.runner.publish_rate_hz,
        )

    def item_rate_hz(self, queue_size: int, interval_ms: float) -> float:
        """The most notifications one monitored item may send per second [1/s]."""
        return min(self.publish_rate_hz, max(1, queue_size) * 1000.0 / max(interval_ms, 1e-3))


class OpcUaGuard:
    """The limits and the login throttle of one OPC UA server (see the module docstring)."""

    def __init__(self, limits: GuardLimits, logins: LoginThrottle):
        self.limits, self.logins = limits, logins
        self.sessions: set[GuardedSession] = set()
        self.refused: collections.Counter = collections.Counter()  # status name -> count

    @classmethod
    def from_settings(cls, s: Any) -> OpcUaGuard:
        return cls(
            GuardLimits.from_settings(s),
            LoginThrottle(s.opcua.login_free_failures, s.opcua.login_backoff_s, s.opcua.login_backoff_max_s),
        )

    def install(self, iserver: Any) -> None:
        """Make asyncua's InternalServer create a GuardedSession for every client session, and cap
        the monitored items' queues."""
        iserver.max_monitored_item_queue_size = self.limits.max_queue_size

        def create_session(name: Any, user: Any = None, external: bool = False) -> InternalSession:
            kwargs = {} if user is None else {"user": user}
            if not external:
                return InternalSession(
                    iserver, iserver.aspace, iserver.subscription_service, name, external=False, **kwargs
                )
            return GuardedSession(
                self, iserver, iserver.aspace, iserver.subscription_service, name, external=True, **kwargs
            )

        iserver.create_session = create_session
        logging.getLogger("asyncua.server.uaprocessor").addFilter(QuietRefusals())

    def refuse(self, status: str, message: str, *args: Any) -> ServiceError:
        """Count a refusal; log it once per kind of refusal and power of two of its count."""
        self.refused[status] += 1
        n = self.refused[status]
        if n & (n - 1) == 0:
            log.warning("OPC UA: " + message + " (%s, %d so far)", *args, status, n)
        return ServiceError(getattr(ua.StatusCodes, status))

    def figures(self) -> dict:
        """For /health `opcua_guard`: open sessions, refusals by status, failed logins [counts]."""
        return {"sessions": len(self.sessions), "refused": dict(self.refused), **self.logins.figures()}


class GuardedSession(InternalSession):
    """asyncua's InternalSession with the guard's limits (see the module docstring)."""

    def __init__(self, guard: OpcUaGuard, *args: Any, **kwargs: Any):
        super().__init__(*args, **kwargs)
        self.guard = guard
        self.address = str(self.name[0]) if isinstance(self.name, tuple) and self.name else str(self.name)
        # monitored item id -> (subscription id, queue size, notification rate [1/s])
        self.item_rates: dict[int, tuple[int, int, float]] = {}

    async def create_session(self, params: ua.CreateSessionParameters, sockname: Any = None) -> ua.CreateSessionResult:
        limits = self.guard.limits
        if len(self.guard.sessions) >= limits.max_sessions:
            raise self.guard.refuse(
                "BadTooManySessions",
                "session from %s refused: %d open (opcua_max_sessions)",
                self.address,
                limits.max_sessions,
            )
        result = await super().create_session(params, sockname)
        self.guard.sessions.add(self)
        return result

    async def close_session(self, delete_subs: bool = True) -> None:
        self.guard.sessions.discard(self)
        await super().close_session(delete_subs)

    def activate_session(
        self, params: ua.ActivateSessionParameters, peer_certificate: bytes | None
    ) -> ua.ActivateSessionResult:
        logins = self.guard.logins
        password = isinstance(params.UserIdentityToken, ua.UserNameIdentityToken)
        if password and logins.wait_s(self.address) > 0:
            logins.refuse(self.address)
            raise ServiceError(ua.StatusCodes.BadUserAccessDenied)
        try:
            result = super().activate_session(params, peer_certificate)
        except ServiceError as exc:
            if exc.code == ua.StatusCodes.BadUserAccessDenied:
                logins.failed(self.address)
            raise
        if password:  # an anonymous session ends no burst of guesses
            logins.succeeded(self.address)
        return result

    # ---- subscriptions and monitored items -----------------------------------------------------
    def _own_subscriptions(self) -> dict[int, Any]:
        return {
            sid: sub
            for sid, sub in self.subscription_service.subscriptions.items()
            if sub.session_id == self.session_id
        }

    async def create_subscription(
        self,
        params: ua.CreateSubscriptionParameters,
        callback: Callable[..., Any],
        request_callback: Callable[..., Any] | None = None,
    ) -> ua.CreateSubscriptionResult:
        limits = self.guard.limits
        if len(self._own_subscriptions()) >= limits.max_subscriptions_per_session:
            raise self.guard.refuse(
                "BadTooManySubscriptions",
                "subscription of a session from %s refused: %d per session (opcua_max_subscriptions_per_session)",
                self.address,
                limits.max_subscriptions_per_session,
            )
        requested = params.RequestedPublishingInterval
        if not math.isfinite(requested) or requested < limits.min_publishing_interval_ms:
            params.RequestedPublishingInterval = limits.min_publishing_interval_ms
        return await super().create_subscription(params, callback, request_callback=request_callback)

    def _queue(self, requested: int) -> int:
        """The queue size an item gets: 0 and 1 are 1 (OPC UA Part 4 7.16), at most max_queue_size."""
        return max(1, min(int(requested), self.guard.limits.max_queue_size))

    def _rates(self) -> dict[int, tuple[int, int, float]]:
        """The live items' (subscription, rate): items of deleted or expired subscriptions go."""
        live = self._own_subscriptions()
        self.item_rates = {i: v for i, v in self.item_rates.items() if v[0] in live}
        return self.item_rates

    async def create_monitored_items(
        self, params: ua.CreateMonitoredItemsParameters
    ) -> list[ua.MonitoredItemCreateResult]:
        limits = self.guard.limits
        sub = self._own_subscriptions().get(params.SubscriptionId)
        if sub is None:
            raise ServiceError(ua.StatusCodes.BadSubscriptionIdInvalid)
        interval_ms = sub.data.RevisedPublishingInterval
        rates = self._rates()
        count, total = len(rates), sum(rate for _sid, _queue, rate in rates.values())
        accepted, item_rates = [], []
        for item in params.ItemsToCreate:
            queue = item.RequestedParameters.QueueSize = self._queue(item.RequestedParameters.QueueSize)
            rate = limits.item_rate_hz(queue, interval_ms)
            if count + 1 > limits.max_monitored_items_per_session or total + rate > limits.max_notifications_per_s:
                break
            count, total = count + 1, total + rate
            accepted.append(item)
            item_rates.append((queue, rate))
        refused = len(params.ItemsToCreate) - len(accepted)
        params.ItemsToCreate = accepted
        results = await super().create_monitored_items(params) if accepted else []
        for result, (queue, rate) in zip(results, item_rates, strict=True):
            if result.StatusCode.is_good():
                self.item_rates[result.MonitoredItemId] = (params.SubscriptionId, queue, rate)
        if refused:
            self.guard.refuse(
                "BadTooManyMonitoredItems",
                "%d monitored item(s) of a session from %s refused: at most "
                "%d items and %g notifications/s per session",
                refused,
                self.address,
                limits.max_monitored_items_per_session,
                limits.max_notifications_per_s,
            )
            too_many = ua.UInt32(ua.StatusCodes.BadTooManyMonitoredItems)
            results += [ua.MonitoredItemCreateResult(StatusCode=ua.StatusCode(too_many)) for _ in range(refused)]
        return results

    async def modify_monitored_items(
        self, params: ua.ModifyMonitoredItemsParameters
    ) -> list[ua.MonitoredItemModifyResult]:
        """An item's queue may shrink, never grow (its notification rate was counted at creation)."""
        for item in params.ItemsToModify:
            counted = self.item_rates.get(item.MonitoredItemId)
            item.RequestedParameters.QueueSize = min(
                self._queue(item.RequestedParameters.QueueSize), counted[1] if counted else 1
            )
        return await super().modify_monitored_items(params)

    async def delete_monitored_items(self, params: ua.DeleteMonitoredItemsParameters) -> list[ua.StatusCode]:
        results = await super().delete_monitored_items(params)
        for item_id in params.MonitoredItemIds:
            self.item_rates.pop(item_id, None)
        return results
