"""`TwinRunner`: one thread per twin, the ONLY writer of that twin's state.

Loop (one iteration per frame, `frame_s` of simulated time, 1 ms by default)::

    scenarios.tick()          take over a new scenario, offer its updates (ScenarioDriver)
    mailbox.take()            the pending setpoint, admitted once at submission (Mailbox)
    faults.advance_frame()    twin.advance(frame_s), fall back when not held (FaultPolicy)
    pacing.publish_due()      publisher.publish(): snapshot to every sink (PacingClock, Publisher)
    pacing.wait_for_deadline()  real-time mode: sleep until the frame's wall-clock deadline

The jobs live in their own classes (service.core.pacing, .mailbox, .faults, .scenario_driver,
.publishing, .stats); this class owns the thread and the frame loop and offers their public
face (submit, start_scenario, latest, stats, ...).

Frame semantics. A setpoint (from the mailbox or a scenario at scenario time t) is in force for
the whole frame [t, t + frame_s); a snapshot taken at the end of a frame shows the setpoint that
was in force during it (so a ramp sampled at t shows the ramp's value at t - frame_s).

Errors. An exception in the loop is caught, counted (`errors`), logged, shown in the snapshots'
`status`, and the twin is warm-restarted at the setpoint in force; after
`max_consecutive_errors` failures in a row the runner stops and says so (`failed`). No NaN
reaches a snapshot: `Snapshot` refuses non-finite numbers, and a frame that fails is restarted
before the next snapshot is taken.

Who may submit and how often (token, size, rate) is the admission gate's job
(service.core.admission), before a setpoint reaches `submit`.
"""

from __future__ import annotations

import logging
import math
import threading
import time
from collections.abc import Callable, Iterable
from typing import Any

from pydantic import ValidationError

from service.core.errors import InputError, field_errors, setpoint_field_errors
from service.core.faults import Fallback, FaultPolicy
from service.core.mailbox import Mailbox, SetpointTiming
from service.core.pacing import PacingClock
from service.core.publishing import Publisher
from service.core.scenario_driver import ScenarioDriver, ScenarioHandle
from service.core.scenarios import ResolvedRun
from service.core.sinks import SnapshotSink
from service.core.stats import LoopCounters, health_record
from twin.engine import Twin
from twin.setpoint import Setpoint, SetpointError, SetpointLimits, SetpointUpdate
from twin.snapshot import Snapshot

log = logging.getLogger(__name__)

__all__ = ["ScenarioHandle", "SetpointTiming", "TwinRunner", "parse_update"]


def parse_update(data: Any, limits: SetpointLimits) -> SetpointUpdate:
    """A parsed setpoint body (dict) as a SetpointUpdate; InputError naming each field with the
    bearing's range for a wrong type, a non-finite number or an unknown field."""
    if isinstance(data, SetpointUpdate):
        return data
    if not isinstance(data, dict):
        raise InputError.one(None, f"a setpoint is a JSON object of fields {sorted(limits.ranges)}, got "
                             f"{type(data).__name__}", sorted(limits.ranges))
    try:
        return SetpointUpdate.model_validate(data)
    except ValidationError as exc:
        raise InputError(field_errors(exc.errors(), limits)) from None


class TwinRunner:
    """Runs one `Twin` in its own thread (see the module docstring)."""

    def __init__(self, twin: Twin, *, fast: bool = False, publish_rate_hz: float = 50.0,
                 frame_s: float = 0.001, sinks: Iterable[SnapshotSink] = (),
                 rtf_window_s: float = 1.0, resync_after_s: float = 0.25,
                 idle_without_scenario: bool = False, max_consecutive_errors: int = 20,
                 setpoint_publish_min_interval_s: float = 0.002, timing_history: int = 10000,
                 safe_after_frames: int = 20, max_restarts_per_frame: int = 2,
                 clock: Callable[[], float] = time.perf_counter):
        if not (publish_rate_hz > 0 and math.isfinite(publish_rate_hz)):
            raise ValueError(f"publish_rate_hz = {publish_rate_hz!r}: must be > 0 [Hz]")
        dt = twin.model.dt_s
        steps = round(frame_s / dt)
        if steps < 1:
            raise ValueError(f"frame_s = {frame_s!r} s is shorter than the time step {dt:g} s")
        self.twin = twin
        self.bearing_id = twin.bearing_id
        self.fast = bool(fast)
        self.publish_rate_hz = float(publish_rate_hz)
        self.frame_steps = steps
        self.frame_s = steps * dt
        self.idle_without_scenario = idle_without_scenario
        self.max_consecutive_errors = max_consecutive_errors
        self.limits: SetpointLimits = twin.limits
        self._clock = clock

        self.mailbox = Mailbox(twin.setpoint, self.limits, clock=clock)
        self.faults = FaultPolicy(twin.setpoint, self.limits, safe_after_frames=safe_after_frames,
                                  max_restarts_per_frame=max_restarts_per_frame)
        self.pacing = PacingClock(fast=self.fast, publish_period_s=1.0 / self.publish_rate_hz, clock=clock,
                                  rtf_window_s=rtf_window_s, resync_after_s=resync_after_s,
                                  setpoint_publish_min_interval_s=setpoint_publish_min_interval_s)
        self.publisher = Publisher(self.bearing_id, sinks, timing_history=timing_history)
        self.scenarios = ScenarioDriver()
        self.counters = LoopCounters()
        self._sim_frames = 0                 # frames advanced by this runner (integer: no drift)
        self._stop = threading.Event()
        self._wake = threading.Event()
        self._thread: threading.Thread | None = None

    # ---- public, any thread ------------------------------------------------------------------
    @property
    def mode(self) -> str:
        return "fast" if self.fast else "real_time"

    @property
    def running(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    @property
    def latest(self) -> Snapshot | None:
        """The latest published snapshot (None before start)."""
        return self.publisher.latest

    def latest_snapshot(self) -> Snapshot | None:
        """Same as `latest` (a callable for the zenoh queryable)."""
        return self.publisher.latest

    @property
    def sim_elapsed_s(self) -> float:
        """Simulated seconds advanced by this runner [s] (survives warm restarts of the twin)."""
        return self._sim_frames * self.frame_s

    @property
    def real_time_factor(self) -> float | None:
        return self.pacing.real_time_factor

    @property
    def target_setpoint(self) -> Setpoint:
        """The latest accepted setpoint (in force, or applied at the next frame)."""
        return self.mailbox.target

    @property
    def last_safe_setpoint(self) -> Setpoint:
        """The newest setpoint held for `safe_after_frames` frames without a restart."""
        return self.faults.last_safe

    # counters, for /health and the tests
    frames = property(lambda self: self.counters.frames)
    errors = property(lambda self: self.counters.errors)
    failed = property(lambda self: self.counters.failed)
    last_error = property(lambda self: self.counters.last_error)
    overruns = property(lambda self: self.pacing.overruns)
    resyncs = property(lambda self: self.pacing.resyncs)
    published = property(lambda self: self.publisher.published)
    sink_errors = property(lambda self: self.publisher.sink_errors)
    dropped = property(lambda self: self.publisher.dropped)
    fallbacks = property(lambda self: self.faults.fallbacks)
    setpoints_accepted = property(lambda self: self.mailbox.accepted)
    setpoints_applied = property(lambda self: self.mailbox.applied)

    @property
    def sinks(self) -> list[SnapshotSink]:
        return self.publisher.sinks

    def add_sink(self, sink: SnapshotSink) -> None:
        self.publisher.add_sink(sink)

    def remove_sink(self, sink: SnapshotSink) -> None:
        self.publisher.remove_sink(sink)

    def submit(self, update: SetpointUpdate | dict | None = None, **fields) -> Setpoint:
        """Put a partial setpoint in the mailbox: merged over what is pending (latest wins per
        field), checked against the bearing's limits once, applied by the runner thread at the
        next frame boundary. Returns the setpoint that will be in force. Raises InputError
        naming each field and the bearing's range."""
        update = parse_update(fields if update is None else update, self.limits)
        return self._offer(update, timed=True)

    def start_scenario(self, run: ResolvedRun, *, restart: bool = False) -> tuple[ScenarioHandle, ScenarioHandle | None]:
        """Hand a scenario run to the runner thread (a running one is cancelled). Values are
        checked against the bearing's limits first (ScenarioError). Returns (handle, replaced)."""
        run.check_limits(self.limits, where="scenario.")
        handle, replaced = self.scenarios.start(run, restart=restart)
        self._wake.set()
        return handle, replaced

    def cancel_scenario(self) -> ScenarioHandle | None:
        """Stop the running scenario where it is (the setpoint stays at its last value)."""
        handle = self.scenarios.cancel()
        self._wake.set()
        return handle

    @property
    def scenario(self) -> ScenarioHandle | None:
        """The pending or running scenario, else the last one."""
        return self.scenarios.current

    def setpoint_latencies(self) -> list[SetpointTiming]:
        """Completed setpoint timings (oldest first)."""
        return self.publisher.timings()

    def stats(self, **refusals: int) -> dict:
        """This twin's /health record (`refusals`: setpoints_refused, setpoints_rate_limited
        counted outside the runner)."""
        return health_record(self, **refusals)

    def start(self, *, publish_initial: bool = True) -> TwinRunner:
        """Take the first snapshot (so GET state never finds none) and start the thread."""
        if self._thread is not None:
            raise RuntimeError("runner already started")
        if publish_initial:
            self._publish(self._clock())
        else:
            self.publisher.set_latest(self.twin.snapshot(real_time_factor=None))
        self._thread = threading.Thread(target=self._run, name=f"twin-{self.bearing_id}", daemon=True)
        self._thread.start()
        return self

    def request_stop(self) -> None:
        """Ask the thread to stop at the end of its frame (does not wait)."""
        self._stop.set()
        self._wake.set()

    def stop(self, timeout: float = 5.0) -> bool:
        """Ask the thread to stop and join it; returns whether it stopped within the timeout."""
        self.request_stop()
        thread = self._thread
        if thread is None:
            return True
        thread.join(timeout)
        alive = thread.is_alive()
        if alive:
            log.error("twin %s: runner did not stop within %.1f s", self.bearing_id, timeout)
        else:
            self.scenarios.stopped()
        return not alive

    # ---- mailbox -------------------------------------------------------------------------------
    def _offer(self, update: SetpointUpdate, *, timed: bool) -> Setpoint:
        guard = self.faults.check_held if self.faults.not_held else None
        try:
            return self.mailbox.offer(update, timed=timed, guard=guard)
        except SetpointError as exc:
            raise InputError(setpoint_field_errors(exc)) from None

    def _apply_mailbox(self) -> bool:
        """Apply the pending setpoint (runner thread). Returns whether a setpoint came in."""
        pending, timings = self.mailbox.take()
        if pending is not None:
            self.twin.set_setpoint(pending)
        if timings:
            self.publisher.await_snapshot(timings)
        return pending is not None or bool(timings)

    # ---- the loop (runner thread) --------------------------------------------------------------
    def _restart_at(self, initial: SetpointUpdate) -> None:
        """A scenario asked to start from the warm start at its initial setpoint."""
        self._offer(initial, timed=False)
        self._apply_mailbox()
        self.twin.reset(warm=True, keep_time=True)

    def _on_fallback(self, fallback: Fallback) -> None:
        self.publisher.note = fallback.describe()
        log.warning("twin %s: %s", self.bearing_id, self.publisher.note)
        self.pacing.publish_soon()

    def _frame(self) -> None:
        fallback = self.faults.advance_frame(self.twin, self.frame_s, self.frame_steps,
                                             on_fallback=self.mailbox.reset)
        if fallback is not None:
            self._on_fallback(fallback)
        self.counters.frames += 1
        self._sim_frames += 1

    def _run(self) -> None:
        pacing, consecutive = self.pacing, 0
        pacing.start(self.sim_elapsed_s)
        while not self._stop.is_set():
            try:
                event = self.scenarios.tick(self.sim_elapsed_s, self.mailbox.target,
                                            lambda u: self._offer(u, timed=False), self._restart_at)
                changed = self._apply_mailbox()
                if self.idle_without_scenario and not self.scenarios.active:
                    if (event and pacing.last_publish_sim != self.sim_elapsed_s) or changed:
                        self._publish(self._clock())
                    self._wake.wait(0.05)
                    self._wake.clear()
                    pacing.reanchor(self.sim_elapsed_s)
                    pacing.restart_sample_grid(self.sim_elapsed_s)
                    continue
                if event and self.fast and (changed or pacing.last_publish_sim != self.sim_elapsed_s):
                    # a scenario started or ended: sample now and restart the sample grid there
                    self._publish(self._clock())
                    pacing.restart_sample_grid(self.sim_elapsed_s)
                self._frame()
                consecutive = 0
            except Exception as exc:  # noqa: BLE001 - counted, shown, recovered
                consecutive += 1
                self._on_error(exc, consecutive)
                if consecutive >= self.max_consecutive_errors:
                    self.counters.failed = True
                    self.publisher.note = (f"failed: runner stopped after {consecutive} errors in a "
                                           f"row; last: {self.last_error}")
                    log.error("twin %s: %s", self.bearing_id, self.publisher.note)
                    self._safe_publish()
                    return
                self._stop.wait(0.01)
                pacing.reanchor(self.sim_elapsed_s)
                continue
            now = self._clock()
            pacing.measure(now, self.sim_elapsed_s)
            if pacing.publish_due(now, self.sim_elapsed_s, changed or event):
                self._safe_publish(now)
            pacing.wait_for_deadline(now, self.sim_elapsed_s, self._stop)

    def _on_error(self, exc: BaseException, consecutive: int) -> None:
        self.counters.error(exc)
        errors = self.counters.errors
        self.publisher.note = f"runner error ({errors} so far): {self.last_error}; twin warm-restarted"
        if errors <= 5 or errors % 100 == 0:
            log.exception("twin %s: runner loop error (%d in a row)", self.bearing_id, consecutive)
        try:
            self.twin.reset(warm=True, keep_time=True)
        except Exception:
            log.exception("twin %s: warm restart failed", self.bearing_id)
        self._safe_publish()

    def _safe_publish(self, now: float | None = None) -> None:
        try:
            self._publish(self._clock() if now is None else now)
        except Exception as exc:  # noqa: BLE001
            self.publisher.sink_errors += 1
            log.warning("twin %s: snapshot failed: %s", self.bearing_id, exc)

    def _publish(self, now: float) -> None:
        self.publisher.publish(self.twin, self.pacing.real_time_factor, now)
        self.pacing.published(now, self.sim_elapsed_s)
