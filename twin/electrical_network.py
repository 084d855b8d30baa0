"""The bearing's electrical network and indicators, from the per-contact parallel RC of the
kernel (seed 000 end of section 2.2, seed 004 conclusion).

Per ball the inner and outer contacts are in series; the balls are in parallel, with the rest of
the bearing (the rings' lands facing each other across the oil-filled annulus, a coaxial
capacitor of the geometry, twin.model) beside them. Open contacts (an unloaded ball off its
raceway) are pure capacitors across the gap the dynamics gives them, integrated over the exact
ball-groove geometry (twin.physics.electrical: the paraboloid law with the geometric gap limit);
an unloaded ball's other contact, pressed by its centrifugal load, has its own film from the film
formula like any loaded contact. Evaluated between frames (numpy), never in the hot loop.

The bearing is published as a capacitance only where the network is capacitive (impedance phase
at or below -45 deg, CAPACITIVE_PHASE_RAD): above it the asperity contacts' conduction dominates
and Im(Y)/omega is not a capacitance of anything (the impedance and phase always are).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from twin.kernels import layout as L
from twin.model import BearingModel
from twin.physics.electrical import outer_zone_capacitance_f
from twin.snapshot import DischargeRisk

_MIN_GAP_M = 1e-9
CAPACITIVE_PHASE_RAD = -math.pi / 4.0  # the network is capacitive at or below this impedance phase


@dataclass(frozen=True)
class ElectricalNetwork:
    """Network values and indicators (SI)."""

    contact_resistance_ohm: np.ndarray  # (2Z,), inf for open contacts
    contact_capacitance_f: np.ndarray  # (2Z,)
    ball_resistance_ohm: np.ndarray  # (Z,) series R_in + R_out, inf if either is open
    ball_capacitance_f: np.ndarray  # (Z,) series C_in C_out / (C_in + C_out)
    resistance_ohm: float  # 1 / Re(Y) at the frequency (inf: no conduction)
    capacitance_f: float | None  # Im(Y) / omega where the network is capacitive, else None
    capacitance_reason: str | None  # why capacitance_f is None (None when it is published)
    impedance_ohm: float  # |Z|
    phase_rad: float  # arg Z (-pi/2: capacitive, 0: resistive)
    frequency_hz: float
    shaft_voltage_v: float
    shaft_current_a: float
    max_film_field_v_m: float
    current_density_a_m2: float
    discharge_risk: DischargeRisk
    reason: str


def _open_contact_capacitance(model: BearingModel, r: int, gap_m: np.ndarray) -> np.ndarray:
    el = model.spec.electrical
    rx, ry = model.race_params[r, L.R_RX], model.race_params[r, L.R_RY]
    return np.array(
        [
            outer_zone_capacitance_f(el.oil_relative_permittivity, rx, ry, max(g, _MIN_GAP_M), model.gap_limit_m[r])
            for g in gap_m
        ]
    )


def bearing_network(
    model: BearingModel, contacts: np.ndarray, shaft_voltage_v: float, shaft_current_a: float
) -> ElectricalNetwork:
    """Evaluate the network for the contact rows `contacts` (TwinState.contacts view)."""
    el = model.spec.electrical
    z = model.ball_count
    omega = 2.0 * math.pi * el.frequency_hz
    loaded = contacts[L.C_LOAD] > 0.0
    r_c = np.where(loaded, contacts[L.C_RESISTANCE], np.inf)
    r_c = np.where(r_c > 0.0, r_c, np.inf)
    c_c = contacts[L.C_CAPACITANCE].copy()
    gap = np.maximum(-contacts[L.G_DELTA], _MIN_GAP_M)
    for r in range(2):
        idx = np.arange(r, 2 * z, 2)
        open_idx = idx[~loaded[idx]]
        if open_idx.size:
            c_c[open_idx] = _open_contact_capacitance(model, r, gap[open_idx])
    with np.errstate(divide="ignore", invalid="ignore"):
        y_c = np.where(np.isinf(r_c), 0.0, 1.0 / r_c) + 1j * omega * c_c
        z_c = 1.0 / y_c
        z_ball = z_c[0::2] + z_c[1::2]
        y_ball = 1.0 / z_ball
    y = complex(np.sum(y_ball)) + 1j * omega * model.rest_capacitance_f
    z_total = 1.0 / y
    r_ball = r_c[0::2] + r_c[1::2]
    c_in, c_out = c_c[0::2], c_c[1::2]
    c_ball = np.where(c_in + c_out > 0, c_in * c_out / np.maximum(c_in + c_out, 1e-300), 0.0)
    # drive: a voltage setpoint wins; a current alone develops I |Z|
    if shaft_voltage_v > 0.0:
        voltage = shaft_voltage_v
        current = shaft_current_a if shaft_current_a > 0.0 else voltage / abs(z_total)
    else:
        current = shaft_current_a
        voltage = current * abs(z_total)
    # each ball carries its admittance's share of the current; each film sees its share of V
    share = np.abs(y_ball) / max(float(np.sum(np.abs(y_ball))), 1e-300)
    i_ball = current * share
    v_contact = voltage * np.abs(z_c) / np.repeat(np.abs(z_ball), 2)
    film = np.where(loaded, np.maximum(contacts[L.C_H_MIN], _MIN_GAP_M), gap)
    field = v_contact / film
    area = math.pi * contacts[L.C_SEMI_MAJOR] * contacts[L.C_SEMI_MINOR]
    density = np.where(loaded & (area > 0), np.repeat(i_ball, 2) / np.where(area > 0, area, 1.0), 0.0)
    max_field = float(np.max(field)) if field.size else 0.0
    max_density = float(np.max(density)) if density.size else 0.0
    risk, reason = _risk(el, max_field, max_density, voltage, current)
    phase = math.atan2(z_total.imag, z_total.real)
    capacitance: float | None = y.imag / omega
    capacitance_reason: str | None = None
    if phase > CAPACITIVE_PHASE_RAD:
        capacitance = None
        capacitance_reason = (
            f"not capacitive: impedance phase {math.degrees(phase):.1f} deg above -45 deg at "
            f"{el.frequency_hz:g} Hz (conduction through asperity contacts dominates); "
            f"|Z| = {abs(z_total):.4g} ohm"
        )
    return ElectricalNetwork(
        contact_resistance_ohm=r_c,
        contact_capacitance_f=c_c,
        ball_resistance_ohm=r_ball,
        ball_capacitance_f=c_ball,
        resistance_ohm=(1.0 / y.real) if y.real > 0 else math.inf,
        capacitance_f=capacitance,
        capacitance_reason=capacitance_reason,
        impedance_ohm=abs(z_total),
        phase_rad=phase,
        frequency_hz=el.frequency_hz,
        shaft_voltage_v=voltage,
        shaft_current_a=current,
        max_film_field_v_m=max_field,
        current_density_a_m2=max_density,
        discharge_risk=risk,
        reason=reason,
    )


def _risk(el, field, density, voltage, current) -> tuple[DischargeRisk, str]:
    if voltage <= 0.0 and current <= 0.0:
        return "none", "no shaft voltage or current"
    if density >= el.fluting_current_density_a_m2:
        return "likely", (
            f"apparent current density {density / 1e6:.2f} A/mm^2 above the fluting threshold "
            f"{el.fluting_current_density_a_m2 / 1e6:.2f} A/mm^2"
        )
    if field >= el.breakdown_field_v_m:
        return "likely", (
            f"film field {field / 1e6:.1f} V/um above the oil's breakdown strength "
            f"{el.breakdown_field_v_m / 1e6:.1f} V/um: discharges through the film"
        )
    if density >= el.harmless_current_density_a_m2:
        return "possible", (
            f"apparent current density {density / 1e6:.2f} A/mm^2 between the harmless "
            f"{el.harmless_current_density_a_m2 / 1e6:.2f} and fluting "
            f"{el.fluting_current_density_a_m2 / 1e6:.2f} A/mm^2 thresholds"
        )
    if field >= 0.5 * el.breakdown_field_v_m:
        return "possible", (
            f"film field {field / 1e6:.1f} V/um above half the breakdown strength "
            f"{el.breakdown_field_v_m / 1e6:.1f} V/um"
        )
    return "none", (
        f"current density {density / 1e6:.3f} A/mm^2 and film field {field / 1e6:.2f} V/um below the thresholds"
    )
