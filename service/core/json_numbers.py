"""Numbers read from JSON documents and snapshot models: a value is a finite float or nothing.

Shared by the alarms (service.core.alarm_inputs, service.core.alarms) and the live monitor
(service.tools.monitor), which reads the published JSON and must start without the engine."""

from __future__ import annotations

import math
from typing import Any


def finite_number(value: Any) -> float | None:
    """A JSON or model value as a finite float; None for anything else (None, bool, text, NaN, inf)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    value = float(value)
    return value if math.isfinite(value) else None
