"""The runner's fault policy: what a twin does when the engine cannot hold its setpoint.

The kernel reports a state it cannot hold (non-finite, excessive penetration); the engine then
warm-restarts at the setpoint in force and records a typed `twin.faults.Fault`. A setpoint inside
the bearing's limits can still be one the model cannot hold (a load step far beyond what the
contacts carry): it fails again right after each restart. The policy bounds that (at most
`max_restarts_per_frame` engine restarts per frame, `Twin.advance(max_restarts=)`) and falls
back: the twin is warm-restarted at the LAST SAFE SETPOINT (one held for `safe_after_frames`
frames without a restart; the twin's initial setpoint to begin with; an older one if even that
fails), which becomes the target again. A `Fallback` value says what was not held, why and what
the twin went back to. A value that was not held (when one load or speed field alone rose) is
remembered: from then on this twin refuses it, and anything beyond it (`check_held`, a mailbox
guard: 422 naming the field).
"""

from __future__ import annotations

import collections
from collections.abc import Callable
from dataclasses import dataclass

from service.core.errors import FieldError, InputError
from twin.engine import Twin
from twin.setpoint import NAMES, Setpoint, SetpointLimits, SetpointUpdate, unit

#: fields whose rise alone can make a setpoint unholdable (remembered as "not held")
_LOAD_FIELDS = ("radial_load_n", "axial_load_n", "shaft_speed_rad_s")


@dataclass(frozen=True)
class Fallback:
    """The twin could not hold `not_held` (because of `cause`) and went back to `safe`."""

    not_held: Setpoint
    safe: Setpoint
    cause: str
    count: int  # fallbacks of this twin so far, this one included

    def describe(self) -> str:
        changed = [n for n in NAMES if getattr(self.not_held, n) != getattr(self.safe, n)]
        what = self.not_held.describe(changed) if changed else "the setpoint in force"
        back = f" ({self.safe.describe(changed)})" if changed else ""
        return (
            f"setpoint not held ({self.cause}): {what}; restarted from the warm start at the "
            f"last safe setpoint{back}; fallbacks: {self.count}"
        )


class FaultPolicy:
    """Safe setpoints, fallbacks and values not held of one twin (see the module docstring).
    `advance_frame` runs in the runner thread; `check_held` in whichever thread offers a setpoint."""

    def __init__(
        self, initial: Setpoint, limits: SetpointLimits, *, safe_after_frames: int = 20, max_restarts_per_frame: int = 2
    ):
        self.limits = limits
        self.safe_after_frames = max(1, int(safe_after_frames))
        self.max_restarts_per_frame = max(1, int(max_restarts_per_frame))
        self.steps_left = 0  # steps of the last frame not run: it was interrupted (Twin.interrupt_frame)
        self._safe: collections.deque[Setpoint] = collections.deque([initial], maxlen=8)
        self._held_setpoint = initial
        self._held_frames = 0
        self._restart_streak = 0  # consecutive frames with an engine restart
        self.fallbacks = 0
        self.not_held: dict[str, tuple[float, str]] = {}  # field -> (lowest |value| not held, why)

    @property
    def last_safe(self) -> Setpoint:
        """The newest setpoint held for `safe_after_frames` frames without a restart."""
        return self._safe[-1]

    def advance_frame(
        self, twin: Twin, frame_s: float, frame_steps: int, on_fallback: Callable[[Setpoint], None]
    ) -> Fallback | None:
        """One frame of physics; on a setpoint the twin cannot hold, fall back (`on_fallback(safe)`
        is called before the twin goes on at the safe setpoint) and return what happened."""
        before = twin.restarts
        self.steps_left = 0
        left = twin.advance(frame_s, frame_steps=frame_steps, max_restarts=self.max_restarts_per_frame) or 0
        if getattr(twin, "frame_interrupted", False):  # ended early for waiting input: not a fault
            self.steps_left, left = left, 0
        if twin.restarts == before:
            self._restart_streak = 0
            self._held(twin.setpoint)
            return None
        self._restart_streak += 1
        self._held_frames = 0
        if left <= 0 and self._restart_streak < 2:
            return None
        fallback = self._fall_back(twin, on_fallback)
        if left > 0:  # the rest of the frame at the safe setpoint (bounded as well)
            rest = twin.advance(left * twin.model.dt_s, frame_steps=frame_steps, max_restarts=1) or 0
            if getattr(twin, "frame_interrupted", False):
                self.steps_left = rest
        return fallback

    def _held(self, sp: Setpoint) -> None:
        if sp != self._held_setpoint:
            self._held_setpoint, self._held_frames = sp, 0
        self._held_frames += 1
        if self._held_frames >= self.safe_after_frames and sp != self._safe[-1]:
            self._safe.append(sp)

    def _fall_back(self, twin: Twin, on_fallback: Callable[[Setpoint], None]) -> Fallback:
        current = twin.setpoint
        cause = twin.fault.cause if twin.fault is not None else "not held"
        if current == self._safe[-1] and self._restart_streak >= 3 and len(self._safe) > 1:
            self._safe.pop()  # even the last safe one is not held: go further back
        safe = self._safe[-1]
        self._learn_not_held(current, safe, cause)
        on_fallback(safe)
        twin.set_setpoint(self.limits.admit(safe))
        twin.reset(warm=True, keep_time=True)
        twin.restarts += 1
        self.fallbacks += 1
        self._held_setpoint, self._held_frames = safe, 0
        return Fallback(not_held=current, safe=safe, cause=cause, count=self.fallbacks)

    def _learn_not_held(self, current: Setpoint, safe: Setpoint, cause: str) -> None:
        rose = [n for n in _LOAD_FIELDS if abs(getattr(current, n)) > abs(getattr(safe, n))]
        if len(rose) == 1:  # one cause only: remember the value
            name = rose[0]
            value = abs(getattr(current, name))
            known = self.not_held.get(name)
            if known is None or value < known[0]:
                self.not_held[name] = (value, cause)

    def check_held(self, new: Setpoint, update: SetpointUpdate) -> None:
        """Refuse (InputError 422) a setpoint reaching a value this twin could not hold."""
        errors = []
        fields = update.fields
        for name, (value, why) in list(self.not_held.items()):
            if name in fields and abs(getattr(new, name)) >= value:
                low, high = self.limits[name]
                u = unit(name)
                errors.append(
                    FieldError(
                        field=name,
                        allowed=[max(low, -value), min(high, value)],
                        message=f"{name} = {getattr(new, name):g} {u}: this twin could not hold "
                        f"{value:g} {u} ({why}) and fell back to its last safe setpoint; values of "
                        f"{value:g} {u} and beyond are refused (re-create the twin to try again)",
                    )
                )
        if errors:
            raise InputError(errors)


class ErrorStreak:
    """Failed frames in a row of one twin, against the limit at which its runner gives up."""

    def __init__(self, limit: int) -> None:
        self.limit = int(limit)
        self.count = 0

    def add(self) -> int:
        """One more failed frame; returns how many in a row."""
        self.count += 1
        return self.count

    def clear(self) -> None:
        """A frame succeeded."""
        self.count = 0

    @property
    def exhausted(self) -> bool:
        return self.count >= self.limit
