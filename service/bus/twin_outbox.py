"""What a twin puts on the zenoh bus: the state message, its balls, vibration windows, waveform
chunks and alarms (the outgoing half of `service.bus.zenoh_bus.TwinChannel`).

`publish` puts the STATE message on the caller's thread (the stepping thread that built the
snapshot, or the publish worker in fast mode): the snapshot's contract JSON (`Snapshot.to_json`,
0.06 ms for a 9-ball twin in a loop, 0.2 ms right after a frame) and one `put` on an express
publisher with congestion control DROP, which never waits on the network. Then it appends the
snapshot to a bounded deque (drop-oldest, counted in `dropped`) for the outbox's own thread,
which puts the rest (one message per ball, the vibration window, the waveform chunks), in
batches: everything queued at once, then a pause of `batch_interval_s` (20 ms: the thread wakes
about 50 times a second whatever the number of snapshots and waveform blocks; these messages
come at most that much later). Publishers other than the state's are declared with their first
message.

Only what subscribers take is serialised. Each publisher but the alarms' has a zenoh matching
listener (`Matching`): zenoh tells it when a subscriber, local or remote, starts or stops
matching the publisher's key, so whether a message has a taker is an attribute read. A message
nobody subscribes to is neither serialised nor put (counted in `unmatched`). `publish` and
`publish_waveform` look first, on the caller's thread: a snapshot or a waveform block none of
whose messages has a subscriber is counted there and never queued, so the outbox's thread is not
woken for it (a wake-up of an idle thread costs 70-140 us of CPU on a 2-core VM; reading the nine
balls' `Publisher.matching_status` after a frame cost about 60 us). The ball messages are the
outbox's largest cost when subscribed (nine JSON documents per snapshot, 0.14 ms). The state
message too is made only for a subscriber; the snapshot queryable answers with the same text,
the last one made (`last_state`) or made for the query from the latest snapshot. A subscriber
declared later is matched from then on: zenoh keeps no history of these messages for it anyway
(congestion control DROP, no publication cache).
"""

from __future__ import annotations

import collections
import logging
import threading
from typing import Any

import zenoh

from service.bus.wire import JSON_ENCODING, Bus, Waveform, dumps, one_line, spectrum_json
from service.keys import ALARM, STATE, VIBRATION, VIBRATION_WAVEFORM, ball_key, twin_key
from twin.snapshot import Snapshot
from twin.snapshot_blocks import ball_json_items
from twin.snapshot_frame import SnapshotFrame

log = logging.getLogger(__name__)

VIBRATION_SCHEMA = "bearing-twin/vibration/1"


class TwinOutbox:
    """The publishers of one twin and the thread that puts all but the state message."""

    def __init__(self, bus: Bus, bearing_id: str, *, queue_size: int, batch_interval_s: float = 0.02):
        if queue_size < 1:
            raise ValueError("queue_size must be >= 1")
        self.batch_interval_s = float(batch_interval_s)
        self._stopped = threading.Event()
        self.bus = bus
        self.bearing_id = bearing_id
        self.prefix = twin_key(bus.prefix, bearing_id)
        self._queue: collections.deque = collections.deque(maxlen=queue_size)
        self._cond = threading.Condition()
        self._stopping = False
        self._dropped = 0
        self.published = 0  # snapshots fully put on the bus
        self.errors = 0  # snapshots that failed to serialise or put
        self.waveform_chunks = 0  # waveform chunks put on the bus
        self.unmatched = 0  # messages not made: no subscriber matched their key
        self._last: tuple[Any, str] | None = None  # (snapshot object, its state JSON)
        self._last_lock = threading.Lock()
        self._pub_lock = threading.Lock()
        self._gone = False  # publishers undeclared
        self._ball_publishers: dict[int, zenoh.Publisher] = {}
        self._ball_matching: dict[int, Matching] = {}  # ball index -> its publisher's listener
        self._matching: dict[int, Matching] = {}  # id(publisher) -> its matching listener
        self._alarm_pub: zenoh.Publisher | None = None  # declared with the first alarm
        self._vibration_pub: zenoh.Publisher | None = None  # declared with the first window
        self._waveform_pub: zenoh.Publisher | None = None  # declared with the first samples
        self._last_window_end_s: float | None = None
        # express: the state message is sent at once, not held for a batch with other messages
        self._state_pub = bus.session.declare_publisher(
            twin_key(bus.prefix, bearing_id, STATE),
            encoding=JSON_ENCODING,
            congestion_control=zenoh.CongestionControl.DROP,
            express=True,
        )
        self._state_matching = self._matching[id(self._state_pub)] = Matching(self._state_pub)
        self._thread = threading.Thread(target=self._loop, name=f"zenoh-pub-{bearing_id}", daemon=True)
        self._thread.start()

    @property
    def dropped(self) -> int:
        """Snapshots dropped because the queue was full (oldest first)."""
        return self._dropped

    def last_state(self, snapshot: Snapshot) -> str | None:
        """The state JSON already made for `snapshot` (None when it was not the last one put):
        the snapshot itself, or the tree of the frame that was put."""
        with self._last_lock:
            last = self._last
        if last is None:
            return None
        put = last[0]
        if put is snapshot or (isinstance(put, SnapshotFrame) and put.built is snapshot):
            return last[1]
        return None

    # ---- any thread -------------------------------------------------------------------------
    accepts_frames = True  # Publisher hands it SnapshotFrames (service.core.sinks)

    def publish(self, snapshot: Snapshot | SnapshotFrame) -> None:
        """Put the state message now and queue the rest; never waits on the network, never raises."""
        try:
            self._send_state(snapshot)
        except Exception as exc:  # noqa: BLE001 - a sink never raises into the physics
            self.errors += 1
            if self.errors <= 3 or self.errors % 1000 == 0:
                log.warning("%s: state not published (%d so far): %s", self.prefix, self.errors, one_line(exc))
            return
        if not self._taken_by_nobody(snapshot):
            self._enqueue(snapshot)

    def publish_waveform(self, blocks: list) -> None:
        """Queue accelerometer blocks for `P/{id}/vibration/waveform`; returns at once (counted
        in `unmatched` and not queued while nobody subscribes)."""
        pub = self._lazy_publisher("_waveform_pub", VIBRATION_WAVEFORM, "application/octet-stream")
        if pub is not None and not self._matched(pub):
            with self._cond:
                self.unmatched += 1
            return
        self._enqueue(Waveform(list(blocks)))

    def _taken_by_nobody(self, snapshot: Any) -> bool:
        """Whether no subscriber takes any of the snapshot's ball or vibration messages; then
        they are counted here (`unmatched`, and the snapshot in `published`). False for anything
        but a snapshot or a frame (the outbox's thread makes and counts its messages)."""
        if isinstance(snapshot, SnapshotFrame):
            balls = snapshot.ball_arrays.ball_count
        elif isinstance(snapshot, Snapshot):
            balls = len(snapshot.balls)
        else:
            return False
        for index in range(balls):
            watch = self._ball_matching.get(index)
            if watch is None and self._ball_publisher(index) is not None:  # declared with the first snapshot
                watch = self._ball_matching.get(index)
            if watch is None:  # detaching
                return False
            if watch.matching:
                return False
        block = getattr(snapshot, "vibration", None)
        window_end = None if block is None else block.window_end_s
        new_window = window_end is not None and window_end != self._last_window_end_s
        if new_window:
            pub = self._lazy_publisher("_vibration_pub", VIBRATION, JSON_ENCODING)
            if pub is None or self._matched(pub):
                return False
            self._last_window_end_s = window_end
        with self._cond:
            self.unmatched += balls + int(new_window)
            self.published += 1
        return True

    def publish_alarm(self, event: dict) -> None:
        """Put one alarm event on `P/{id}/alarm` at once (events are rare)."""
        with self._pub_lock:
            if self._gone:
                return
            if self._alarm_pub is None:
                self._alarm_pub = self.bus.session.declare_publisher(
                    twin_key(self.bus.prefix, self.bearing_id, ALARM), encoding=JSON_ENCODING
                )
            pub = self._alarm_pub
        pub.put(dumps({**event, "bearing_id": self.bearing_id}))

    def stop(self, timeout_s: float) -> None:
        """Put what is queued (bounded by `timeout_s`), stop the thread, undeclare the publishers."""
        with self._cond:
            self._stopping = True
            self._cond.notify()
        self._stopped.set()
        if self._thread is not threading.current_thread():
            self._thread.join(timeout_s)
        with self._pub_lock:
            self._gone = True
            publishers = [self._state_pub, *self._ball_publishers.values()]
            publishers += [p for p in (self._alarm_pub, self._vibration_pub, self._waveform_pub) if p is not None]
            self._ball_publishers.clear()
            watches = list(self._matching.values())
            self._matching.clear()
            self._ball_matching.clear()
        for watch in watches:
            watch.close()
        for pub in publishers:
            undeclare(pub)

    def _send_state(self, snapshot: Snapshot | SnapshotFrame) -> None:
        """The state message, serialised once (kept for the snapshot queryable) and put; neither
        while no subscriber takes it (counted in `unmatched`)."""
        with self._pub_lock:
            if self._gone or self._stopping:
                return
            pub = self._state_pub
        if not self._state_matching.matching:
            with self._cond:
                self.unmatched += 1
            return
        state_json = snapshot.to_json()
        with self._last_lock:
            self._last = (snapshot, state_json)
        pub.put(state_json)

    def _enqueue(self, item: Any) -> None:
        """Append to the queue (the oldest item drops out when full, counted); never raises."""
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

    # ---- the outbox's thread ----------------------------------------------------------------
    def _loop(self) -> None:
        while True:
            with self._cond:
                while not self._queue and not self._stopping:
                    self._cond.wait()
                if not self._queue:
                    return  # stopping and drained
                batch = list(self._queue)
                self._queue.clear()
            for item in batch:
                try:
                    if isinstance(item, Waveform):
                        self._send_waveform(item.blocks)
                        continue
                    self._send(item)
                    with self._cond:  # also counted by `publish` on the caller's thread
                        self.published += 1
                except Exception as exc:  # noqa: BLE001 - nothing kills the publisher
                    self.errors += 1
                    if self.errors <= 3 or self.errors % 1000 == 0:
                        log.warning(
                            "%s: snapshot not published (%d so far): %s", self.prefix, self.errors, one_line(exc)
                        )
            if self.batch_interval_s > 0.0:
                self._stopped.wait(self.batch_interval_s)  # what comes meanwhile waits for the next batch

    def _send(self, snapshot: Snapshot | SnapshotFrame) -> None:
        """The ball and vibration messages of a snapshot whose state `publish` has put. A ball's
        message is made only for a matching subscriber: from a frame's arrays
        (twin.snapshot_blocks.ball_json_items, the text pydantic gives the ball's model), from a
        snapshot by pydantic's serialiser (a Snapshot never holds NaN/Infinity, its models
        refuse them; json.dumps of the merged dicts held the GIL about five times longer)."""
        # each ball's message is the head's fields then the ball's: {"schema":..,"bearing_id":..,"time_s":..,<ball>}
        head: str | None = None
        if isinstance(snapshot, SnapshotFrame):
            texts: list[str] | None = None
            for index in range(snapshot.ball_arrays.ball_count):
                pub = self._ball_publisher(index)
                if pub is None:
                    return  # detaching
                if not self._matched(pub):
                    self.unmatched += 1
                    continue
                if texts is None:
                    texts, head = ball_json_items(snapshot.ball_arrays), self._ball_head(snapshot)
                pub.put(f"{head}{texts[index][1:]}")
        else:
            head = self._ball_head(snapshot)
            for position, ball in enumerate(snapshot.balls):
                index = getattr(ball, "index", position)
                pub = self._ball_publisher(int(index))
                if pub is None:
                    return  # detaching
                if not self._matched(pub):
                    self.unmatched += 1
                    continue
                pub.put(head + ball.model_dump_json(by_alias=True)[1:])
        self._send_vibration(snapshot)

    def _ball_head(self, snapshot: Snapshot | SnapshotFrame) -> str:
        """The fields a ball message starts with, open for the ball's: `{"schema":..,"bearing_id":..,"time_s":..,`."""
        head = {
            "schema": snapshot.schema_,
            "bearing_id": snapshot.bearing_id or self.bearing_id,
            "time_s": snapshot.time_s,
        }
        return dumps(head)[:-1] + ","

    def _send_vibration(self, snapshot: Snapshot | SnapshotFrame) -> None:
        """`P/{id}/vibration` when the snapshot carries a new accelerometer window."""
        block = getattr(snapshot, "vibration", None)
        if block is None:
            return
        end = block.window_end_s
        if end == self._last_window_end_s:
            return
        self._last_window_end_s = end
        pub = self._lazy_publisher("_vibration_pub", VIBRATION, JSON_ENCODING)
        if pub is not None and not self._matched(pub):
            self.unmatched += 1
            return
        if pub is not None:
            vib = block.model_dump(by_alias=True, mode="json")
            spectra = {
                key: spectrum_json(getattr(block, key, None)) for key in ("envelope_spectrum", "amplitude_spectrum")
            }
            defects = [d.model_dump(by_alias=True, mode="json") for d in (getattr(snapshot, "defects", None) or ())]
            pub.put(
                dumps(
                    {
                        "schema": VIBRATION_SCHEMA,
                        "bearing_id": self.bearing_id,
                        "seq": snapshot.seq,
                        "time_s": snapshot.time_s,
                        "defects": defects,
                        **vib,
                        **{k: v for k, v in spectra.items() if v is not None},
                    }
                )
            )

    def _send_waveform(self, blocks: list) -> None:
        """One binary chunk per block on `P/{id}/vibration/waveform` (twin.vibration.waveform)."""
        from twin.vibration.waveform import encode_chunk

        pub = self._lazy_publisher("_waveform_pub", VIBRATION_WAVEFORM, "application/octet-stream")
        if pub is None:
            return
        if not self._matched(pub):
            self.unmatched += 1
            return
        for block in blocks:
            if len(block.samples) == 0:
                continue
            pub.put(
                encode_chunk(self.bearing_id, self.waveform_chunks, block.t0_s, block.sample_rate_hz, block.samples)
            )
            self.waveform_chunks += 1

    def _lazy_publisher(self, attr: str, suffix: str, encoding: str) -> zenoh.Publisher | None:
        with self._pub_lock:
            pub = getattr(self, attr)
            if pub is None and not self._gone:
                pub = self.bus.session.declare_publisher(
                    twin_key(self.bus.prefix, self.bearing_id, suffix),
                    encoding=encoding,
                    congestion_control=zenoh.CongestionControl.DROP,
                )
                self._matching[id(pub)] = Matching(pub)
                setattr(self, attr, pub)
            return pub

    def _ball_publisher(self, index: int) -> zenoh.Publisher | None:
        with self._pub_lock:
            pub = self._ball_publishers.get(index)
            if pub is None and not self._gone and not self._stopping:
                pub = self.bus.session.declare_publisher(
                    ball_key(self.bus.prefix, self.bearing_id, index),
                    encoding=JSON_ENCODING,
                    congestion_control=zenoh.CongestionControl.DROP,
                )
                self._matching[id(pub)] = self._ball_matching[index] = Matching(pub)
                self._ball_publishers[index] = pub
            return pub

    def _matched(self, pub: zenoh.Publisher) -> bool:
        """Whether a subscriber matches `pub`'s key (its listener's word; `matched` without one)."""
        watch = self._matching.get(id(pub))
        return watch.matching if watch is not None else matched(pub)


class Matching:
    """Whether any subscriber, local or remote, matches a publisher's key, kept up to date by a
    zenoh matching listener (zenoh calls it on each change, and at once when a subscriber
    already matches), so a read is an attribute, not a call into zenoh. True while zenoh cannot
    say (no listener): the message is then made and put, as `matched` does."""

    def __init__(self, pub: zenoh.Publisher):
        self.matching = True
        self._changes = 0
        self._listener: Any = None
        try:
            self._listener = pub.declare_matching_listener(self._on_change)
        except Exception as exc:  # noqa: BLE001 - without a listener every message is made
            log.debug("no matching listener: %s", one_line(exc))
            return
        seen = self._changes
        now = matched(pub)  # the status when declared; the listener keeps it from here
        if self._changes == seen:
            self.matching = now

    def _on_change(self, status: Any) -> None:
        self._changes += 1
        self.matching = bool(status.matching)

    def close(self) -> None:
        """Undeclare the listener; never raises."""
        if self._listener is not None:
            undeclare(self._listener)
            self._listener = None


def matched(pub: zenoh.Publisher) -> bool:
    """Whether a subscriber (local or remote) matches the publisher's key; True when zenoh
    cannot say (the message is then made and put as before). zenoh-python's stub types
    `matching_status` as bool; it is a MatchingStatus, always truthy: its `.matching` says."""
    try:
        status: Any = pub.matching_status
        return bool(status.matching)
    except Exception:  # noqa: BLE001 - a closed session: the put fails and is counted as before
        return True


def undeclare(entity: Any) -> None:
    """Undeclare a zenoh entity; never raises (the session may already be closed)."""
    try:
        entity.undeclare()
    except Exception as exc:  # noqa: BLE001 - session may already be closed
        log.debug("undeclare failed: %s", exc)
