"""THE setpoint vocabulary: what a plant engineer sets, in one place for every layer.

* `FIELDS`: name, unit, description, static bounds and default of each setpoint field. The
  static bounds are the envelope of every bearing's limits (a field's allowed range for a given
  bearing lies inside them); they are not a check of their own.
* `Setpoint`: a complete setpoint (every field set), immutable. `SetpointUpdate`: a partial one
  (missing fields keep their value). Both are strict: a number is an int or a float, never a
  bool or a string ("3000"), never NaN or Infinity, and no unknown field. They check types
  only; ranges are checked once, against the bearing's own limits.
* `SetpointLimits`: a bearing's allowed [low, high] per field (`SetpointLimits.for_model`),
  `admit(update, base)` merges a partial update over a setpoint and checks the result: the ONE
  range check of every path (HTTP, zenoh, scenario, CLI, Python API). It returns an `Admitted`
  setpoint, which the engine applies without checking again.
* `SetpointError`: every field out of range, each with the bearing's own range and unit
  ("shaft_speed_rad_s = 3000 rad/s is outside the allowed range [0, 2073.66] rad/s for bearing
  6208").

All SI except the oil temperature in degC.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

from pydantic import BaseModel, ConfigDict, Field


@dataclass(frozen=True)
class SetpointField:
    """One setpoint field: its name (which carries the unit), unit, meaning, static bounds and
    the default of a fresh twin."""

    name: str
    unit: str
    description: str
    low: float  # static lower bound, in `unit`
    high: float  # static upper bound, in `unit`
    default: float  # in `unit`


FIELDS: tuple[SetpointField, ...] = (
    SetpointField("shaft_speed_rad_s", "rad/s", "Inner ring (shaft) speed", 0.0, 1e4, 500.0),
    SetpointField("radial_load_n", "N", "Radial load on the inner ring", 0.0, 1e6, 3000.0),
    SetpointField("axial_load_n", "N", "Axial load on the inner ring", -1e6, 1e6, 0.0),
    SetpointField("oil_temperature_c", "degC", "Oil temperature", -30.0, 150.0, 40.0),
    SetpointField("shaft_current_a", "A", "Current through the bearing, shaft to housing", 0.0, 100.0, 0.0),
    SetpointField("shaft_voltage_v", "V", "Shaft-to-housing voltage amplitude", 0.0, 1000.0, 0.0),
)
FIELD: Mapping[str, SetpointField] = MappingProxyType({f.name: f for f in FIELDS})
NAMES: tuple[str, ...] = tuple(f.name for f in FIELDS)


def unit(name: str) -> str:
    """The unit of a setpoint field ('' for a name that is not one)."""
    f = FIELD.get(name)
    return f.unit if f is not None else ""


_CONFIG = ConfigDict(frozen=True, extra="forbid", strict=True, allow_inf_nan=False)


def _field(name: str, *, partial: bool) -> Any:
    f = FIELD[name]
    return Field(
        default=None if partial else f.default,
        description=f"{f.description} [{f.unit}]; the bearing's own limits apply "
        f"(GET /v1/bearings/{{id}} 'limits'), within [{f.low:g}, {f.high:g}].",
        json_schema_extra={"minimum": f.low, "maximum": f.high},
    )


class Setpoint(BaseModel):
    """A complete setpoint (every field set; units in the names)."""

    model_config = _CONFIG
    shaft_speed_rad_s: float = _field("shaft_speed_rad_s", partial=False)
    radial_load_n: float = _field("radial_load_n", partial=False)
    axial_load_n: float = _field("axial_load_n", partial=False)
    oil_temperature_c: float = _field("oil_temperature_c", partial=False)
    shaft_current_a: float = _field("shaft_current_a", partial=False)
    shaft_voltage_v: float = _field("shaft_voltage_v", partial=False)

    def describe(self, names: Iterable[str] | None = None) -> str:
        """'radial_load_n = 3000 N, ...' for `names` (default: every field)."""
        return ", ".join(f"{n} = {getattr(self, n):g} {unit(n)}" for n in (NAMES if names is None else names))


class SetpointUpdate(BaseModel):
    """A partial setpoint: every field optional, missing fields keep their value."""

    model_config = _CONFIG
    shaft_speed_rad_s: float | None = _field("shaft_speed_rad_s", partial=True)
    radial_load_n: float | None = _field("radial_load_n", partial=True)
    axial_load_n: float | None = _field("axial_load_n", partial=True)
    oil_temperature_c: float | None = _field("oil_temperature_c", partial=True)
    shaft_current_a: float | None = _field("shaft_current_a", partial=True)
    shaft_voltage_v: float | None = _field("shaft_voltage_v", partial=True)

    @property
    def fields(self) -> dict[str, float]:
        """The fields this update sets."""
        return self.model_dump(exclude_none=True)

    def apply_to(self, current: Setpoint) -> Setpoint:
        """The setpoint after this update (types were checked; ranges are `SetpointLimits`')."""
        return current.model_copy(update=self.fields)

    def merged(self, later: SetpointUpdate) -> SetpointUpdate:
        """This update followed by `later` (later wins per field)."""
        return SetpointUpdate.model_construct(None, **{**self.fields, **later.fields})


@dataclass(frozen=True)
class OutOfRange:
    """One field outside the bearing's range."""

    field: str
    value: float
    low: float
    high: float
    unit: str

    def message(self, bearing: str) -> str:
        where = f" for bearing {bearing}" if bearing else " for this bearing"
        return (
            f"{self.field} = {self.value:g} {self.unit} is outside the allowed range "
            f"[{self.low:g}, {self.high:g}] {self.unit}{where}"
        )


class SetpointError(ValueError):
    """Setpoint fields outside the bearing's limits; the message names each field and its range.
    `field`, `value`, `low`, `high`, `unit` are those of the first problem, `problems` all."""

    def __init__(self, problems: list[OutOfRange], bearing: str = ""):
        self.problems, self.bearing = problems, bearing
        first = problems[0]
        self.field, self.value, self.low, self.high, self.unit = (
            first.field,
            first.value,
            first.low,
            first.high,
            first.unit,
        )
        super().__init__("; ".join(p.message(bearing) for p in problems))

    def messages(self) -> list[tuple[str, str, list[float]]]:
        """(field, message, [low, high]) of every problem."""
        return [(p.field, p.message(self.bearing), [p.low, p.high]) for p in self.problems]


@dataclass(frozen=True)
class Admitted:
    """A complete setpoint checked against `limits` (made by `SetpointLimits.admit`): the engine
    applies it without checking it again."""

    setpoint: Setpoint
    limits: SetpointLimits


@dataclass(frozen=True)
class SetpointLimits(Mapping):
    """Allowed [low, high] of every setpoint field for one bearing (in the field's unit); reads
    like a dict `{field: (low, high)}`."""

    ranges: Mapping[str, tuple[float, float]]
    bearing: str = ""  # designation, quoted in the errors

    def __post_init__(self) -> None:
        missing = [n for n in NAMES if n not in self.ranges]
        if missing:
            raise ValueError(f"limits without {missing}")
        clipped = {}
        for name in NAMES:  # inside the static bounds, in the vocabulary's order
            low, high = self.ranges[name]
            f = FIELD[name]
            clipped[name] = (float(max(low, f.low)), float(min(high, f.high)))
        object.__setattr__(self, "ranges", MappingProxyType(clipped))

    @classmethod
    def static(cls) -> SetpointLimits:
        """The static bounds (no bearing)."""
        return cls({f.name: (f.low, f.high) for f in FIELDS})

    @classmethod
    def for_bearing(
        cls,
        designation: str,
        *,
        max_shaft_speed_rad_s: float,
        max_radial_load_n: float,
        max_axial_load_n: float,
        angular_contact: bool,
    ) -> SetpointLimits:
        """A bearing's limits: speed and loads from its model (an angular-contact bearing takes
        axial load in one direction only), the rest the static bounds."""
        ranges = {f.name: (f.low, f.high) for f in FIELDS}
        ranges["shaft_speed_rad_s"] = (0.0, max_shaft_speed_rad_s)
        ranges["radial_load_n"] = (0.0, max_radial_load_n)
        ranges["axial_load_n"] = (0.0 if angular_contact else -max_axial_load_n, max_axial_load_n)
        return cls(ranges, bearing=designation)

    @classmethod
    def for_model(cls, model: Any) -> SetpointLimits:
        """The limits of a compiled `twin.model.BearingModel`."""
        return cls.for_bearing(
            model.spec.designation,
            max_shaft_speed_rad_s=model.max_shaft_speed_rad_s,
            max_radial_load_n=model.max_radial_load_n,
            max_axial_load_n=model.max_axial_load_n,
            angular_contact=model.spec.kind == "angular_contact",
        )

    def __getitem__(self, name: str) -> tuple[float, float]:
        return self.ranges[name]

    def __contains__(self, name: object) -> bool:
        return name in self.ranges

    def __iter__(self):
        return iter(self.ranges)

    def __len__(self) -> int:
        return len(self.ranges)

    __hash__ = None  # type: ignore[assignment]  # a mapping (compared by value), not hashable

    def as_dict(self) -> dict[str, tuple[float, float]]:
        return dict(self.ranges)

    def problems(self, values: Mapping[str, float]) -> list[OutOfRange]:
        """Every field of `values` outside its range."""
        out = []
        for name, value in values.items():
            if name not in self.ranges:
                continue
            low, high = self.ranges[name]
            if not (low <= value <= high):
                out.append(OutOfRange(name, float(value), low, high, unit(name)))
        return out

    def check(self, values: Setpoint | SetpointUpdate | Mapping[str, float]) -> None:
        """Raise SetpointError naming every field outside the bearing's range."""
        if isinstance(values, Setpoint):
            values = values.model_dump()
        elif isinstance(values, SetpointUpdate):
            values = values.fields
        problems = self.problems(values)
        if problems:
            raise SetpointError(problems, self.bearing)

    def admit(self, update: SetpointUpdate | Setpoint, base: Setpoint | None = None) -> Admitted:
        """`update` merged over `base` (a complete `Setpoint` replaces it) and checked: the one
        range check of a path. Raises SetpointError."""
        new = update if isinstance(update, Setpoint) else update.apply_to(base if base is not None else Setpoint())
        self.check(new)
        return Admitted(new, self)
