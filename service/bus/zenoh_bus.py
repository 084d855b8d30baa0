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
    P/{id}/temperature       a measured node temperature in (subscriber): JSON {"node":
                             "outer_ring" | "housing" | "oil", "temperature_c": ...} as PUT
                             /v1/bearings/{id}/temperature; same admission as a setpoint
    P/{id}/temperature/result  what became of it (JSON: accepted, node, temperature_c, or
                             the refusal: accepted false, status, field)
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
Python queue) and return. A `TwinChannel` is three parts, each with its own job:

* its `TwinOutbox` (service.bus.twin_outbox) puts what the twin publishes. `publish` puts the
  STATE message itself, on the caller's thread (the runner's publish worker, or its stepping
  thread for the snapshot of a setpoint, service.core.publishing): the snapshot's contract JSON
  and one `put` on an express publisher with congestion control DROP, which never waits on the
  network. Handing it to a thread of ours first cost a wake-up of a thread at the I/O priority
  (service.core.priority) and a slower serialisation there: 1.4 ms at the median and up to 12 ms
  of the PUT -> zenoh state latency. The rest (one message per ball, the vibration window, the
  waveform) goes through a bounded deque (drop-oldest, counted in `dropped`) to the outbox's
  thread. There is NO rate limiter here: the runner decides how often it calls `publish`.
* its `TwinInbox` (service.bus.twin_inbox) takes setpoints, defects and measured windows and
  answers snapshot and owner queries on its control thread (calls `on_setpoint(payload)`,
  publishes the result). Every exception from the callee is a refusal; nothing kills the thread.
* the channel itself holds the liveliness token and detaches the parts in order.

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
from service.bus.twin_inbox import CONTROL_QUEUE_SIZE, TwinInbox
from service.bus.twin_outbox import TwinOutbox, undeclare
from service.bus.wire import one_line as _one_line
from service.bus.wire import quoted as _quoted
from service.core.errors import InputError
from service.keys import ALIVE, DEFAULT_PREFIX, TWIN_ID_RE, check_prefix, twin_key
from twin.snapshot import Snapshot

log = logging.getLogger(__name__)

DEFAULT_LISTEN = ["tcp/127.0.0.1:7447"]
DEFAULT_QUEUE_SIZE = 64
_CONTROL_QUEUE_SIZE = CONTROL_QUEUE_SIZE


_ZID_RE = re.compile(r"^[0-9a-f]{1,32}$")  # a zenoh id as zenoh writes it (hex)


def make_config(
    listen: Iterable[str] | None = None,
    connect: Iterable[str] | None = None,
    mode: str = "peer",
    *,
    gossip: bool = True,
    access: ZenohAccess | None = None,
    prefix: str | Iterable[str] = DEFAULT_PREFIX,
) -> zenoh.Config:
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
    if secured and access is not None:
        access.apply(config, [prefix] if isinstance(prefix, str) else list(prefix), listening=bool(listen))
    return config


def client_config(
    connect: Iterable[str],
    *,
    access: ZenohAccess | None = None,
    listen: Iterable[str] | None = None,
    prefix: str = DEFAULT_PREFIX,
) -> zenoh.Config:
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


class TwinChannel:
    """One twin on the bus; a `SnapshotSink`. Created by `ZenohBus.attach_twin`.

    Three jobs, three parts: the `TwinOutbox` (service.bus.twin_outbox) puts what the twin
    publishes, the `TwinInbox` (service.bus.twin_inbox) takes and answers what reaches it, and
    the channel holds the liveliness token and detaches the whole in order."""

    def __init__(
        self,
        bus: ZenohBus,
        bearing_id: str,
        get_snapshot: Callable[[], Snapshot | None],
        on_setpoint: Callable[[bytes], dict],
        *,
        queue_size: int = DEFAULT_QUEUE_SIZE,
        flush_timeout_s: float = 2.0,
        on_defects: Callable[[bytes], dict] | None = None,
        on_measured: Callable[[bytes], dict] | None = None,
        on_temperature: Callable[[bytes], dict] | None = None,
    ):
        self.bus = bus
        self.bearing_id = bearing_id
        self.prefix = twin_key(bus.prefix, bearing_id)  # the twin's key: P/{id}
        self._flush_timeout_s = flush_timeout_s
        self._closed = False
        self._close_lock = threading.Lock()
        self.outbox = TwinOutbox(bus, bearing_id, queue_size=queue_size)
        self.inbox = TwinInbox(
            bus,
            bearing_id,
            get_snapshot,
            on_setpoint,
            on_defects=on_defects,
            on_measured=on_measured,
            on_temperature=on_temperature,
            known_state=self.outbox.last_state,
        )
        self._token = bus.session.liveliness().declare_token(twin_key(bus.prefix, bearing_id, ALIVE))

    # ---- SnapshotSink -----------------------------------------------------------------------
    accepts_frames = True  # the outbox writes a frame's messages from its arrays

    def publish(self, snapshot: Snapshot) -> None:
        """Put the snapshot's state message now and queue the rest (balls, vibration); never waits
        on the network, never raises. No rate limiting: the caller (runner) decides the rate."""
        self.outbox.publish(snapshot)

    def publish_waveform(self, bearing_id: str, blocks: list, seq: int | None = None) -> None:
        """Queue accelerometer blocks (twin.accelerometer.WaveformBlock) for
        `P/{id}/vibration/waveform`; returns at once, never raises."""
        self.outbox.publish_waveform(blocks)

    def publish_alarm(self, event: dict) -> None:
        """Put one alarm event on `P/{id}/alarm` (called from the alarm hub's thread)."""
        self.outbox.publish_alarm(event)

    # ---- figures ----------------------------------------------------------------------------
    @property
    def dropped(self) -> int:
        """Snapshots dropped because the outbox queue was full (oldest first)."""
        return self.outbox.dropped

    published = property(lambda self: self.outbox.published, doc="Snapshots fully put on the bus.")
    errors = property(lambda self: self.outbox.errors, doc="Snapshots that failed to serialise or put.")
    waveform_chunks = property(lambda self: self.outbox.waveform_chunks, doc="Waveform chunks put on the bus.")
    unmatched = property(
        lambda self: self.outbox.unmatched,
        doc="Messages not made: no subscriber matched their key (service.bus.twin_outbox).",
    )
    setpoints_received = property(lambda self: self.inbox.setpoints_received, doc="Setpoint messages taken.")
    setpoints_refused_busy = property(
        lambda self: self.inbox.setpoints_refused_busy,
        doc="Setpoints refused with 429 because the control queue was full.",
    )
    queries_answered = property(lambda self: self.inbox.queries_answered, doc="Snapshot queries answered.")

    @property
    def closed(self) -> bool:
        return self._closed

    def close(self) -> None:
        """Same as `detach`."""
        self.detach()

    def detach(self) -> None:
        """Withdraw the twin: liveliness token first (watchers see it go), then the subscribers and
        queryables, answer what waits, flush queued snapshots (bounded by flush_timeout_s), stop
        the threads and undeclare the publishers. Idempotent, never raises."""
        with self._close_lock:
            if self._closed:
                return
            self._closed = True
        undeclare(self._token)
        self.inbox.close_entrances()
        self.inbox.stop(self._flush_timeout_s)
        self.outbox.stop(self._flush_timeout_s)
        self.bus._forget(self)


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

    def __init__(
        self,
        listen: Iterable[str] | None = None,
        connect: Iterable[str] | None = None,
        mode: str = "peer",
        *,
        gossip: bool = True,
        prefix: str = DEFAULT_PREFIX,
        access: ZenohAccess | None = None,
        owner: dict | None = None,
        claim_timeout_s: float = 2.0,
        trust_claims: bool = True,
    ):
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
        config = make_config(
            self.listen, self.connect, mode, gossip=gossip, access=self.access, prefix=self.prefix
        )  # ValueError on typos
        try:
            self.session = zenoh.open(config)
        except Exception as exc:
            raise RuntimeError(
                f"zenoh: cannot open a {mode} session (listen={self.listen}, connect={self.connect}): {_one_line(exc)}"
            ) from exc
        self.zid = str(self.session.info.zid())
        self._closed = False
        self._atexit = _closer(weakref.ref(self))
        atexit.register(self._atexit)

    @classmethod
    def open(
        cls,
        listen: Iterable[str] | None = None,
        connect: Iterable[str] | None = None,
        mode: str = "peer",
        **kwargs: Any,
    ) -> ZenohBus:
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

    def attach_twin(
        self,
        bearing_id: str,
        get_snapshot: Callable[[], Snapshot | None],
        on_setpoint: Callable[[bytes], dict],
        *,
        queue_size: int = DEFAULT_QUEUE_SIZE,
        on_defects: Callable[[bytes], dict] | None = None,
        on_measured: Callable[[bytes], dict] | None = None,
        on_temperature: Callable[[bytes], dict] | None = None,
    ) -> TwinChannel:
        """Declare the twin's publishers, setpoint subscriber, snapshot and owner queryables and
        liveliness token; return its channel (a SnapshotSink: hand it to the runner).

        InputError 409 (field `id`) naming the other process when the id is taken under this
        prefix anywhere on the zenoh network (see the module docstring)."""
        if not isinstance(bearing_id, str) or not TWIN_ID_RE.match(bearing_id):
            raise ValueError(
                f"bearing id {bearing_id!r} is not a single key-expression chunk "
                "(letters, digits, _ . - ... ; no '/', '*', '$', '?', '#')"
            )
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
                log.warning(
                    "twin %r: a zenoh peer holds the liveliness token %s/alive, but zenoh did not "
                    "authenticate it (zenoh access control is off while the HTTP API needs a token): "
                    "the claim is not trusted and the twin starts here",
                    bearing_id,
                    key,
                )
            channel = TwinChannel(
                self,
                bearing_id,
                get_snapshot,
                on_setpoint,
                queue_size=queue_size,
                on_defects=on_defects,
                on_measured=on_measured,
                on_temperature=on_temperature,
            )
            others = self._claimants(key) if self.trust_claims else []
            if others:  # claimed at the same moment elsewhere: withdraw
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
        return {"key": twin_key(self.prefix, bearing_id), "bearing_id": bearing_id, **self._owner, "zid": self.zid}

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
            replies = self.session.get(
                f"{key}/owner",
                target=zenoh.QueryTarget.ALL,
                consolidation=zenoh.ConsolidationMode.NONE,
                timeout=self.claim_timeout_s,
            )
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
            log.warning(
                "twin %r already runs under %r in process %s on %s%s, zenoh id %s (as its owner answer says)",
                bearing_id,
                self.prefix,
                _quoted(o.get("pid")),
                _quoted(o.get("host")),
                f" (HTTP {_quoted(o['http'])})" if o.get("http") else "",
                z or _quoted(o.get("zid")),
            )
        return InputError.one(
            "id",
            f"twin {bearing_id!r} already runs under {self.prefix!r} in {who}; "
            "twin ids are unique per key prefix across the zenoh network: choose "
            "another id or prefix (this service's log names the process)",
            status_code=409,
        )

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
