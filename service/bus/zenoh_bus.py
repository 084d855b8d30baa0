"""The zenoh bus: ONE zenoh session for the whole service, one `TwinChannel` per twin.

Key expressions (docs/architecture.md, schema "bearing-twin/state/1"), under the service's key
prefix P (`zenoh_prefix`, default `bearing`; site / line / asset, e.g. `plant1/line2/motor7`):

    P/{id}/state             snapshot JSON (publisher)
    P/{id}/ball/{i}          one ball: the ball's fields plus schema, bearing_id, time_s
    P/{id}/setpoint          setpoint JSON in (subscriber); no token: who may put is zenoh's
                             access control (service.bus.access)
    P/{id}/setpoint/result   what became of each setpoint message (publisher), one result for
                             each: {"accepted": true, "setpoint": {...}} or
                             {"accepted": false, "status": 403|413|422|429, "error": "..."};
                             always carries bearing_id (429 also when too many wait: never
                             dropped unanswered)
    P/{id}/snapshot          queryable: replies with the latest snapshot JSON
    P/{id}/owner             queryable: which process runs the twin (pid, host, zenoh id, HTTP)
    P/{id}/alarm             alarm events JSON, schema "bearing-twin/alarm/1" (publisher;
                             service.core.alarms, handed over by the alarm hub)
    P/{id}/defects           local defects JSON in (subscriber): {"defects": [...]}
                             or the list, [] clears (service.core.defects); same rules as a setpoint
    P/{id}/defects/result    what became of each defects message, like setpoint/result
    P/{id}/vibration         the vibration indicators of each new accelerometer window, JSON,
                             schema "bearing-twin/vibration/1": bearing_id, seq and time_s of the
                             snapshot, the active defects, and every field of the snapshot's
                             `vibration` block (twin.snapshot.VibrationState), plus the window's
                             full spectra, which the state message leaves out:
                             `envelope_spectrum` and `amplitude_spectrum`, each {"start_hz",
                             "step_hz", "bins", "units": "m/s^2", "amplitude_m_s2": [...]}
                             (bin k at start_hz + k step_hz; 6 significant digits). Envelope: 0 Hz
                             to min(half the envelope band, 5 x max(BPFI, 2 x BSF)) at
                             1 / window_s; acceleration: 0 - fs/2, power-summed into <= 2000 bins
                             (twin.vibration.indicators). ~42 kB per 1 s window (6208)
    P/{id}/vibration/waveform  accelerometer samples, binary (twin.vibration.waveform: header
                             "BTWF" v1, float32 little-endian m/s^2; one chunk per block the twin
                             produced, its own chunk seq), not JSON numbers
    P/{id}/vibration/measured  a measured accelerometer window in (subscriber): binary, header
                             "BTVM" v1 + float32 little-endian (service.core.measured); same
                             admission as a setpoint
    P/{id}/vibration/comparison  its analysis beside the twin's prediction, residual and alarms
                             (JSON), or the refusal (accepted false, status, field)
    P/{id}/alive             liveliness token while the twin is attached

One id per prefix in the whole zenoh network: `attach_twin` first asks for the liveliness token
P/{id}/alive and refuses (InputError 409) when another process has it; after declaring its own,
it asks P/{id}/owner again and withdraws if another process answers (two processes claiming the
same id at once: neither, or only one, keeps it). Only claims the bus may trust refuse an id
(`trust_claims`): with zenoh access control on, zenoh authenticated every peer and only services
may declare P/*/alive or answer P/*/owner (service.bus.access); with nothing secured (no HTTP
token either) every peer is as trusted as any HTTP client. With an HTTP token but no zenoh access
control, anyone who reaches the endpoint could squat an id, so a claim there is logged and the
twin starts anyway. The 409 never repeats what the other peer said (its pid, host, URL are remote
text): it names the zenoh id zenoh itself reports for the reply; the service log names the rest,
quoted.

Threads. zenoh runs its callbacks on its own threads; ours only hand work off (append to a
Python queue) and return. Each channel owns two daemon threads:

* `TwinChannel.publish` puts the STATE message itself, on the caller's thread (the runner's
  publish worker, service.core.publishing): the snapshot's contract JSON (`Snapshot.to_json`,
  pydantic's serialiser, ~0.06 ms for a 9-ball twin) and one `put` on a publisher with
  congestion control DROP, which never waits on the network (a full transmission queue drops
  the message). Handing it to a thread of ours first cost a wake-up of a thread at the I/O
  priority (service.core.priority) and a slower serialisation there: 1.4 ms at the median and
  up to 12 ms of the PUT -> zenoh state latency. Then it appends the snapshot to a bounded deque
  (drop-oldest, counted in `dropped`) for the publisher thread, which puts the rest (one message
  per ball, the vibration window). There is NO rate limiter here: the runner decides how often
  it calls `publish` (e.g. 50 Hz); every call is published.
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
* zenoh >= 1.9 has no "failover brokering": a router does not relay between two PEERS that are
  not linked to each other. Whatever joins a router without listening itself (a service with
  --zenoh-connect, the monitor, soak) is therefore a zenoh CLIENT: every message goes through
  the router (and its access-control rules).
* with access control on (service.bus.access) gossip scouting is off: a secured node opens
  links only to the endpoints it was given.
"""

from __future__ import annotations

import atexit
import collections
import contextlib
import json
import logging
import os
import re
import socket
import threading
import weakref
from collections.abc import Callable, Iterable
from typing import Any, Self

import zenoh

from service.bus.access import ZenohAccess
from service.keys import (ALARM, ALIVE, DEFAULT_PREFIX, DEFECTS, DEFECTS_RESULT, OWNER, SETPOINT, SETPOINT_RESULT,
                          SNAPSHOT, STATE, TWIN_ID_RE, VIBRATION_COMPARISON, VIBRATION_MEASURED, ball_key,
                          check_prefix, twin_key)
from service.core.errors import InputError
from twin.snapshot import Snapshot

log = logging.getLogger(__name__)

DEFAULT_LISTEN = ["tcp/127.0.0.1:7447"]
DEFAULT_QUEUE_SIZE = 64
_CONTROL_QUEUE_SIZE = 256
_JSON = "application/json"
VIBRATION_SCHEMA = "bearing-twin/vibration/1"


class _Waveform:
    """Accelerometer blocks queued with the snapshots (publisher thread)."""

    __slots__ = ("blocks",)

    def __init__(self, blocks: list):
        self.blocks = blocks
_ZID_RE = re.compile(r"^[0-9a-f]{1,32}$")            # a zenoh id as zenoh writes it (hex)


def make_config(listen: Iterable[str] | None = None, connect: Iterable[str] | None = None,
                mode: str = "peer", *, gossip: bool = True, access: ZenohAccess | None = None,
                prefix: str | Iterable[str] = DEFAULT_PREFIX) -> zenoh.Config:
    """A zenoh config that touches only what it is told.

    `listen` None means DEFAULT_LISTEN (loopback 7447); an empty list means do not listen.
    Multicast scouting is off (no UDP to 224.0.0.224); gossip scouting (over the configured
    links only) is on by default so that peers connected through a common peer find each other,
    and off with access control. `access`: authentication and, on a node that listens, the
    access-control rules for the key prefix(es) `prefix` (service.bus.access).
    """
    if mode not in ("peer", "client", "router"):
        raise ValueError(f"zenoh mode must be peer, client or router, got {mode!r}")
    listen = [check_endpoint(e) for e in (DEFAULT_LISTEN if listen is None else listen)]
    connect = [check_endpoint(e) for e in (connect or [])]
    if mode == "client" and listen:
        raise ValueError("a zenoh client does not listen: give no listen endpoint or use peer mode")
    secured = access is not None and access.enabled
    config = zenoh.Config()
    config.insert_json5("mode", json.dumps(mode))
    config.insert_json5("listen/endpoints", json.dumps(listen))
    config.insert_json5("connect/endpoints", json.dumps(connect))
    config.insert_json5("scouting/multicast/enabled", "false")
    config.insert_json5("scouting/gossip/enabled", json.dumps(bool(gossip) and not secured))
    if secured:
        access.apply(config, [prefix] if isinstance(prefix, str) else list(prefix), listening=bool(listen))
    return config


def client_config(connect: Iterable[str], *, access: ZenohAccess | None = None,
                  listen: Iterable[str] | None = None, prefix: str = DEFAULT_PREFIX) -> zenoh.Config:
    """The config of a bundled client (monitor, soak, benchmarks): a zenoh client of the
    endpoints (a router or a service), or a peer when it listens itself; credentials from the
    environment (BEARING_TWIN_ZENOH_USER / _PASSWORD, _TLS_*) unless `access` is given."""
    listen = list(listen or [])
    access = ZenohAccess.from_env() if access is None else access
    return make_config(listen, list(connect), "peer" if listen else "client", access=access, prefix=prefix)


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


def _quoted(value: Any, limit: int = 80) -> str:
    """Remote text for a log line: at most `limit` characters, quoted with control characters
    escaped (repr), so a peer cannot forge or split log lines."""
    return repr(str(value)[:limit])


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
        except Exception:  # noqa: BLE001 - fall back to str()
            pass
    text = " ".join(str(exc).split())
    return text or type(exc).__name__


def _dumps(obj: Any) -> str:
    """Contract JSON: compact, never NaN/Infinity (raises ValueError instead)."""
    return json.dumps(obj, allow_nan=False, separators=(",", ":"))


def _spectrum_json(spectrum: Any) -> dict | None:
    """A window's spectrum (twin.snapshot.Spectrum) for `P/{id}/vibration`: its axis and the
    amplitudes rounded to 6 significant digits (half the text of full doubles); None without one."""
    if spectrum is None:
        return None
    amp = spectrum.amplitude_m_s2
    return {"start_hz": spectrum.start_hz, "step_hz": spectrum.step_hz, "bins": len(amp), "units": "m/s^2",
            "amplitude_m_s2": [float(f"{a:.6g}") for a in amp]}


def _payload(sample: zenoh.Sample) -> bytes:
    """A sample's payload bytes; b"" when they cannot be read (the intake refuses those)."""
    try:
        return sample.payload.to_bytes()
    except Exception:  # noqa: BLE001
        return b""


class TwinChannel:
    """One twin on the bus; a `SnapshotSink`. Created by `ZenohBus.attach_twin`."""

    def __init__(self, bus: ZenohBus, bearing_id: str, get_snapshot: Callable[[], Snapshot | None],
                 on_setpoint: Callable[[bytes], dict], *, queue_size: int = DEFAULT_QUEUE_SIZE,
                 flush_timeout_s: float = 2.0, on_defects: Callable[[bytes], dict] | None = None,
                 on_measured: Callable[[bytes], dict] | None = None):
        if queue_size < 1:
            raise ValueError("queue_size must be >= 1")
        self.bus = bus
        self.bearing_id = bearing_id
        self.prefix = twin_key(bus.prefix, bearing_id)   # the twin's key: P/{id}
        self._get_snapshot = get_snapshot
        self._on_setpoint = on_setpoint
        self._on_defects = on_defects
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
        self.setpoints_refused_busy = 0   # setpoints refused (429 on the result key): control queue full
        self._busy_pending = 0      # of those, refusals not yet published
        self._busy_marked = 0       # 1 while a ("busy", None) marker waits in the control queue
        self.queries_answered = 0
        self._last: tuple[Any, str] | None = None  # (snapshot object, its state JSON)
        self._last_lock = threading.Lock()

        # control queue (zenoh callbacks -> control thread)
        self._control: collections.deque = collections.deque()
        self._control_cond = threading.Condition()

        self._ball_publishers: dict[int, zenoh.Publisher] = {}
        self._alarm_pub: zenoh.Publisher | None = None   # declared with the first alarm
        self._vibration_pub: zenoh.Publisher | None = None   # declared with the first window
        self._waveform_pub: zenoh.Publisher | None = None    # declared with the first samples
        self._last_window_end_s: float | None = None
        self.waveform_chunks = 0    # waveform chunks put on the bus
        self._pub_lock = threading.Lock()
        # express: the state message is sent at once, not held for a batch with other messages
        self._state_pub = session.declare_publisher(
            twin_key(bus.prefix, bearing_id, STATE), encoding=_JSON, congestion_control=zenoh.CongestionControl.DROP,
            express=True)
        # BLOCK, not DROP: a result is never lost in zenoh's transmission queue (with DROP, 13-18 of
        # 30 000 results of an `attack --record` zenoh flood never arrived); the back-pressure is the
        # control thread's bounded queue, which refuses further setpoints with 429
        self._result_pub = session.declare_publisher(
            twin_key(bus.prefix, bearing_id, SETPOINT_RESULT), encoding=_JSON,
            congestion_control=zenoh.CongestionControl.BLOCK)
        self._setpoint_sub = session.declare_subscriber(twin_key(bus.prefix, bearing_id, SETPOINT),
                                                        self._on_setpoint_sample)
        self._defects_sub = self._defects_result_pub = None
        if on_defects is not None:
            self._defects_result_pub = session.declare_publisher(
                twin_key(bus.prefix, bearing_id, DEFECTS_RESULT), encoding=_JSON,
                congestion_control=zenoh.CongestionControl.BLOCK)
            self._defects_sub = session.declare_subscriber(twin_key(bus.prefix, bearing_id, DEFECTS),
                                                           self._on_defects_sample)
        # measured accelerometer windows (service.core.measured: binary frame in, comparison out)
        self._on_measured = on_measured
        self._measured_sub = self._comparison_pub = None
        if on_measured is not None:
            self._comparison_pub = session.declare_publisher(
                twin_key(bus.prefix, bearing_id, VIBRATION_COMPARISON), encoding=_JSON,
                congestion_control=zenoh.CongestionControl.BLOCK)
            self._measured_sub = session.declare_subscriber(
                twin_key(bus.prefix, bearing_id, VIBRATION_MEASURED),
                lambda sample: self._enqueue_control(("measured", _payload(sample))))
        self._queryable = session.declare_queryable(twin_key(bus.prefix, bearing_id, SNAPSHOT), self._on_query)
        self._owner_queryable = session.declare_queryable(twin_key(bus.prefix, bearing_id, OWNER),
                                                          self._on_owner_query)
        self._token = session.liveliness().declare_token(twin_key(bus.prefix, bearing_id, ALIVE))

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
        """Put the snapshot's state message now and queue the rest (balls, vibration) for the
        publisher thread; never waits on the network or on that thread, never raises. A
        snapshot that cannot be serialised is counted in `errors` and not queued.

        No rate limiting: the caller (runner) decides the publish rate."""
        try:
            self._send_state(snapshot)
        except Exception as exc:  # noqa: BLE001 - a sink never raises into the physics
            self.errors += 1
            if self.errors <= 3 or self.errors % 1000 == 0:
                log.warning("%s: state not published (%d so far): %s", self.prefix, self.errors, _one_line(exc))
            return
        self._enqueue(snapshot)

    def _send_state(self, snapshot: Snapshot) -> None:
        """The state message, serialised once (kept for the snapshot queryable) and put."""
        with self._pub_lock:
            if self._publishers_gone or self._stopping:
                return
            pub = self._state_pub
        state_json = snapshot.to_json()
        with self._last_lock:
            self._last = (snapshot, state_json)
        pub.put(state_json)

    def _enqueue(self, item) -> None:
        """Append to the publish queue (the oldest item drops out when full, counted); never raises."""
        try:
            with self._cond:
                if self._stopping:
                    return
                if len(self._queue) == self._queue.maxlen:
                    self._dropped += 1
                self._queue.append(item)
                self._cond.notify()
        except Exception:  # noqa: BLE001 - a sink never raises into the physics
            pass

    def publish_waveform(self, bearing_id: str, blocks: list, seq: int | None = None) -> None:
        """Queue accelerometer blocks (twin.accelerometer.WaveformBlock) for
        `P/{id}/vibration/waveform`; returns at once, never raises (same queue as the snapshots)."""
        self._enqueue(_Waveform(list(blocks)))

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
        for entity in (self._token, self._setpoint_sub, self._defects_sub, self._measured_sub, self._queryable,
                       self._owner_queryable):
            if entity is not None:
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
            publishers += [p for p in (self._alarm_pub, self._defects_result_pub, self._vibration_pub,
                                       self._waveform_pub, self._comparison_pub) if p is not None]
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
                if isinstance(snapshot, _Waveform):
                    self._send_waveform(snapshot.blocks)
                    continue
                self._send(snapshot)
                self.published += 1
            except Exception as exc:  # noqa: BLE001 - nothing kills the publisher
                self.errors += 1
                if self.errors <= 3 or self.errors % 1000 == 0:
                    log.warning("%s: snapshot not published (%d so far): %s",
                                self.prefix, self.errors, _one_line(exc))

    def _send(self, snapshot: Snapshot) -> None:
        """The ball and vibration messages of a snapshot whose state `publish` has put. The JSON
        comes from pydantic's serialiser (a Snapshot never holds NaN/Infinity, its models refuse
        them): json.dumps of the merged dicts held the GIL about five times longer, the stepping
        threads waiting (service.core.priority)."""
        # each ball's message is the head's fields then the ball's: {"schema":..,"bearing_id":..,"time_s":..,<ball>}
        head = _dumps({"schema": snapshot.schema_, "bearing_id": snapshot.bearing_id or self.bearing_id,
                       "time_s": snapshot.time_s})[:-1] + ","
        for position, ball in enumerate(snapshot.balls):
            index = getattr(ball, "index", position)
            pub = self._ball_publisher(int(index))
            if pub is None:
                return  # detaching
            pub.put(head + ball.model_dump_json(by_alias=True)[1:])
        self._send_vibration(snapshot)

    def _send_vibration(self, snapshot: Snapshot) -> None:
        """`P/{id}/vibration` when the snapshot carries a new accelerometer window."""
        block = getattr(snapshot, "vibration", None)
        if block is None:
            return
        vib = block.model_dump(by_alias=True, mode="json")
        end = vib.get("window_end_s")
        if end == self._last_window_end_s:
            return
        self._last_window_end_s = end
        pub = self._lazy_publisher("_vibration_pub", "vibration", _JSON)
        if pub is not None:
            spectra = {key: _spectrum_json(getattr(block, key, None))
                       for key in ("envelope_spectrum", "amplitude_spectrum")}
            defects = [d.model_dump(by_alias=True, mode="json") for d in (getattr(snapshot, "defects", None) or ())]
            pub.put(_dumps({"schema": VIBRATION_SCHEMA, "bearing_id": self.bearing_id, "seq": snapshot.seq,
                            "time_s": snapshot.time_s, "defects": defects, **vib,
                            **{k: v for k, v in spectra.items() if v is not None}}))

    def _send_waveform(self, blocks: list) -> None:
        """One binary chunk per block on `P/{id}/vibration/waveform` (twin.vibration.waveform)."""
        from twin.vibration.waveform import encode_chunk

        pub = self._lazy_publisher("_waveform_pub", "vibration/waveform", "application/octet-stream")
        if pub is None:
            return
        for block in blocks:
            if len(block.samples) == 0:
                continue
            pub.put(encode_chunk(self.bearing_id, self.waveform_chunks, block.t0_s, block.sample_rate_hz,
                                 block.samples))
            self.waveform_chunks += 1

    def _lazy_publisher(self, attr: str, suffix: str, encoding: str) -> zenoh.Publisher | None:
        with self._pub_lock:
            pub = getattr(self, attr)
            if pub is None and not self._publishers_gone:
                pub = self.bus.session.declare_publisher(twin_key(self.bus.prefix, self.bearing_id, suffix),
                                                         encoding=encoding,
                                                         congestion_control=zenoh.CongestionControl.DROP)
                setattr(self, attr, pub)
            return pub

    def _ball_publisher(self, index: int) -> zenoh.Publisher | None:
        with self._pub_lock:
            pub = self._ball_publishers.get(index)
            if pub is None and not self._closed:
                pub = self.bus.session.declare_publisher(
                    ball_key(self.bus.prefix, self.bearing_id, index), encoding=_JSON,
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
                self._alarm_pub = self.bus.session.declare_publisher(
                    twin_key(self.bus.prefix, self.bearing_id, ALARM), encoding=_JSON)
            pub = self._alarm_pub
        pub.put(_dumps({**event, "bearing_id": self.bearing_id}))

    # ---- zenoh callbacks: hand off only -----------------------------------------------------
    def _on_setpoint_sample(self, sample: zenoh.Sample) -> None:
        self._enqueue_control(("setpoint", _payload(sample)))

    def _on_defects_sample(self, sample: zenoh.Sample) -> None:
        self._enqueue_control(("defects", _payload(sample)))

    def _on_query(self, query: zenoh.Query) -> None:
        self._enqueue_control(("query", query))

    def _on_owner_query(self, query: zenoh.Query) -> None:
        self._enqueue_control(("owner", query))

    def _enqueue_control(self, item: tuple[str, Any]) -> None:
        """Queue a setpoint or query for the control thread. Nothing is dropped unanswered: when
        `_CONTROL_QUEUE_SIZE` items wait, a new query is answered "busy" at once and a new
        setpoint is counted; the control thread then publishes one refusal (status 429, with
        retry_after_s) on the result key for each such setpoint."""
        with self._control_cond:
            if self._closed:
                self._finish_query(item, error="twin detached")
                return
            if len(self._control) - self._busy_marked >= _CONTROL_QUEUE_SIZE:
                if item[0] == "setpoint":
                    self.setpoints_refused_busy += 1
                    self._busy_pending += 1
                    if not self._busy_marked:        # one marker, beyond the bound
                        self._busy_marked = 1
                        self._control.append(("busy", None))
                        self._control_cond.notify()
                elif item[0] == "defects":           # rare: refused at once on its result key
                    self.setpoints_refused_busy += 1
                    if not self._publishers_gone and self._defects_result_pub is not None:
                        with contextlib.suppress(Exception):
                            self._defects_result_pub.put(self._busy_refusal("messages"))
                else:
                    self._finish_query(item, error="busy: too many requests waiting, retry")
                return
            self._control.append(item)
            self._control_cond.notify()

    @staticmethod
    def _finish_query(item: Any, error: str) -> None:
        if item is None or item[0] not in ("query", "owner"):
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
                if kind == "busy":
                    self._refuse_busy()
                elif kind == "setpoint":
                    self._handle_setpoint(value)
                elif kind == "defects":
                    self._handle_write(value, self._on_defects, self._defects_result_pub)
                elif kind == "measured":
                    self._handle_write(value, self._on_measured, self._comparison_pub)
                elif kind == "owner":
                    self._handle_owner_query(value)
                else:
                    self._handle_query(value)
            except Exception as exc:  # noqa: BLE001 - nothing kills the control thread
                log.warning("%s: %s handling failed: %s", self.prefix, kind, _one_line(exc))

    def _handle_setpoint(self, payload: bytes) -> None:
        self.setpoints_received += 1
        self._handle_write(payload, self._on_setpoint, self._result_pub)

    def _handle_write(self, payload: bytes, handler: Callable[[bytes], dict] | None, result_pub) -> None:
        """Call the intake, publish what became of the message on its result key."""
        try:
            result = handler(payload)
            if not isinstance(result, dict):
                raise TypeError(f"handler returned {type(result).__name__}, not a dict")
            result = dict(result)
            result.setdefault("accepted", False)
            text = _dumps({**result, "bearing_id": self.bearing_id})
        except Exception as exc:  # noqa: BLE001 - every failure is a refusal
            text = _dumps({"accepted": False, "error": _one_line(exc), "bearing_id": self.bearing_id})
        if not self._publishers_gone and result_pub is not None:
            result_pub.put(text)

    def _busy_refusal(self, what: str) -> str:
        """The result-key refusal (status 429) of a message of kind `what` (plural) that found
        the control queue full."""
        return _dumps({"accepted": False, "status": 429, "retry_after_s": 0.1,
                       "error": f"too many {what} waiting for twin {self.bearing_id!r} "
                       f"({_CONTROL_QUEUE_SIZE} queued, the most this twin queues): refused, retry",
                       "bearing_id": self.bearing_id})

    def _refuse_busy(self) -> None:
        """Publish one 429 refusal for each setpoint that found the control queue full."""
        with self._control_cond:
            count, self._busy_pending, self._busy_marked = self._busy_pending, 0, 0
        text = self._busy_refusal("setpoints")
        self.setpoints_received += count
        for _ in range(count):
            if self._publishers_gone:
                return
            self._result_pub.put(text)

    def _handle_query(self, query: zenoh.Query) -> None:
        try:
            snapshot = self._get_snapshot()
            if snapshot is None:
                query.reply_err(_dumps({"error": "no snapshot yet"}), encoding=_JSON)
                return
            with self._last_lock:
                last = self._last
            text = last[1] if last is not None and last[0] is snapshot else snapshot.to_json()
            query.reply(twin_key(self.bus.prefix, self.bearing_id, SNAPSHOT), text, encoding=_JSON)  # concrete key
            self.queries_answered += 1
        except Exception as exc:  # noqa: BLE001
            with contextlib.suppress(Exception):
                query.reply_err(_dumps({"error": _one_line(exc)}), encoding=_JSON)
        finally:
            with contextlib.suppress(Exception):
                query.drop()


    def _handle_owner_query(self, query: zenoh.Query) -> None:
        try:
            query.reply(twin_key(self.bus.prefix, self.bearing_id, OWNER), _dumps(self.bus.owner(self.bearing_id)),
                        encoding=_JSON)
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
                 mode: str = "peer", *, gossip: bool = True, prefix: str = DEFAULT_PREFIX,
                 access: ZenohAccess | None = None, owner: dict | None = None,
                 claim_timeout_s: float = 2.0, trust_claims: bool = True):
        """`prefix`: the key prefix P of every twin (docs/service.md "A fleet"); `access`: zenoh's
        authentication and access-control rules (service.bus.access); `owner`: what P/{id}/owner
        tells about this process besides pid, host and zenoh id (e.g. {"http": url});
        `claim_timeout_s`: how long the id clash check waits for answers [s]; `trust_claims`:
        whether another peer's liveliness token or owner answer may refuse an id (see the module
        docstring; False: such a claim is only logged)."""
        self.listen = list(DEFAULT_LISTEN if listen is None else listen)
        self.connect = list(connect or [])
        self.mode = mode
        self.prefix = check_prefix(prefix)
        self.access = access if access is not None else ZenohAccess()
        self.claim_timeout_s = float(claim_timeout_s)
        self.trust_claims = bool(trust_claims)
        self._owner = {"pid": os.getpid(), "host": socket.gethostname(), **(owner or {})}
        self._channels: dict[str, TwinChannel] = {}
        self._claiming: set[str] = set()
        self._lock = threading.Lock()
        self._closed = True  # until the session is open
        config = make_config(self.listen, self.connect, mode, gossip=gossip, access=self.access,
                             prefix=self.prefix)  # ValueError on typos
        try:
            self.session = zenoh.open(config)
        except Exception as exc:
            raise RuntimeError(f"zenoh: cannot open a {mode} session (listen={self.listen}, "
                               f"connect={self.connect}): {_one_line(exc)}") from exc
        self.zid = str(self.session.info.zid())
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
                    queue_size: int = DEFAULT_QUEUE_SIZE,
                    on_defects: Callable[[bytes], dict] | None = None,
                    on_measured: Callable[[bytes], dict] | None = None) -> TwinChannel:
        """Declare the twin's publishers, setpoint subscriber, snapshot and owner queryables and
        liveliness token; return its channel (a SnapshotSink: hand it to the runner).

        InputError 409 (field `id`) naming the other process when the id is taken under this
        prefix anywhere on the zenoh network (see the module docstring)."""
        if not isinstance(bearing_id, str) or not TWIN_ID_RE.match(bearing_id):
            raise ValueError(f"bearing id {bearing_id!r} is not a single key-expression chunk "
                             "(letters, digits, _ . - ... ; no '/', '*', '$', '?', '#')")
        with self._lock:
            if self._closed:
                raise RuntimeError("zenoh bus is closed")
            if bearing_id in self._channels or bearing_id in self._claiming:
                raise ValueError(f"twin {bearing_id!r} is already attached to this bus")
            self._claiming.add(bearing_id)
        try:
            key = twin_key(self.prefix, bearing_id)
            if self._alive_elsewhere(key):
                if self.trust_claims:
                    raise self._taken(bearing_id, self._claimants(key))
                log.warning("twin %r: a zenoh peer holds the liveliness token %s/alive, but zenoh did not "
                            "authenticate it (zenoh access control is off while the HTTP API needs a token): "
                            "the claim is not trusted and the twin starts here", bearing_id, key)
            channel = TwinChannel(self, bearing_id, get_snapshot, on_setpoint, queue_size=queue_size,
                                  on_defects=on_defects, on_measured=on_measured)
            others = self._claimants(key) if self.trust_claims else []
            if others:                      # claimed at the same moment elsewhere: withdraw
                channel.detach()
                raise self._taken(bearing_id, others)
            with self._lock:
                if self._closed:
                    channel.detach()
                    raise RuntimeError("zenoh bus is closed")
                self._channels[bearing_id] = channel
        finally:
            with self._lock:
                self._claiming.discard(bearing_id)
        return channel

    # ---- one id per prefix across processes ---------------------------------------------
    def owner(self, bearing_id: str) -> dict:
        """What P/{id}/owner answers: the twin's key, this process and its zenoh id."""
        return {"key": twin_key(self.prefix, bearing_id), "bearing_id": bearing_id, **self._owner,
                "zid": self.zid}

    def _alive_elsewhere(self, key: str) -> bool:
        """Whether a liveliness token `key`/alive exists on the network (ours are not: the
        caller checked its own channels)."""
        try:
            replies = self.session.liveliness().get(f"{key}/alive", timeout=self.claim_timeout_s)
            return any(reply.ok is not None for reply in replies)
        except Exception as exc:  # noqa: BLE001 - a failed check must not block creation
            log.warning("%s: liveliness check failed: %s", key, _one_line(exc))
            return False

    def _owners(self, key: str) -> list[dict]:
        """Every answer of `key`/owner (all queryables, no consolidation), as the peers sent it."""
        return [owner for _zid, owner in self._answers(key)]

    def _answers(self, key: str) -> list[tuple[str | None, dict]]:
        """(zenoh id of the replier as zenoh reports it, or None; the answer) for every answer of
        `key`/owner."""
        out = []
        try:
            replies = self.session.get(f"{key}/owner", target=zenoh.QueryTarget.ALL,
                                       consolidation=zenoh.ConsolidationMode.NONE,
                                       timeout=self.claim_timeout_s)
            for reply in replies:
                if reply.ok is None:
                    continue
                with contextlib.suppress(Exception):
                    data = json.loads(reply.ok.payload.to_bytes())
                    if isinstance(data, dict):
                        replier = str(reply.replier_id.zid) if reply.replier_id is not None else None
                        out.append((replier if replier and _ZID_RE.match(replier) else None, data))
        except Exception as exc:  # noqa: BLE001
            log.warning("%s: owner query failed: %s", key, _one_line(exc))
        return out

    def _claimants(self, key: str) -> list[tuple[str | None, dict]]:
        """The answers of `key`/owner from other processes than this one."""
        return [(zid, o) for zid, o in self._answers(key) if (zid or o.get("zid")) != self.zid]

    def _taken(self, bearing_id: str, claimants: list[tuple[str | None, dict]]) -> InputError:
        """The 409: the words are ours and the replier's zenoh id as zenoh reports it; what the
        other peer says about itself (pid, host, URL) goes to the log only, quoted."""
        zid = next((z for z, _o in claimants if z), None)
        who = f"another process (zenoh id {zid})" if zid else "another process"
        for z, o in claimants[:4]:
            log.warning("twin %r already runs under %r in process %s on %s%s, zenoh id %s (as its owner answer "
                        "says)", bearing_id, self.prefix, _quoted(o.get("pid")), _quoted(o.get("host")),
                        f" (HTTP {_quoted(o['http'])})" if o.get("http") else "", z or _quoted(o.get("zid")))
        return InputError.one("id", f"twin {bearing_id!r} already runs under {self.prefix!r} in {who}; "
                              "twin ids are unique per key prefix across the zenoh network: choose "
                              "another id or prefix (this service's log names the process)", status_code=409)

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
