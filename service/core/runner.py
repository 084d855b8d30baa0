"""`TwinRunner`: one thread per twin, the ONLY writer of that twin's state.

Loop (one iteration per frame, `frame_s` of simulated time, 1 ms by default)::

    take a new scenario, if one was handed over -> scenario updates at the scenario time
    drain the mailbox (partial setpoints, merged in order, latest wins per field)
    twin.advance(frame_s)                               # numba, releases the GIL
    publish a snapshot to every sink when due           # sinks only enqueue (bounded, drop-oldest)
    real-time mode: sleep until the frame's wall-clock deadline

Pacing. In real-time mode frame k has the deadline `anchor + k * frame_s` on the monotonic
clock; a frame that finishes after its deadline is an overrun (counted), the loop then does not
sleep and catches up on the following frames. If it falls more than `resync_after_s` behind
(a stall, a cold JIT compile) the schedule is re-anchored (`resyncs`) instead of racing to catch
up. Fast mode never sleeps. The real-time factor is simulated / wall time over a sliding window
(`rtf_window_s`, 1 s) and is written into every snapshot.

Publishing rate (choice): in real-time mode snapshots are published every 1/publish_rate_hz of
WALL time (what a viewer or a zenoh subscriber sees stays steady even if the twin falls behind);
in fast mode every 1/publish_rate_hz of SIMULATED time (a scenario's samples sit on a regular grid
of simulated time however fast the machine is). In real-time mode a frame that applied a new
setpoint is also published at once (at most every `setpoint_publish_min_interval_s`; a closer one
waits for the next frame after that interval), so the
delay from an accepted setpoint to the first snapshot reflecting it is about one frame, not one
publishing period.

Frame semantics. A setpoint (from the mailbox or a scenario at scenario time t) is in force for
the whole frame [t, t + frame_s); a snapshot taken at the end of a frame shows the setpoint that
was in force during it (so a ramp sampled at t shows the ramp's value at t - frame_s).

Setpoint timing. For every setpoint accepted through `submit` the runner records the wall time it
was accepted and the seq and wall time of the first published snapshot that reflects it
(`setpoint_latencies()`), for the latency benchmark.

Errors. An exception in the loop is caught, counted (`errors`), logged, shown in the snapshots'
`status`, and the twin is warm-restarted at the setpoint in force; after
`max_consecutive_errors` failures in a row the runner stops and says so (`failed`).

Physics faults. The kernel reports a state it cannot hold (non-finite, excessive penetration);
the engine then warm-restarts at the setpoint in force and counts it (`Twin.restarts`, its
`status` says why). A setpoint inside the bearing's limits can still be one the model cannot
hold (a load step far beyond what the contacts carry): it fails again right after each restart.
The runner bounds that (at most 2 engine restarts per frame, `Twin.advance(max_restarts=)`) and
falls back: the twin is warm-restarted at the LAST SAFE SETPOINT (one held for
`safe_after_frames` frames without a restart; the twin's initial setpoint to begin with), the
setpoint target becomes that one, `fallbacks` and the twin's `restarts` count it and `status`
names the setpoint that was not held and why. A value that was not held (when one load or speed
field alone rose) is remembered: from then on this twin refuses it, and anything beyond it, at
submission (422 naming the field). No NaN reaches a snapshot: `Snapshot` refuses non-finite
numbers, and a frame that fails is restarted before the next snapshot is taken.

Access and limits (service.core.admission). `submit_setpoint_json` (zenoh) refuses payloads larger than
`max_payload_bytes`, payloads without the configured `token` field (it is removed before
validation), and setpoints beyond the twin's rate (`admit_setpoint`, a token bucket shared with
HTTP); each refusal carries a `status` (401, 413, 422, 429) like the HTTP answer would.
"""

from __future__ import annotations

import collections
import json
import logging
import math
import threading
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass

from service.core.scenarios import ResolvedRun, ScenarioExecutor
from service.api.schemas import (
    FieldError,
    InputError,
    parse_setpoint,
    parse_setpoint_json,
    setpoint_error,
)
from service.core.admission import TokenBucket, token_matches
from service.core.sinks import SnapshotSink
from twin.engine import Twin
from twin.setpoint import _UNITS as SETPOINT_UNITS
from twin.setpoint import Setpoint, SetpointError, SetpointUpdate, check_limits
from twin.snapshot import Snapshot

log = logging.getLogger(__name__)


def warm_restart(twin: Twin) -> None:
    """Warm-restart a twin at the setpoint in force without moving its simulated time back
    (snapshots and recordings need a monotonic time_s)."""
    twin.reset(warm=True, keep_time=True)


@dataclass
class SetpointTiming:
    """When a setpoint was accepted and when it was first seen in a published snapshot."""

    accepted_wall_s: float            # time.perf_counter() at acceptance
    applied_wall_s: float | None = None    # when the runner applied it (frame boundary)
    published_wall_s: float | None = None  # when the first snapshot reflecting it was published
    seq: int | None = None                 # that snapshot's seq

    @property
    def latency_s(self) -> float | None:
        """Accepted -> first published snapshot reflecting it [s]."""
        if self.published_wall_s is None:
            return None
        return self.published_wall_s - self.accepted_wall_s


class ScenarioHandle:
    """What the caller gets back for a scenario handed to a runner (thread-safe to read)."""

    def __init__(self, run: ResolvedRun, restart: bool = False):
        self.run = run
        self.restart = restart
        self.state = "pending"      # pending -> running -> done | cancelled | failed
        self.scenario_time_s = 0.0
        self.phase: str | None = None
        self.error: str | None = None
        self.done = threading.Event()

    @property
    def name(self) -> str:
        return self.run.scenario

    @property
    def duration_s(self) -> float:
        return self.run.duration_s

    @property
    def progress(self) -> float:
        return min(1.0, self.scenario_time_s / self.run.duration_s) if self.run.duration_s > 0 else 1.0

    def _finish(self, state: str, error: str | None = None) -> None:
        if self.done.is_set():
            return
        self.state, self.error = state, error
        self.done.set()

    def wait(self, timeout: float | None = None) -> bool:
        return self.done.wait(timeout)

    def status(self) -> dict:
        return {"name": self.name, "run": self.run.id, "state": self.state,
                "scenario_time_s": self.scenario_time_s, "duration_s": self.duration_s,
                "progress": self.progress, "phase": self.phase, "error": self.error}


class TwinRunner:
    """Runs one `Twin` in its own thread (see the module docstring)."""

    def __init__(self, twin: Twin, *, fast: bool = False, publish_rate_hz: float = 50.0,
                 frame_s: float = 0.001, sinks: Iterable[SnapshotSink] = (),
                 rtf_window_s: float = 1.0, resync_after_s: float = 0.25,
                 idle_without_scenario: bool = False, max_consecutive_errors: int = 20,
                 setpoint_publish_min_interval_s: float = 0.002, timing_history: int = 10000,
                 token: str | None = None, setpoint_rate_hz: float | None = None,
                 setpoint_burst: int = 100, max_payload_bytes: int | None = None,
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
        self.publish_period_s = 1.0 / self.publish_rate_hz
        self.frame_steps = steps
        self.frame_s = steps * dt
        self.rtf_window_s = rtf_window_s
        self.resync_after_s = resync_after_s
        self.idle_without_scenario = idle_without_scenario
        self.max_consecutive_errors = max_consecutive_errors
        self.setpoint_publish_min_interval_s = setpoint_publish_min_interval_s
        self.limits: dict[str, tuple[float, float]] = dict(twin.limits)
        self._clock = clock

        self._lock = threading.Lock()          # mailbox, sinks, scenario hand-over
        self._sinks: list[SnapshotSink] = list(sinks)
        self._target: Setpoint = twin.setpoint  # latest accepted (in force or pending)
        self._pending: dict[str, float] = {}
        self._pending_timings: list[SetpointTiming] = []
        self._unpublished_timings: list[SetpointTiming] = []
        self._timings: collections.deque[SetpointTiming] = collections.deque(maxlen=timing_history)
        self._scenario_request: ScenarioHandle | None = None
        self._scenario: ScenarioHandle | None = None      # the one running (runner thread)
        self._last_scenario: ScenarioHandle | None = None
        self._executor: ScenarioExecutor | None = None
        self._scenario_t0 = 0.0

        self._stop = threading.Event()
        self._wake = threading.Event()
        self._thread: threading.Thread | None = None
        self._latest: Snapshot | None = None

        # counters (written by the runner thread only)
        self.frames = 0
        self.overruns = 0
        self.resyncs = 0
        self.published = 0
        self.errors = 0
        self.sink_errors = 0
        self.setpoints_accepted = 0
        self.setpoints_applied = 0
        self.last_error: str | None = None
        self.failed = False
        self._sim_frames = 0                    # frames advanced by this runner (integer: no drift)
        self._rtf_samples: collections.deque[tuple[float, float]] = collections.deque()
        self._rtf: float | None = None
        self._status_note: str | None = None
        self._last_publish_wall = -math.inf
        self._last_publish_sim = -math.inf
        self._publish_soon = False

        # access and limits
        self.token = token
        self.setpoint_bucket = (TokenBucket(setpoint_rate_hz, setpoint_burst)
                                if setpoint_rate_hz else None)
        self.max_payload_bytes = max_payload_bytes
        self.setpoints_refused = 0              # zenoh setpoints refused (any reason)
        # physics faults: the last safe setpoints (newest last), fallbacks, values not held
        self.safe_after_frames = max(1, int(safe_after_frames))
        self.max_restarts_per_frame = max(1, int(max_restarts_per_frame))
        self._safe: collections.deque[Setpoint] = collections.deque([twin.setpoint], maxlen=8)
        self._held_setpoint: Setpoint = twin.setpoint
        self._held_frames = 0
        self._restart_streak = 0                # consecutive frames with an engine restart
        self.fallbacks = 0
        self._not_held: dict[str, tuple[float, str]] = {}   # field -> (lowest |value| not held, why)
        self._faults: list[tuple[str, float | None]] = []   # injected by tests (inject_fault)

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
        return self._latest

    def latest_snapshot(self) -> Snapshot | None:
        """Same as `latest` (a callable for the zenoh queryable)."""
        return self._latest

    @property
    def sim_elapsed_s(self) -> float:
        """Simulated seconds advanced by this runner [s] (survives warm restarts of the twin)."""
        return self._sim_frames * self.frame_s

    @property
    def real_time_factor(self) -> float | None:
        return self._rtf

    @property
    def target_setpoint(self) -> Setpoint:
        """The latest accepted setpoint (in force, or applied at the next frame)."""
        with self._lock:
            return self._target

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

    def submit(self, update: SetpointUpdate | dict | None = None, **fields) -> Setpoint:
        """Put a partial setpoint in the mailbox: validated (SetpointUpdate, then the bearing's
        limits on the merged setpoint), merged with what is pending (latest wins per field),
        applied by the runner thread at the next frame boundary. Returns the setpoint that will
        be in force. Raises InputError naming the field and its allowed range."""
        if update is None:
            update = fields
        if not isinstance(update, SetpointUpdate):
            update = parse_setpoint(update, self.limits)
        return self._offer(update.model_dump(exclude_none=True), timed=True)

    def admit_setpoint(self) -> tuple[bool, float]:
        """Take one setpoint from this twin's rate budget: (True, 0.0) or (False, retry after [s])."""
        if self.setpoint_bucket is None:
            return True, 0.0
        return self.setpoint_bucket.take()

    def submit_setpoint_json(self, payload: bytes | str) -> dict:
        """zenoh's `on_setpoint`: size cap, token, rate limit, then the same validation as HTTP;
        never raises. Returns {"accepted": True, "setpoint": {...}} or
        {"accepted": False, "status": 401 | 413 | 422 | 429, "error": "...", ...}.

        With a token configured the payload must be a JSON object carrying it as "token" (removed
        before validation, never echoed)."""
        try:
            size = len(payload)
            if self.max_payload_bytes is not None and size > self.max_payload_bytes:
                return self._refused(413, f"payload of {size} bytes is larger than the limit of "
                                     f"{self.max_payload_bytes} bytes")
            data = None
            if self.token is not None:
                try:
                    data = json.loads(payload)
                except (ValueError, UnicodeDecodeError, RecursionError):
                    data = None
                given = data.pop("token", None) if isinstance(data, dict) else None
                if not isinstance(given, str) or not token_matches(given, self.token):
                    return self._refused(401, "missing token: send the setpoint as a JSON object "
                                         "with a \"token\" field" if given is None else "invalid token")
            ok, retry_after = self.admit_setpoint()
            if not ok:
                return self._refused(429, f"too many setpoints: at most {self.setpoint_bucket.rate_hz:g} "
                                     f"per second (bursts of {self.setpoint_bucket.burst}); retry after "
                                     f"{retry_after:.3f} s", retry_after_s=retry_after)
            if data is not None:
                update = parse_setpoint(data, self.limits)
            else:
                update = parse_setpoint_json(payload, self.limits)
            setpoint = self.submit(update)
            return {"accepted": True, "setpoint": setpoint.model_dump()}
        except InputError as exc:
            self.setpoints_refused += 1
            return {"accepted": False, "status": exc.status_code, "error": str(exc),
                    "detail": [e.model_dump() for e in exc.errors]}
        except Exception as exc:  # noqa: BLE001 - a refusal, never a crash
            self.setpoints_refused += 1
            return {"accepted": False, "status": 422, "error": f"{type(exc).__name__}: {exc}"}

    def _refused(self, status: int, message: str, **extra) -> dict:
        self.setpoints_refused += 1
        return {"accepted": False, "status": status, "error": message, **extra}

    def start_scenario(self, run: ResolvedRun, *, restart: bool = False) -> tuple[ScenarioHandle, ScenarioHandle | None]:
        """Hand a scenario run to the runner thread (a running one is cancelled). Values are
        checked against the bearing's limits first (ScenarioError). Returns (handle, replaced)."""
        run.check_limits(self.limits, where="scenario.")
        handle = ScenarioHandle(run, restart=restart)
        with self._lock:
            replaced = self._scenario_request or self._scenario
            old_request = self._scenario_request
            self._scenario_request = handle
        if old_request is not None:
            old_request._finish("cancelled", "replaced before it started")
        self._wake.set()
        return handle, (replaced if replaced is not None and not replaced.done.is_set() else None)

    def cancel_scenario(self) -> ScenarioHandle | None:
        """Stop the running scenario where it is (the setpoint stays at its last value)."""
        with self._lock:
            request, self._scenario_request = self._scenario_request, None
            current = self._scenario
        if request is not None:
            request._finish("cancelled")
        if current is not None:
            current._finish("cancelled")   # the runner thread notices and drops it
        self._wake.set()
        return current or request

    @property
    def scenario(self) -> ScenarioHandle | None:
        """The pending or running scenario, else the last one."""
        with self._lock:
            return self._scenario_request or self._scenario or self._last_scenario

    def setpoint_latencies(self) -> list[SetpointTiming]:
        """Completed setpoint timings (oldest first)."""
        with self._lock:
            return list(self._timings)

    def stats(self) -> dict:
        latest = self._latest
        return {
            "id": self.bearing_id, "running": self.running, "mode": self.mode,
            "status": latest.status if latest is not None else self._status_text(self.twin.status),
            "time_s": latest.time_s if latest else self.twin.time_s,
            "real_time_factor": self._rtf, "frames": self.frames, "overruns": self.overruns,
            "resyncs": self.resyncs, "published": self.published, "dropped": self.dropped,
            "errors": self.errors, "restarts": self.twin.restarts,
            "setpoints_accepted": self.setpoints_accepted,
            "setpoints_refused": self.setpoints_refused,
            "setpoints_rate_limited": self.setpoint_bucket.refused if self.setpoint_bucket else 0,
            "fallbacks": self.fallbacks,
            "last_safe_setpoint": self.last_safe_setpoint.model_dump(),
        }

    @property
    def last_safe_setpoint(self) -> Setpoint:
        """The newest setpoint held for `safe_after_frames` frames without a restart."""
        return self._safe[-1]

    def inject_fault(self, kind: str, value: float | None = None) -> None:
        """Fault injection for tests, applied by the runner thread before its next frame:
        "nan" puts NaN into the first ball's position; "overload" sets the radial load in force
        to `value` [N] bypassing every validation (as a bug or a corrupted setpoint would)."""
        if kind not in ("nan", "overload"):
            raise ValueError(f"unknown fault {kind!r}: 'nan' or 'overload'")
        with self._lock:
            self._faults.append((kind, value))
        self._wake.set()

    def start(self, *, publish_initial: bool = True) -> TwinRunner:
        """Take the first snapshot (so GET state never finds none) and start the thread."""
        if self._thread is not None:
            raise RuntimeError("runner already started")
        if publish_initial:
            self._publish(self._clock())
        else:
            self._latest = self.twin.snapshot(real_time_factor=None)
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
        if not alive:
            for handle in (self._scenario, self._scenario_request):
                if handle is not None:
                    handle._finish("cancelled", "runner stopped")
        if alive:
            log.error("twin %s: runner did not stop within %.1f s", self.bearing_id, timeout)
        return not alive

    # ---- mailbox -------------------------------------------------------------------------------
    def _offer(self, fields: dict[str, float], *, timed: bool) -> Setpoint:
        with self._lock:
            new = self._target.model_copy(update=fields)
            try:
                check_limits(new, self.limits)
            except SetpointError as exc:
                raise InputError([setpoint_error(exc)]) from None
            if self._not_held:
                self._check_held(new, fields)
            if fields:
                self._pending.update(fields)
            self._target = new
            if timed:
                self.setpoints_accepted += 1
                self._pending_timings.append(SetpointTiming(accepted_wall_s=self._clock()))
        return new

    def _drain_mailbox(self) -> bool:
        """Apply the merged pending update (runner thread). Returns whether anything changed."""
        with self._lock:
            pending, self._pending = self._pending, {}
            timings, self._pending_timings = self._pending_timings, []
        if not pending and not timings:
            return False
        if pending:
            self.twin.set_setpoint(SetpointUpdate(**pending))
            self.setpoints_applied += 1
        now = self._clock()
        for t in timings:
            t.applied_wall_s = now
        self._unpublished_timings.extend(timings)
        return bool(pending) or bool(timings)

    def _check_held(self, new: Setpoint, fields: dict) -> None:
        """Refuse (InputError 422) a setpoint reaching a value this twin could not hold."""
        errors = []
        for name, (value, why) in list(self._not_held.items()):
            if name in fields and abs(getattr(new, name)) >= value:
                low, high = self.limits[name]
                unit = SETPOINT_UNITS.get(name, "")
                errors.append(FieldError(
                    field=name, allowed=[max(low, -value), min(high, value)],
                    message=f"{name} = {getattr(new, name):g} {unit}: this twin could not hold "
                    f"{value:g} {unit} ({why}) and fell back to its last safe setpoint; values of "
                    f"{value:g} {unit} and beyond are refused (re-create the twin to try again)"))
        if errors:
            raise InputError(errors)

    # ---- physics faults (runner thread) ----------------------------------------------------------
    def _advance_frame(self) -> None:
        """One frame of physics with the fault handling of the module docstring."""
        twin = self.twin
        self._apply_faults()
        before = twin.restarts
        left = twin.advance(self.frame_s, frame_steps=self.frame_steps,
                            max_restarts=self.max_restarts_per_frame) or 0
        if twin.restarts == before:
            self._restart_streak = 0
            self._held()
            return
        self._restart_streak += 1
        self._held_frames = 0
        if left > 0 or self._restart_streak >= 2:
            self._fall_back()
            if left > 0:   # the rest of the frame at the safe setpoint (bounded as well)
                twin.advance(left * twin.model.dt_s, frame_steps=self.frame_steps, max_restarts=1)

    def _held(self) -> None:
        sp = self.twin.setpoint
        if sp != self._held_setpoint:
            self._held_setpoint, self._held_frames = sp, 0
        self._held_frames += 1
        if self._held_frames >= self.safe_after_frames and sp != self._safe[-1]:
            self._safe.append(sp)

    def _fall_back(self) -> None:
        """Warm-restart at the last safe setpoint (an older one if that fails too)."""
        twin = self.twin
        current = twin.setpoint
        why = twin.status.removeprefix("restarted: ").split(" at t = ")[0]
        if current == self._safe[-1] and self._restart_streak >= 3 and len(self._safe) > 1:
            self._safe.pop()            # even the last safe one is not held: go further back
        safe = self._safe[-1]
        with self._lock:
            self._learn_not_held(current, safe, why)
        twin.set_setpoint(SetpointUpdate(**safe.model_dump()))   # also rewrites what the kernel sees
        warm_restart(twin)
        twin.restarts += 1
        self.fallbacks += 1
        with self._lock:
            self._target = safe
            self._pending.clear()       # updates merged onto the setpoint that was not held
        self._held_setpoint, self._held_frames = safe, 0
        changed = [n for n in SETPOINT_UNITS if getattr(current, n) != getattr(safe, n)]
        what = ", ".join(f"{n} = {getattr(current, n):g} {SETPOINT_UNITS[n]}" for n in changed)
        back = ", ".join(f"{n} = {getattr(safe, n):g} {SETPOINT_UNITS[n]}" for n in changed)
        self._status_note = (f"setpoint not held ({why}): {what or 'the setpoint in force'}; "
                             f"restarted from the warm start at the last safe setpoint"
                             f"{' (' + back + ')' if back else ''}; fallbacks: {self.fallbacks}")
        log.warning("twin %s: %s", self.bearing_id, self._status_note)
        self._publish_soon = True

    def _learn_not_held(self, current: Setpoint, safe: Setpoint, why: str) -> None:
        rose = [n for n in ("radial_load_n", "axial_load_n", "shaft_speed_rad_s")
                if abs(getattr(current, n)) > abs(getattr(safe, n))]
        if len(rose) == 1:              # one cause only: remember the value
            name = rose[0]
            value = abs(getattr(current, name))
            known = self._not_held.get(name)
            if known is None or value < known[0]:
                self._not_held[name] = (value, why)

    def _apply_faults(self) -> None:
        with self._lock:
            faults, self._faults = self._faults, []
        for kind, value in faults:
            twin = self.twin
            if kind == "nan":
                twin.state.ball_position_m[0, 0] = math.nan
            else:   # overload: bypass validation, as a bug or a corrupted setpoint would
                from twin.kernels import layout as L

                twin._setpoint = twin.setpoint.model_copy(update={"radial_load_n": float(value)})
                twin._setpoint_vector[L.S_RADIAL_LOAD] = float(value)

    # ---- scenarios (runner thread) -----------------------------------------------------------
    def _scenario_tick(self) -> bool:
        """Take over a new scenario, apply its updates at the current scenario time, finish it
        when its time is up. Returns whether a scenario just started or finished (publish now)."""
        event = False
        with self._lock:
            request, self._scenario_request = self._scenario_request, None
        if request is not None and not request.done.is_set():
            if self._scenario is not None:
                self._scenario._finish("cancelled", f"replaced by {request.name}")
                self._last_scenario = self._scenario
            self._scenario = request
            self._executor = ScenarioExecutor(request.run)
            if request.restart:
                initial = request.run.initial.model_dump(exclude_none=True)
                self._offer(initial, timed=False)
                self._drain_mailbox()
                warm_restart(self.twin)
            self._scenario_t0 = self.sim_elapsed_s
            request.state = "running"
            event = True
        handle = self._scenario
        if handle is None:
            return event
        if handle.done.is_set():       # cancelled from outside
            self._last_scenario, self._scenario, self._executor = handle, None, None
            return True
        t = self.sim_elapsed_s - self._scenario_t0
        handle.scenario_time_s = t
        try:
            update = self._executor.updates(t, self._target)
            if update:
                self._offer(update, timed=False)
            handle.phase = self._executor.phase
        except Exception as exc:  # noqa: BLE001 - a bad scenario must not stop the twin
            handle._finish("failed", f"{type(exc).__name__}: {exc}")
            self._last_scenario, self._scenario, self._executor = handle, None, None
            return True
        if self._executor.done(t):
            handle.scenario_time_s = handle.duration_s
            handle._finish("done")
            self._last_scenario, self._scenario, self._executor = handle, None, None
            return True
        return event

    # ---- the loop ------------------------------------------------------------------------------
    def _run(self) -> None:
        consecutive = 0
        anchor_wall = self._clock()
        anchor_sim = self.sim_elapsed_s
        next_publish_wall = anchor_wall + self.publish_period_s
        next_publish_sim = self.sim_elapsed_s + self.publish_period_s
        while not self._stop.is_set():
            try:
                event = self._scenario_tick()
                changed = self._drain_mailbox()
                if self.idle_without_scenario and self._scenario is None:
                    if (event and self._last_publish_sim != self.sim_elapsed_s) or changed:
                        self._publish(self._clock())
                    self._wake.wait(0.05)
                    self._wake.clear()
                    anchor_wall, anchor_sim = self._clock(), self.sim_elapsed_s
                    next_publish_sim = self.sim_elapsed_s + self.publish_period_s
                    continue
                if event and self.fast and (changed or self._last_publish_sim != self.sim_elapsed_s):
                    # a scenario started or ended: sample now and restart the sample grid there
                    self._publish(self._clock())
                    next_publish_sim = self.sim_elapsed_s + self.publish_period_s
                self._advance_frame()
                self.frames += 1
                self._sim_frames += 1
                consecutive = 0
            except Exception as exc:  # noqa: BLE001 - counted, shown, recovered
                consecutive += 1
                self._on_error(exc, consecutive)
                if consecutive >= self.max_consecutive_errors:
                    self.failed = True
                    self._status_note = (f"failed: runner stopped after {consecutive} errors in a "
                                         f"row; last: {self.last_error}")
                    log.error("twin %s: %s", self.bearing_id, self._status_note)
                    self._safe_publish()
                    return
                self._stop.wait(0.01)
                anchor_wall, anchor_sim = self._clock(), self.sim_elapsed_s
                continue

            now = self._clock()
            self._measure_rtf(now)
            # publish
            if self.fast:
                if self.sim_elapsed_s >= next_publish_sim - 1e-9:
                    self._safe_publish(now)
                    next_publish_sim += self.publish_period_s
                    if next_publish_sim <= self.sim_elapsed_s:
                        next_publish_sim = self.sim_elapsed_s + self.publish_period_s
            else:
                if changed or event:
                    self._publish_soon = True   # deferred (not dropped) if the last one was too recent
                if now >= next_publish_wall:
                    self._safe_publish(now)
                    next_publish_wall += self.publish_period_s
                    if next_publish_wall <= now:
                        next_publish_wall = now + self.publish_period_s
                elif self._publish_soon and now - self._last_publish_wall >= self.setpoint_publish_min_interval_s:
                    self._safe_publish(now)
            # pace
            if not self.fast:
                deadline = anchor_wall + (self.sim_elapsed_s - anchor_sim)
                late = now - deadline
                if late > 0.0:
                    self.overruns += 1
                    if late > self.resync_after_s:
                        self.resyncs += 1
                        anchor_wall, anchor_sim = now, self.sim_elapsed_s
                else:
                    self._stop.wait(-late)

    def _measure_rtf(self, now: float) -> None:
        samples = self._rtf_samples
        samples.append((now, self.sim_elapsed_s))
        while len(samples) > 2 and now - samples[0][0] > self.rtf_window_s:
            samples.popleft()
        if len(samples) >= 2:
            dw = now - samples[0][0]
            if dw > 0:
                self._rtf = (self.sim_elapsed_s - samples[0][1]) / dw

    def _on_error(self, exc: BaseException, consecutive: int) -> None:
        self.errors += 1
        self.last_error = f"{type(exc).__name__}: {exc}"
        self._status_note = f"runner error ({self.errors} so far): {self.last_error}; twin warm-restarted"
        if self.errors <= 5 or self.errors % 100 == 0:
            log.exception("twin %s: runner loop error (%d in a row)", self.bearing_id, consecutive)
        try:
            warm_restart(self.twin)
        except Exception:
            log.exception("twin %s: warm restart failed", self.bearing_id)
        self._safe_publish()

    def _status_text(self, engine_status: str) -> str:
        if self._status_note is None:
            return engine_status
        if engine_status and engine_status != "ok":
            return f"{self._status_note}; engine: {engine_status}"
        return self._status_note

    def _safe_publish(self, now: float | None = None) -> None:
        try:
            self._publish(self._clock() if now is None else now)
        except Exception as exc:  # noqa: BLE001
            self.sink_errors += 1
            log.warning("twin %s: snapshot failed: %s", self.bearing_id, exc)

    def _publish(self, now: float) -> None:
        snap = self.twin.snapshot(real_time_factor=self._rtf)
        if self._status_note is not None:
            snap = snap.model_copy(update={"status": self._status_text(snap.status)})
        self._latest = snap
        self._publish_soon = False
        self.published += 1
        self._last_publish_wall = now
        self._last_publish_sim = self.sim_elapsed_s
        for sink in self.sinks:
            try:
                sink.publish(snap)
            except Exception as exc:  # noqa: BLE001 - a sink never stops the physics
                self.sink_errors += 1
                if self.sink_errors <= 5:
                    log.warning("twin %s: sink %r failed: %s", self.bearing_id, sink, exc)
        if self._unpublished_timings:
            done, self._unpublished_timings = self._unpublished_timings, []
            for t in done:
                t.published_wall_s, t.seq = now, snap.seq
            with self._lock:
                self._timings.extend(done)
