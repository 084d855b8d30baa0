"""`AlarmHub`: the service's alarms, evaluated off the physics threads and handed to subscribers.

A `SnapshotSink` on every runner: `publish(snapshot)` only appends to a bounded queue
(drop-oldest, counted) and returns, so a runner thread does no alarm work. One daemon thread
takes the queue in batches, at most one batch per `batch_interval_s` (0.1 s: ten wake-ups a
second for every twin together instead of one per snapshot; an alarm comes at most that much
wall time later, its times are the twin's), runs each twin's `AlarmEvaluator`
(service.core.alarms) on every snapshot in order and hands every `AlarmEvent` to the
subscribers, in order: the zenoh channel of the twin (`bearing/{id}/alarm`),
the rerun recorder, the OPC UA facade (service.wiring and the registry subscribe them). A
subscriber must not block (enqueue and return); one that raises is counted and skipped.

`observe_measured(comparison)` queues a measured-window comparison (service.core.measured; the
registry makes it a listener of every twin's comparator) in the same order as the snapshots: the
`measured_*` alarms follow the windows.

Twins are added and forgotten by the registry; snapshots of a twin the hub does not know (a late
one after a delete) are ignored.
"""

from __future__ import annotations

import collections
import logging
import threading
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from service.core.alarm_inputs import inputs_from_snapshot
from service.core.alarms import Alarm, AlarmEvaluator, AlarmEvent
from service.settings import AlarmSettings
from twin.snapshot import Snapshot
from twin.snapshot_frame import SnapshotFrame

log = logging.getLogger(__name__)

AlarmSubscriber = Callable[[AlarmEvent], None]


@dataclass(frozen=True)
class MeasuredItem:
    """A measured-window comparison queued beside the snapshots."""

    bearing_id: str
    comparison: Mapping[str, Any]


class AlarmHub:
    """Alarm evaluators of every twin of one service (see the module docstring)."""

    def __init__(
        self,
        settings: AlarmSettings | None = None,
        *,
        queue_size: int = 256,
        wall_clock: Callable[[], float] = time.time,
        batch_interval_s: float = 0.1,
    ):
        self.settings = settings or AlarmSettings()
        self.batch_interval_s = float(batch_interval_s)
        self._closing = threading.Event()
        self._wall_clock = wall_clock
        self._queue: collections.deque[Snapshot | SnapshotFrame | MeasuredItem] = collections.deque(maxlen=queue_size)
        self._cond = threading.Condition()
        self._evaluators: dict[str, AlarmEvaluator] = {}
        self._history: dict[str, collections.deque[AlarmEvent]] = {}
        self._subscribers: list[AlarmSubscriber] = []
        self._lock = threading.Lock()
        self._busy = False
        self._closed = False
        self._dropped = 0
        self.evaluated = 0
        self.subscriber_errors = 0
        self._thread = threading.Thread(target=self._run, name="alarms", daemon=True)
        self._thread.start()

    # ---- twins and subscribers ---------------------------------------------------------------
    def add_twin(self, bearing_id: str) -> None:
        with self._lock:
            self._evaluators[bearing_id] = AlarmEvaluator(bearing_id, self.settings, self._wall_clock)
            self._history[bearing_id] = collections.deque(maxlen=self.settings.history)

    def forget(self, bearing_id: str) -> None:
        with self._lock:
            self._evaluators.pop(bearing_id, None)
            self._history.pop(bearing_id, None)

    def subscribe(self, callback: AlarmSubscriber) -> None:
        """Call `callback(event)` for every alarm event (from the hub's thread)."""
        with self._lock:
            if callback not in self._subscribers:
                self._subscribers.append(callback)

    # ---- reads, any thread -------------------------------------------------------------------
    def states(self, bearing_id: str) -> list[Alarm]:
        """Every alarm of the twin (active or not); [] for an unknown twin."""
        with self._lock:
            ev = self._evaluators.get(bearing_id)
            return ev.states() if ev is not None else []

    def active(self, bearing_id: str) -> list[Alarm]:
        return [a for a in self.states(bearing_id) if a.active]

    def events(self, bearing_id: str, limit: int | None = None) -> list[AlarmEvent]:
        """The twin's latest alarm events, oldest first (at most `limit`)."""
        with self._lock:
            history = list(self._history.get(bearing_id, ()))
        return history if limit is None else history[-limit:] if limit > 0 else []

    # ---- SnapshotSink ------------------------------------------------------------------------
    accepts_frames = True  # its inputs read a frame's arrays (service.core.alarm_inputs)

    def publish(self, snapshot: Snapshot | SnapshotFrame) -> None:
        self._put(snapshot)

    def observe_measured(self, comparison: Mapping[str, Any]) -> None:
        """Queue a measured-window comparison of a twin (a MeasuredComparator listener: never blocks)."""
        self._put(MeasuredItem(str(comparison.get("bearing_id")), comparison))

    def _put(self, item: Snapshot | SnapshotFrame | MeasuredItem) -> None:
        with self._cond:
            if self._closed:
                return
            if len(self._queue) == self._queue.maxlen:
                self._dropped += 1
            self._queue.append(item)
            self._cond.notify()

    @property
    def dropped(self) -> int:
        return self._dropped

    def close(self) -> None:
        """Evaluate what is queued, then stop the thread (idempotent)."""
        with self._cond:
            if self._closed:
                return
            self._closed = True
            self._cond.notify()
        self._closing.set()
        if self._thread is not threading.current_thread():
            self._thread.join(5.0)

    def wait_idle(self, timeout_s: float = 10.0) -> bool:
        """Wait until every queued snapshot is evaluated and its events handed out."""
        deadline = time.monotonic() + timeout_s
        with self._cond:
            while self._queue or self._busy:
                left = deadline - time.monotonic()
                if left <= 0:
                    return False
                self._cond.wait(min(left, 0.05))
        return True

    # ---- the hub's thread --------------------------------------------------------------------
    def _run(self) -> None:
        while True:
            with self._cond:
                while not self._queue and not self._closed:
                    self._cond.wait()
                if not self._queue:
                    return
                batch = list(self._queue)
                self._queue.clear()
                self._busy = True
            try:
                for item in batch:
                    try:
                        self._evaluate(item)
                    except Exception:
                        log.exception("alarms: evaluating a snapshot of %s failed", item.bearing_id)
            finally:
                with self._cond:
                    self._busy = False
                    self._cond.notify_all()
            if self.batch_interval_s > 0.0:
                self._closing.wait(self.batch_interval_s)  # what comes meanwhile waits for the next batch

    def _evaluate(self, item: Snapshot | SnapshotFrame | MeasuredItem) -> None:
        with self._lock:
            ev = self._evaluators.get(item.bearing_id)
            if ev is None:
                return
            if isinstance(item, MeasuredItem):
                events = ev.update_measured(item.comparison)
            else:
                events = ev.update(inputs_from_snapshot(item, self.settings))
            self.evaluated += 1
            if not events:
                return
            self._history[item.bearing_id].extend(events)
            subscribers = list(self._subscribers)
        for event in events:
            log.info("alarm %s/%s %s: %s", event.bearing_id, event.alarm_id, event.transition, event.message)
            for callback in subscribers:
                try:
                    callback(event)
                except Exception as exc:  # noqa: BLE001 - a subscriber never stops the others
                    self.subscriber_errors += 1
                    if self.subscriber_errors <= 5:
                        log.warning("alarm subscriber %r failed: %s", callback, exc)
