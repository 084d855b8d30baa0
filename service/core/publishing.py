"""Publishing of a runner: the snapshot taken after a frame goes to every sink.

Sinks (zenoh channel, recorder, table) only enqueue (bounded, drop-oldest, counted: see
service.core.sinks), so publishing never blocks the physics; a sink that raises is counted and
skipped. The runner's own status note (a fallback, a caught error) is written into the
snapshot's `status` beside the engine's. The first snapshot that reflects an accepted setpoint
completes its `SetpointTiming`.
"""

from __future__ import annotations

import collections
import logging
import threading
from collections.abc import Iterable

from service.core.mailbox import SetpointTiming
from service.core.sinks import SnapshotSink
from twin.engine import Twin
from twin.snapshot import Snapshot

log = logging.getLogger(__name__)


class Publisher:
    """Sinks, the latest snapshot and the status note of one twin."""

    def __init__(self, bearing_id: str, sinks: Iterable[SnapshotSink] = (), timing_history: int = 10000):
        self.bearing_id = bearing_id
        self._lock = threading.Lock()
        self._sinks: list[SnapshotSink] = list(sinks)
        self._latest: Snapshot | None = None
        self._unpublished: list[SetpointTiming] = []
        self._timings: collections.deque[SetpointTiming] = collections.deque(maxlen=timing_history)
        self.note: str | None = None     # the runner's word on the twin's state, or None
        self.published = 0
        self.sink_errors = 0

    # ---- any thread ------------------------------------------------------------------------
    @property
    def latest(self) -> Snapshot | None:
        return self._latest

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
            except Exception:  # noqa: BLE001, S110 - a sink without a usable counter counts 0
                pass
        return total

    def timings(self) -> list[SetpointTiming]:
        """Completed setpoint timings (oldest first)."""
        with self._lock:
            return list(self._timings)

    def status_text(self, engine_status: str) -> str:
        """The snapshot status: the engine's, with the runner's note in front."""
        if self.note is None:
            return engine_status
        if engine_status and engine_status != "ok":
            return f"{self.note}; engine: {engine_status}"
        return self.note

    # ---- runner thread ---------------------------------------------------------------------
    def await_snapshot(self, timings: list[SetpointTiming]) -> None:
        """These setpoints were applied: complete their timings at the next publication."""
        self._unpublished.extend(timings)

    def set_latest(self, snapshot: Snapshot) -> None:
        """The latest snapshot without publishing it (before the runner starts)."""
        self._latest = snapshot

    def publish(self, twin: Twin, real_time_factor: float | None, now: float) -> Snapshot:
        """Take a snapshot of `twin` and hand it to every sink."""
        snap = twin.snapshot(real_time_factor=real_time_factor)
        if self.note is not None:
            snap = snap.model_copy(update={"status": self.status_text(snap.status)})
        self._latest = snap
        self.published += 1
        for sink in self.sinks:
            try:
                sink.publish(snap)
            except Exception as exc:  # noqa: BLE001 - a sink never stops the physics
                self.sink_errors += 1
                if self.sink_errors <= 5:
                    log.warning("twin %s: sink %r failed: %s", self.bearing_id, sink, exc)
        if self._unpublished:
            done, self._unpublished = self._unpublished, []
            for t in done:
                t.published_wall_s, t.seq = now, snap.seq
            with self._lock:
                self._timings.extend(done)
        return snap
