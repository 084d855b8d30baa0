"""Local defects from the outside: HTTP `PUT /v1/bearings/{id}/defects`, zenoh
`{prefix}/{id}/defects`, scenario steps `defects:`. Validated here, in the calling thread, against
the bearing's own geometry (`twin.vibration.defects.validate_defects`: a spall wider than the
ball spacing or longer than the groove arc, a depth beyond Rb / 2, a ball index the bearing does
not have, a negative size); the runner thread applies them between frames (`DefectBox`), so no
thread but the runner's touches the twin.

Vocabulary (twin.vibration.defects; every size in metres, angles in degrees):

    {"kind": "outer", "width_m": ..., "length_m": ..., "depth_m": ..., "edge_radius_m": 0, "azimuth_deg": 0}
    {"kind": "inner", ..., "ring_angle_deg": 0}
    {"kind": "ball", ..., "ball_index": 0, "colatitude_deg": 90, "longitude_deg": 0}

A request replaces the whole set (`[]` or DELETE clears it); at most `MAX_DEFECTS` at once.
"""

from __future__ import annotations

import re
import threading
from typing import Any

from pydantic import ValidationError

from service.core.errors import InputError, field_errors, models_bounds
from service.core.mailbox import LatestValue

try:  # the engine's limit (twin.state, with the vibration engine)
    from twin.state import MAX_DEFECTS
except ImportError:  # pragma: no cover - an engine without defects
    MAX_DEFECTS = 8

__all__ = ["MAX_DEFECTS", "DefectBox", "parse_defects"]

_NAMED = re.compile(r"^([a-z_]+) = ")


def _loc(prefix: str, loc: tuple) -> str:
    """'defects[0].width_m' from pydantic's ('0', 'outer', 'width_m') (the union tag dropped)."""
    out = prefix
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        elif part in ("outer", "inner", "ball") or part == "":
            continue
        else:
            out += f".{part}"
    return out


def parse_defects(data: Any, geometry, *, prefix: str = "defects") -> tuple:
    """Validated defects (twin.vibration.defects models) from a list of dicts (or a dict
    {"defects": [...]}). InputError 422 naming each field (`defects[i].<name>`) and the bearing's
    own allowed range."""
    if isinstance(data, dict) and set(data) == {"defects"}:
        data = data["defects"]
    if not isinstance(data, (list, tuple)):
        raise InputError.one(
            prefix, f"a list of defects (objects with kind outer | inner | ball), got {type(data).__name__}"
        )
    if len(data) > MAX_DEFECTS:
        raise InputError.one(prefix, f"{len(data)} defects given: at most {MAX_DEFECTS} at once", [0, MAX_DEFECTS])
    items = [d.model_dump() if hasattr(d, "model_dump") else d for d in data]
    from twin.vibration.defects import BallDefect, InnerRaceSpall, OuterRaceSpall, validate_defects

    try:
        return tuple(validate_defects(items, geometry))
    except ValidationError as exc:
        raw = exc.errors(include_url=False)
        # the messages with both sides of a declared range (pydantic names only the side crossed)
        described = field_errors(raw, bounds=models_bounds((OuterRaceSpall, InnerRaceSpall, BallDefect)))
        errors = []
        for e, error in zip(raw, described, strict=True):
            field = _loc(prefix, tuple(e.get("loc", ())))
            named = _NAMED.match(error.message)  # a model-level check names its field first
            if named and not field.endswith(f".{named.group(1)}"):
                field = f"{field}.{named.group(1)}"
            errors.append(error.model_copy(update={"field": field}))
        raise InputError(errors) from None


class DefectBox:
    """The defects waiting for the runner thread (a `LatestValue`: latest wins) and the ones
    accepted last, with counts of both."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._slot: LatestValue[tuple] = LatestValue()
        self._target: tuple = ()
        self.accepted = 0
        self.applied = 0

    @property
    def target(self) -> tuple:
        """The defects accepted last (in force, or applied at the next frame)."""
        with self._lock:
            return self._target

    def offer(self, defects: tuple) -> tuple:
        with self._lock:
            self._target = tuple(defects)
            self.accepted += 1
            self._slot.offer(self._target)
            return self._target

    @property
    def waiting(self) -> bool:
        """Whether defects wait for the runner thread."""
        return self._slot.waiting

    def take(self) -> tuple | None:
        """The pending defects or None (runner thread)."""
        pending = self._slot.take()
        if pending is not None:
            self.applied += 1
        return pending
