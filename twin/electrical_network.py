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
from numba import njit

from twin.jit import JIT_VECTOR
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


@njit(**JIT_VECTOR)
def _reciprocal(re, im):
    """1 / (re + i im) by Smith's scaling, as numpy's complex division computes it (the same
    roundings, so the network's published values equal numpy's)."""
    if abs(re) >= abs(im):
        if re == 0.0 and im == 0.0:
            return 1.0 / abs(re), 0.0 / abs(re)
        rat = im / re
        scl = 1.0 / (re + im * rat)
        return (1.0 + 0.0 * rat) * scl, (0.0 - 1.0 * rat) * scl
    rat = re / im
    scl = 1.0 / (im + re * rat)
    return (1.0 * rat + 0.0) * scl, (0.0 * rat - 1.0) * scl


@njit(**JIT_VECTOR)
def contact_impedances(
    contacts, omega_rad_s, relative_permittivity, race_params, gap_limit_inner_m, gap_limit_outer_m
):  # pragma: no cover - compiled
    """The per-contact and per-ball elements of the network at angular frequency `omega_rad_s`,
    from the contact lanes `contacts` (N_ROWS, 2Z; column 2j the inner, 2j + 1 the outer contact
    of ball j).

    A loaded contact is its lane's parallel R (inf where the lane gives none or a non-positive
    one) and C; an open contact a pure capacitor across its gap (at least _MIN_GAP_M), integrated
    over the ball-groove geometry of its raceway (twin.physics.electrical.outer_zone_capacitance_f).
    Each ball is its two contacts in series: Z_ball = Z_in + Z_out, R_ball = R_in + R_out,
    C_ball = C_in C_out / (C_in + C_out) (0 when both are 0).

    Returns (r_contact [ohm], c_contact [F], z_contact [ohm], r_ball [ohm], c_ball [F],
    z_ball [ohm], y_ball [S]); z and y complex."""
    n = contacts.shape[1]
    z = n // 2
    r_c = np.empty(n)
    c_c = np.empty(n)
    z_c = np.empty(n, np.complex128)
    for k in range(n):
        loaded = contacts[L.C_LOAD, k] > 0.0
        r = contacts[L.C_RESISTANCE, k] if loaded else math.inf
        r_c[k] = r if r > 0.0 else math.inf
        if loaded:
            c_c[k] = contacts[L.C_CAPACITANCE, k]
        else:
            race = k % 2
            gap = -contacts[L.G_DELTA, k]
            if gap < _MIN_GAP_M:
                gap = _MIN_GAP_M
            c_c[k] = outer_zone_capacitance_f(
                relative_permittivity,
                race_params[race, L.R_RX],
                race_params[race, L.R_RY],
                gap,
                gap_limit_inner_m if race == 0 else gap_limit_outer_m,
            )
        conductance = 0.0 if math.isinf(r_c[k]) else 1.0 / r_c[k]
        re, im = _reciprocal(conductance, omega_rad_s * c_c[k])
        z_c[k] = complex(re, im)
    r_ball = np.empty(z)
    c_ball = np.empty(z)
    z_ball = np.empty(z, np.complex128)
    y_ball = np.empty(z, np.complex128)
    for j in range(z):
        z_sum = complex(z_c[2 * j].real + z_c[2 * j + 1].real, z_c[2 * j].imag + z_c[2 * j + 1].imag)
        z_ball[j] = z_sum
        re, im = _reciprocal(z_sum.real, z_sum.imag)
        y_ball[j] = complex(re, im)
        r_ball[j] = r_c[2 * j] + r_c[2 * j + 1]
        c_in, c_out = c_c[2 * j], c_c[2 * j + 1]
        c_sum = c_in + c_out
        c_ball[j] = c_in * c_out / max(c_sum, 1e-300) if c_sum > 0 else 0.0
    return r_c, c_c, z_c, r_ball, c_ball, z_ball, y_ball


@njit(**JIT_VECTOR)
def film_stress_maxima(
    contacts, abs_z_contact, abs_z_ball, abs_y_ball, abs_y_sum, voltage_v, current_a
):  # pragma: no cover - compiled
    """(largest film field [V/m], largest apparent current density [A/m^2]) over the contacts.

    Each ball carries its admittance's share of the current, I |Y_ball| / sum |Y_ball|; each film
    sees its share of the voltage, V |Z_contact| / |Z_ball| (the moduli given), across its thickness (the lane's
    h_min where loaded, the gap where open, at least _MIN_GAP_M); the density is the ball's
    current over the Hertz ellipse pi a b of a loaded contact (0 for an open one). NaN propagates
    to the maximum."""
    n = contacts.shape[1]
    max_field = -math.inf
    max_density = -math.inf
    for k in range(n):
        j = k // 2
        loaded = contacts[L.C_LOAD, k] > 0.0
        v_contact = voltage_v * abs_z_contact[k] / abs_z_ball[j]
        if loaded:
            film = contacts[L.C_H_MIN, k]
            if film < _MIN_GAP_M:
                film = _MIN_GAP_M
        else:
            film = -contacts[L.G_DELTA, k]
            if film < _MIN_GAP_M:
                film = _MIN_GAP_M
        field = v_contact / film
        area = math.pi * contacts[L.C_SEMI_MAJOR, k] * contacts[L.C_SEMI_MINOR, k]
        density = 0.0
        if loaded and area > 0.0:
            density = current_a * (abs_y_ball[j] / max(abs_y_sum, 1e-300)) / area
        if field > max_field or math.isnan(field):
            max_field = field if not math.isnan(max_field) else max_field
        if density > max_density or math.isnan(density):
            max_density = density if not math.isnan(max_density) else max_density
    return max_field, max_density


@njit(**JIT_VECTOR)
def network_solution(
    contacts,
    omega_rad_s,
    relative_permittivity,
    race_params,
    gap_limit_inner_m,
    gap_limit_outer_m,
    rest_capacitance_f,
    shaft_voltage_v,
    shaft_current_a,
):  # pragma: no cover - compiled
    """The whole network at angular frequency `omega_rad_s` in one pass: the elements of
    `contact_impedances`, the bearing's admittance Y = sum Y_ball + i omega C_rest, the drive (a
    voltage setpoint wins, with the current it drives through |Z| = 1 / |Y| unless one is set; a
    current alone develops I |Z|) and `film_stress_maxima` at that drive.

    Returns (r_contact [ohm], c_contact [F], r_ball [ohm], c_ball [F], Re Y [S], Im Y [S],
    voltage [V], current [A], largest film field [V/m], largest current density [A/m^2])."""
    r_c, c_c, z_c, r_ball, c_ball, z_ball, y_ball = contact_impedances(
        contacts, omega_rad_s, relative_permittivity, race_params, gap_limit_inner_m, gap_limit_outer_m
    )
    n = z_c.size
    z = y_ball.size
    y_re = 0.0
    y_im = 0.0
    abs_y_sum = 0.0
    abs_y_ball = np.empty(z)
    abs_z_ball = np.empty(z)
    for j in range(z):
        y_re += y_ball[j].real
        y_im += y_ball[j].imag
        abs_y_ball[j] = abs(y_ball[j])
        abs_z_ball[j] = abs(z_ball[j])
        abs_y_sum += abs_y_ball[j]
    y_im += omega_rad_s * rest_capacitance_f
    abs_z_total = 1.0 / math.hypot(y_re, y_im)
    if shaft_voltage_v > 0.0:
        voltage = shaft_voltage_v
        current = shaft_current_a if shaft_current_a > 0.0 else voltage / abs_z_total
    else:
        current = shaft_current_a
        voltage = current * abs_z_total
    abs_z_contact = np.empty(n)
    for k in range(n):
        abs_z_contact[k] = abs(z_c[k])
    max_field, max_density = film_stress_maxima(
        contacts, abs_z_contact, abs_z_ball, abs_y_ball, abs_y_sum, voltage, current
    )
    return r_c, c_c, r_ball, c_ball, y_re, y_im, voltage, current, max_field, max_density


def bearing_network(
    model: BearingModel, contacts: np.ndarray, shaft_voltage_v: float, shaft_current_a: float
) -> ElectricalNetwork:
    """Evaluate the network for the contact rows `contacts` (TwinState.contacts view): one
    compiled pass (`network_solution`), then the indicators' verdicts and texts."""
    el = model.spec.electrical
    omega = 2.0 * math.pi * el.frequency_hz
    r_c, c_c, r_ball, c_ball, y_re, y_im, voltage, current, max_field, max_density = network_solution(
        contacts,
        omega,
        el.oil_relative_permittivity,
        model.race_params,
        model.gap_limit_m[0],
        model.gap_limit_m[1],
        model.rest_capacitance_f,
        float(shaft_voltage_v),
        float(shaft_current_a),
    )
    z_total = 1.0 / complex(y_re, y_im)
    risk, reason = _risk(el, max_field, max_density, voltage, current)
    phase = math.atan2(z_total.imag, z_total.real)
    capacitance: float | None = y_im / omega
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
        resistance_ohm=(1.0 / y_re) if y_re > 0 else math.inf,
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
