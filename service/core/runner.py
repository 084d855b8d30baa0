"""`TwinRunner`: one twin's frame loop, run by a stepping pool; the ONLY writer of the twin's state.

One `step` = one frame (`frame_s` of simulated time; the service runs 20 ms frames)::

    scenarios.tick()          take over a new scenario, offer its updates (ScenarioDriver)
    mailbox.take()            the pending setpoint, admitted once at submission (Mailbox)
    faults.advance_frame()    twin.advance(frame), fall back when not held (FaultPolicy)
    pacing.publish_due()      publisher.capture(): the snapshot built and delivered (Publisher)
    pacing.frame_done()       lateness counted; the release of the next frame is returned

The jobs live in their own classes (service.core.pacing, .mailbox, .faults, .scenario_driver,
.publishing, .stats); this class owns the frame loop and offers their public face (submit,
start_scenario, latest, stats, ...). The loop does not own a thread: a `SteppingPool`
(service.core.pool) runs `step` on one of its stepping threads, earliest deadline first, and
waits for the release time `step` returns (real time: the wall-clock time the twin's simulated
clock has reached). A runner given no pool makes its own, of one stepping thread. Only one
thread at a time runs a twin's frame, so its state has one writer at any moment.

Frame semantics. A setpoint (from the mailbox or a scenario at scenario time t) is in force for
the whole frame [t, t + frame_s); a snapshot taken at the end of a frame shows the setpoint that
was in force during it (so a ramp sampled at t shows the ramp's value at t - frame_s). A
setpoint that arrives mid-frame applies at the next frame. In real-time mode an outside
setpoint (or defects) also ends the frame in progress at its next step (Twin.interrupt_frame:
the frame is shorter, the simulated clock counts the steps it ran) and releases a twin that
waits for its next frame at once, and the frame that applies it lasts `setpoint_frame_s` (0.25
ms, when shorter than `frame_s`), so the state that reflects it is published a quarter of a
millisecond of simulated time after its arrival instead of up to two frames (the frame's engine
CPU is the `step` stage of the setpoint latency: 0.5 ms at the median for 1 ms, 0.3 ms for 0.25
ms, one twin on the 2-core EPYC VM).

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
from typing import Any, Literal

from pydantic import ValidationError

from service.core.capacity import CpuMeter, TwinCost
from service.core.defects import DefectBox, parse_defects
from service.core.errors import InputError, field_errors, setpoint_field_errors
from service.core.faults import ErrorStreak, Fallback, FaultPolicy
from service.core.mailbox import LatestValue, Mailbox, SetpointTiming
from service.core.measured_temperature import MeasuredTemperature
from service.core.pacing import PacingClock
from service.core.pool import Job, Schedule, SteppingPool
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

IDLE_POLL_S = 0.05  # an idle twin (no scenario) looks at its mailbox this often [s]
ERROR_PAUSE_S = 0.01  # pause after a caught error [s]

RunMode = Literal["real_time", "fast"]  # real time, or as fast as the CPU steps (scenarios, studies)


def parse_update(data: Any, limits: SetpointLimits) -> SetpointUpdate:
    """A parsed setpoint body (dict) as a SetpointUpdate; InputError naming each field with the
    bearing's range for a wrong type, a non-finite number or an unknown field."""
    if isinstance(data, SetpointUpdate):
        return data
    if not isinstance(data, dict):
        raise InputError.one(
            None,
            f"a setpoint is a JSON object of fields {sorted(limits.ranges)}, got {type(data).__name__}",
            sorted(limits.ranges),
        )
    try:
        return SetpointUpdate.model_validate(data)
    except ValidationError as exc:
        raise InputError(field_errors(exc.errors(), limits)) from None


class TwinRunner:
    """Runs one `Twin` frame by frame in a stepping pool (see the module docstring)."""

    def __init__(
        self,
        twin: Twin,
        *,
        fast: bool = False,
        publish_rate_hz: float = 50.0,
        frame_s: float = 0.001,
        sinks: Iterable[SnapshotSink] = (),
        rtf_window_s: float = 1.0,
        resync_after_s: float = 0.25,
        idle_without_scenario: bool = False,
        max_consecutive_errors: int = 20,
        setpoint_publish_min_interval_s: float = 0.002,
        timing_history: int = 10000,
        safe_after_frames: int = 20,
        max_restarts_per_frame: int = 2,
        lateness_s: float = 0.005,
        setpoint_frame_s: float | None = 0.00025,
        lead_s: float = 0.0,
        pool: SteppingPool | None = None,
        cost: TwinCost | None = None,
        clock: Callable[[], float] = time.perf_counter,
    ):
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
        sp_steps = steps if setpoint_frame_s is None else max(1, min(steps, round(setpoint_frame_s / dt)))
        self.setpoint_frame_steps = steps if self.fast else sp_steps
        self.idle_without_scenario = idle_without_scenario
        self.errors_in_a_row = ErrorStreak(max_consecutive_errors)
        self.limits: SetpointLimits = twin.limits
        self.calibration: TwinCost | None = cost  # measured at admission (service.core.capacity)
        self._clock = clock

        self.mailbox = Mailbox(twin.setpoint, self.limits, clock=clock)
        self.defect_box = DefectBox()  # local defects waiting for the next frame
        self.measured_temperature: LatestValue[tuple[str, float]] = LatestValue()  # (node, degC) for the next frame
        self.faults = FaultPolicy(
            twin.setpoint,
            self.limits,
            safe_after_frames=safe_after_frames,
            max_restarts_per_frame=max_restarts_per_frame,
        )
        self.pacing = PacingClock(
            fast=self.fast,
            publish_period_s=1.0 / self.publish_rate_hz,
            clock=clock,
            rtf_window_s=rtf_window_s,
            resync_after_s=resync_after_s,
            setpoint_publish_min_interval_s=setpoint_publish_min_interval_s,
            lateness_s=lateness_s,
            lead_s=lead_s,
        )
        self.publisher = Publisher(
            self.bearing_id, sinks, timing_history=timing_history, lossless=self.fast, clock=clock
        )
        self.scenarios = ScenarioDriver()
        self.counters = LoopCounters()
        self.engine_cpu = CpuMeter(window=2.0)  # CPU s per simulated s of this twin's frames
        self._sim_steps = 0  # steps advanced by this runner (integer: no drift)
        self._reanchor = False
        self._stop = threading.Event()
        self._done = threading.Event()
        self._pool = pool
        self._own_pool = pool is None
        self._job: Job | None = None

    # ---- public, any thread ------------------------------------------------------------------
    @property
    def name(self) -> str:
        """The stepping thread's and the pool job's name."""
        return f"twin-{self.bearing_id}"

    @property
    def frame_s(self) -> float:
        """Simulated time of a frame [s]: a whole number of the twin's time steps."""
        return self.frame_steps * self.twin.model.dt_s

    @property
    def mode(self) -> RunMode:
        return "fast" if self.fast else "real_time"

    @property
    def running(self) -> bool:
        """Started, and neither stopped nor failed (its last snapshot delivered)."""
        return self._job is not None and not self._done.is_set()

    @property
    def stepping_threads(self) -> list[str]:
        """Names of the threads that may run this twin's frames."""
        return self._pool.thread_names if self._pool is not None else []

    @property
    def latest(self) -> Snapshot | None:
        """The latest published snapshot (None before start)."""
        return self.publisher.latest

    def latest_json(self) -> bytes | None:
        """The latest snapshot's contract JSON, serialised once per publication (Publisher.latest_json)."""
        return self.publisher.latest_json()

    def latest_snapshot(self) -> Snapshot | None:
        """Same as `latest` (a callable for the zenoh queryable)."""
        return self.publisher.latest

    @property
    def sim_elapsed_s(self) -> float:
        """Simulated seconds advanced by this runner [s] (survives warm restarts of the twin)."""
        return self._sim_steps * self.twin.model.dt_s

    @property
    def real_time_factor(self) -> float | None:
        return self.pacing.real_time_factor

    @property
    def late_fraction(self) -> float | None:
        """Frames later than `lateness_s` / frames, last 10 s (None in fast mode)."""
        return None if self.fast else self.pacing.late_fraction

    @property
    def cost(self) -> TwinCost | None:
        """CPU this twin needs in real time: measured while running (engine over the last 2 s of
        simulated time, snapshots over the last 50), its calibration until then."""
        cal = self.calibration
        engine = self.engine_cpu.rate
        snap = self.publisher.cpu.rate
        if engine is None:
            if cal is None:
                return None
            engine = cal.engine_cpu_s_per_sim_s
        return TwinCost(
            engine_cpu_s_per_sim_s=engine,
            publish_cpu_s_per_s=(
                snap * self.publish_rate_hz
                if snap is not None
                else (cal.publish_cpu_s_per_s if cal is not None else 0.0)
            ),
        )

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

    def submit(
        self, update: SetpointUpdate | dict | None = None, *, received_s: float | None = None, **fields
    ) -> Setpoint:
        """Put a partial setpoint in the mailbox: merged over what is pending (latest wins per
        field), checked against the bearing's limits once, applied by the stepping thread at
        the next frame boundary. Returns the setpoint that will be in force. Raises InputError
        naming each field and the bearing's range. `received_s`: when the request carrying it
        arrived (this runner's clock), the start of its `SetpointTiming`."""
        submitted = self._clock()
        update = parse_update(fields if update is None else update, self.limits)
        setpoint = self._offer(update, timed=True, received_s=received_s, submitted_s=submitted)
        self._interrupt()
        self._wake(urgent=True)
        return setpoint

    def submit_defects(self, defects: Any) -> tuple:
        """Replace the twin's local defects (a list of dicts, see service.core.defects; [] clears
        them): validated here against the bearing's geometry (InputError 422 naming the field
        and the bearing's range), applied by the stepping thread at the next frame boundary.
        Returns the defects that will be in force."""
        items = parse_defects(defects, self.twin.model.spec.geometry)
        items = self.defect_box.offer(items)
        self._interrupt()
        self._wake(urgent=True)
        return items

    def submit_temperature(self, measured: MeasuredTemperature) -> None:
        """A measured node temperature for the twin's dissipation estimator
        (twin.thermal.estimator), its node and range already checked by the model
        (service.core.measured_temperature); InputError 409 with the fixed oil temperature. Handed
        to the twin at the next frame boundary (the latest wins)."""
        if self.twin.thermal is None:
            raise InputError.one(
                "node",
                "the twin runs with the fixed oil temperature (ModelOptions.thermal = "
                "'fixed'): no thermal network to follow a measurement",
                status_code=409,
            )
        self.measured_temperature.offer((measured.node, measured.temperature_c))
        self._wake()

    def _take_measurement(self) -> None:
        pending = self.measured_temperature.take()
        if pending is not None and self.twin.thermal is not None:
            self.twin.measure_temperature(*pending)

    def start_scenario(
        self, run: ResolvedRun, *, restart: bool = False
    ) -> tuple[ScenarioHandle, ScenarioHandle | None]:
        """Hand a scenario run to the runner (a running one is cancelled). Values are checked
        against the bearing's limits first (ScenarioError). Returns (handle, replaced)."""
        run.check_limits(self.limits, where="scenario.")
        run.check_defects(self.twin.model.spec.geometry, where="scenario.")
        handle, replaced = self.scenarios.start(run, restart=restart)
        self._wake()
        return handle, replaced

    def cancel_scenario(self) -> ScenarioHandle | None:
        """Stop the running scenario where it is (the setpoint stays at its last value)."""
        handle = self.scenarios.cancel()
        self._wake()
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
        """Take the first snapshot (so GET state never finds none) and hand the twin to the pool."""
        if self._job is not None:
            raise RuntimeError("runner already started")
        if publish_initial:
            self.publisher.capture(self.twin, None)  # no worker yet: built here, now
        else:
            self.publisher.set_latest(self.twin.snapshot(real_time_factor=None))
        if self._pool is None:
            self._pool = SteppingPool(1, name=self.name, clock=self._clock)
        self._pool.start()
        self.publisher.attach(self._pool.publisher)
        self.pacing.start(self.sim_elapsed_s, published=publish_initial)
        self._job = self._pool.add(self)
        return self

    def request_stop(self) -> None:
        """Ask the runner to stop at the end of its frame (does not wait; a real-time frame in
        progress ends at its next step)."""
        self._interrupt()  # before the stop flag: `left_pool` withdraws it after
        self._stop.set()
        self._wake()

    def stop(self, timeout: float = 5.0) -> bool:
        """Stop at the end of the frame and wait until the last snapshot is delivered; returns
        whether that happened within the timeout."""
        self.request_stop()
        if self._job is None:
            return True
        stopped = self._done.wait(timeout)
        if not stopped:
            log.error("twin %s: runner did not stop within %.1f s", self.bearing_id, timeout)
        else:
            self.scenarios.stopped()
            if self._own_pool and self._pool is not None:
                self._pool.close(timeout)
        return stopped

    def _wake(self, *, urgent: bool = False) -> None:
        """Release the twin's next frame now (`urgent`: an outside setpoint or defects, whose frame
        the pool runs before the frames of twins that only keep their pace, SteppingPool.wake)."""
        if self._pool is not None and self._job is not None:
            self._pool.wake(self._job, urgent=urgent and not self.fast)

    def _interrupt(self) -> None:
        """An outside input waits (real time): end the frame in progress at its next step
        (Twin.interrupt_frame); withdrawn by `step` before it takes the mailbox and when the
        twin leaves the pool. Only while the runner runs: a twin stepped by anyone else (the
        calibration before the start, a caller after the stop) is never cut."""
        if not self.fast and self._job is not None and not self._done.is_set():
            self.twin.interrupt_frame()

    # ---- mailbox -------------------------------------------------------------------------------
    def _offer(
        self,
        update: SetpointUpdate,
        *,
        timed: bool,
        received_s: float | None = None,
        submitted_s: float | None = None,
    ) -> Setpoint:
        guard = self.faults.check_held if self.faults.not_held else None
        try:
            return self.mailbox.offer(update, timed=timed, guard=guard, received_s=received_s, submitted_s=submitted_s)
        except SetpointError as exc:
            raise InputError(setpoint_field_errors(exc)) from None

    def _apply_mailbox(self) -> tuple[bool, bool]:
        """Apply the pending setpoint (stepping thread). Returns (a setpoint came in, it was an
        outside one)."""
        pending, timings = self.mailbox.take()
        if pending is not None:
            self.twin.set_setpoint(pending)
        if timings:
            self.publisher.await_snapshot(timings)
        defects = self.defect_box.take()
        if defects is not None:
            self.twin.set_defects(defects)
        self._take_measurement()
        outside = bool(timings) or defects is not None
        return pending is not None or outside, outside

    # ---- the frame (stepping thread) -----------------------------------------------------------
    def _offer_scenario_defects(self, defects: list) -> None:
        """A scenario step's defects (checked when the run started): in force from this frame."""
        self.defect_box.offer(parse_defects(defects, self.twin.model.spec.geometry))

    def _offer_scenario_temperature(self, node: str, temperature_c: float) -> None:
        """A scenario step's measured temperature: to the twin's network at this frame (ignored with
        the fixed oil temperature, where there is no network to follow it)."""
        if self.twin.thermal is not None:
            self.twin.measure_temperature(node, temperature_c)

    def _restart_at(self, initial: SetpointUpdate) -> None:
        """A scenario asked to start from the warm start at its initial setpoint."""
        self._offer(initial, timed=False)
        self._apply_mailbox()
        self.twin.reset(warm=True, keep_time=True)

    def _on_fallback(self, fallback: Fallback) -> None:
        self.publisher.note = fallback.describe()
        log.warning("twin %s: %s", self.bearing_id, self.publisher.note)
        self.pacing.publish_soon()

    def _frame(self, steps: int) -> None:
        dt = self.twin.model.dt_s
        c0 = time.thread_time()
        fallback = self.faults.advance_frame(self.twin, steps * dt, steps, on_fallback=self.mailbox.reset)
        done = steps - self.faults.steps_left  # fewer when an outside input interrupted it
        self.engine_cpu.add(time.thread_time() - c0, done * dt)
        if fallback is not None:
            self._on_fallback(fallback)
        self.counters.frames += 1
        self._sim_steps += done

    def step(self, now: float) -> Schedule | None:
        """One frame (or one idle look at the mailbox); returns when the pool should run the
        next, None when the runner stops (asked to, or failed)."""
        if self._stop.is_set():
            return None
        pacing = self.pacing
        if not self.fast:
            self.twin.clear_frame_interrupt()  # before the mailbox: a later input interrupts again
        try:
            if self._reanchor:
                pacing.reanchor(self.sim_elapsed_s)
                self._reanchor = False
            event = self.scenarios.tick(
                self.sim_elapsed_s,
                self.mailbox.target,
                lambda u: self._offer(u, timed=False),
                self._restart_at,
                self._offer_scenario_defects,
                self._offer_scenario_temperature,
            )
            changed, outside = self._apply_mailbox()
            if self.idle_without_scenario and not self.scenarios.active:
                if (event and pacing.last_publish_sim != self.sim_elapsed_s) or changed:
                    self._publish(self._clock())
                self._notify_ended()
                pacing.restart_sample_grid(self.sim_elapsed_s)
                self._reanchor = True
                return Schedule(self._clock() + IDLE_POLL_S)
            if event and self.fast and (changed or pacing.last_publish_sim != self.sim_elapsed_s):
                # a scenario started or ended: sample now and restart the sample grid there
                self._publish(self._clock())
                pacing.restart_sample_grid(self.sim_elapsed_s)
            self._frame(self.setpoint_frame_steps if outside else self.frame_steps)
            self.errors_in_a_row.clear()
        except Exception as exc:  # noqa: BLE001 - counted, shown, recovered
            streak = self.errors_in_a_row.add()
            self._on_error(exc, streak)
            self._notify_ended()
            if self.errors_in_a_row.exhausted:
                self.counters.failed = True
                self.publisher.note = f"failed: runner stopped after {streak} errors in a row; last: {self.last_error}"
                log.error("twin %s: %s", self.bearing_id, self.publisher.note)
                self._safe_publish()
                return None
            self._reanchor = True
            retry = self._clock() + ERROR_PAUSE_S  # due then (not after every other twin's frames)
            return Schedule(retry, math.inf if self.fast else retry)
        now = self._clock()
        sim = self.sim_elapsed_s
        pacing.measure(now, sim)
        release = pacing.frame_done(now, sim)
        # a frame an outside input cut short publishes nothing: the input applies at the next
        # step and its frame publishes the tick (service.core.pacing, "Publishing"); a stop
        # cuts the frame too, and that one publishes as due. An input that was taken before its
        # interrupt landed (offered, taken here, then the interrupt) cuts the frame that applies
        # it with nothing waiting: that frame publishes as due, or the setpoint it carries would
        # wait for the next tick
        cut_for_input = (
            self.faults.steps_left > 0
            and not self._stop.is_set()
            and self._input_waiting()
            and pacing.tick_may_wait(now)
        )
        if not cut_for_input and pacing.publish_due(now, sim, changed or event):
            self._safe_publish(now)
        self._notify_ended()
        return Schedule(release, math.inf if self.fast else release + self.frame_s)

    def _input_waiting(self) -> bool:
        """Whether an outside input (a setpoint or defects) waits for the next step."""
        return self.mailbox.waiting or self.defect_box.waiting

    def _notify_ended(self) -> None:
        """A scenario ended in this step: its waiters wake once what it published is delivered."""
        ended = self.scenarios.take_ended()
        if ended is not None:
            self.publisher.after_pending(ended.notify)

    def left_pool(self) -> None:
        """The pool let the twin go: done once its last capture is delivered."""
        self.twin.clear_frame_interrupt()
        self.publisher.after_pending(self._done.set)

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
        self.publisher.capture(self.twin, self.pacing.real_time_factor, self.late_fraction, stop=self._stop)
        self.pacing.published(now, self.sim_elapsed_s)
