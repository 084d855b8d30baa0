"""Publishing of a runner: what a frame captured becomes a snapshot for every sink.

Real-time mode. The stepping thread that ran the frame builds the snapshot at its end and hands
it to the sinks itself (`Twin.frame`: a `twin.snapshot_frame.SnapshotFrame`, the balls and
contacts as arrays in one compiled pass, the bearing-level blocks as a few pydantic models;
about 0.2 ms for a 9-ball twin right after its frame, while its arrays are still in the cache).
Why on the stepping thread: a hand-off to another thread costs more than the build. On the
2-core EPYC VM, waking an idle thread costs 70-140 us of CPU on each side, and a build that
comes alone (a frozen copy, then a cold capture on the worker) costs 0.5-0.6 ms instead of
0.2 (docs/performance.md, "What limits the service on this VM"). The stepping thread is the twin's only writer
and steps it again only after the delivery, so no copy is needed; the sinks only enqueue (the
zenoh channel also puts the state message, a few microseconds), so the delivery never waits on
I/O. A capture that carries setpoint timings (the frame that applies an outside setpoint) is
delivered the same way, so the state that reflects it goes out without a hop.

Fast mode (lossless: a scenario's samples must all arrive). The stepping thread takes a frozen
copy (`Twin.frozen`: the twin object shallow-copied with its state arrays copied) with the
real-time factor, the late fraction and the runner's status note of that moment, and the pool's
`PublishWorker` thread builds and delivers it, in capture order, while the twin steps on. At most
`max_pending` captures wait for the worker; one more makes the stepping thread wait. Without a
worker (before the runner starts) a capture is built and delivered at once.

Frames. The sinks that declare `accepts_frames` (the zenoh channel, the recorder, the alarm hub)
read the frame's arrays and its state JSON, written from them; any other sink gets the
`Snapshot`, whose per-ball pydantic tree the frame builds on the first read (about 0.1 ms). The
latest frame is `latest` (its tree, built for an HTTP read, OPC UA or /health at their own rate)
and `latest_json` (the state message already made for zenoh).

Sinks (zenoh channel, recorder, table) only enqueue (bounded, drop-oldest, counted: see
service.core.sinks); a sink that raises is counted and skipped. The runner's own status note (a
fallback, a caught error) is written into the snapshot's `status` beside the engine's. The
accelerometer samples the twin produced since the last capture (`Twin.drain_waveform`) are
drained with each capture and handed, after the snapshot, to the sinks that have
`publish_waveform(bearing_id, blocks, seq=...)` (zenoh `.../vibration/waveform`, the recorder).
The first snapshot that reflects an accepted setpoint completes its `SetpointTiming`
(published = when it was handed to the sinks). One delivery of a twin at a time
(`_deliver_lock`), in capture order, with gapless sequence numbers.
"""

from __future__ import annotations

import collections
import logging
import threading
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any

from service.core.capacity import CpuMeter
from service.core.mailbox import SetpointTiming
from service.core.pool import PublishWorker
from service.core.sinks import SnapshotSink
from twin.engine import Twin
from twin.snapshot import Snapshot
from twin.snapshot_frame import SnapshotFrame, as_snapshot

log = logging.getLogger(__name__)


@dataclass
class Capture:
    """A twin as a frame left it, waiting to become a snapshot."""

    twin: Twin
    real_time_factor: float | None
    late_fraction: float | None
    note: str | None
    timings: list[SetpointTiming] = field(default_factory=list)
    waveform: list = field(default_factory=list)  # accelerometer blocks drained with it


class Publisher:
    """Sinks, the latest snapshot, the status note and the captures waiting for the worker of
    one twin (see the module docstring)."""

    def __init__(
        self,
        bearing_id: str,
        sinks: Iterable[SnapshotSink] = (),
        timing_history: int = 10000,
        *,
        max_pending: int = 8,
        lossless: bool = False,
        clock: Callable[[], float] = time.perf_counter,
    ):
        self.bearing_id = bearing_id
        self.max_pending = max(1, int(max_pending))
        self.lossless = lossless
        self.clock = clock
        self._lock = threading.Lock()
        self._cv = threading.Condition(threading.Lock())
        self._deliver_lock = threading.Lock()  # one delivery of this twin at a time, in capture order
        self._sinks: list[SnapshotSink] = list(sinks)
        self._latest: Snapshot | SnapshotFrame | None = None
        self._latest_json: tuple[Snapshot | SnapshotFrame, bytes] | None = None  # (snapshot, its contract JSON)
        self._json_lock = threading.Lock()
        self._unpublished: list[SetpointTiming] = []
        self._pending: collections.deque[Capture] = collections.deque()
        self._timings: collections.deque[SetpointTiming] = collections.deque(maxlen=timing_history)
        self._worker: PublishWorker | None = None
        self._seq: int | None = None
        self._carry: list[SetpointTiming] = []  # timings of a capture whose snapshot failed (worker)
        self.note: str | None = None  # the runner's word on the twin's state, or None
        self.published = 0
        self.sink_errors = 0
        self.cpu = CpuMeter(window=50)  # CPU s per snapshot built and handed to the sinks

    # ---- any thread ------------------------------------------------------------------------
    @property
    def latest(self) -> Snapshot | None:
        """The latest published snapshot (its pydantic tree is built by the first read)."""
        latest = self._latest
        return None if latest is None else as_snapshot(latest)

    def latest_json(self) -> bytes | None:
        """The latest snapshot as its contract JSON (`Snapshot.to_json`, UTF-8), made at most once
        per published snapshot: the state message already made for zenoh, or the first read
        after a publication (about 0.05 ms for a 9-ball twin, from the frame's arrays); every
        later read until the next publication gets the same bytes, and concurrent first readers
        wait for one serialisation instead of each making their own. None before the first
        snapshot."""
        snap = self._latest
        if snap is None:
            return None
        cached = self._latest_json
        if cached is not None and cached[0] is snap:
            return cached[1]
        with self._json_lock:
            cached = self._latest_json
            if cached is None or cached[0] is not snap:
                cached = self._latest_json = (snap, snap.to_json().encode())
            return cached[1]

    @property
    def sinks(self) -> list[SnapshotSink]:
        with self._lock:
            return list(self._sinks)

    def add_sink(self, sink: SnapshotSink) -> None:
        with self._lock:
            if sink not in self._sinks:
                self._sinks.append(sink)

    def remove_sink(self, sink: SnapshotSink) -> None:
        with self._lock:
            if sink in self._sinks:
                self._sinks.remove(sink)

    @property
    def dropped(self) -> int:
        """Snapshots dropped by the sinks so far."""
        total = 0
        for sink in self.sinks:
            try:
                total += int(sink.dropped)
            except Exception:  # noqa: BLE001 - a sink without a usable counter counts 0
                pass
        return total

    @property
    def pending(self) -> int:
        """Captures waiting for the worker."""
        with self._cv:
            return len(self._pending)

    def timings(self) -> list[SetpointTiming]:
        """Completed setpoint timings (oldest first)."""
        with self._lock:
            return list(self._timings)

    def recent_timings(self, n: int) -> list[SetpointTiming]:
        """The newest `n` completed setpoint timings (oldest first)."""
        with self._lock:
            k = len(self._timings)
            return [self._timings[i] for i in range(max(0, k - n), k)]

    def status_text(self, engine_status: str, note: str | None = None) -> str:
        """The snapshot status: the engine's, with the runner's note in front."""
        note = self.note if note is None else note
        if note is None:
            return engine_status
        if engine_status and engine_status != "ok":
            return f"{note}; engine: {engine_status}"
        return note

    def attach(self, worker: PublishWorker | None) -> None:
        """Build and deliver on `worker` from now on (None: in the calling thread)."""
        self._worker = worker

    def after_pending(self, fn: Callable[[], None]) -> None:
        """Run `fn` once every capture queued so far is delivered (on the worker, or now)."""
        worker = self._worker
        if worker is None or not worker.submit(fn):
            self._drain()
            fn()

    # ---- stepping thread -------------------------------------------------------------------
    def await_snapshot(self, timings: list[SetpointTiming]) -> None:
        """These setpoints were applied: complete their timings at the next publication."""
        self._unpublished.extend(timings)

    def set_latest(self, snapshot: Snapshot) -> None:
        """The latest snapshot without publishing it (before the runner starts)."""
        self._latest = snapshot

    def capture(
        self,
        twin: Twin,
        real_time_factor: float | None,
        late_fraction: float | None = None,
        *,
        stop: threading.Event | None = None,
    ) -> None:
        """Capture `twin` for publication: built and delivered now in real-time mode, a frozen copy
        for the worker in fast mode (see the module docstring)."""
        worker = self._worker
        timings, self._unpublished = self._unpublished, []
        if timings:
            now = self.clock()
            for t in timings:
                t.captured_wall_s = now
        waveform = twin.drain_waveform()  # [] without the housing
        if not self.lossless or worker is None or not worker.alive:
            with self._deliver_lock:
                self._drain_locked()  # captures a stopped worker left behind go first
                self._deliver(Capture(twin, real_time_factor, late_fraction, self.note, timings, waveform))
            return
        cap = Capture(twin.frozen(), real_time_factor, late_fraction, self.note, timings, waveform)
        with self._cv:
            while len(self._pending) >= self.max_pending and worker.alive and not (stop is not None and stop.is_set()):
                self._cv.wait(0.1)
            self._pending.append(cap)
        if not worker.submit(self._deliver_next):
            self._drain()

    # ---- worker thread (or the caller without one) -----------------------------------------
    def _drain(self) -> None:
        with self._deliver_lock:
            self._drain_locked()

    def _drain_locked(self) -> None:
        while self._deliver_one():
            pass

    def _deliver_next(self) -> bool:
        with self._deliver_lock:
            return self._deliver_one()

    def _deliver_one(self) -> bool:
        """Deliver the oldest waiting capture (holding `_deliver_lock`); False when none waits."""
        with self._cv:
            if not self._pending:
                return False
            cap = self._pending.popleft()
            self._cv.notify_all()
        self._deliver(cap)
        return True

    def _deliver(self, cap: Capture) -> None:
        c0 = time.thread_time()
        if self._carry:
            cap.timings[:0], self._carry = self._carry, []
        try:
            tw = cap.twin
            if self._seq is not None:
                tw.seq = self._seq  # the publisher numbers the snapshots of its twin
            head: dict[str, object] = {"late_fraction": cap.late_fraction} if cap.late_fraction is not None else {}
            if cap.note is not None:
                head["status"] = self.status_text(tw.status, cap.note)
            frame = tw.frame(cap.real_time_factor, **head)
            self._seq = frame.seq
        except Exception as exc:  # noqa: BLE001 - counted; the twin goes on
            self.sink_errors += 1
            self._carry = cap.timings  # completed by the next snapshot that is built
            log.warning("twin %s: snapshot failed: %s", self.bearing_id, exc)
            return
        if cap.timings:
            built = self.clock()
            for t in cap.timings:
                t.built_wall_s = built
        self._latest = frame
        self.published += 1
        for sink in self.sinks:
            try:
                # a sink that declares accepts_frames reads a frame as it reads a snapshot (service.core.sinks)
                item: Any = frame if getattr(sink, "accepts_frames", False) else frame.snapshot
                sink.publish(item)
                if cap.waveform:
                    publish_waveform = getattr(sink, "publish_waveform", None)
                    if publish_waveform is not None:
                        publish_waveform(self.bearing_id, cap.waveform, seq=frame.seq)
            except Exception as exc:  # noqa: BLE001 - a sink never stops the physics
                self.sink_errors += 1
                if self.sink_errors <= 5:
                    log.warning("twin %s: sink %r failed: %s", self.bearing_id, sink, exc)
        if cap.timings:
            now = self.clock()
            for t in cap.timings:
                t.published_wall_s, t.seq = now, frame.seq
            with self._lock:
                self._timings.extend(cap.timings)
        self.cpu.add(time.thread_time() - c0, 1.0)
