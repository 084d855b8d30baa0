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
* A twin is admitted when (1) its own cost fits one core's share (`core_fraction`): a twin is
  stepped by one thread at a time, so it can never use more than one core, and (2) the costs of
  the running twins plus its own fit the capacity. Otherwise it is refused (HTTP 503) with the
  reason and the measured figures. The twin the configuration starts with the service is
  started in any case and said to be over capacity (warning in the log and in /health).

`max_twins` (a setting) is a fixed cap on top; unset, the capacity alone decides (up to 256).
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass

from twin.engine import Twin


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
        self.cpu_s = 0.0           # totals since the start
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

    engine_cpu_s_per_sim_s: float    # CPU s per simulated s of the engine (1 / lone real-time factor)
    publish_cpu_s_per_s: float       # CPU s per wall s spent building its snapshots

    @property
    def cpu_s_per_s(self) -> float:
        """Total CPU s per wall s in real time [CPU s / s]."""
        return self.engine_cpu_s_per_sim_s + self.publish_cpu_s_per_s

    def as_dict(self) -> dict:
        return {"engine_cpu_s_per_sim_s": self.engine_cpu_s_per_sim_s,
                "publish_cpu_s_per_s": self.publish_cpu_s_per_s, "cpu_s_per_s": self.cpu_s_per_s}


def calibrate(twin: Twin, *, sim_s: float = 0.02, frame_steps: int = 5000, publish_rate_hz: float = 50.0,
              cpu_clock: Callable[[], float] = time.thread_time) -> TwinCost:
    """Measure a twin's cost: a warm-up frame (JIT cache load), then `sim_s` of simulated time in
    two halves (the cheaper half counts: a preemption or page fault is not the twin's), and two
    snapshots (the second counts). The twin's simulated clock moves on by `sim_s` plus one
    frame: the same trajectory it would have run anyway."""
    dt = twin.model.dt_s
    twin.advance(min(sim_s, 0.001), frame_steps=frame_steps)          # warm-up
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
    twin.seq -= 2            # the calibration snapshots are not published
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

    def __init__(self, stepping_threads: int, core_fraction: float = 0.85, cores: int | None = None,
                 reserve_cores: float = 0.0):
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

    def check(self, new: TwinCost, running: Iterable[TwinCost]) -> Verdict:
        used = sum(c.cpu_s_per_s for c in running)
        need = new.cpu_s_per_s
        budget, per_twin = self.budget_cpu_s_per_s, self.per_twin_cpu_s_per_s
        figures = (f"it needs {need:.3f} CPU s per s (engine {new.engine_cpu_s_per_sim_s:.3f} CPU s per "
                   f"simulated s, snapshots {new.publish_cpu_s_per_s:.3f})")
        if need > per_twin:
            return Verdict(False, f"this host cannot run the twin in real time: {figures}, one core gives "
                           f"a twin at most {per_twin:.3f} (core_fraction)", need, used, budget, per_twin)
        if used + need > budget:
            return Verdict(False, f"this host has no capacity left for the twin in real time: {figures}, "
                           f"the twins running use {used:.3f} of {budget:.3f} ({self.usable_cores} cores x "
                           f"core_fraction {self.core_fraction:g}, less {self.reserve_cores:g} reserved for the service)", need, used, budget, per_twin)
        return Verdict(True, f"admitted: {figures}; in use {used + need:.3f} of {budget:.3f}",
                       need, used, budget, per_twin)

    def estimate_max_twins(self, typical: TwinCost | None, running: int, used_cpu_s_per_s: float) -> int | None:
        """Twins this host holds in real time: the running ones plus as many more like `typical`
        as the budget has room for (None without a measured cost)."""
        if typical is None or typical.cpu_s_per_s <= 0 or not math.isfinite(typical.cpu_s_per_s):
            return None
        if typical.cpu_s_per_s > self.per_twin_cpu_s_per_s:
            return running
        room = max(0.0, self.budget_cpu_s_per_s - used_cpu_s_per_s)
        return running + int(room // typical.cpu_s_per_s)
