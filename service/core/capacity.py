"""Admission by measured capacity: a twin this host cannot run in real time is refused when it is
created, instead of slowing every twin.

The rule (docs/service.md "Runner pool"):

* A twin's COST is the CPU time it needs per wall-clock second in real time [CPU s / s]: the
  engine's CPU time per simulated second (`engine_cpu_s_per_sim_s`, 1 / the real-time factor
  it would have alone on a core) plus building its snapshots (`publish_cpu_s_per_s`: CPU per
  snapshot x the publish rate). A new twin's cost is measured at creation by a short
  calibration (`calibrate`: `calibration_s` of simulated time on its own, warm-started model,
  thread CPU time, so other load on the machine does not count as the twin's); a running
  twin's cost is what its runner measured over its last window (`CpuMeter`: 2 s of simulated
  time of frames, 50 snapshots), its calibration until then.
* The CAPACITY is `core_fraction` (0.85 by default) of each core the stepping threads can use
  (`min(stepping threads, cores)`), less `reserve_cores` (0.5 by default in the service) kept for
  the zenoh, rerun, HTTP and publishing threads and the machine, and never less than one twin's
  share. Why the reserve: on the 2-core VM two default 6208 twins (0.74 and 0.76 CPU s per s by
  their calibration) fitted 2 x 0.85 = 1.7, were admitted, and ran at 0.97 and 0.93 of real time
  with 93-96 % of frames late (`bearing-twin bench-service --twins 4`, zenoh and recording on).
* A calibration runs the twin ALONE (a warm model on an idle stepping thread, 20 ms of simulated
  time); in the service the same engine may cost more, its frames sharing the caches with the
  Python between them and the service's threads. On the 2-core Intel Xeon VM the default 6208
  calibrates at 0.27-0.31 in 6 of 28 runs and 0.35-0.54 CPU s per simulated s in the others, and
  measures 0.34-0.46 running beside zenoh, the recorder and the HTTP client. So a new twin ALIKE
  running ones (the same spec and model options) counts at the larger of its calibration and
  their measured engine cost (`expected_engine_cost`: their mean, over the twins whose 2 s
  window has closed); a twin unlike every running one counts at its calibration. Without it a
  low calibration of the first twin let `--twins auto` start a third default twin there, and
  the three ran 0.3-2.2 % of their frames late.
* The SERVICE SHARE of a twin is what the service spends for it beside its engine: the measured
  service overhead per twin (`ThreadCpuMeter`: the stepping threads beside the engines, the zenoh,
  recording and alarm threads, over the last closed window, HTTP not counted), or its snapshots'
  calibrated cost while none is measured (no twin running yet), whichever is larger. A twin's
  NEED is its engine cost plus that share.
* A twin is admitted when (1) its own cost fits one core's share (`core_fraction`): a twin is
  stepped by one thread at a time, so it can never use more than one core, and (2) the costs of
  the running twins plus its own fit the capacity. Otherwise it is refused (HTTP 503) with the
  reason and the measured figures. The twin the configuration starts with the service is
  started in any case and said to be over capacity (warning in the log and in /health).

`max_twins` (a setting) is a fixed cap on top; unset, the capacity alone decides (up to 256).

The number of twins the host holds (`Capacity.estimate_max_twins`, /health `capacity.max_twins`,
`bench-service --twins auto`) is, with C the cores the stepping threads can use, f the
core_fraction, R the reserve, U the measured need of the running twins and c the need of a twin
like the last one calibrated (its engine plus the service share)::

    max_twins = running + floor((C f - R - U) / c)          (c <= f, else no more twin fits)

with c's engine part the expected engine cost of a twin like the last calibrated one.

and `Capacity.formula` writes it out with the figures of the moment.

The SERVICE OVERHEAD is what the process spends beside the engines: the Python between frames,
building and publishing snapshots, the zenoh, recording, alarm and HTTP threads
(`ServiceOverheadMeter`: the process's CPU time less the engines' thread CPU time, over at least
a second of wall time). Its share of the engines' own CPU (`overhead_fraction`) has a goal of
`OVERHEAD_GOAL` (10 %): above it the service, not the physics, limits how many twins a host holds.
"""

from __future__ import annotations

import math
import os
import threading
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass

from twin.engine import Twin

OVERHEAD_GOAL = 0.10  # service CPU beside the engines / the engines' CPU, at most [-]


def usable_cores() -> int:
    """Cores this process may run on (its CPU affinity), at least 1."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return max(1, os.cpu_count() or 1)


class CpuMeter:
    """CPU seconds per unit of work (simulated seconds, snapshots) over the last closed window of
    `window` units; the running totals besides. Written by one thread at a time."""

    def __init__(self, window: float):
        self.window = float(window)
        self.cpu_s = 0.0  # totals since the start
        self.work = 0.0
        self._cpu_open = 0.0
        self._work_open = 0.0
        self._rate: float | None = None

    def add(self, cpu_s: float, work: float) -> None:
        self.cpu_s += cpu_s
        self.work += work
        self._cpu_open += cpu_s
        self._work_open += work
        if self._work_open >= self.window:
            self._rate = self._cpu_open / self._work_open
            self._cpu_open = self._work_open = 0.0

    @property
    def rate(self) -> float | None:
        """CPU s per unit over the last closed window (None before the first closes)."""
        return self._rate


@dataclass(frozen=True)
class TwinCost:
    """CPU a twin needs in real time (see the module docstring)."""

    engine_cpu_s_per_sim_s: float  # CPU s per simulated s of the engine (1 / lone real-time factor)
    publish_cpu_s_per_s: float  # CPU s per wall s spent building its snapshots

    @property
    def cpu_s_per_s(self) -> float:
        """Total CPU s per wall s in real time [CPU s / s]."""
        return self.engine_cpu_s_per_sim_s + self.publish_cpu_s_per_s

    @property
    def publish_fraction(self) -> float | None:
        """Snapshot building per engine CPU [-] (None for an engine that costs nothing)."""
        e = self.engine_cpu_s_per_sim_s
        return self.publish_cpu_s_per_s / e if e > 0 else None

    def with_engine(self, engine_cpu_s_per_sim_s: float) -> TwinCost:
        """This cost with another engine part (the expected one, `expected_engine_cost`)."""
        return TwinCost(engine_cpu_s_per_sim_s, self.publish_cpu_s_per_s)

    def as_dict(self) -> dict:
        return {
            "engine_cpu_s_per_sim_s": self.engine_cpu_s_per_sim_s,
            "publish_cpu_s_per_s": self.publish_cpu_s_per_s,
            "cpu_s_per_s": self.cpu_s_per_s,
            "publish_fraction": self.publish_fraction,
        }


def mean_engine_cost(measured: Iterable[float]) -> float | None:
    """The mean of measured engine costs [CPU s per simulated s], non-positive or non-finite ones
    left out; None without one."""
    rates = [r for r in measured if r > 0.0 and math.isfinite(r)]
    return sum(rates) / len(rates) if rates else None


def expected_engine_cost(calibrated: float, alike_engine: float | None) -> float:
    """The engine cost a new twin is counted at [CPU s per simulated s]: its lone calibration, or
    the measured engine cost of the running twins alike it (`mean_engine_cost`; None: none
    measured) when that is larger (the calibration is the least contended case there is; what
    alike twins measure in the service is what this one will cost there)."""
    return calibrated if alike_engine is None else max(calibrated, alike_engine)


def calibrate(
    twin: Twin,
    *,
    sim_s: float = 0.02,
    frame_steps: int = 5000,
    publish_rate_hz: float = 50.0,
    cpu_clock: Callable[[], float] = time.thread_time,
) -> TwinCost:
    """Measure a twin's cost: a warm-up frame (JIT cache load), then `sim_s` of simulated time in
    two halves (the cheaper half counts: a preemption or page fault is not the twin's), and two
    snapshots (the second counts). The twin's simulated clock moves on by `sim_s` plus one
    frame: the same trajectory it would have run anyway."""
    dt = twin.model.dt_s
    twin.advance(min(sim_s, 0.001), frame_steps=frame_steps)  # warm-up
    half = max(dt, 0.5 * sim_s)
    rates = []
    for _ in range(2):
        c0 = cpu_clock()
        twin.advance(half, frame_steps=frame_steps)
        rates.append((cpu_clock() - c0) / half)
    twin.snapshot()
    c0 = cpu_clock()
    twin.snapshot()
    snap_cpu = cpu_clock() - c0
    twin.seq -= 2  # the calibration snapshots are not published
    return TwinCost(engine_cpu_s_per_sim_s=min(rates), publish_cpu_s_per_s=snap_cpu * publish_rate_hz)


@dataclass(frozen=True)
class Verdict:
    """What the capacity check says about one more twin."""

    admitted: bool
    reason: str
    need_cpu_s_per_s: float
    used_cpu_s_per_s: float
    budget_cpu_s_per_s: float
    per_twin_cpu_s_per_s: float


class Capacity:
    """The host's capacity for twins in real time (see the module docstring)."""

    def __init__(
        self, stepping_threads: int, core_fraction: float = 0.85, cores: int | None = None, reserve_cores: float = 0.0
    ):
        if not (0.0 < core_fraction <= 1.0):
            raise ValueError(f"core_fraction = {core_fraction!r}: must be in (0, 1]")
        if not (0.0 <= reserve_cores <= 64.0):
            raise ValueError(f"reserve_cores = {reserve_cores!r}: must be in [0, 64]")
        self.cores = cores if cores is not None else usable_cores()
        self.stepping_threads = int(stepping_threads)
        self.core_fraction = float(core_fraction)
        self.reserve_cores = float(reserve_cores)

    @property
    def usable_cores(self) -> int:
        """Cores the stepping threads can keep busy."""
        return max(1, min(self.stepping_threads, self.cores))

    @property
    def budget_cpu_s_per_s(self) -> float:
        """CPU s per s the twins may use together: the cores' share less the service's reserve, at
        least one twin's share."""
        return max(self.core_fraction, self.usable_cores * self.core_fraction - self.reserve_cores)

    @property
    def per_twin_cpu_s_per_s(self) -> float:
        return self.core_fraction

    @staticmethod
    def service_share(cost: TwinCost, overhead_per_twin_cpu_s_per_s: float | None = None) -> float:
        """What the service spends for a twin beside its engine [CPU s / s]: the measured overhead
        per twin, its snapshots' cost while none is measured, whichever is larger."""
        o = overhead_per_twin_cpu_s_per_s
        return max(cost.publish_cpu_s_per_s, o if o is not None and math.isfinite(o) else 0.0)

    @classmethod
    def need(cls, cost: TwinCost, overhead_per_twin_cpu_s_per_s: float | None = None) -> float:
        """A twin's engine cost plus its service share [CPU s / s]."""
        return cost.engine_cpu_s_per_sim_s + cls.service_share(cost, overhead_per_twin_cpu_s_per_s)

    def used(self, running: Iterable[TwinCost], overhead_per_twin_cpu_s_per_s: float | None = None) -> float:
        """What the running twins need together [CPU s / s]."""
        return sum(self.need(c, overhead_per_twin_cpu_s_per_s) for c in running)

    def _share_text(self, cost: TwinCost, overhead: float | None) -> str:
        share = self.service_share(cost, overhead)
        if overhead is not None and share > cost.publish_cpu_s_per_s:
            return f"service {share:.3f} (measured per twin; its snapshots alone {cost.publish_cpu_s_per_s:.3f})"
        return f"snapshots {cost.publish_cpu_s_per_s:.3f} (no service overhead measured yet)"

    def check(
        self, new: TwinCost, running: Iterable[TwinCost], overhead_per_twin_cpu_s_per_s: float | None = None
    ) -> Verdict:
        overhead = overhead_per_twin_cpu_s_per_s
        used = self.used(running, overhead)
        need = self.need(new, overhead)
        budget, per_twin = self.budget_cpu_s_per_s, self.per_twin_cpu_s_per_s
        figures = (
            f"it needs {need:.3f} CPU s per s (engine {new.engine_cpu_s_per_sim_s:.3f} CPU s per "
            f"simulated s, {self._share_text(new, overhead)})"
        )
        if need > per_twin:
            return Verdict(
                False,
                f"this host cannot run the twin in real time: {figures}, one core gives "
                f"a twin at most {per_twin:.3f} (core_fraction)",
                need,
                used,
                budget,
                per_twin,
            )
        if used + need > budget:
            return Verdict(
                False,
                f"this host has no capacity left for the twin in real time: {figures}, "
                f"the twins running use {used:.3f} of {budget:.3f} ({self.usable_cores} cores x "
                f"core_fraction {self.core_fraction:g}, less {self.reserve_cores:g} reserved for the service)",
                need,
                used,
                budget,
                per_twin,
            )
        return Verdict(
            True, f"admitted: {figures}; in use {used + need:.3f} of {budget:.3f}", need, used, budget, per_twin
        )

    def formula(
        self,
        typical: TwinCost | None,
        running: int,
        used_cpu_s_per_s: float,
        overhead_per_twin_cpu_s_per_s: float | None = None,
        alike_engine: float | None = None,
    ) -> str:
        """How `estimate_max_twins` reaches its number, with the figures of the moment; `typical`
        is a lone calibration, `alike_engine` the measured engine cost of the running twins alike
        it (None: none measured)."""
        head = (
            f"budget = {self.usable_cores} cores x core_fraction {self.core_fraction:g} - reserve "
            f"{self.reserve_cores:g} = {self.budget_cpu_s_per_s:.3f} CPU s/s"
        )
        if typical is None or not (typical.cpu_s_per_s > 0 and math.isfinite(typical.cpu_s_per_s)):
            return head + "; no twin calibrated yet"
        overhead = overhead_per_twin_cpu_s_per_s
        cal = typical.engine_cpu_s_per_sim_s
        expected = typical.with_engine(expected_engine_cost(cal, alike_engine))
        c = self.need(expected, overhead)
        n = self.estimate_max_twins(expected, running, used_cpu_s_per_s, overhead)
        engine = (
            f"engine {cal:.3f} (calibrated)"
            if alike_engine is None
            else f"engine max(calibrated {cal:.3f}, running alike {alike_engine:.3f})"
        )
        return (
            f"{head}; a twin like the last calibrated needs c = {engine} + "
            f"{self._share_text(expected, overhead)} = {c:.3f} CPU s/s; max_twins = "
            f"{running} running + floor(({self.budget_cpu_s_per_s:.3f} - {used_cpu_s_per_s:.3f} in use) / "
            f"{c:.3f}) = {n}"
        )

    def estimate_max_twins(
        self,
        typical: TwinCost | None,
        running: int,
        used_cpu_s_per_s: float,
        overhead_per_twin_cpu_s_per_s: float | None = None,
    ) -> int | None:
        """Twins this host holds in real time: the running ones plus as many more like `typical`
        (its engine plus the service share) as the budget has room for (None without a measured
        cost)."""
        if typical is None or typical.cpu_s_per_s <= 0 or not math.isfinite(typical.cpu_s_per_s):
            return None
        c = self.need(typical, overhead_per_twin_cpu_s_per_s)
        if c > self.per_twin_cpu_s_per_s:
            return running
        room = max(0.0, self.budget_cpu_s_per_s - used_cpu_s_per_s)
        return running + int(room // c)


class ServiceOverheadMeter:
    """The service's CPU beside the engines (see the module docstring): each `sample` compares the
    process's CPU time and the engines' summed thread CPU time with those of the sample at least
    `min_window_s` of wall time before, and keeps the last closed window's figures. Thread-safe."""

    def __init__(
        self,
        min_window_s: float = 1.0,
        *,
        clock: Callable[[], float] = time.monotonic,
        cpu_clock: Callable[[], float] = time.process_time,
    ):
        self.min_window_s = float(min_window_s)
        self._clock = clock
        self._cpu_clock = cpu_clock
        self._lock = threading.Lock()
        self._mark: tuple[float, float, float] | None = None  # (wall, process CPU, engine CPU)
        self._last: dict | None = None

    def sample(self, engine_cpu_s_total: float, twins: int) -> dict | None:
        """The last closed window's figures (None before one closes): `process_cpu_s_per_s`,
        `engine_cpu_s_per_s`, `overhead_cpu_s_per_s` (their difference), its share per twin and of
        the engines' CPU (`overhead_fraction`) against `goal_fraction` [CPU s / s, -]."""
        now, cpu = self._clock(), self._cpu_clock()
        with self._lock:
            mark = self._mark
            if mark is None or engine_cpu_s_total < mark[2]:  # first sample, or a twin left
                self._mark = (now, cpu, engine_cpu_s_total)
                return self._last
            wall = now - mark[0]
            if wall < self.min_window_s:
                return self._last
            process = (cpu - mark[1]) / wall
            engine = (engine_cpu_s_total - mark[2]) / wall
            overhead = max(0.0, process - engine)
            self._last = {
                "window_s": wall,
                "process_cpu_s_per_s": process,
                "engine_cpu_s_per_s": engine,
                "overhead_cpu_s_per_s": overhead,
                "overhead_per_twin_cpu_s_per_s": overhead / twins if twins > 0 else None,
                "overhead_fraction": overhead / engine if engine > 0 else None,
                "goal_fraction": OVERHEAD_GOAL,
            }
            self._mark = (now, cpu, engine_cpu_s_total)
            return self._last
