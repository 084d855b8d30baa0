"""The mailbox between any thread and a twin's runner thread.

Any thread `offer`s a partial `SetpointUpdate`: it is merged over the latest accepted target
(latest wins per field, in order of arrival) and checked against the bearing's limits ONCE
(`SetpointLimits.admit`); the result becomes the new target and waits as the pending setpoint.
The runner thread `take`s the pending one between frames and hands it to the engine, which does
not check it again (it is `Admitted`). A `guard` may refuse more (the fault policy refuses
values this twin could not hold).

Timing: for every offer marked `timed` (an outside setpoint) the mailbox records when it was
accepted; the runner stamps when it was applied and the publisher when the first snapshot that
reflects it was published (`SetpointTiming`, for the latency benchmark).
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

from twin.setpoint import Admitted, Setpoint, SetpointLimits, SetpointUpdate


@dataclass
class SetpointTiming:
    """When a setpoint was accepted and when it was first seen in a published snapshot."""

    accepted_wall_s: float  # clock() at acceptance
    applied_wall_s: float | None = None  # when the runner applied it (frame boundary)
    captured_wall_s: float | None = None  # when the frame that reflects it was captured for publication
    built_wall_s: float | None = None  # when that capture's snapshot was built
    published_wall_s: float | None = None  # when the first snapshot reflecting it was published
    seq: int | None = None  # that snapshot's seq

    @property
    def latency_s(self) -> float | None:
        """Accepted -> first published snapshot reflecting it [s]."""
        if self.published_wall_s is None:
            return None
        return self.published_wall_s - self.accepted_wall_s

    def stages_s(self) -> dict[str, float] | None:
        """The latency by stage [s] (None until published): `apply` accepted -> applied at a frame
        boundary (the stepping thread's wake-up), `step` applied -> captured (the frame that applies
        it), `build` captured -> its snapshot built, `publish` built -> handed to every sink (the
        zenoh state put)."""
        a, b, c, e, d = (
            self.accepted_wall_s,
            self.applied_wall_s,
            self.captured_wall_s,
            self.built_wall_s,
            self.published_wall_s,
        )
        if b is None or c is None or e is None or d is None:
            return None
        return {"apply": b - a, "step": c - b, "build": e - c, "publish": d - e}


Guard = Callable[[Setpoint, SetpointUpdate], None]


class Mailbox:
    """Latest accepted setpoint of one twin and the one waiting for the next frame."""

    def __init__(self, setpoint: Setpoint, limits: SetpointLimits, *, clock: Callable[[], float] = time.perf_counter):
        self.limits = limits
        self._clock = clock
        self._lock = threading.Lock()
        self._target = setpoint
        self._pending: Admitted | None = None
        self._timings: list[SetpointTiming] = []
        self.accepted = 0  # timed offers accepted
        self.applied = 0  # pending setpoints taken by the runner

    @property
    def target(self) -> Setpoint:
        """The latest accepted setpoint (in force, or applied at the next frame)."""
        with self._lock:
            return self._target

    def offer(self, update: SetpointUpdate, *, timed: bool = True, guard: Guard | None = None) -> Setpoint:
        """Merge `update` over the target and check it (SetpointError naming every field out of
        the bearing's range; whatever `guard` raises). Returns the new target."""
        with self._lock:
            admitted = self.limits.admit(update, self._target)
            if guard is not None:
                guard(admitted.setpoint, update)
            if update.fields:
                self._pending = admitted
            self._target = admitted.setpoint
            if timed:
                self.accepted += 1
                self._timings.append(SetpointTiming(accepted_wall_s=self._clock()))
            return admitted.setpoint

    def take(self) -> tuple[Admitted | None, list[SetpointTiming]]:
        """(the pending setpoint or None, the timings of the offers it merges) - runner thread."""
        with self._lock:
            pending, self._pending = self._pending, None
            timings, self._timings = self._timings, []
        if pending is not None:
            self.applied += 1
        now = self._clock()
        for t in timings:
            t.applied_wall_s = now
        return pending, timings

    def reset(self, setpoint: Setpoint) -> None:
        """The twin fell back to `setpoint`: it is the target, what was pending is dropped."""
        with self._lock:
            self._target = setpoint
            self._pending = None
