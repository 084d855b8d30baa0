"""What the engine did about a state its kernel could not hold: a typed value, not prose.

The kernel reports a status code (twin.kernels.layout: non-finite state, excessive contact
penetration); the engine warm-restarts and records a `Fault`. `Fault.describe()` is the text a
snapshot's `status` carries; code reads `kind`, `cause` and `time_s`.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum


class FaultKind(StrEnum):
    """What the engine did."""

    RESTARTED = "restarted"  # warm-restarted at the setpoint in force, simulated time kept
    HALTED = "halted"  # failed again right after a restart: waits for a new setpoint


@dataclass(frozen=True)
class Fault:
    """One fault of the engine: what it did, why (the kernel's status name, e.g. 'overloaded:
    excessive contact penetration') and when [s of simulated time]."""

    kind: FaultKind
    cause: str
    time_s: float
    restart_window_s: float = 0.0  # HALTED: the failure came within this much of a restart [s]

    def describe(self) -> str:
        """The snapshot's `status` text."""
        if self.kind is FaultKind.HALTED:
            return (
                f"halted: {self.cause} again within {self.restart_window_s * 1e3:.0f} ms of a "
                f"restart at t = {self.time_s:.6f} s; the setpoint cannot be held, waiting for a new one"
            )
        return f"restarted: {self.cause} at t = {self.time_s:.6f} s"
