"""The mailbox between any thread and a twin's runner thread.

Any thread `offer`s a partial `SetpointUpdate`: it is merged over the latest accepted target
(latest wins per field, in order of arrival) and checked against the bearing's limits ONCE
(`SetpointLimits.admit`); the result becomes the new target and waits as the pending setpoint.
The runner thread `take`s the pending one between frames and hands it to the engine, which does
not check it again (it is `Admitted`). A `guard` may refuse more (the fault policy refuses
values this twin could not hold).

Timing: for every offer marked `timed` (an outside setpoint) the mailbox records when its request
arrived (when the transport says so), when it was submitted and when it was accepted; the runner
stamps when it was applied and the publisher when the first snapshot that reflects it was
published (`SetpointTiming`, for /health and the latency benchmark). All stamps are the runner's
clock (`time.perf_counter` in the service: CLOCK_MONOTONIC on Linux, so a client process on the
same host can compare its own stamps with them).
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Generic, TypeVar

from twin.setpoint import Admitted, Setpoint, SetpointLimits, SetpointUpdate

T = TypeVar("T")


@dataclass
class SetpointTiming:
    """When a setpoint arrived, was accepted, and was first seen in a published snapshot."""

    accepted_wall_s: float  # clock() at acceptance
    submitted_wall_s: float | None = None  # when `TwinRunner.submit` was called (None: = accepted)
    received_wall_s: float | None = None  # when its request arrived at the server (None: unknown)
    applied_wall_s: float | None = None  # when the runner applied it (frame boundary)
    captured_wall_s: float | None = None  # when the frame that reflects it was captured for publication
    built_wall_s: float | None = None  # when that capture's snapshot was built
    published_wall_s: float | None = None  # when the first snapshot reflecting it was published
    seq: int | None = None  # that snapshot's seq

    @property
    def start_wall_s(self) -> float:
        """Where its latency counts from: the request's arrival when known, else the submission."""
        if self.received_wall_s is not None:
            return self.received_wall_s
        return self.accepted_wall_s if self.submitted_wall_s is None else self.submitted_wall_s

    @property
    def latency_s(self) -> float | None:
        """Arrival (or submission) -> first published snapshot reflecting it [s]."""
        if self.published_wall_s is None:
            return None
        return self.published_wall_s - self.start_wall_s

    def stages_s(self) -> dict[str, float] | None:
        """The latency by stage [s] (None until published); they add up to `latency_s`:

        * `http` (only when the request's arrival is known): the request's bytes read by the
          server -> `submit` called (parsing, middleware, routing, the token and rate checks,
          the body's validation);
        * `admission`: `submit` -> accepted (merged in the mailbox, checked against the bearing's
          limits and the fault policy);
        * `apply`: accepted -> applied at a frame boundary (the stepping thread's wake-up);
        * `step`: applied -> captured (the frame that applies it);
        * `build`: captured -> its snapshot built;
        * `publish`: built -> handed to every sink (the zenoh state put)."""
        a, b, c, e, d = (
            self.accepted_wall_s,
            self.applied_wall_s,
            self.captured_wall_s,
            self.built_wall_s,
            self.published_wall_s,
        )
        if b is None or c is None or e is None or d is None:
            return None
        submitted = a if self.submitted_wall_s is None else self.submitted_wall_s
        out = {} if self.received_wall_s is None else {"http": submitted - self.received_wall_s}
        out.update({"admission": a - submitted, "apply": b - a, "step": c - b, "build": e - c, "publish": d - e})
        return out


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

    def offer(
        self,
        update: SetpointUpdate,
        *,
        timed: bool = True,
        guard: Guard | None = None,
        received_s: float | None = None,
        submitted_s: float | None = None,
    ) -> Setpoint:
        """Merge `update` over the target and check it (SetpointError naming every field out of
        the bearing's range; whatever `guard` raises). Returns the new target. `received_s`,
        `submitted_s`: when its request arrived and when it was submitted (a timed offer's
        `SetpointTiming`)."""
        with self._lock:
            admitted = self.limits.admit(update, self._target)
            if guard is not None:
                guard(admitted.setpoint, update)
            if update.fields:
                self._pending = admitted
            self._target = admitted.setpoint
            if timed:
                self.accepted += 1
                self._timings.append(
                    SetpointTiming(
                        accepted_wall_s=self._clock(), submitted_wall_s=submitted_s, received_wall_s=received_s
                    )
                )
            return admitted.setpoint

    @property
    def waiting(self) -> bool:
        """Whether an offer waits for the runner's next `take` (a setpoint or an outside offer's
        timing)."""
        with self._lock:
            return self._pending is not None or bool(self._timings)

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


class LatestValue(Generic[T]):
    """A one-slot mailbox between threads: the value offered last waits for the runner thread,
    which takes it once (latest wins)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._pending: T | None = None

    def offer(self, value: T) -> None:
        with self._lock:
            self._pending = value

    @property
    def waiting(self) -> bool:
        """Whether a value waits to be taken."""
        with self._lock:
            return self._pending is not None

    def take(self) -> T | None:
        """The pending value, or None; the slot is empty afterwards."""
        with self._lock:
            pending, self._pending = self._pending, None
        return pending
