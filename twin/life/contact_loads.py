"""Life from the contact loads the twin carries (ISO/TS 16281 spirit).

Lundberg-Palmgren per raceway (Harris & Kotzalas, Rolling Bearing Analysis, chapter "Fatigue
life"): basic dynamic load ratings Q_ci, Q_ce of the raceway contacts, equivalent raceway loads
(cube mean on the rotating inner ring, 10/3 power mean on the stationary outer ring),
L = (L_i^(-10/9) + L_e^(-10/9))^(-0.9). It reads the loads the twin actually carries, so it sees
clearance, preload, combined loads and centrifugal force.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from twin.kernels import layout as L
from twin.life.iso281 import raceway_load_rating_n
from twin.warmstart import race_contacts, solve_equilibrium


@dataclass(frozen=True)
class RacewayGeometry:
    """What the Lundberg-Palmgren raceway ratings need (SI)."""

    ball_diameter_m: float
    pitch_diameter_m: float
    inner_groove_radius_m: float
    outer_groove_radius_m: float
    ball_count: int

    @classmethod
    def of(cls, geometry) -> RacewayGeometry:
        """From a `twin.spec.Geometry`."""
        return cls(
            2.0 * geometry.ball_radius_m,
            2.0 * geometry.pitch_radius_m,
            geometry.inner_groove_radius_m,
            geometry.outer_groove_radius_m,
            geometry.ball_count,
        )


def _floats(values) -> list[float]:
    return values.tolist() if isinstance(values, np.ndarray) else [float(v) for v in values]


def contact_load_damage_per_mrev(
    geometry: RacewayGeometry, inner_loads_n, outer_loads_n, inner_angles_rad, outer_angles_rad
) -> float:
    """1 / L [per 10^6 inner-ring revolutions] from the ball loads Q_j and contact angles of both
    raceways (Lundberg-Palmgren, Harris & Kotzalas ch. "Fatigue life"; ISO/TS 16281 spirit):
    rotating inner ring 1/L_i = (Q_ei / Q_ci)^3 with Q_ei = (1/Z sum Q_j^3)^(1/3), stationary
    outer ring 1/L_e = (Q_ee / Q_ce)^3 with Q_ee = (1/Z sum Q_j^(10/3))^(3/10), and the bearing
    1/L = (L_i^(-10/9) + L_e^(-10/9))^(9/10). Q_c of each raceway at its load-weighted mean
    contact angle (Q_c moves by about 1.5 % between 0 and 15 deg). 0 when no ball is loaded."""
    g = geometry
    z = g.ball_count
    # plain Python on a few dozen numbers: faster than numpy's per-call overhead between frames
    qi = [max(q, 0.0) for q in _floats(inner_loads_n)]
    qe = [max(q, 0.0) for q in _floats(outer_loads_n)]
    si, se = sum(qi), sum(qe)
    inv_li = inv_le = 0.0
    if si > 0.0:
        ai = sum(q * a for q, a in zip(qi, _floats(inner_angles_rad))) / si
        qci = raceway_load_rating_n(g.ball_diameter_m, g.pitch_diameter_m, g.inner_groove_radius_m, ai, z, True)
        inv_li = sum(q * q * q for q in qi) / z / qci**3
    if se > 0.0:
        ae = sum(q * a for q, a in zip(qe, _floats(outer_angles_rad))) / se
        qce = raceway_load_rating_n(g.ball_diameter_m, g.pitch_diameter_m, g.outer_groove_radius_m, ae, z, False)
        inv_le = (sum(q ** (10.0 / 3.0) for q in qe) / z) ** 0.9 / qce**3
    if inv_li <= 0.0 and inv_le <= 0.0:
        return 0.0
    return float((inv_li ** (10.0 / 9.0) + inv_le ** (10.0 / 9.0)) ** 0.9)


def contact_load_life_mrev(
    geometry: RacewayGeometry, inner_loads_n, outer_loads_n, inner_angles_rad, outer_angles_rad
) -> float:
    """L [10^6 inner-ring revolutions] = 1 / `contact_load_damage_per_mrev` (inf when unloaded)."""
    d = contact_load_damage_per_mrev(geometry, inner_loads_n, outer_loads_n, inner_angles_rad, outer_angles_rad)
    return math.inf if d <= 0.0 else 1.0 / d


def contact_loads_from_state(contacts: np.ndarray) -> tuple[list, list, list, list]:
    """(inner loads, outer loads [N], inner angles, outer angles [rad]) from the twin's contact
    lanes (`TwinState.contacts`, lane 2j inner, 2j+1 outer); the angle is that of the contact
    normal to the radial plane."""
    q = contacts[L.C_LOAD].tolist()
    ang = [math.asin(min(abs(n), 1.0)) for n in contacts[L.G_NZ].tolist()]
    return q[0::2], q[1::2], ang[0::2], ang[1::2]


def contact_loads_from_equilibrium(
    model, radial_load_n: float, axial_load_n: float, shaft_speed_rad_s: float, cage_angle_rad: float = 0.0
):
    """The same four arrays from the quasi-static equilibrium of the warm start
    (`twin.warmstart.solve_equilibrium`: Hertz contacts on the torus grooves, applied loads,
    centrifugal force of the orbit at the rolling cage speed) with ball 0 at `cage_angle_rad`."""

    z = model.ball_count
    azimuths = cage_angle_rad + 2.0 * math.pi * np.arange(z) / z
    ring, d_rho, zb, ok = solve_equilibrium(
        model, azimuths, radial_load_n, axial_load_n, model.cage_speed_rad_s(shaft_speed_rad_s)
    )
    if not ok:
        raise ValueError("the quasi-static equilibrium did not converge for these loads")
    q, ang = np.zeros((2, z)), np.zeros((2, z))
    for j in range(z):
        rho = model.pitch_radius_m + d_rho[j]
        ball = np.array([rho * math.cos(azimuths[j]), rho * math.sin(azimuths[j]), zb[j]])
        for r, (delta, _nx, _ny, nz, k) in enumerate(race_contacts(model, ring, ball)):
            if delta > 0.0:
                q[r, j] = k * delta**1.5
                ang[r, j] = math.asin(min(1.0, abs(nz)))
    return q[0], q[1], ang[0], ang[1]


def equilibrium_contact_life_mrev(model, radial_load_n: float, axial_load_n: float, shaft_speed_rad_s: float) -> float:
    """Contact-load life [10^6 rev] from the quasi-static equilibrium, its damage averaged
    (Palmgren-Miner) over the two cage positions symmetric about the load line: a ball on the
    load line, and two balls straddling it. (Positions in between break the symmetry, and with the
    centrifugal force the warm-start solver does not always converge there; on the 6208 at 3000 N
    the four quarter-pitch positions give the same mean within 0.1 %.)"""
    geometry = RacewayGeometry.of(model.spec.geometry)
    z = model.ball_count
    damage = [
        contact_load_damage_per_mrev(
            geometry,
            *contact_loads_from_equilibrium(model, radial_load_n, axial_load_n, shaft_speed_rad_s, math.pi * k / z),
        )
        for k in range(2)
    ]
    mean = float(np.mean(damage))
    return math.inf if mean <= 0.0 else 1.0 / mean
