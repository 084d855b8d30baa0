"""The public state message, schema "bearing-twin/state/1" (docs/architecture.md): immutable, units in
every field name, JSON without NaN or Infinity (undefined values are null)."""

from __future__ import annotations

from typing import Final, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from twin.physics.friction import Regime
from twin.setpoint import Setpoint
from twin.vibration.defects import Defect

SCHEMA = "bearing-twin/state/1"

_FROZEN = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False)

DischargeRisk = Literal["none", "possible", "likely"]

LAMBDA_KEY: Final = "lambda"
"""The film parameter's name in every message, entity path and table; `ContactState.lambda_` in
Python, where `lambda` is a keyword."""


class ContactState(BaseModel):
    """One ball-raceway contact. Lambda is `lambda_` in Python (`lambda` is a keyword) and
    "lambda" on the wire: the model is built with `lambda_` and dumps by alias."""

    model_config = ConfigDict(**_FROZEN, validate_by_name=True)
    load_n: float = Field(description="Normal (elastic Hertz) load [N].")
    h_min_m: float | None = Field(description="Minimum film thickness [m]; null without contact.")
    h_c_m: float | None = Field(description="Central film thickness [m]; null without contact.")
    lambda_: float | None = Field(
        alias=LAMBDA_KEY,
        serialization_alias=LAMBDA_KEY,
        description="Film parameter Lambda = h_min / (1.25 sqrt(s1^2 + s2^2)) [-]; null without contact.",
    )
    regime: Regime = Field(description="Lubrication regime (seed 000 Table 2).")
    mu: float = Field(
        description="Effective friction coefficient |F_t| / Q: net tangential force over normal load of the "
        "contact, the traction integrated over its ellipse (with the centre-point friction options: "
        "their Coulomb coefficient) [-] (0 without contact)."
    )
    entrainment_speed_m_s: float = Field(description="Mean surface speed relative to the contact [m/s].")
    slide_roll_ratio: float = Field(description="Sliding / entrainment speed, signed [-].")
    contact_angle_rad: float = Field(description="Angle of the contact normal to the radial plane [rad].")
    max_pressure_pa: float = Field(description="Hertz maximum pressure [Pa].")
    resistance_ohm: float | None = Field(
        description="Parallel-RC resistance of the contact [ohm]; null: open circuit (no conduction)."
    )
    capacitance_f: float = Field(description="Parallel-RC capacitance of the contact (film or open gap) [F].")


class BallState(BaseModel):
    """One ball and its inner and outer contacts."""

    model_config = _FROZEN
    index: int = Field(description="Ball number, 0..Z-1.")
    azimuth_rad: float = Field(
        description="Angle from the radial load line, in (-pi, pi], positive with the shaft rotation [rad]."
    )
    spin_rad_s: float = Field(description="Magnitude of the ball's absolute angular velocity [rad/s].")
    orbital_speed_rad_s: float = Field(description="Angular speed of the ball centre about the bearing axis [rad/s].")
    cage_load_n: float = Field(description="Largest ball-cage contact force [N].")
    inner: ContactState
    outer: ContactState
    resistance_ohm: float | None = Field(
        description="Inner and outer contact resistances in series [ohm]; null: open circuit."
    )
    capacitance_f: float = Field(description="Inner and outer contact capacitances in series [F].")


class ElectricalState(BaseModel):
    """The bearing as an electrical component, and its discharge indicators."""

    model_config = _FROZEN
    resistance_ohm: float | None = Field(
        description="Equivalent parallel resistance 1/Re(Y) at the frequency [ohm]; null: no conduction."
    )
    capacitance_f: float | None = Field(
        description="Equivalent parallel capacitance Im(Y)/omega [F], published where the network is capacitive "
        "(impedance "
        "phase at or below -45 deg); null otherwise, with capacitance_reason."
    )
    capacitance_reason: str | None = Field(
        default=None, description="Why capacitance_f is null (the network is resistive); null when it is published."
    )
    impedance_ohm: float = Field(description="Impedance magnitude at the frequency [ohm].")
    phase_rad: float = Field(description="Impedance phase [rad]: -pi/2 capacitive, 0 resistive.")
    frequency_hz: float = Field(description="Frequency of the impedance [Hz].")
    shaft_voltage_v: float = Field(description="Voltage across the bearing (set, or current x |Z|) [V].")
    shaft_current_a: float = Field(description="Current through the bearing (set, or voltage / |Z|) [A].")
    max_film_field_v_m: float = Field(description="Largest electric field across a film or gap [V/m].")
    current_density_a_m2: float = Field(
        description="Largest apparent current density over a loaded contact area [A/m^2]."
    )
    discharge_risk: DischargeRisk = Field(description="Electrical discharge risk.")
    reason: str = Field(description="Why the risk is what it is.")
    contact_temperature_rise_k: float = Field(
        description="Inlet temperature rise above the oil temperature: current + shear heating, fed into the film [K]."
    )
    current_temperature_rise_k: float = Field(
        default=0.0, description="Race-track temperature rise from the current discharge (seed 003 eq. 10) [K]."
    )
    shear_temperature_rise_k: float = Field(
        default=0.0,
        description="Inlet shear-heating temperature rise (seed 003 eq. 6 at the inlet; 0 when shear heating is off) "
        "[K].",
    )
    film_thermal_factor: float = Field(
        default=1.0, description="Film thickness / isothermal film thickness from the heating (1: none) [-]."
    )


class LifeState(BaseModel):
    """Rating life at the current conditions and the damage accumulated so far (twin.life:
    ISO 281:2007 and a Lundberg-Palmgren life from the twin's own contact loads). Null where a
    value is undefined or unbounded (e.g. at rest the life is unbounded and kappa undefined);
    `reason` says why."""

    model_config = _FROZEN
    kappa: float | None = Field(
        default=None, description="Viscosity ratio nu / nu1 of ISO 281:2007 clause 9.3 [-]; null at rest."
    )
    a_iso: float | None = Field(
        default=None,
        description="Life modification factor a_ISO (ISO 281:2007 clause 9.3, <= 50) [-]; null at rest or for kappa < "
        "0.1.",
    )
    l10_h: float | None = Field(
        default=None, description="Basic rating life L10 = (C/P)^3 at the current shaft speed [h]; null when unbounded."
    )
    l10m_h: float | None = Field(
        default=None,
        description="Modified rating life a_ISO L10 (90 % reliability) [h]; null when unbounded or not applicable.",
    )
    l10_contact_loads_h: float | None = Field(
        default=None,
        description="Lundberg-Palmgren life from the twin's ball loads (ISO/TS 16281 spirit), running mean over the "
        "ball passages [h]; null when unbounded.",
    )
    damage_fraction: float = Field(
        default=0.0, description="Palmgren-Miner damage accumulated along the twin's history [-] (1 = life used up)."
    )
    damage_rate_per_s: float = Field(
        default=0.0, description="Fraction of life used per second at the current conditions [1/s]."
    )
    remaining_life_h: float | None = Field(
        default=None,
        description="(1 - damage) x the damage basis life at the current conditions [h]; null when unbounded.",
    )
    dynamic_load_rating_n: float | None = Field(default=None, description="Basic dynamic load rating C used [N].")
    equivalent_load_n: float | None = Field(
        default=None, description="Equivalent dynamic load P = X Fr + Y Fa (ISO 281 Table 3) [N]."
    )
    contamination_factor: float | None = Field(
        default=None, description="Contamination factor e_C (ISO 281:2007 Table 13 / Annex A) [-]."
    )
    viscosity_m2_s: float | None = Field(
        default=None, description="Kinematic viscosity of the oil at the film inlet, nu [m^2/s]."
    )
    rated_viscosity_m2_s: float | None = Field(
        default=None, description="Rated viscosity nu1 of ISO 281:2007 clause 9.3 [m^2/s]; null at rest."
    )
    damage_basis: Literal["iso_281", "contact_loads"] | None = Field(
        default=None, description="Life the damage accrues against."
    )
    reason: str | None = Field(default=None, description="Why values are null, or a caveat; null when there is none.")


class EnvelopePeak(BaseModel):
    """One peak of the envelope spectrum."""

    model_config = _FROZEN
    frequency_hz: float = Field(description="Peak frequency (parabolic interpolation between bins) [Hz].")
    amplitude: float = Field(description="Envelope amplitude at the peak [m/s^2].")


class DefectFrequenciesHz(BaseModel):
    """Kinematic defect frequencies at the window's mean shaft speed and loaded contact angle [Hz]
    (twin.vibration.defect_frequencies)."""

    model_config = _FROZEN
    ftf: float = Field(description="Cage (fundamental train) frequency [Hz].")
    bpfo: float = Field(description="Ball pass frequency, outer race [Hz].")
    bpfi: float = Field(description="Ball pass frequency, inner race [Hz].")
    bsf: float = Field(description="Ball spin frequency [Hz].")
    two_bsf: float = Field(description="2 x BSF, the rate at which a ball defect strikes the races [Hz].")


class DefectLine(BaseModel):
    """Envelope amplitudes at one defect frequency (largest bin within +-1 % of each line)."""

    model_config = _FROZEN
    frequency_hz: float = Field(description="The defect frequency [Hz].")
    harmonics: tuple[float, ...] = Field(description="Envelope amplitude at 1x, 2x, 3x the frequency [m/s^2].")
    sidebands: tuple[float, float] | None = Field(
        default=None,
        description="Envelope amplitude at the frequency minus and plus the modulation [m/s^2]: "
        "the shaft frequency for BPFI, FTF for 2 x BSF; null for the others.",
    )


class Spectrum(BaseModel):
    """A one-sided amplitude spectrum on a uniform frequency axis: bin k at start_hz + k step_hz."""

    model_config = _FROZEN
    start_hz: float = Field(description="Frequency of bin 0 (the centre of the FFT bins it stands for) [Hz].")
    step_hz: float = Field(description="Bin spacing, the frequency resolution [Hz].")
    amplitude_m_s2: tuple[float, ...] = Field(description="Amplitude of each bin [m/s^2].")

    @property
    def frequencies_hz(self) -> np.ndarray:
        """Bin frequencies [Hz]."""
        return self.start_hz + self.step_hz * np.arange(len(self.amplitude_m_s2))

    @property
    def max_hz(self) -> float:
        """Frequency of the last bin [Hz]."""
        return self.start_hz + self.step_hz * (len(self.amplitude_m_s2) - 1)


class VibrationState(BaseModel):
    """Indicators of the last complete window of housing acceleration (twin.vibration.indicators).

    The window's full spectra (`envelope_spectrum`, `amplitude_spectrum`) ride on the object for the
    sinks that show them (zenoh `.../vibration`, the rerun recording) but are left out of its JSON
    (exclude=True): the state message (50 Hz, HTTP state) does not grow by ~4000 numbers."""

    model_config = _FROZEN
    window_end_s: float = Field(description="Simulated time of the window's last sample [s].")
    window_s: float = Field(description="Window length [s].")
    sample_rate_hz: float = Field(description="Accelerometer sample rate [Hz].")
    shaft_speed_rad_s: float = Field(description="Mean shaft speed over the window [rad/s].")
    contact_angle_rad: float = Field(
        description="Loaded contact angle at the window end (mean over loaded balls) [rad]."
    )
    rms_m_s2: float = Field(description="RMS acceleration, mean removed [m/s^2].")
    peak_m_s2: float = Field(description="Peak |acceleration|, mean removed [m/s^2].")
    crest_factor: float = Field(description="Peak / RMS [-].")
    kurtosis: float = Field(description="Kurtosis [-] (3 for Gaussian noise).")
    band_kurtosis: float = Field(description="Kurtosis of the signal band-passed to the envelope band [-].")
    velocity_rms_mm_s: float = Field(description="RMS velocity over 10-1000 Hz (ISO 20816-1) [mm/s].")
    defect_frequencies_hz: DefectFrequenciesHz
    envelope_band_hz: tuple[float, float] = Field(description="Band-pass of the envelope analysis [Hz].")
    envelope_peaks_hz: tuple[EnvelopePeak, ...] = Field(
        description="The five largest envelope-spectrum peaks, largest first."
    )
    envelope_noise_floor_m_s2: float = Field(
        description="Median envelope amplitude up to 5 x the highest defect frequency [m/s^2]."
    )
    envelope_lines: dict[str, DefectLine] = Field(
        description="Envelope amplitudes at each defect frequency (keys ftf, bpfo, bpfi, bsf, two_bsf)."
    )
    envelope_spectrum: Spectrum | None = Field(
        default=None,
        exclude=True,
        description="The window's envelope spectrum [m/s^2], the one the peaks, lines and noise floor come from: "
        "0 Hz to min(half the envelope band width, 5 x max(BPFI, 2 x BSF)), the window's resolution 1 / window_s "
        "(peak-held into 4096 bins beyond; twin.vibration.indicators.envelope_spectrum_view). Not serialised.",
    )
    amplitude_spectrum: Spectrum | None = Field(
        default=None,
        exclude=True,
        description="The window's acceleration amplitude spectrum [m/s^2], 0 to sample_rate_hz / 2, FFT bins "
        "power-summed into at most 2000 (13 Hz for 1 s at 51.2 kHz; Parseval: sum A^2 / 2 = rms_m_s2^2; "
        "twin.vibration.indicators.amplitude_spectrum). Not serialised.",
    )


class ThermalState(BaseModel):
    """The thermal network in the loop (twin.thermal): node temperatures, heat by source, the
    dissipation estimate that follows a measured temperature, and its residual."""

    model_config = _FROZEN
    accelerated: bool = Field(
        description="True: the heat capacities are scaled down (heat_capacity_scale < 1), the "
        "transient runs 1 / scale times faster than a real bearing's; steady states are the same."
    )
    heat_capacity_scale: float = Field(description="Factor on every heat capacity [-] (1: real).")
    network_time_s: float = Field(description="Thermal time: simulated time / heat_capacity_scale [s].")
    ambient_c: float = Field(
        description="Ambient (sump) or oil-inlet (circulating) temperature: the setpoint's oil temperature [degC]."
    )
    temperatures_c: dict[str, float] = Field(
        description="Node temperatures: shaft, inner_ring, balls, outer_ring, housing, oil [degC]."
    )
    inlet_temperature_c: float = Field(
        description="The contacts' inlet temperature, which sets the film viscosity [degC]."
    )
    heat_w: dict[str, float] = Field(description="Friction heat by source: rolling, sliding, spin, drag, seal [W].")
    heat_inner_contacts_w: float = Field(description="Friction heat of the inner-ring contacts [W].")
    heat_outer_contacts_w: float = Field(description="Friction heat of the outer-ring contacts [W].")
    dissipated_w: float = Field(description="Heat carried to the surroundings and the oil supply [W].")
    slowest_time_constant_s: float | None = Field(
        description="Slowest time constant of the network with real heat capacities [s]."
    )
    clearance_change_m: float = Field(
        description="Change of the diametral clearance by thermal expansion (< 0: closes) [m]."
    )
    outer_ring_rate_k_per_min: float = Field(
        description="Rise of the outer ring over the last minute of thermal time (within the first minute: the "
        "rise since the start, over a minute) [K/min]."
    )
    dissipation_factor: float = Field(
        description="Estimated factor on the dissipation to the surroundings [-] (1: the correlations)."
    )
    dissipation_factor_sigma: float = Field(description="Its standard deviation [-].")
    measured_node: str | None = Field(default=None, description="Node of the last measured temperature; null: none.")
    measured_c: float | None = Field(default=None, description="Last measured temperature [degC]; null: none.")
    residual_k: float | None = Field(
        default=None, description="Measured - predicted temperature before the update [K]; null: no measurement."
    )
    residual_sigma_k: float | None = Field(
        default=None, description="Standard deviation of that residual (prediction and sensor) [K]."
    )
    unexplained_heating: bool = Field(
        default=False,
        description="The last measurement lay beyond the filter's gate: heat "
        "the friction and the dissipation cannot explain (lubricant loss, overload, a failing bearing).",
    )


class FrictionPowerState(BaseModel):
    """Friction power of the bearing by source at the snapshot's instant [W]
    (twin.friction_power; Twin.friction_power_w() gives it contact by contact)."""

    model_config = _FROZEN
    rolling: float = Field(description="Rolling resistance of the ball-raceway contacts, F_R u (seed 001) [W].")
    sliding: float = Field(description="Traction against the slip of the contacts (centre and differential slip) [W].")
    spin: float = Field(description="Traction moment about the contact normals against the spin rate [W].")
    drag: float = Field(description="Drag of the balls in the oil (Harris and Kotzalas; twin.physics.drag) [W].")
    seal: float = Field(description="Rubbing seals, M_seal omega (SKF model; twin.physics.seals) [W].")


class Snapshot(BaseModel):
    """Everything the world may see of one twin at one instant."""

    model_config = _FROZEN
    schema_: str = Field(
        default=SCHEMA, alias="schema", serialization_alias="schema", description="Message schema identifier."
    )
    bearing_id: str = Field(description="Twin name.")
    designation: str = Field(description="Bearing designation.")
    seq: int = Field(description="Per-twin counter of snapshots (gaps reveal drops).")
    time_s: float = Field(description="Simulated time [s].")
    real_time_factor: float | None = Field(
        description="Simulated seconds per wall second over the last frames [-]; null when not measured."
    )
    late_fraction: float | None = Field(
        default=None,
        description="Fraction of the frames of the last 10 s of wall time that ended later than the service's lateness "
        "(5 ms by default) after their wall-clock deadline [-]; null when not measured (fast mode, before the first "
        "frame, outside the service).",
    )
    status: str = Field(description="'ok' or what went wrong and what the twin did about it.")
    restarts: int = Field(description="Warm restarts after a diverged or overloaded state.")
    setpoint: Setpoint = Field(
        description="The setpoint in force during the frame that ended at time_s [fields with units]."
    )
    shaft_speed_rad_s: float = Field(description="Current (ramped) shaft speed [rad/s].")
    cage_speed_rad_s: float = Field(description="Cage angular speed [rad/s].")
    inner_ring_displacement_m: tuple[float, float, float] = Field(
        description="Inner ring centre relative to the outer ring's (x along the radial load, y, z axial) [m]."
    )
    friction_torque_n_m: float = Field(
        description="Friction torque of the bearing averaged over the last frame [N m]: the torque its outer ring "
        "holds "
        "(the shaft's drive torque less the rate of change of the balls' and cage's angular momentum) plus the balls' "
        "drag and the seals."
    )
    friction_power_w: FrictionPowerState | None = Field(
        default=None, description="Friction power by source at time_s [W] (rolling, sliding, spin, drag, seal)."
    )
    viscosity_pa_s: float = Field(
        description="Inlet viscosity: the oil at the oil temperature plus the inlet's current and shear heating "
        "(Roelands, seed 003 eq. 3) [Pa s]."
    )
    electrical: ElectricalState
    balls: tuple[BallState, ...]
    life: LifeState | None = Field(
        default=None, description="Rating life and accumulated damage (twin.life); null before the first evaluation."
    )
    outer_ring_displacement_m: tuple[float, float, float] = Field(
        default=(0.0, 0.0, 0.0),
        description="Outer ring (housing) centre (x, y, z) [m]; zero with the rigid outer ring.",
    )
    defects: tuple[Defect, ...] = Field(default=(), description="Active local defects (twin.vibration.defects).")
    thermal: ThermalState | None = Field(
        default=None,
        description="The thermal network (ModelOptions.thermal = 'network'); null with the fixed oil temperature.",
    )
    vibration: VibrationState | None = Field(
        default=None,
        description="Indicators of the last complete accelerometer window; null before the first "
        "window or with the rigid outer ring.",
    )

    def to_json(self) -> str:
        """JSON text with the contract's field names."""
        return self.model_dump_json(by_alias=True)

    def to_dict(self) -> dict:
        """Plain dict with the contract's field names."""
        return self.model_dump(by_alias=True, mode="json")
