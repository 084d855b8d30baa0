"""The alarm vocabulary: ids, severities, the ISO 20816-3:2022 zone table, and the `Rule` and `Level`
an alarm is judged by (service.core.alarms holds the state machines that use them).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Literal

EVENT_SCHEMA = "bearing-twin/alarm/1"

Severity = Literal["warning", "critical"]
Transition = Literal["raised", "escalated", "deescalated", "cleared"]
Direction = Literal["above", "below"]

# OPC UA event Severity (1..1000, OPC 10000-5 BaseEventType) of each level
OPCUA_SEVERITY = {"warning": 500, "critical": 800, None: 100}

# ISO 20816-3:2022 Annex A: zone boundaries A/B, B/C, C/D of the broadband velocity RMS [mm/s]
# (10-1000 Hz), Table A.1 (group 1) and Table A.2 (group 2), by support class.
ISO_20816_3_ZONES: Mapping[tuple[int, str], tuple[float, float, float]] = {
    (1, "rigid"): (2.3, 4.5, 7.1),
    (1, "flexible"): (3.5, 7.1, 11.0),
    (2, "rigid"): (1.4, 2.8, 4.5),
    (2, "flexible"): (2.3, 4.5, 7.1),
}

DEFECT_LINES = ("ftf", "bpfo", "bpfi", "bsf", "two_bsf")  # keys of VibrationState.envelope_lines
TIME_EPS_S = 1e-9  # a delay of 0.2 s is over at t = 0.3 after 0.1 (0.3 - 0.1 = 0.19999999999999998)
DISCHARGE_LEVELS = {"none": 0.0, "possible": 1.0, "likely": 2.0}

# the alarms on measured accelerometer windows (service.core.measured): fed by `update_measured`
MEASURED_ALARMS = ("measured_line", "measured_kurtosis")
ALARM_IDS: tuple[str, ...] = (
    "vibration_zone",
    "lubrication_kappa",
    "lubrication_boundary",
    "electrical_discharge",
    *(f"defect_{n}" for n in DEFECT_LINES),
    "life_used",
    "temperature_zone",
    "temperature_rate",
    "temperature_unexplained",
    *MEASURED_ALARMS,
)


def line_name(name: str) -> str:
    """'BPFO', ..., '2 x BSF' for the envelope line keys."""
    return "2 x BSF" if name == "two_bsf" else name.upper()


def zone_boundaries(machine_group: int, support: str) -> tuple[float, float, float]:
    """(A/B, B/C, C/D) boundaries [mm/s] of ISO 20816-3:2022 Table A.1 (group 1) / A.2 (group 2)."""
    try:
        return ISO_20816_3_ZONES[(int(machine_group), support)]
    except KeyError:
        raise ValueError(
            f"no ISO 20816-3 zones for machine group {machine_group!r} and support "
            f"{support!r}; known: {sorted(ISO_20816_3_ZONES)}"
        ) from None


def vibration_zone(velocity_rms_mm_s: float, machine_group: int = 2, support: str = "rigid") -> str:
    """ISO 20816-3 evaluation zone 'A', 'B', 'C' or 'D' of a velocity RMS [mm/s] (a value on a
    boundary belongs to the worse zone)."""
    ab, bc, cd = zone_boundaries(machine_group, support)
    v = float(velocity_rms_mm_s)
    return "A" if v < ab else "B" if v < bc else "C" if v < cd else "D"


@dataclass(frozen=True)
class Level:
    """One level of an alarm: raised beyond `threshold`, left on the safe side of `clear`."""

    severity: Severity
    threshold: float
    clear: float


@dataclass(frozen=True)
class Rule:
    """What an alarm watches: its id, category, unit, direction and timing."""

    id: str
    category: str
    unit: str
    direction: Direction
    raise_delay_s: float
    clear_hold_s: float
    description: str

    def beyond(self, value: float, limit: float) -> bool:
        """Whether `value` is on the alarm side of `limit` (inclusive)."""
        return value >= limit if self.direction == "above" else value <= limit
