"""The zenoh bus: ONE zenoh session for the whole service, one `TwinChannel` per twin.

Key expressions (README "Architecture", schema "bearing-twin/state/1"):

    bearing/{id}/state             snapshot JSON (publisher)
    bearing/{id}/ball/{i}          one ball: the ball's fields plus schema, bearing_id, time_s
    bearing/{id}/setpoint          setpoint JSON in (subscriber)
    bearing/{id}/setpoint/result   what became of each setpoint message (publisher):
                                   {"accepted": true, "setpoint": {...}} or
                                   {"accepted": false, "error": "..."}; always carries bearing_id
    bearing/{id}/snapshot          queryable: replies with the latest snapshot JSON
    bearing/{id}/alarm             alarm events JSON, schema "bearing-twin/alarm/1" (publisher;
                                   service.core.alarms, handed over by the alarm hub)
    bearing/{id}/alive             liveliness token while the twin is attached

Threads. zenoh runs its callbacks on its own threads; ours only hand work off (append to a
Python queue) and return. Each channel owns two daemon threads:

* the publisher thread serialises queued snapshots and puts them (state + one message per
  ball). `TwinChannel.publish` only appends to a bounded deque (drop-oldest, counted in
  `dropped`), so the runner (physics) never waits on the network. There is NO rate limiter
  here: the runner decides how often it calls `publish` (e.g. 50 Hz); every call is published.
* the control thread answers setpoints (calls `on_setpoint(payload)`, publishes the result)
  and snapshot queries (calls `get_snapshot()`, replies on the concrete key). Every exception
  from the callee is caught and reported as a refusal; nothing kills the thread.

Zenoh 1.x notes (checked against eclipse-zenoh 1.10.2):
* the session must be closed explicitly (`ZenohBus.close`, also registered with atexit as a
  safety net); sessions with callback subscribers/queryables otherwise keep the process alive.
* peer mode without multicast scouting: gossip scouting must stay ON so that a peer that
  connects to one service learns about the other services connected to it (zenoh >= 1.9 does
  not relay between peers; gossip lets peers open direct links). Gossip only travels over the
  links we were told to open, so nothing is sent to the LAN.
* never block in a channel handler's `recv()` on one thread while undeclaring on another
  ("RuntimeError: Already borrowed" and a stuck thread): we use Python callbacks + our queues.
* `Publisher.matching_status` returns a `MatchingStatus` object (always truthy), not the bool
  the stubs promise: read `.matching`. It does become true once a remote subscriber is routed.
* a malformed *connect* endpoint does not fail `zenoh.open` (only a listen one does), so
  `make_config` checks endpoints itself.
* open sessions only after any fork (one service process owns the bus).
"""

from __future__ import annotations

import atexit
import collections
import contextlib
import json
import logging
import re
import threading
import time
import weakref
from collections.abc import Callable, Iterable
from typing import Any, Self

import zenoh

from twin.snapshot import Snapshot

log = logging.getLogger(__name__)

DEFAULT_LISTEN = ["tcp/127.0.0.1:7447"]
DEFAULT_QUEUE_SIZE = 64
_CONTROL_QUEUE_SIZE = 256
_JSON = "application/json"
_ID_RE = re.compile(r"^[A-Za-z0-9_.:+=,;~@%-]+$")  # one key-expression chunk, no wildcards/slashes


def make_config(listen: Iterable[str] | None = None, connect: Iterable[str] | None = None,
                mode: str = "peer", *, gossip: bool = True) -> zenoh.Config:
    """A zenoh config that touches only what it is told.

    `listen` None means DEFAULT_LISTEN (loopback 7447); an empty list means do not listen.
    Multicast scouting is off (no UDP to 224.0.0.224); gossip scouting (over the configured
    links only) is on by default so that peers connected through a common peer find each other.
    """
    if mode not in ("peer", "client", "router"):
        raise ValueError(f"zenoh mode must be peer, client or router, got {mode!r}")
    listen = [check_endpoint(e) for e in (DEFAULT_LISTEN if listen is None else listen)]
    connect = [check_endpoint(e) for e in (connect or [])]
    config = zenoh.Config()
    config.insert_json5("mode", json.dumps(mode))
    config.insert_json5("listen/endpoints", json.dumps(listen))
    config.insert_json5("connect/endpoints", json.dumps(connect))
    config.insert_json5("scouting/multicast/enabled", "false")
    config.insert_json5("scouting/gossip/enabled", json.dumps(bool(gossip)))
    return config


_ENDPOINT_RE = re.compile(r"^([a-z0-9-]+)/([^?#]+)([?#].*)?$")
_IP_PROTOCOLS = {"tcp", "udp", "tls", "quic", "ws"}


def check_endpoint(endpoint: str) -> str:
    """Return `endpoint` if it looks like a zenoh endpoint (proto/address[?meta][#config]).

    zenoh refuses a malformed listen endpoint at open, but only logs a malformed connect endpoint
    and carries on unconnected; checking both here turns a typo into an error up front."""
    m = _ENDPOINT_RE.match(endpoint.strip()) if isinstance(endpoint, str) else None
    if m is None:
        raise ValueError(f"not a zenoh endpoint: {endpoint!r} (expected e.g. tcp/127.0.0.1:7447)")
    proto, address = m.group(1), m.group(2)
    if proto in _IP_PROTOCOLS:
        host, sep, port = address.rpartition(":")
        if not sep or not host or not port.isdigit() or not 0 <= int(port) <= 65535:
            raise ValueError(f"not a zenoh endpoint: {endpoint!r} (expected {proto}/HOST:PORT)")
    return endpoint.strip()


def _one_line(exc: BaseException) -> str:
    """A short, single-line description of a refusal (pydantic errors name their field)."""
    errors = getattr(exc, "errors", None)
    if callable(errors) and type(exc).__name__ == "ValidationError":
        try:
            parts = []
            for e in errors():
                loc = ".".join(str(p) for p in e.get("loc", ())) or "payload"
                parts.append(f"{loc}: {e.get('msg', '')}")
            if parts:
                return "; ".join(parts)
        except Exception:  # noqa: BLE001, S110 - fall back to str()
            pass
    text = " ".join(str(exc).split())
    return text or type(exc).__name__


def _dumps(obj: Any) -> str:
    """Contract JSON: compact, never NaN/Infinity (raises ValueError instead)."""
    return json.dumps(obj, allow_nan=False, separators=(",", ":"))


class TwinChannel:
    """One twin on the bus; a `SnapshotSink`. Created by `ZenohBus.attach_twin`."""

    def __init__(self, bus: ZenohBus, bearing_id: str, get_snapshot: Callable[[], Snapshot | None],
                 on_setpoint: Callable[[bytes], dict], *, queue_size: int = DEFAULT_QUEUE_SIZE,
                 flush_timeout_s: float = 2.0):
        if queue_size < 1:
            raise ValueError("queue_size must be >= 1")
        self.bus = bus
        self.bearing_id = bearing_id
        self.prefix = f"bearing/{bearing_id}"
        self._get_snapshot = get_snapshot
        self._on_setpoint = on_setpoint
        self._flush_timeout_s = flush_timeout_s
        session = bus.session

        # snapshot queue (runner -> publisher thread)
        self._queue: collections.deque = collections.deque(maxlen=queue_size)
        self._cond = threading.Condition()
        self._stopping = False
        self._closed = False
        self._publishers_gone = False
        self._close_lock = threading.Lock()
        self._dropped = 0
        self.published = 0          # snapshots fully put on the bus
        self.errors = 0             # snapshots that failed to serialise or put
        self.setpoints_received = 0
        self.setpoints_dropped = 0  # control queue overflow (never expected)
        self.queries_answered = 0
        self._last: tuple[Any, str] | None = None  # (snapshot object, its state JSON)
        self._last_lock = threading.Lock()

        # control queue (zenoh callbacks -> control thread)
        self._control: collections.deque = collections.deque()
        self._control_cond = threading.Condition()

        self._ball_publishers: dict[int, zenoh.Publisher] = {}
        self._alarm_pub: zenoh.Publisher | None = None   # declared with the first alarm
        self._pub_lock = threading.Lock()
        self._state_pub = session.declare_publisher(
            f"{self.prefix}/state", encoding=_JSON, congestion_control=zenoh.CongestionControl.DROP)
        self._result_pub = session.declare_publisher(
            f"{self.prefix}/setpoint/result", encoding=_JSON,
            congestion_control=zenoh.CongestionControl.DROP)
        self._setpoint_sub = session.declare_subscriber(f"{self.prefix}/setpoint", self._on_setpoint_sample)
        self._queryable = session.declare_queryable(f"{self.prefix}/snapshot", self._on_query)
        self._token = session.liveliness().declare_token(f"{self.prefix}/alive")

        self._publisher_thread = threading.Thread(
            target=self._publish_loop, name=f"zenoh-pub-{bearing_id}", daemon=True)
        self._control_thread = threading.Thread(
            target=self._control_loop, name=f"zenoh-ctl-{bearing_id}", daemon=True)
        self._publisher_thread.start()
        self._control_thread.start()

    # ---- SnapshotSink -----------------------------------------------------------------------
    @property
    def dropped(self) -> int:
        """Snapshots dropped because the queue was full (oldest first)."""
        return self._dropped

    @property
    def closed(self) -> bool:
        return self._closed

    def publish(self, snapshot: Snapshot) -> None:
        """Queue a snapshot for publication; returns at once, never raises.

        No rate limiting: the caller (runner) decides the publish rate."""
        try:
            with self._cond:
                if self._stopping:
                    return
                if len(self._queue) == self._queue.maxlen:
                    self._dropped += 1
                self._queue.append(snapshot)
                self._cond.notify()
        except Exception:  # noqa: BLE001, S110 - a sink never raises into the physics
            pass

    def close(self) -> None:
        """Same as `detach`."""
        self.detach()

    def detach(self) -> None:
        """Withdraw the twin: liveliness token first (watchers see it go), then the subscriber and
        queryable, flush queued snapshots (bounded by flush_timeout_s), stop the threads and
        undeclare the publishers. Idempotent, never raises."""
        with self._close_lock:
            if self._closed:
                return
            self._closed = True
        for entity in (self._token, self._setpoint_sub, self._queryable):
            self._undeclare(entity)
        with self._control_cond:
            self._control.append(None)
            self._control_cond.notify()
        with self._cond:
            self._stopping = True
            self._cond.notify()
        for thread in (self._publisher_thread, self._control_thread):
            if thread is not threading.current_thread():  # e.g. detach from inside on_setpoint
                thread.join(self._flush_timeout_s)
        with self._pub_lock:
            self._publishers_gone = True
            publishers = [self._state_pub, self._result_pub, *self._ball_publishers.values()]
            if self._alarm_pub is not None:
                publishers.append(self._alarm_pub)
            self._ball_publishers.clear()
        for pub in publishers:
            self._undeclare(pub)
        self.bus._forget(self)

    @staticmethod
    def _undeclare(entity: Any) -> None:
        try:
            entity.undeclare()
        except Exception as exc:  # noqa: BLE001 - session may already be closed
            log.debug("undeclare failed: %s", exc)

    # ---- publisher thread -------------------------------------------------------------------
    def _publish_loop(self) -> None:
        while True:
            with self._cond:
                while not self._queue and not self._stopping:
                    self._cond.wait()
                if not self._queue:
                    return  # stopping and drained
                snapshot = self._queue.popleft()
            try:
                self._send(snapshot)
                self.published += 1
            except Exception as exc:  # noqa: BLE001 - nothing kills the publisher
                self.errors += 1
                if self.errors <= 3 or self.errors % 1000 == 0:
                    log.warning("bearing/%s: snapshot not published (%d so far): %s",
                                self.bearing_id, self.errors, _one_line(exc))

    def _send(self, snapshot: Snapshot) -> None:
        data = snapshot.to_dict()
        balls = data.get("balls") or []
        state_json = _dumps(data)
        with self._last_lock:
            self._last = (snapshot, state_json)
        self._state_pub.put(state_json)
        head = {"schema": data.get("schema"), "bearing_id": data.get("bearing_id", self.bearing_id),
                "time_s": data.get("time_s")}
        for position, ball in enumerate(balls):
            index = ball.get("index", position)
            pub = self._ball_publisher(int(index))
            if pub is None:
                return  # detaching
            pub.put(_dumps({**head, **ball}))

    def _ball_publisher(self, index: int) -> zenoh.Publisher | None:
        with self._pub_lock:
            pub = self._ball_publishers.get(index)
            if pub is None and not self._closed:
                pub = self.bus.session.declare_publisher(
                    f"{self.prefix}/ball/{index}", encoding=_JSON,
                    congestion_control=zenoh.CongestionControl.DROP)
                self._ball_publishers[index] = pub
            return pub

    def publish_alarm(self, event: dict) -> None:
        """Put one alarm event on `bearing/{id}/alarm` (called from the alarm hub's thread; events
        are rare, so they are put at once, not queued)."""
        with self._pub_lock:
            if self._publishers_gone:
                return
            if self._alarm_pub is None:
                self._alarm_pub = self.bus.session.declare_publisher(f"{self.prefix}/alarm", encoding=_JSON)
            pub = self._alarm_pub
        pub.put(_dumps({**event, "bearing_id": self.bearing_id}))

    # ---- zenoh callbacks: hand off only -----------------------------------------------------
    def _on_setpoint_sample(self, sample: zenoh.Sample) -> None:
        try:
            payload = sample.payload.to_bytes()
        except Exception:  # noqa: BLE001
            payload = b""
        self._enqueue_control(("setpoint", payload))

    def _on_query(self, query: zenoh.Query) -> None:
        self._enqueue_control(("query", query))

    def _enqueue_control(self, item: tuple[str, Any]) -> None:
        with self._control_cond:
            if self._closed:
                self._finish_query(item, error="twin detached")
                return
            if len(self._control) >= _CONTROL_QUEUE_SIZE:
                old = self._control.popleft()
                if old is not None and old[0] == "setpoint":
                    self.setpoints_dropped += 1
                self._finish_query(old, error="busy")
            self._control.append(item)
            self._control_cond.notify()

    @staticmethod
    def _finish_query(item: Any, error: str) -> None:
        if item is None or item[0] != "query":
            return
        query = item[1]
        with contextlib.suppress(Exception):
            query.reply_err(_dumps({"error": error}), encoding=_JSON)
        with contextlib.suppress(Exception):
            query.drop()

    # ---- control thread ---------------------------------------------------------------------
    def _control_loop(self) -> None:
        while True:
            with self._control_cond:
                while not self._control:
                    self._control_cond.wait()
                item = self._control.popleft()
            if item is None:
                with self._control_cond:  # answer what is left, then stop
                    rest, self._control = list(self._control), collections.deque()
                for other in rest:
                    self._finish_query(other, error="twin detached")
                return
            kind, value = item
            try:
                if kind == "setpoint":
                    self._handle_setpoint(value)
                else:
                    self._handle_query(value)
            except Exception as exc:  # noqa: BLE001 - nothing kills the control thread
                log.warning("bearing/%s: %s handling failed: %s", self.bearing_id, kind, _one_line(exc))

    def _handle_setpoint(self, payload: bytes) -> None:
        self.setpoints_received += 1
        try:
            result = self._on_setpoint(payload)
            if not isinstance(result, dict):
                raise TypeError(f"setpoint handler returned {type(result).__name__}, not a dict")
            result = dict(result)
            result.setdefault("accepted", False)
            text = _dumps({**result, "bearing_id": self.bearing_id})
        except Exception as exc:  # noqa: BLE001 - every failure is a refusal
            text = _dumps({"accepted": False, "error": _one_line(exc), "bearing_id": self.bearing_id})
        if not self._publishers_gone:
            self._result_pub.put(text)

    def _handle_query(self, query: zenoh.Query) -> None:
        try:
            snapshot = self._get_snapshot()
            if snapshot is None:
                query.reply_err(_dumps({"error": "no snapshot yet"}), encoding=_JSON)
                return
            with self._last_lock:
                last = self._last
            text = last[1] if last is not None and last[0] is snapshot else _dumps(snapshot.to_dict())
            query.reply(f"{self.prefix}/snapshot", text, encoding=_JSON)  # concrete key
            self.queries_answered += 1
        except Exception as exc:  # noqa: BLE001
            with contextlib.suppress(Exception):
                query.reply_err(_dumps({"error": _one_line(exc)}), encoding=_JSON)
        finally:
            with contextlib.suppress(Exception):
                query.drop()


def _closer(ref: weakref.ref) -> Callable[[], None]:
    """atexit safety net: close the bus if the owner forgot (an open session can hang exit)."""
    def close() -> None:
        bus = ref()
        if bus is not None:
            bus.close()
    return close


class ZenohBus:
    """Owns the service's single zenoh session and the channels of the twins attached to it.

    >>> bus = ZenohBus(listen=["tcp/127.0.0.1:7447"], connect=[])
    >>> channel = bus.attach_twin("t1", runner.latest_snapshot, intake)   # intake(payload) -> dict
    >>> runner.add_sink(channel)      # runner calls channel.publish(snapshot) at its publish rate
    >>> bus.close()                   # in the lifespan `finally`: detaches all, closes the session

    Open it after any fork (in the service lifespan), never at import time.
    """

    def __init__(self, listen: Iterable[str] | None = None, connect: Iterable[str] | None = None,
                 mode: str = "peer", *, gossip: bool = True):
        self.listen = list(DEFAULT_LISTEN if listen is None else listen)
        self.connect = list(connect or [])
        self.mode = mode
        self._channels: dict[str, TwinChannel] = {}
        self._lock = threading.Lock()
        self._closed = True  # until the session is open
        config = make_config(self.listen, self.connect, mode, gossip=gossip)  # ValueError on typos
        try:
            self.session = zenoh.open(config)
        except Exception as exc:
            raise RuntimeError(f"zenoh: cannot open a {mode} session (listen={self.listen}, "
                               f"connect={self.connect}): {_one_line(exc)}") from exc
        self._closed = False
        self._atexit = _closer(weakref.ref(self))
        atexit.register(self._atexit)

    @classmethod
    def open(cls, listen: Iterable[str] | None = None, connect: Iterable[str] | None = None,
             mode: str = "peer", **kwargs: Any) -> ZenohBus:
        """Open a bus (same as the constructor)."""
        return cls(listen, connect, mode, **kwargs)

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()

    @property
    def closed(self) -> bool:
        return self._closed

    @property
    def channels(self) -> dict[str, TwinChannel]:
        with self._lock:
            return dict(self._channels)

    def attach_twin(self, bearing_id: str, get_snapshot: Callable[[], Snapshot | None],
                    on_setpoint: Callable[[bytes], dict], *,
                    queue_size: int = DEFAULT_QUEUE_SIZE) -> TwinChannel:
        """Declare the twin's publishers, setpoint subscriber, snapshot queryable and liveliness
        token; return its channel (a SnapshotSink: hand it to the runner)."""
        if not isinstance(bearing_id, str) or not _ID_RE.match(bearing_id):
            raise ValueError(f"bearing id {bearing_id!r} is not a single key-expression chunk "
                             "(letters, digits, _ . - ... ; no '/', '*', '$', '?', '#')")
        with self._lock:
            if self._closed:
                raise RuntimeError("zenoh bus is closed")
            if bearing_id in self._channels:
                raise ValueError(f"twin {bearing_id!r} is already attached to this bus")
            channel = TwinChannel(self, bearing_id, get_snapshot, on_setpoint, queue_size=queue_size)
            self._channels[bearing_id] = channel
        return channel

    def detach_twin(self, bearing_id: str) -> None:
        channel = self.channels.get(bearing_id)
        if channel is not None:
            channel.detach()

    def _forget(self, channel: TwinChannel) -> None:
        with self._lock:
            if self._channels.get(channel.bearing_id) is channel:
                del self._channels[channel.bearing_id]

    def close(self) -> None:
        """Detach every twin and close the session. Idempotent, never raises."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
            channels = list(self._channels.values())
        for channel in channels:
            try:
                channel.detach()
            except Exception as exc:  # noqa: BLE001
                log.warning("detach %s failed: %s", channel.bearing_id, exc)
        try:
            self.session.close()
        except Exception as exc:  # noqa: BLE001
            log.warning("zenoh session close failed: %s", exc)
        with contextlib.suppress(Exception):
            atexit.unregister(self._atexit)


def wait_until(predicate: Callable[[], bool], timeout_s: float, interval_s: float = 0.02) -> bool:
    """Poll `predicate` until true or the timeout passes (helper for tests and start-up)."""
    deadline = time.monotonic() + timeout_s
    while True:
        if predicate():
            return True
        if time.monotonic() >= deadline:
            return False
        time.sleep(interval_s)
