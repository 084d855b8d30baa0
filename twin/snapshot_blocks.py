"""The snapshot's per-ball, per-contact and electrical blocks (twin.snapshot), read from the
state's lanes, the electrical network and the inlet film at one instant.

The contact lanes are read once per snapshot as lists of floats (`contacts.T.tolist()`), and the
network's per-contact values likewise, instead of element by element from the arrays (element
reads from numpy cost a third of the snapshot's time).
"""

from __future__ import annotations

import math

import numpy as np

from twin.electrical_network import ElectricalNetwork
from twin.inlet_film import InletFilm
from twin.kernels import layout as L
from twin.model import BearingModel
from twin.physics.friction import REGIME_NAMES
from twin.physics.hertz import max_pressure_pa
from twin.snapshot import BallState, ContactState, ElectricalState
from twin.state import TwinState
from twin.state_measures import ball_azimuths_rad


def finite_or_none(value: float) -> float | None:
    """The value as a float, or None when it is inf or NaN (the snapshot's JSON has neither)."""
    return float(value) if math.isfinite(value) else None


def contact_mu(model: BearingModel, column: list[float], effective_mu: bool) -> float:
    """Published mu of one loaded contact's lane column: with the ellipse friction
    (`effective_mu`) the effective coefficient |F_t| / Q (the tangential spring's elastic force,
    which the strips transmit, over the normal load); with the centre-point laws their Coulomb
    coefficient."""
    c = column
    if not effective_mu:
        return float(c[L.C_MU])
    kt = model.options.tangential_stiffness_ratio * 1.5 * c[L.M_STIFFNESS] * c[L.G_SQRT_DELTA]
    return float(kt * math.sqrt(c[L.T_XI0] ** 2 + c[L.T_XI1] ** 2 + c[L.T_XI2] ** 2) / c[L.C_LOAD])


def contact_state(
    model: BearingModel, column: list[float], resistance_ohm: float, capacitance_f: float, effective_mu: bool
) -> ContactState:
    """One contact's block from its lane column and its parallel-RC values; the film, regime,
    friction and kinematics are null / no_contact / 0 when it carries no load."""
    c = column
    loaded = c[L.C_LOAD] > 0.0
    regime = REGIME_NAMES[int(c[L.C_REGIME])] if loaded else "no_contact"
    return ContactState(
        load_n=float(c[L.C_LOAD]),
        h_min_m=finite_or_none(c[L.C_H_MIN]) if loaded else None,
        h_c_m=finite_or_none(c[L.C_H_C]) if loaded else None,
        lambda_=finite_or_none(c[L.C_LAMBDA]) if loaded else None,
        regime=regime,
        mu=contact_mu(model, c, effective_mu) if loaded else 0.0,
        entrainment_speed_m_s=float(c[L.C_ENTRAINMENT]) if loaded else 0.0,
        slide_roll_ratio=float(c[L.C_SRR]) if loaded else 0.0,
        contact_angle_rad=float(math.asin(min(1.0, max(-1.0, c[L.G_NZ])))) if loaded else 0.0,
        max_pressure_pa=float(max_pressure_pa(c[L.C_LOAD], c[L.C_SEMI_MAJOR], c[L.C_SEMI_MINOR])),
        resistance_ohm=finite_or_none(resistance_ohm),
        capacitance_f=float(capacitance_f),
    )


def ball_states(
    model: BearingModel, state: TwinState, net: ElectricalNetwork, effective_mu: bool
) -> tuple[BallState, ...]:
    """Every ball's block: azimuth, spin, orbital speed about the bearing axis, cage load, its
    inner (k = 2j) and outer (k = 2j + 1) contacts and their series RC."""
    s = state
    x, v, w = s.ball_position_in_bearing_m, s.ball_velocity_in_bearing_m_s, s.ball_angular_velocity_rad_s
    az = ball_azimuths_rad(s)
    rho2 = x[:, 0] ** 2 + x[:, 1] ** 2
    orbital = (x[:, 0] * v[:, 1] - x[:, 1] * v[:, 0]) / rho2
    spin = np.linalg.norm(w, axis=1)
    columns = s.contacts.T.tolist()
    resistance = np.asarray(net.contact_resistance_ohm, dtype=float).tolist()
    capacitance = np.asarray(net.contact_capacitance_f, dtype=float).tolist()
    az, spin, orbital = az.tolist(), spin.tolist(), orbital.tolist()
    cage = s.cage_load_n.max(axis=1).tolist()

    def contact(k: int) -> ContactState:
        return contact_state(model, columns[k], resistance[k], capacitance[k], effective_mu)

    return tuple(
        BallState(
            index=j,
            azimuth_rad=az[j],
            spin_rad_s=spin[j],
            orbital_speed_rad_s=orbital[j],
            cage_load_n=cage[j],
            inner=contact(2 * j),
            outer=contact(2 * j + 1),
            resistance_ohm=finite_or_none(net.ball_resistance_ohm[j]),
            capacitance_f=float(net.ball_capacitance_f[j]),
        )
        for j in range(model.ball_count)
    )


def electrical_state(net: ElectricalNetwork, inlet: InletFilm) -> ElectricalState:
    """The bearing's electrical block: the network's impedance and discharge indicators, and the
    inlet's current and shear heating with the film factor they give."""
    return ElectricalState(
        resistance_ohm=finite_or_none(net.resistance_ohm),
        capacitance_f=net.capacitance_f,
        capacitance_reason=net.capacitance_reason,
        impedance_ohm=net.impedance_ohm,
        phase_rad=net.phase_rad,
        frequency_hz=net.frequency_hz,
        shaft_voltage_v=net.shaft_voltage_v,
        shaft_current_a=net.shaft_current_a,
        max_film_field_v_m=net.max_film_field_v_m,
        current_density_a_m2=net.current_density_a_m2,
        discharge_risk=net.discharge_risk,
        reason=net.reason,
        contact_temperature_rise_k=float(inlet.current_heating_k + inlet.shear_heating_k),
        current_temperature_rise_k=float(inlet.current_heating_k),
        shear_temperature_rise_k=float(inlet.shear_heating_k),
        film_thermal_factor=float(inlet.film_thermal_factor),
    )
