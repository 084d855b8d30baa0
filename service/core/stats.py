"""Statistics of a runner: the loop's own counters and the one health record per twin that
gathers them with the pacing clock's, the publisher's, the mailbox's and the fault policy's
(`/health` shows it; `service.api.schemas.TwinHealth` documents every field)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any


@dataclass
class LoopCounters:
    """Written by the runner thread only."""

    frames: int = 0            # frames advanced
    errors: int = 0            # exceptions caught in the loop (each followed by a warm restart)
    last_error: str | None = None
    failed: bool = False       # stopped after too many errors in a row

    def error(self, exc: BaseException) -> None:
        self.errors += 1
        self.last_error = f"{type(exc).__name__}: {exc}"


def health_record(runner: Any, *, setpoints_refused: int = 0, setpoints_rate_limited: int = 0) -> dict:
    """One twin's /health entry from its runner (`service.core.runner.TwinRunner`) and the
    refusals counted outside it (zenoh intake, admission gate)."""
    latest = runner.latest
    cost = runner.cost
    return {
        "id": runner.bearing_id, "running": runner.running, "mode": runner.mode,
        "status": latest.status if latest is not None else runner.publisher.status_text(runner.twin.status),
        "time_s": latest.time_s if latest is not None else runner.twin.time_s,
        "real_time_factor": runner.real_time_factor, "late_fraction": runner.late_fraction,
        "lateness_s": runner.pacing.lateness_s, "frame_s": runner.frame_s, "frames": runner.frames,
        "overruns": runner.overruns, "resyncs": runner.resyncs, "published": runner.published,
        "dropped": runner.dropped, "errors": runner.errors, "restarts": runner.twin.restarts,
        "setpoints_accepted": runner.setpoints_accepted, "setpoints_refused": setpoints_refused,
        "setpoints_rate_limited": setpoints_rate_limited, "fallbacks": runner.fallbacks,
        "last_safe_setpoint": runner.last_safe_setpoint.model_dump(),
        "publish_skipped": runner.publisher.skipped,
        "cost": cost.as_dict() if cost is not None else None,
    }
