"""Operating setpoint: what a plant engineer sets. Partial updates keep the other fields."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field


class SetpointError(ValueError):
    """A setpoint field outside what the model can hold; the message names field and range."""

    def __init__(self, field: str, value: float, low: float, high: float, unit: str):
        self.field, self.value, self.low, self.high, self.unit = field, value, low, high, unit
        super().__init__(f"{field} = {value:g} {unit} is outside the allowed range "
                         f"[{low:g}, {high:g}] {unit} for this bearing")


class Setpoint(BaseModel):
    """A complete setpoint (all fields set)."""

    model_config = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False)

    shaft_speed_rad_s: float = Field(default=500.0, ge=0.0, le=1e4, description="Inner ring (shaft) speed [rad/s].")
    radial_load_n: float = Field(default=3000.0, ge=0.0, le=1e6, description="Radial load on the inner ring [N].")
    axial_load_n: float = Field(default=0.0, ge=-1e6, le=1e6, description="Axial load on the inner ring [N].")
    oil_temperature_c: float = Field(default=40.0, ge=-30.0, le=150.0, description="Oil temperature [degC].")
    shaft_current_a: float = Field(default=0.0, ge=0.0, le=100.0, description="Current through the bearing, shaft to housing [A].")
    shaft_voltage_v: float = Field(default=0.0, ge=0.0, le=1000.0, description="Shaft-to-housing voltage amplitude [V].")


class SetpointUpdate(BaseModel):
    """A partial setpoint: every field optional, missing fields keep their value."""

    model_config = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False)

    shaft_speed_rad_s: float | None = Field(default=None, ge=0.0, le=1e4, description="Inner ring (shaft) speed [rad/s].")
    radial_load_n: float | None = Field(default=None, ge=0.0, le=1e6, description="Radial load on the inner ring [N].")
    axial_load_n: float | None = Field(default=None, ge=-1e6, le=1e6, description="Axial load on the inner ring [N].")
    oil_temperature_c: float | None = Field(default=None, ge=-30.0, le=150.0, description="Oil temperature [degC].")
    shaft_current_a: float | None = Field(default=None, ge=0.0, le=100.0, description="Current through the bearing, shaft to housing [A].")
    shaft_voltage_v: float | None = Field(default=None, ge=0.0, le=1000.0, description="Shaft-to-housing voltage amplitude [V].")

    def apply_to(self, current: Setpoint) -> Setpoint:
        """The setpoint after this update."""
        return current.model_copy(update=self.model_dump(exclude_none=True))


_UNITS = {"shaft_speed_rad_s": "rad/s", "radial_load_n": "N", "axial_load_n": "N",
          "oil_temperature_c": "degC", "shaft_current_a": "A", "shaft_voltage_v": "V"}


def check_limits(setpoint: Setpoint, limits: dict[str, tuple[float, float]]) -> None:
    """Raise SetpointError for the first field outside the model's (low, high) limits."""
    for field, (low, high) in limits.items():
        value = getattr(setpoint, field)
        if not (low <= value <= high):
            raise SetpointError(field, value, low, high, _UNITS[field])
