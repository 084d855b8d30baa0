"""The address space of the OPC UA facade: namespace URI, folders and browse names, and how each
variable is read from a twin's latest snapshot (docs/service.md "OPC UA").

Browse names are the service's own field names (units in the name, as in the JSON contract and
the setpoint vocabulary twin.setpoint), so one vocabulary serves HTTP, zenoh and OPC UA. Node ids
are strings in the facade's namespace: `<twin id>`, `<twin id>/<Folder>`,
`<twin id>/<Folder>/<browse name>` (a twin id never holds a '/').

No asyncua here: types are named by their OPC UA built-in type name ("Double", "String", ...).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, Literal

from service.core.alarm_inputs import AlarmInputs
from service.core.alarm_rules import ALARM_IDS, vibration_zone
from service.core.alarms import Alarm
from service.core.measured_temperature import MEASURABLE_NODES, TEMPERATURE_RANGE_C
from service.settings import AlarmSettings
from twin.life.iso281 import ratings_for
from twin.setpoint import FIELDS as SETPOINT_FIELDS
from twin.setpoint import Setpoint
from twin.snapshot import Snapshot

NAMESPACE_URI = "urn:bearing-twin:opcua"  # the twins' nodes
APPLICATION_URI = "urn:bearing-twin:server"  # the server application (namespace 1)
ROOT_FOLDER = "BearingTwins"  # under Objects: one object per twin
EVENT_TYPE = "BearingAlarmEventType"  # under BaseEventType
LAST_RESULT = "last_result"  # <input folder>/last_result: what became of its latest write

UaType = Literal["Double", "String", "UInt32", "Int64", "Boolean"]


@dataclass(frozen=True)
class View:
    """What a twin's variables are read from at one update."""

    snapshot: Snapshot | None
    inputs: AlarmInputs | None
    alarms: Mapping[str, Alarm]
    target: Setpoint | None
    settings: AlarmSettings
    measured: Mapping[str, Any] | None = None  # the last measured-window comparison (service.core.measured)


@dataclass(frozen=True)
class Var:
    """One variable: browse name (units in it), built-in type, description and reader."""

    name: str
    type: UaType
    description: str
    read: Callable[[View], Any]


def _contacts(v: View) -> list:
    snap = v.snapshot
    if snap is None:
        return []
    return [c for b in snap.balls for c in (b.inner, b.outer)]


def _min(values) -> float | None:
    values = [x for x in values if x is not None and math.isfinite(x)]
    return min(values) if values else None


def _max(values) -> float | None:
    values = [x for x in values if x is not None and math.isfinite(x)]
    return max(values) if values else None


def _snap(attr: str) -> Callable[[View], Any]:
    return lambda v: getattr(v.snapshot, attr) if v.snapshot is not None else None


def _in_force(name: str) -> Callable[[View], Any]:
    return lambda v: getattr(v.snapshot.setpoint, name) if v.snapshot is not None else None


def _electrical(name: str) -> Callable[[View], Any]:
    return lambda v: getattr(v.snapshot.electrical, name) if v.snapshot is not None else None


def _life(name: str) -> Callable[[View], Any]:
    def read(v: View) -> Any:
        life = getattr(v.snapshot, "life", None) if v.snapshot is not None else None
        return getattr(life, name, None) if life is not None else None

    return read


def _thermal(name: str) -> Callable[[View], Any]:
    """A field of the snapshot's thermal block (twin.snapshot.ThermalState)."""

    def read(v: View) -> Any:
        block = getattr(v.snapshot, "thermal", None) if v.snapshot is not None else None
        return getattr(block, name, None) if block is not None else None

    return read


def _thermal_temperature(node: str) -> Callable[[View], Any]:
    def read(v: View) -> Any:
        block = getattr(v.snapshot, "thermal", None) if v.snapshot is not None else None
        return block.temperatures_c.get(node) if block is not None else None

    return read


def _thermal_heat(source: str) -> Callable[[View], Any]:
    def read(v: View) -> Any:
        block = getattr(v.snapshot, "thermal", None) if v.snapshot is not None else None
        return block.heat_w.get(source) if block is not None else None

    return read


def _vib(v: View):
    return v.inputs.vibration if v.inputs is not None else None


def _zone(v: View) -> str | None:
    vib = _vib(v)
    if vib is None or vib.velocity_rms_mm_s is None:
        return None
    return vibration_zone(vib.velocity_rms_mm_s, v.settings.machine_group, v.settings.support)


def _vib_field(name: str) -> Callable[[View], Any]:
    """A field of the snapshot's vibration block (twin.snapshot.VibrationState)."""

    def read(v: View) -> Any:
        block = getattr(v.snapshot, "vibration", None) if v.snapshot is not None else None
        return getattr(block, name, None) if block is not None else None

    return read


def _defect_frequency(name: str) -> Callable[[View], Any]:
    def read(v: View) -> Any:
        f = _vib_field("defect_frequencies_hz")(v)
        return getattr(f, name, None) if f is not None else None

    return read


def _line(name: str) -> Callable[[View], Any]:
    return lambda v: _vib(v).line_amplitudes_m_s2.get(name) if _vib(v) is not None else None


def _regime_count(regime: str) -> Callable[[View], Any]:
    return lambda v: sum(1 for c in _contacts(v) if c.regime == regime) if v.snapshot is not None else None


def _measured(*path: str) -> Callable[[View], Any]:
    """A value of the last measured-window comparison (service.core.measured) by its JSON path."""

    def read(v: View) -> Any:
        value: Any = v.measured
        for key in path:
            if not isinstance(value, Mapping):
                return None
            value = value.get(key)
        return value

    return read


def _measured_line(name: str) -> Callable[[View], Any]:
    def read(v: View) -> Any:
        lines = _measured("measured", "defect_lines")(v) or ()
        return next((d["height_db"] for d in lines if d.get("name") == name), None)

    return read


def _alarm_level(alarm_id: str) -> Callable[[View], Any]:
    def read(v: View) -> str | None:
        a = v.alarms.get(alarm_id)
        return None if a is None else (a.severity if a.active else "inactive")

    return read


# ---- the folders of a twin (Identification is static: see `identification`) ------------------
FOLDERS: dict[str, tuple[Var, ...]] = {
    "OperatingConditions": (
        Var("time_s", "Double", "Simulated time of the snapshot [s].", _snap("time_s")),
        Var("seq", "Int64", "Snapshot counter of the twin (gaps: snapshots not shown) [-].", _snap("seq")),
        Var("status", "String", "'ok' or what went wrong and what the twin did about it [text].", _snap("status")),
        Var("real_time_factor", "Double", "Simulated seconds per wall second [-].", _snap("real_time_factor")),
        Var("shaft_speed_rad_s", "Double", "Current (ramped) shaft speed [rad/s].", _snap("shaft_speed_rad_s")),
        Var("cage_speed_rad_s", "Double", "Cage angular speed [rad/s].", _snap("cage_speed_rad_s")),
        *(
            Var(
                f.name,
                "Double",
                f"{f.description} in force during the last frame [{f.unit}] "
                "(the writable target is Setpoint/" + f.name + ").",
                _in_force(f.name),
            )
            for f in SETPOINT_FIELDS
            if f.name != "shaft_speed_rad_s"
        ),
    ),
    "Lubrication": (
        Var(
            "viscosity_pa_s",
            "Double",
            "Inlet viscosity (Roelands, with inlet heating) [Pa s].",
            _snap("viscosity_pa_s"),
        ),
        Var(
            "min_lambda",
            "Double",
            "Smallest film parameter Lambda over the contacts [-].",
            lambda v: _min(c.lambda_ for c in _contacts(v)),
        ),
        Var(
            "min_loaded_lambda",
            "Double",
            "Smallest Lambda over the loaded contacts (the lubrication alarm's value) [-].",
            lambda v: v.inputs.min_loaded_lambda if v.inputs is not None else None,
        ),
        Var(
            "min_film_thickness_m",
            "Double",
            "Smallest minimum film thickness h_min over the contacts [m].",
            lambda v: _min(c.h_min_m for c in _contacts(v)),
        ),
        Var(
            "boundary_contacts",
            "UInt32",
            "Contacts in the boundary regime (seed 000 Table 2) [-].",
            _regime_count("boundary"),
        ),
        Var("mixed_contacts", "UInt32", "Contacts in the mixed regime [-].", _regime_count("mixed")),
        Var("full_film_contacts", "UInt32", "Contacts in the full-film regime [-].", _regime_count("full_film")),
        Var(
            "max_contact_load_n",
            "Double",
            "Largest ball-raceway contact load [N].",
            lambda v: _max(c.load_n for c in _contacts(v)),
        ),
        Var(
            "max_pressure_pa",
            "Double",
            "Largest Hertz maximum pressure [Pa].",
            lambda v: _max(c.max_pressure_pa for c in _contacts(v)),
        ),
        Var(
            "kappa",
            "Double",
            "Viscosity ratio nu / nu1 (ISO 281:2007 clause 9.3) [-]; no value without the snapshot's life block.",
            _life("kappa"),
        ),
    ),
    "Friction": (
        Var("friction_torque_n_m", "Double", "Friction torque of the bearing [N m].", _snap("friction_torque_n_m")),
        Var(
            "max_friction_coefficient",
            "Double",
            "Largest sliding friction coefficient over the contacts [-].",
            lambda v: _max(c.mu for c in _contacts(v)),
        ),
        Var(
            "max_slide_roll_ratio",
            "Double",
            "Largest |sliding / entrainment speed| over the contacts [-].",
            lambda v: _max(abs(c.slide_roll_ratio) for c in _contacts(v)),
        ),
    ),
    "Electrical": (
        Var("discharge_risk", "String", "none | possible | likely [text].", _electrical("discharge_risk")),
        Var("reason", "String", "Why the risk is what it is [text].", _electrical("reason")),
        Var("shaft_voltage_v", "Double", "Voltage across the bearing [V].", _electrical("shaft_voltage_v")),
        Var("shaft_current_a", "Double", "Current through the bearing [A].", _electrical("shaft_current_a")),
        Var(
            "resistance_ohm",
            "Double",
            "Equivalent parallel resistance [ohm]; no value: no conduction.",
            _electrical("resistance_ohm"),
        ),
        Var("capacitance_f", "Double", "Equivalent parallel capacitance [F].", _electrical("capacitance_f")),
        Var("impedance_ohm", "Double", "Impedance magnitude [ohm].", _electrical("impedance_ohm")),
        Var("phase_rad", "Double", "Impedance phase [rad].", _electrical("phase_rad")),
        Var("frequency_hz", "Double", "Frequency of the impedance [Hz].", _electrical("frequency_hz")),
        Var(
            "max_film_field_v_m",
            "Double",
            "Largest electric field across a film or gap [V/m].",
            _electrical("max_film_field_v_m"),
        ),
        Var(
            "current_density_a_m2",
            "Double",
            "Largest apparent current density [A/m^2].",
            _electrical("current_density_a_m2"),
        ),
        Var(
            "contact_temperature_rise_k",
            "Double",
            "Inlet temperature rise above the oil [K].",
            _electrical("contact_temperature_rise_k"),
        ),
    ),
    "Vibration": (
        Var(
            "velocity_rms_mm_s",
            "Double",
            "Housing velocity RMS 10-1000 Hz (ISO 20816-1) [mm/s]; no value without the snapshot's vibration block.",
            lambda v: _vib(v).velocity_rms_mm_s if _vib(v) is not None else None,
        ),
        Var(
            "zone",
            "String",
            "ISO 20816-3 evaluation zone A | B | C | D for the configured machine group and support [text].",
            _zone,
        ),
        Var("rms_m_s2", "Double", "Housing acceleration RMS over the last window [m/s^2].", _vib_field("rms_m_s2")),
        Var("peak_m_s2", "Double", "Peak |acceleration| over the last window [m/s^2].", _vib_field("peak_m_s2")),
        Var("crest_factor", "Double", "Peak / RMS [-].", _vib_field("crest_factor")),
        Var("kurtosis", "Double", "Kurtosis of the acceleration [-] (3 for Gaussian noise).", _vib_field("kurtosis")),
        Var("window_end_s", "Double", "Simulated time of the last window's end [s].", _vib_field("window_end_s")),
        *(
            Var(
                f"{n}_hz",
                "Double",
                f"Defect frequency {n.upper().replace('TWO_BSF', '2 x BSF')} at the window's "
                "speed and loaded contact angle [Hz].",
                _defect_frequency(n),
            )
            for n in ("ftf", "bpfo", "bpfi", "bsf", "two_bsf")
        ),
        *(
            Var(
                f"{n}_m_s2",
                "Double",
                f"Envelope-spectrum amplitude at {n.upper().replace('TWO_BSF', '2 x BSF')} [m/s^2].",
                _line(n),
            )
            for n in ("ftf", "bpfo", "bpfi", "bsf", "two_bsf")
        ),
        Var(
            "noise_floor_m_s2",
            "Double",
            "Envelope-spectrum noise floor (median) [m/s^2].",
            lambda v: _vib(v).noise_floor_m_s2 if _vib(v) is not None else None,
        ),
        Var(
            "defect_count",
            "UInt32",
            "Local defects active (twin.vibration.defects) [-].",
            lambda v: len(getattr(v.snapshot, "defects", ()) or ()) if v.snapshot is not None else None,
        ),
    ),
    "MeasuredVibration": (
        Var(
            "window",
            "UInt32",
            "Measured windows compared so far (POST .../vibration/measured, zenoh "
            ".../vibration/measured) [-]; no value before the first.",
            _measured("window"),
        ),
        Var(
            "alarm", "Boolean", "The measurement shows what the twin's state does not explain [-].", _measured("alarm")
        ),
        Var(
            "alarm_codes",
            "String",
            "The comparison's alarms: unexplained_line:<line> | kurtosis_above_twin, comma separated [text].",
            lambda v: (
                ",".join(f"{a['code']}:{a['line']}" if a.get("line") else a["code"] for a in _measured("alarms")(v))
                if v.measured
                else None
            ),
        ),
        Var("shaft_hz", "Double", "Shaft frequency of the analysis [Hz].", _measured("shaft_hz")),
        Var("rms_m_s2", "Double", "Measured acceleration RMS [m/s^2].", _measured("measured", "rms_m_s2")),
        Var("kurtosis", "Double", "Measured kurtosis [-].", _measured("measured", "kurtosis")),
        Var("crest_factor", "Double", "Measured crest factor [-].", _measured("measured", "crest_factor")),
        Var(
            "predicted_kurtosis",
            "Double",
            "The twin's kurtosis at the same moment [-].",
            _measured("predicted", "kurtosis"),
        ),
        Var("kurtosis_residual", "Double", "Measured - predicted kurtosis [-].", _measured("residual", "kurtosis")),
        *(
            Var(
                f"{key}_height_db",
                "Double",
                f"Measured {name} line over the median of +-20 Hz around it [dB].",
                _measured_line(name),
            )
            for key, name in (("bpfo", "BPFO"), ("bpfi", "BPFI"), ("two_bsf", "2xBSF"))
        ),
    ),
    "Life": tuple(
        Var(name, "Double", desc + "; no value without the snapshot's life block.", _life(name))
        for name, desc in (
            ("kappa", "Viscosity ratio nu / nu1 (ISO 281:2007 clause 9.3) [-]"),
            ("a_iso", "Life modification factor a_ISO (ISO 281:2007 clause 9.3, <= 50) [-]"),
            ("l10_h", "Basic rating life L10 at the current speed [h]"),
            ("l10m_h", "Modified rating life a_ISO L10 [h]"),
            ("l10_contact_loads_h", "Life from the twin's contact loads (ISO/TS 16281 spirit) [h]"),
            ("damage_fraction", "Palmgren-Miner damage accumulated [-]"),
            ("remaining_life_h", "Remaining life at the current conditions [h]"),
        )
    ),
    "Thermal": (
        *(
            Var(
                f"{node}_c",
                "Double",
                f"Thermal network node {node.replace('_', ' ')} [degC]; no value with the fixed "
                "oil temperature (ModelOptions.thermal = 'fixed').",
                _thermal_temperature(node),
            )
            for node in ("shaft", "inner_ring", "balls", "outer_ring", "housing", "oil")
        ),
        Var(
            "inlet_temperature_c",
            "Double",
            "Contacts' inlet temperature, which sets the film viscosity [degC].",
            _thermal("inlet_temperature_c"),
        ),
        *(
            Var(f"heat_{source}_w", "Double", f"Friction heat from {source} [W].", _thermal_heat(source))
            for source in ("rolling", "sliding", "spin", "drag", "seal")
        ),
        Var(
            "dissipated_w",
            "Double",
            "Heat carried to the surroundings and the oil supply [W].",
            _thermal("dissipated_w"),
        ),
        Var(
            "dissipation_factor",
            "Double",
            "Estimated factor on the dissipation to the surroundings [-].",
            _thermal("dissipation_factor"),
        ),
        Var("dissipation_factor_sigma", "Double", "Its standard deviation [-].", _thermal("dissipation_factor_sigma")),
        Var(
            "residual_k",
            "Double",
            "Measured - predicted temperature [K]; no value without a measurement.",
            _thermal("residual_k"),
        ),
        Var(
            "outer_ring_rate_k_per_min",
            "Double",
            "Rate of rise of the outer ring [K/min].",
            _thermal("outer_ring_rate_k_per_min"),
        ),
        Var(
            "clearance_change_m",
            "Double",
            "Diametral clearance change by thermal expansion [m].",
            _thermal("clearance_change_m"),
        ),
        Var(
            "accelerated",
            "Boolean",
            "Heat capacities scaled down (accelerated thermal mode) [-].",
            _thermal("accelerated"),
        ),
    ),
    "Alarms": (
        Var(
            "active_count",
            "UInt32",
            "Number of active alarms [-].",
            lambda v: sum(1 for a in v.alarms.values() if a.active),
        ),
        *(
            Var(
                alarm_id,
                "String",
                f"State of alarm {alarm_id}: inactive | warning | critical [text] "
                "(transitions are BearingAlarmEventType events on the twin object and the Server).",
                _alarm_level(alarm_id),
            )
            for alarm_id in ALARM_IDS
        ),
    ),
}

# Setpoint/<field>: writable, the latest accepted target (twin.setpoint vocabulary)
SETPOINT_VARS: tuple[Var, ...] = tuple(
    Var(
        f.name,
        "Double",
        f"{f.description} [{f.unit}], target (write it to change the setpoint; the "
        "bearing's own limits apply, as over HTTP).",
        (lambda name: lambda v: getattr(v.target, name) if v.target is not None else None)(f.name),
    )
    for f in SETPOINT_FIELDS
)


MEASURED_TEMPERATURE = "MeasuredTemperature"  # folder of the writable measured temperatures


def _measured_c(node: str) -> Callable[[View], Any]:
    """The last measured temperature of `node` the thermal block shows [degC], or None."""

    def read(v: View) -> Any:
        thermal = v.snapshot.thermal if v.snapshot is not None else None
        return thermal.measured_c if thermal is not None and thermal.measured_node == node else None

    return read


MEASURED_TEMPERATURE_VARS: tuple[Var, ...] = tuple(
    Var(
        f"{node}_c",
        "Double",
        f"Measured {node.replace('_', ' ')} temperature [degC]: write it for the thermal network to follow "
        f"(as PUT /v1/bearings/{{id}}/temperature; [{TEMPERATURE_RANGE_C[0]:g}, {TEMPERATURE_RANGE_C[1]:g}] "
        "degC); reads the last measurement the twin took.",
        _measured_c(node),
    )
    for node in MEASURABLE_NODES
)


def identification(entry: Any) -> list[tuple[str, UaType, str, Any]]:
    """Static (name, type, description, value) of a twin: designation, kind, geometry, C, C0.

    C and C0 come from `twin.life.ratings_for` (catalogue, else ISO 281 / ISO 76 from the
    geometry)."""
    model = entry.twin.model
    spec = model.spec
    g = spec.geometry
    r = ratings_for(spec)
    c, c0 = float(r.dynamic_load_rating_n), float(r.static_load_rating_n)
    return [
        ("bearing_id", "String", "Twin name [text].", entry.id),
        ("designation", "String", "Catalog designation [text].", spec.designation),
        ("kind", "String", "deep_groove | angular_contact [text].", spec.kind),
        ("dynamic_load_rating_n", "Double", "Basic dynamic load rating C (ISO 281) [N].", c),
        ("static_load_rating_n", "Double", "Basic static load rating C0 (ISO 76) [N].", c0),
        ("ball_count", "UInt32", "Number of balls Z [-].", int(model.ball_count)),
        ("ball_diameter_m", "Double", "Ball diameter Dw [m].", 2.0 * float(g.ball_radius_m)),
        ("pitch_diameter_m", "Double", "Pitch diameter Dpw [m].", 2.0 * float(model.pitch_radius_m)),
        ("contact_angle_rad", "Double", "Nominal contact angle [rad].", float(model.contact_angle_rad)),
        (
            "diametral_clearance_m",
            "Double",
            "Diametral clearance Pd [m]; negative = preload.",
            float(entry.diametral_clearance_m),
        ),
        ("lubricant", "String", "Lubricant name [text].", entry.lubricant),
    ]
