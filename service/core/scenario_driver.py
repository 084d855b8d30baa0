"""Scenarios in a runner: the timeline executor, the handle a caller gets, and the driver that
hands a scenario to the runner thread and runs it between frames.

* `ScenarioExecutor` turns a run's timeline into setpoint updates: `updates(t, current)` is
  called before each frame with the scenario time t [s] and the setpoint in force and returns
  the partial `SetpointUpdate` to apply now (empty if none). No threads, no clocks.
* `ScenarioHandle`: state (pending -> running -> done | cancelled | failed), progress, phase,
  error; thread-safe to read, `wait()` for the end.
* `ScenarioDriver`: `start` / `cancel` from any thread; `tick` in the runner thread before each
  frame (takes over a new scenario, offers its updates to the mailbox, finishes it when its
  time is up; a value the mailbox refuses fails the scenario, never the twin).
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass, field

from service.core.scenarios import MeasuredTemperature, ResolvedRun
from twin.setpoint import Setpoint, SetpointUpdate


@dataclass
class _ActiveRamp:
    field: str
    start_s: float
    over_s: float
    start_value: float
    target: float


@dataclass
class ScenarioExecutor:
    """A run's timeline as setpoint updates (see the module docstring)."""

    run: ResolvedRun
    _next_step: int = 0
    _ramps: dict[str, _ActiveRamp] = field(default_factory=dict)
    _initial_done: bool = False
    phase: str | None = None
    defects: list | None = None  # the defects of the steps just passed (taken by the driver)
    temperature: MeasuredTemperature | None = None  # the measured temperature of the steps just passed

    def updates(self, t: float, current: Setpoint) -> SetpointUpdate:
        eps = 1e-9
        out: dict[str, float] = {}
        if not self._initial_done:
            out.update(self.run.initial.fields)
            self._initial_done = True
        steps = self.run.steps
        while self._next_step < len(steps) and steps[self._next_step].at_s <= t + eps:
            step = steps[self._next_step]
            self._next_step += 1
            if step.phase is not None:
                self.phase = step.phase
            if step.defects is not None:
                self.defects = list(step.defects)  # the latest step wins
            if step.temperature is not None:
                self.temperature = step.temperature  # the latest step wins
            if step.set is None and step.ramp is None:
                continue
            if step.set is not None:
                fields = step.set.fields
                for name in fields:
                    self._ramps.pop(name, None)  # a later set overrides a running ramp
                out.update(fields)
            elif step.ramp is not None and step.over_s is not None:  # a ramp has its over_s (ScenarioStep)
                for name, target in step.ramp.fields.items():
                    start_value = out.get(name, getattr(current, name))
                    self._ramps[name] = _ActiveRamp(
                        name, step.at_s, float(step.over_s), float(start_value), float(target)
                    )
        for name, ramp in list(self._ramps.items()):
            x = (t - ramp.start_s) / ramp.over_s
            if x >= 1.0 - eps:
                out[name] = ramp.target
                del self._ramps[name]
            else:
                x = min(max(x, 0.0), 1.0)
                out[name] = ramp.start_value + (ramp.target - ramp.start_value) * x
        return SetpointUpdate(**out)

    def done(self, t: float) -> bool:
        """Whether the scenario time t has reached the run's duration."""
        return t >= self.run.duration_s - 1e-9


class ScenarioHandle:
    """What the caller gets back for a scenario handed to a runner (thread-safe to read)."""

    def __init__(self, run: ResolvedRun, restart: bool = False):
        self.run = run
        self.restart = restart
        self.state = "pending"  # pending -> running -> done | cancelled | failed
        self.scenario_time_s = 0.0
        self.phase: str | None = None
        self.error: str | None = None
        self.done = threading.Event()
        self._lock = threading.Lock()
        self._finished = False

    @property
    def name(self) -> str:
        return self.run.scenario

    @property
    def duration_s(self) -> float:
        return self.run.duration_s

    @property
    def progress(self) -> float:
        return min(1.0, self.scenario_time_s / self.run.duration_s) if self.run.duration_s > 0 else 1.0

    @property
    def finished(self) -> bool:
        """Whether it has ended (`done` may be set a little later: after its last sample is out)."""
        return self._finished

    def finish(self, state: str, error: str | None = None, *, notify: bool = True) -> None:
        """End it (first call wins); `notify=False`: set `done` later (`notify()`)."""
        with self._lock:
            if self._finished:
                return
            self._finished = True
            self.state, self.error = state, error
        if notify:
            self.done.set()

    def notify(self) -> None:
        """Wake whoever waits for the end."""
        self.done.set()

    def wait(self, timeout: float | None = None) -> bool:
        return self.done.wait(timeout)

    def status(self) -> dict:
        return {
            "name": self.name,
            "run": self.run.id,
            "state": self.state,
            "scenario_time_s": self.scenario_time_s,
            "duration_s": self.duration_s,
            "progress": self.progress,
            "phase": self.phase,
            "error": self.error,
        }


class ScenarioDriver:
    """One twin's scenarios: the hand-over from any thread, the execution in the runner thread."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._request: ScenarioHandle | None = None
        self._running: ScenarioHandle | None = None  # runner thread
        self._last: ScenarioHandle | None = None
        self._executor: ScenarioExecutor | None = None
        self._t0_s = 0.0
        self._ended: ScenarioHandle | None = None  # ended in the runner, not yet notified

    # ---- any thread ----------------------------------------------------------------------------
    def start(self, run: ResolvedRun, *, restart: bool = False) -> tuple[ScenarioHandle, ScenarioHandle | None]:
        """Queue a run for the runner thread (a running one is cancelled when it takes over).
        Returns (handle, the scenario it replaces or None)."""
        handle = ScenarioHandle(run, restart=restart)
        with self._lock:
            replaced = self._request or self._running
            old_request, self._request = self._request, handle
        if old_request is not None:
            old_request.finish("cancelled", "replaced before it started")
        return handle, (replaced if replaced is not None and not replaced.finished else None)

    def cancel(self) -> ScenarioHandle | None:
        """Stop the running (or pending) scenario where it is."""
        with self._lock:
            request, self._request = self._request, None
            current = self._running
        if request is not None:
            request.finish("cancelled")
        if current is not None:
            current.finish("cancelled")  # the runner thread notices and drops it
        return current or request

    @property
    def current(self) -> ScenarioHandle | None:
        """The pending or running scenario, else the last one."""
        with self._lock:
            return self._request or self._running or self._last

    @property
    def active(self) -> bool:
        """Whether a scenario is running (runner thread's view)."""
        return self._running is not None

    def stopped(self) -> None:
        """The runner stopped: whatever is pending or running is cancelled."""
        for handle in (self._running, self._request, self._ended):
            if handle is not None:
                handle.finish("cancelled", "runner stopped")
                handle.notify()

    def take_ended(self) -> ScenarioHandle | None:
        """The scenario the last `tick` ended, to `notify()` once its last sample is published
        (runner thread)."""
        ended, self._ended = self._ended, None
        return ended

    # ---- runner thread -------------------------------------------------------------------------
    def tick(
        self,
        elapsed_s: float,
        target: Setpoint,
        offer: Callable[[SetpointUpdate], object],
        restart_at: Callable[[SetpointUpdate], None],
        offer_defects: Callable[[list], object] | None = None,
        offer_temperature: Callable[[str, float], object] | None = None,
    ) -> bool:
        """Before a frame at `elapsed_s` of the runner's simulated time: take over a new scenario
        (`restart_at(initial)` when it asks for a warm restart), `offer` its updates and
        `offer_defects` its steps' defects, finish it when its time is up. Returns whether a
        scenario started or ended (publish now)."""
        event = False
        with self._lock:
            request, self._request = self._request, None
        if request is not None and not request.finished:
            if self._running is not None:
                self._running.finish("cancelled", f"replaced by {request.name}")
                self._last = self._running
            self._running = request
            self._executor = ScenarioExecutor(request.run)
            if request.restart:
                restart_at(request.run.initial)
            self._t0_s = elapsed_s
            request.state = "running"
            event = True
        handle, executor = self._running, self._executor
        if handle is None:
            return event
        assert executor is not None  # set with the running handle
        if handle.finished:  # cancelled from outside
            self._end(handle)
            return True
        t = elapsed_s - self._t0_s
        handle.scenario_time_s = t
        try:
            update = executor.updates(t, target)
            if update.fields:
                offer(update)
            defects, executor.defects = executor.defects, None
            if defects is not None and offer_defects is not None:
                offer_defects(defects)
            measured, executor.temperature = executor.temperature, None
            if measured is not None and offer_temperature is not None:
                offer_temperature(measured.node, measured.temperature_c)
            handle.phase = executor.phase
        except Exception as exc:  # noqa: BLE001 - a bad scenario must not stop the twin
            handle.finish("failed", f"{type(exc).__name__}: {exc}", notify=False)
            self._end(handle)
            return True
        if executor.done(t):
            handle.scenario_time_s = handle.duration_s
            handle.finish("done", notify=False)
            self._end(handle)
            return True
        return event

    def _end(self, handle: ScenarioHandle) -> None:
        with self._lock:
            self._last, self._running, self._executor = handle, None, None
        if not handle.done.is_set():
            self._ended = handle
