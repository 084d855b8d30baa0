"""The public state message, schema "bearing-twin/state/1" (README, Architecture): immutable, units in
every field name, JSON without NaN or Infinity (undefined values are null)."""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field

from twin.setpoint import Setpoint

SCHEMA = "bearing-twin/state/1"

_FROZEN = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False)

Regime = Literal["no_contact", "boundary", "mixed", "full_film"]


class ContactState(BaseModel):
    """One ball-raceway contact."""

    model_config = _FROZEN
    load_n: float = Field(description="Normal (elastic Hertz) load [N].")
    h_min_m: float | None = Field(description="Minimum film thickness [m]; null without contact.")
    h_c_m: float | None = Field(description="Central film thickness [m]; null without contact.")
    lambda_: float | None = Field(alias="lambda", serialization_alias="lambda",
                                  description="Film parameter Lambda = h_min / (1.25 sqrt(s1^2 + s2^2)) [-]; null without contact.")
    regime: Regime = Field(description="Lubrication regime (seed 000 Table 2).")
    mu: float = Field(description="Sliding friction coefficient [-] (0 without contact).")
    entrainment_speed_m_s: float = Field(description="Mean surface speed relative to the contact [m/s].")
    slide_roll_ratio: float = Field(description="Sliding / entrainment speed, signed [-].")
    contact_angle_rad: float = Field(description="Angle of the contact normal to the radial plane [rad].")
    max_pressure_pa: float = Field(description="Hertz maximum pressure [Pa].")
    resistance_ohm: float | None = Field(description="Parallel-RC resistance of the contact [ohm]; null: open circuit (no conduction).")
    capacitance_f: float = Field(description="Parallel-RC capacitance of the contact (film or open gap) [F].")


class BallState(BaseModel):
    """One ball and its inner and outer contacts."""

    model_config = _FROZEN
    index: int = Field(description="Ball number, 0..Z-1.")
    azimuth_rad: float = Field(description="Angle from the radial load line, in (-pi, pi], positive with the shaft rotation [rad].")
    spin_rad_s: float = Field(description="Magnitude of the ball's absolute angular velocity [rad/s].")
    orbital_speed_rad_s: float = Field(description="Angular speed of the ball centre about the bearing axis [rad/s].")
    cage_load_n: float = Field(description="Largest ball-cage contact force [N].")
    inner: ContactState
    outer: ContactState
    resistance_ohm: float | None = Field(description="Inner and outer contact resistances in series [ohm]; null: open circuit.")
    capacitance_f: float = Field(description="Inner and outer contact capacitances in series [F].")


class ElectricalState(BaseModel):
    """The bearing as an electrical component, and its discharge indicators."""

    model_config = _FROZEN
    resistance_ohm: float | None = Field(description="Equivalent parallel resistance 1/Re(Y) at the frequency [ohm]; null: no conduction.")
    capacitance_f: float = Field(description="Equivalent parallel capacitance Im(Y)/omega [F].")
    impedance_ohm: float = Field(description="Impedance magnitude at the frequency [ohm].")
    phase_rad: float = Field(description="Impedance phase [rad]: -pi/2 capacitive, 0 resistive.")
    frequency_hz: float = Field(description="Frequency of the impedance [Hz].")
    shaft_voltage_v: float = Field(description="Voltage across the bearing (set, or current x |Z|) [V].")
    shaft_current_a: float = Field(description="Current through the bearing (set, or voltage / |Z|) [A].")
    max_film_field_v_m: float = Field(description="Largest electric field across a film or gap [V/m].")
    current_density_a_m2: float = Field(description="Largest apparent current density over a loaded contact area [A/m^2].")
    discharge_risk: Literal["none", "possible", "likely"] = Field(description="Electrical discharge risk.")
    reason: str = Field(description="Why the risk is what it is.")
    contact_temperature_rise_k: float = Field(description="Inlet temperature rise above the oil temperature: current + shear heating, fed into the film [K].")
    current_temperature_rise_k: float = Field(default=0.0, description="Race-track temperature rise from the current discharge (seed 003 eq. 10) [K].")
    shear_temperature_rise_k: float = Field(default=0.0, description="Inlet shear-heating temperature rise (seed 003 eq. 6 at the inlet; 0 when shear heating is off) [K].")
    film_thermal_factor: float = Field(default=1.0, description="Film thickness / isothermal film thickness from the heating (1: none) [-].")


class Snapshot(BaseModel):
    """Everything the world may see of one twin at one instant."""

    model_config = _FROZEN
    schema_: str = Field(default=SCHEMA, alias="schema", serialization_alias="schema",
                         description="Message schema identifier.")
    bearing_id: str = Field(description="Twin name.")
    designation: str = Field(description="Bearing designation.")
    seq: int = Field(description="Per-twin counter of snapshots (gaps reveal drops).")
    time_s: float = Field(description="Simulated time [s].")
    real_time_factor: float | None = Field(description="Simulated seconds per wall second over the last frames [-]; null when not measured.")
    late_fraction: float | None = Field(default=None, description="Fraction of the frames of the last 10 s of wall time that ended later than the service's lateness (5 ms by default) after their wall-clock deadline [-]; null when not measured (fast mode, before the first frame, outside the service).")
    status: str = Field(description="'ok' or what went wrong and what the twin did about it.")
    restarts: int = Field(description="Warm restarts after a diverged or overloaded state.")
    setpoint: Setpoint = Field(description="The setpoint in force during the frame that ended at time_s [fields with units].")
    shaft_speed_rad_s: float = Field(description="Current (ramped) shaft speed [rad/s].")
    cage_speed_rad_s: float = Field(description="Cage angular speed [rad/s].")
    inner_ring_displacement_m: tuple[float, float, float] = Field(description="Inner ring centre (x along the radial load, y, z axial) [m].")
    friction_torque_n_m: float = Field(description="Torque the shaft supplies to the bearing, averaged over the last frame [N m].")
    viscosity_pa_s: float = Field(description="Inlet viscosity: the oil at the oil temperature plus the inlet's current and shear heating (Roelands, seed 003 eq. 3) [Pa s].")
    electrical: ElectricalState
    balls: tuple[BallState, ...]

    def to_json(self) -> str:
        """JSON text with the contract's field names."""
        return self.model_dump_json(by_alias=True)

    def to_dict(self) -> dict:
        """Plain dict with the contract's field names."""
        return self.model_dump(by_alias=True, mode="json")
