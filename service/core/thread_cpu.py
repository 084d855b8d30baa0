"""Where the service's CPU goes, by the job of each thread: a breakdown of the service overhead.

The service overhead (service.core.capacity.ServiceOverheadMeter) is the process's CPU less the
engines'. `ThreadCpuMeter` splits it by the job of the threads that spend it, from each Python
thread's own CPU clock (Linux, by its kernel id, nanoseconds) and the process's
(`time.process_time`); the threads without a Python name (zenoh's and rerun's native runtimes)
are what the process spent beyond the Python threads:

=================  =========================================================================
role               threads
=================  =========================================================================
stepping           `step-N` less the engines' own frames: the runner's Python between
                   frames and, in real time, every snapshot built and handed to the sinks
publish_worker     `step-publish`: fast mode's snapshots built and handed to the sinks
zenoh_outbox       `zenoh-pub-*`: ball, vibration and waveform messages
zenoh_inbox        `zenoh-ctl-*` and zenoh's callbacks (`pyo3-closure`)
alarms             `alarms`
recording          `rerun-*`
http               `MainThread` (uvicorn's event loop) and the `AnyIO worker thread`s
opcua              `opcua`
other              any other Python thread
native             the process less its Python threads: zenoh's and rerun's runtimes
=================  =========================================================================

The roles a twin brings with it (stepping, publish_worker, zenoh_outbox, zenoh_inbox, alarms,
recording, native) make `twin_overhead_cpu_s_per_s`; http and opcua serve clients and grow with
their requests, not with the twins. Linux (a per-thread CPU clock by kernel id); elsewhere the
breakdown is empty.
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Callable

ROLES = (
    "stepping",
    "publish_worker",
    "zenoh_outbox",
    "zenoh_inbox",
    "alarms",
    "recording",
    "http",
    "opcua",
    "other",
    "native",
)
CLIENT_ROLES = frozenset({"http", "opcua"})


def thread_role(name: str) -> str:
    """The role of a Python thread by its name (see the module docstring)."""
    if name == "step-publish" or name.endswith("-publish"):
        return "publish_worker"
    if name.startswith("step-") or name.startswith("twin-"):
        return "stepping"
    if name.startswith("zenoh-pub-"):
        return "zenoh_outbox"
    if name.startswith("zenoh-ctl-") or "pyo3-closure" in name:
        return "zenoh_inbox"
    if name == "alarms":
        return "alarms"
    if name.startswith("rerun"):
        return "recording"
    if name == "MainThread" or name.startswith("AnyIO worker"):
        return "http"
    if name == "opcua":
        return "opcua"
    return "other"


def thread_cpu_clock(native_id: int) -> int:
    """The CPU-time clock of a thread by its kernel id (Linux: the clock id glibc's
    pthread_getcpuclockid makes, `MAKE_THREAD_CPUCLOCK(tid, CPUCLOCK_SCHED)`). Made from the kernel
    id, a thread that has ended gives EINVAL instead of a read through a freed pthread handle."""
    return ((~native_id) << 3) | 6


def thread_cpu_by_role() -> dict[str, float]:
    """CPU seconds spent so far by the live Python threads of each role, and `native` (the
    process's CPU less theirs) [s]. Threads that ended take their CPU out of the Python roles and
    into `native`: the rates of a window over such an end are approximate. {} off Linux."""
    if not sys.platform.startswith("linux"):
        return {}
    totals = dict.fromkeys(ROLES, 0.0)
    process = time.process_time()
    python = 0.0
    for t in threading.enumerate():
        if t.native_id is None:
            continue
        try:
            cpu = time.clock_gettime(thread_cpu_clock(t.native_id))
        except (OSError, OverflowError, ValueError):  # the thread ended meanwhile
            continue
        totals[thread_role(t.name)] += cpu
        python += cpu
    totals["native"] = max(0.0, process - python)
    return totals


class ThreadCpuMeter:
    """CPU per wall second by role over the last closed window of at least `min_window_s`
    (see the module docstring). Thread-safe."""

    def __init__(
        self,
        min_window_s: float = 1.0,
        *,
        clock: Callable[[], float] = time.monotonic,
        sample: Callable[[], dict[str, float]] = thread_cpu_by_role,
    ):
        self.min_window_s = float(min_window_s)
        self._clock = clock
        self._sample = sample
        self._lock = threading.Lock()
        self._mark: tuple[float, dict[str, float], float] | None = None  # (wall, role totals, engine CPU)
        self._last: dict[str, float | None] = {}

    @property
    def overhead_per_twin_cpu_s_per_s(self) -> float | None:
        """The service's CPU per twin beside the engines over the last closed window (HTTP not
        counted), None before one closes [CPU s / s]."""
        with self._lock:
            return self._last.get("twin_overhead_per_twin_cpu_s_per_s")

    def sample(self, engine_cpu_s_total: float, twins: int) -> dict[str, float | None]:
        """Flat figures of the last closed window: `<role>_cpu_s_per_s` for each role (stepping
        less the engines' CPU), `twin_overhead_cpu_s_per_s` (the roles a twin brings),
        `twin_overhead_per_twin_cpu_s_per_s` and `twin_overhead_fraction` (of the engines' CPU)
        [CPU s / s, -]; beside them the totals of the live threads so far, `<role>_cpu_s_total`,
        `twin_overhead_cpu_s_total` and the engines' `engine_cpu_s_total` [CPU s], from which a client computes the
        figures over a
        window of its own (`bench-service` over its whole measurement). Only the totals before
        a window closes; {} without per-thread clocks."""
        now, totals = self._clock(), self._sample()
        if not totals:
            return {}
        totals = {**totals, "stepping": max(0.0, totals.get("stepping", 0.0) - engine_cpu_s_total)}
        cumulative: dict[str, float | None] = {f"{role}_cpu_s_total": totals.get(role, 0.0) for role in ROLES}
        cumulative["twin_overhead_cpu_s_total"] = sum(v for role, v in totals.items() if role not in CLIENT_ROLES)
        cumulative["engine_cpu_s_total"] = engine_cpu_s_total
        with self._lock:
            mark = self._mark
            if mark is None or engine_cpu_s_total < mark[2]:
                self._mark = (now, totals, engine_cpu_s_total)
                return {**self._last, **cumulative}
            wall = now - mark[0]
            if wall < self.min_window_s:
                return {**self._last, **cumulative}
            engine = (engine_cpu_s_total - mark[2]) / wall
            rates = {role: max(0.0, (totals.get(role, 0.0) - mark[1].get(role, 0.0)) / wall) for role in ROLES}
            twin = sum(v for role, v in rates.items() if role not in CLIENT_ROLES)
            out: dict[str, float | None] = {f"{role}_cpu_s_per_s": v for role, v in rates.items()}
            out["twin_overhead_cpu_s_per_s"] = twin
            out["twin_overhead_per_twin_cpu_s_per_s"] = twin / twins if twins > 0 else None
            out["twin_overhead_fraction"] = twin / engine if engine > 0 else None
            self._last = out
            self._mark = (now, totals, engine_cpu_s_total)
            return {**out, **cumulative}
