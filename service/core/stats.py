"""Statistics of a runner: the loop's own counters and the one health record per twin that
gathers them with the pacing clock's, the publisher's, the mailbox's and the fault policy's
(`/health` shows it; `service.api.schemas.TwinHealth` documents every field)."""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

LATENCY_WINDOW = 1000  # setpoints the /health latency figures cover (the newest)


@dataclass
class LoopCounters:
    """Written by the runner thread only."""

    frames: int = 0  # frames advanced
    errors: int = 0  # exceptions caught in the loop (each followed by a warm restart)
    last_error: str | None = None
    failed: bool = False  # stopped after too many errors in a row

    def error(self, exc: BaseException) -> None:
        self.errors += 1
        self.last_error = f"{type(exc).__name__}: {exc}"


def percentile(values: list[float], q: float) -> float:
    """The q-th percentile of non-empty `values` by the nearest rank (no interpolation)."""
    ordered = sorted(values)
    return ordered[max(0, min(len(ordered) - 1, math.ceil(q / 100.0 * len(ordered)) - 1))]


def setpoint_latency_ms(timings: Iterable[Any]) -> dict | None:
    """Accepted -> published latency of setpoints inside the service, whole and by stage
    (`SetpointTiming.stages_s`), as {stage: {"p50", "p99", "max"}} [ms] plus `count`; None
    without a completed timing."""
    stages: dict[str, list[float]] = {}
    for t in timings:
        parts = t.stages_s()
        if parts is None:
            continue
        for name, value in (*parts.items(), ("total", t.latency_s)):
            stages.setdefault(name, []).append(1e3 * value)
    if not stages:
        return None
    out: dict[str, Any] = {
        name: {"p50": round(percentile(v, 50), 3), "p99": round(percentile(v, 99), 3), "max": round(max(v), 3)}
        for name, v in stages.items()
    }
    out["count"] = len(stages["total"])
    return out


def health_record(runner: Any, *, setpoints_refused: int = 0, setpoints_rate_limited: int = 0) -> dict:
    """One twin's /health entry from its runner (`service.core.runner.TwinRunner`) and the
    refusals counted outside it (zenoh intake, admission gate)."""
    latest = runner.latest
    cost = runner.cost
    return {
        "id": runner.bearing_id,
        "running": runner.running,
        "mode": runner.mode,
        "status": latest.status if latest is not None else runner.publisher.status_text(runner.twin.status),
        "time_s": latest.time_s if latest is not None else runner.twin.time_s,
        "real_time_factor": runner.real_time_factor,
        "late_fraction": runner.late_fraction,
        "lateness_s": runner.pacing.lateness_s,
        "frame_s": runner.frame_s,
        "frames": runner.frames,
        "overruns": runner.overruns,
        "resyncs": runner.resyncs,
        "published": runner.published,
        "dropped": runner.dropped,
        "errors": runner.errors,
        "restarts": runner.twin.restarts,
        "setpoints_accepted": runner.setpoints_accepted,
        "setpoints_refused": setpoints_refused,
        "setpoints_rate_limited": setpoints_rate_limited,
        "fallbacks": runner.fallbacks,
        "last_safe_setpoint": runner.last_safe_setpoint.model_dump(),
        "cost": cost.as_dict() if cost is not None else None,
        "setpoint_latency_ms": setpoint_latency_ms(runner.publisher.recent_timings(LATENCY_WINDOW)),
    }
