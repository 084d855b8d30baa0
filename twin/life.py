"""Rating life of a ball bearing: ISO 281:2007 basic and modified rating life, a life from the
contact loads in the spirit of ISO/TS 16281, and Palmgren-Miner damage accumulation.

Pure functions of SI inputs (plain Python, evaluated between frames, never in the hot loop).
The ISO formulas are written in the standard's own units (N, mm, r/min, mm^2/s) inside each
function; every argument and result is SI (m, N, rad/s, m^2/s, s or hours where the name says so).

- Basic rating life (ISO 281:2007 clause 5.3): L10 = (C/P)^3 [10^6 revolutions], in hours at the
  shaft speed. The inner ring rotates, the outer ring stands still (the twin's mounting).
- Equivalent dynamic load (clause 5.2, Table 3): P = X Fr + Y Fa, e and Y of deep-groove and
  15 deg angular-contact bearings interpolated on f0 Fa / C0, f0 from Dw cos(alpha) / Dpw (ISO 76).
- Modified rating life (clause 9): L10m = a_ISO L10 (a1 = 1, 90 % reliability, Table 12), a_ISO
  from the radial-ball-bearing equations of clause 9.3 in kappa = nu / nu1 and e_C Cu / P, capped
  at 50; nu1 the rated viscosity of clause 9.3 (two speed ranges), e_C from Table 13 / Annex A.
- Contact-load life (ISO/TS 16281 spirit; Lundberg-Palmgren per raceway, Harris & Kotzalas,
  Rolling Bearing Analysis, chapter "Fatigue life"): basic dynamic load ratings Q_ci, Q_ce of the
  raceway contacts, equivalent raceway loads (cube mean on the rotating inner ring, 10/3 power mean
  on the stationary outer ring), L = (L_i^(-10/9) + L_e^(-10/9))^(-0.9). It reads the loads the
  twin actually carries, so it sees clearance, preload, combined loads and centrifugal force.
- Damage (Palmgren-Miner): dD/dt = 1 / life(current conditions) [1/s], accumulated along the
  twin's history by `LifeMonitor`; remaining life = (1 - D) x life at the current conditions.

The ISO clause, table and equation numbers cited here are those of ISO 281:2007 as the project
reads them; the standard's text is not part of this repository.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from twin.kernels import layout as L

SECONDS_PER_HOUR = 3600.0
LIFE_EXPONENT_BALL = 3.0            # ISO 281:2007 eq. for L10 of ball bearings, p = 3
B_M_RADIAL_BALL = 1.3               # ISO 281:2007 Table 1: rating factor b_m, radial ball bearings
A_ISO_CAP = 50.0                    # ISO 281:2007 clause 9.3: a_ISO <= 50
KAPPA_MIN, KAPPA_MAX = 0.1, 4.0     # ISO 281:2007 clause 9.3: valid from 0.1; above 4 use 4
LP_CONSTANT_N_MM = 98.1             # Lundberg-Palmgren A for point contact in N and mm (Harris & Kotzalas)
LP_REDUCTION = 0.95                 # reduction factor lambda of ISO 281's f_c: 98.1 x 0.95 = 93.2 (Harris & Kotzalas)
PU_CONTACT_STRESS_RATIO = (1500.0 / 4200.0) ** 3   # Cu / C0 when no catalogue Pu: 1500 MPa (clause 9.3.2) vs 4200 MPa (ISO 76)

# ISO 76: f0 for radial (deep-groove and angular-contact) ball bearings against Dw cos(alpha) / Dpw
_F0_GAMMA = np.round(np.arange(0.0, 0.4001, 0.01), 2)
_F0_VALUES = np.array([14.7, 14.9, 15.1, 15.3, 15.5, 15.7, 15.9, 16.1, 16.3, 16.5, 16.4, 16.1, 15.9, 15.6,
                       15.4, 15.2, 14.9, 14.7, 14.4, 14.2, 14.0, 13.7, 13.5, 13.2, 13.0, 12.8, 12.5, 12.3,
                       12.1, 11.8, 11.6, 11.4, 11.2, 10.9, 10.7, 10.5, 10.3, 10.0, 9.8, 9.6, 9.4])

# ISO 281:2007 Table 2: f_c of radial ball bearings (deep-groove, angular-contact) against Dw cos(alpha) / Dpw
_FC_GAMMA = np.array([0.01, 0.02, 0.03, 0.04, 0.05, 0.06, 0.07, 0.08, 0.09, 0.10, 0.12, 0.14, 0.16, 0.18,
                      0.20, 0.22, 0.24, 0.26, 0.28, 0.30, 0.32, 0.34, 0.36, 0.38, 0.40])
_FC_VALUES = np.array([29.1, 35.8, 40.3, 43.8, 46.7, 49.1, 51.1, 52.8, 54.3, 55.5, 57.5, 58.8, 59.6, 59.9,
                       59.9, 59.6, 59.0, 58.2, 57.1, 56.0, 54.6, 53.2, 51.7, 50.0, 48.4])

# ISO 281:2007 Table 3, single-row bearings, Fa/Fr > e (for Fa/Fr <= e: X = 1, Y = 0)
# deep-groove, normal clearance: f0 Fa / C0 -> e, Y; X = 0.56
_DG_F0FA_C0 = np.array([0.172, 0.345, 0.689, 1.03, 1.38, 2.07, 3.45, 5.17, 6.89])
_DG_E = np.array([0.19, 0.22, 0.26, 0.28, 0.30, 0.34, 0.38, 0.42, 0.44])
_DG_Y = np.array([2.30, 1.99, 1.71, 1.55, 1.45, 1.31, 1.15, 1.04, 1.00])
_DG_X = 0.56
# angular contact, alpha = 15 deg: f0 i Fa / C0 -> e, Y; X = 0.44
_AC15_F0FA_C0 = np.array([0.178, 0.357, 0.714, 1.07, 1.43, 2.14, 3.57, 5.35, 7.14])
_AC15_E = np.array([0.38, 0.40, 0.43, 0.46, 0.47, 0.50, 0.55, 0.56, 0.56])
_AC15_Y = np.array([1.47, 1.40, 1.30, 1.23, 1.19, 1.12, 1.02, 1.00, 1.00])
_AC15_X = 0.44
# angular contact, fixed rows: alpha deg -> (e, X, Y)
_AC_FIXED = {20.0: (0.57, 0.43, 1.00), 25.0: (0.68, 0.41, 0.87), 30.0: (0.80, 0.39, 0.76),
             35.0: (0.95, 0.37, 0.66), 40.0: (1.14, 0.35, 0.57), 45.0: (1.34, 0.33, 0.50)}

# ISO 281:2007 Annex A: e_C = a (1 - c / Dpw^(1/3)), a = k kappa^0.68 Dpw^0.55 <= 1, Dpw in mm;
# (k, c) per contamination level. Oil without filtering or with off-line filters (ISO 4406
# -/13/10, -/15/12, -/17/14, -/19/16, -/21/18) and grease.
_EC_OIL = {"high_cleanliness": (0.0864, 0.6796), "normal_cleanliness": (0.0432, 1.141),
           "slight_to_typical_contamination": (0.0288, 1.67), "severe_contamination": (0.0216, 2.5164),
           "very_severe_contamination": (0.0132, 3.8974)}
_EC_GREASE = {"high_cleanliness": (0.0864, 0.6796), "normal_cleanliness": (0.0432, 1.141),
              "slight_to_typical_contamination": (0.0177, 1.887), "severe_contamination": (0.0115, 2.662),
              "very_severe_contamination": (0.00617, 4.06)}

ContaminationLevel = Literal["extreme_cleanliness", "high_cleanliness", "normal_cleanliness",
                             "slight_to_typical_contamination", "severe_contamination",
                             "very_severe_contamination"]


# ---- ISO 281 / ISO 76 building blocks ---------------------------------------------------------
def rad_s_to_rpm(speed_rad_s: float) -> float:
    """Shaft speed [rad/s] -> [r/min]."""
    return speed_rad_s * 60.0 / (2.0 * math.pi)


def basic_rating_life_mrev(dynamic_load_rating_n: float, equivalent_load_n: float) -> float:
    """L10 = (C / P)^3 [10^6 revolutions] (ISO 281:2007 clause 5.3, ball bearings); inf at P = 0."""
    if equivalent_load_n <= 0.0:
        return math.inf
    return (dynamic_load_rating_n / equivalent_load_n) ** LIFE_EXPONENT_BALL


def life_hours(life_mrev: float, shaft_speed_rad_s: float) -> float:
    """A life in 10^6 revolutions of the rotating ring -> hours at the shaft speed
    (ISO 281:2007 clause 5.3: L10h = 10^6 L10 / (60 n)); inf at rest or for an infinite life."""
    rev_per_s = abs(shaft_speed_rad_s) / (2.0 * math.pi)
    if rev_per_s <= 0.0 or math.isinf(life_mrev):
        return math.inf
    return life_mrev * 1e6 / rev_per_s / SECONDS_PER_HOUR


def static_load_factor_f0(ball_diameter_m: float, pitch_diameter_m: float, contact_angle_rad: float) -> float:
    """f0 [-] of a radial ball bearing from gamma = Dw cos(alpha) / Dpw (ISO 76 table for
    deep-groove and angular-contact ball bearings, linear interpolation; the factor SKF tabulates
    as f0, e.g. 14 for a 6208)."""
    gamma = ball_diameter_m * math.cos(contact_angle_rad) / pitch_diameter_m
    if not 0.0 <= gamma <= 0.4:
        raise ValueError(f"Dw cos(alpha) / Dpw = {gamma:g} outside the ISO 76 table [0, 0.4]")
    return float(np.interp(gamma, _F0_GAMMA, _F0_VALUES))


def basic_static_load_rating_n(ball_diameter_m: float, pitch_diameter_m: float, contact_angle_rad: float,
                               ball_count: int) -> float:
    """C0 = f0 i Z Dw^2 cos(alpha) [N], single row, Dw in mm (ISO 76, radial ball bearings)."""
    f0 = static_load_factor_f0(ball_diameter_m, pitch_diameter_m, contact_angle_rad)
    return f0 * ball_count * (ball_diameter_m * 1e3) ** 2 * math.cos(contact_angle_rad)


def basic_dynamic_load_rating_n(ball_diameter_m: float, pitch_diameter_m: float, contact_angle_rad: float,
                                ball_count: int) -> float:
    """C = b_m f_c (i cos(alpha))^0.7 Z^(2/3) Dw^1.8 [N], single row (i = 1), Dw <= 25.4 mm in mm
    (ISO 281:2007 clause 5.1, eq. for radial ball bearings; b_m = 1.3, Table 1; f_c, Table 2)."""
    dw_mm = ball_diameter_m * 1e3
    if dw_mm > 25.4:
        raise ValueError(f"ball diameter {dw_mm:g} mm: the Dw^1.8 form of ISO 281 holds up to 25.4 mm")
    gamma = ball_diameter_m * math.cos(contact_angle_rad) / pitch_diameter_m
    if not _FC_GAMMA[0] <= gamma <= _FC_GAMMA[-1]:
        raise ValueError(f"Dw cos(alpha) / Dpw = {gamma:g} outside ISO 281 Table 2 [0.01, 0.4]")
    fc = float(np.interp(gamma, _FC_GAMMA, _FC_VALUES))
    return B_M_RADIAL_BALL * fc * math.cos(contact_angle_rad) ** 0.7 * ball_count ** (2.0 / 3.0) * dw_mm ** 1.8


@dataclass(frozen=True)
class LoadFactors:
    """X, Y and e of ISO 281:2007 Table 3 for one load case."""

    x: float
    y: float
    e: float


def load_factors(kind: str, contact_angle_deg: float, radial_load_n: float, axial_load_n: float,
                 static_load_rating_n: float, f0: float) -> LoadFactors:
    """X, Y, e of a single-row radial ball bearing (ISO 281:2007 clause 5.2, Table 3).

    Deep-groove (normal clearance): e and Y interpolated linearly on f0 Fa / C0 (ends held).
    Angular contact: 15 deg interpolated on f0 i Fa / C0 (i = 1); 20-45 deg from the fixed rows,
    linearly in alpha between them, and between 15 and 20 deg (the table's note on intermediate
    angles). Fa/Fr <= e: X = 1, Y = 0. The axial load's sign does not matter."""
    fa, fr = abs(axial_load_n), max(radial_load_n, 0.0)
    ratio = f0 * fa / static_load_rating_n

    def deep_or_15(a_ratio, e_tab, y_tab, x):
        return (float(np.interp(ratio, a_ratio, e_tab)), x, float(np.interp(ratio, a_ratio, y_tab)))

    if kind == "deep_groove":
        e, x, y = deep_or_15(_DG_F0FA_C0, _DG_E, _DG_Y, _DG_X)
    elif kind == "angular_contact":
        a = contact_angle_deg
        if a < 15.0 - 1e-9 or a > 45.0 + 1e-9:
            raise ValueError(f"nominal_contact_angle_deg = {a:g}: ISO 281 Table 3 factors are implemented "
                             "for angular-contact bearings of 15 to 45 deg")
        if a <= 15.0 + 1e-9:
            e, x, y = deep_or_15(_AC15_F0FA_C0, _AC15_E, _AC15_Y, _AC15_X)
        elif a < 20.0:
            e15, x15, y15 = deep_or_15(_AC15_F0FA_C0, _AC15_E, _AC15_Y, _AC15_X)
            e20, x20, y20 = _AC_FIXED[20.0]
            w = (a - 15.0) / 5.0
            e, x, y = e15 + w * (e20 - e15), x15 + w * (x20 - x15), y15 + w * (y20 - y15)
        else:
            angles = np.array(sorted(_AC_FIXED))
            rows = np.array([_AC_FIXED[k] for k in angles])
            e, x, y = (float(np.interp(a, angles, rows[:, i])) for i in range(3))
    else:
        raise ValueError(f"kind = {kind!r}: ISO 281 Table 3 factors for deep_groove or angular_contact only")
    if fr > 0.0 and fa / fr <= e:
        return LoadFactors(x=1.0, y=0.0, e=e)
    if fa == 0.0:
        return LoadFactors(x=1.0, y=0.0, e=e)
    return LoadFactors(x=x, y=y, e=e)


def equivalent_dynamic_load_n(factors: LoadFactors, radial_load_n: float, axial_load_n: float) -> float:
    """P = X Fr + Y Fa [N] (ISO 281:2007 clause 5.2, eq. for the dynamic equivalent radial load)."""
    return factors.x * max(radial_load_n, 0.0) + factors.y * abs(axial_load_n)


def rated_viscosity_m2_s(shaft_speed_rad_s: float, pitch_diameter_m: float) -> float:
    """nu1 [m^2/s], the reference kinematic viscosity for adequate lubrication (ISO 281:2007
    clause 9.3, eqs. for nu1): nu1 = 45000 n^-0.83 Dpw^-0.5 for n < 1000 r/min,
    nu1 = 4500 n^-0.5 Dpw^-0.5 for n >= 1000 r/min (nu1 mm^2/s, n r/min, Dpw mm); inf at rest."""
    n = rad_s_to_rpm(abs(shaft_speed_rad_s))
    if n <= 0.0:
        return math.inf
    dpw = pitch_diameter_m * 1e3
    nu1_mm2_s = 45000.0 * n ** -0.83 * dpw ** -0.5 if n < 1000.0 else 4500.0 * n ** -0.5 * dpw ** -0.5
    return nu1_mm2_s * 1e-6


def viscosity_ratio(kinematic_viscosity_m2_s: float, rated_viscosity: float) -> float:
    """kappa = nu / nu1 [-] (ISO 281:2007 clause 9.3); 0 when nu1 is infinite (shaft at rest)."""
    return kinematic_viscosity_m2_s / rated_viscosity if math.isfinite(rated_viscosity) else 0.0


def contamination_factor(level: str, pitch_diameter_m: float, kappa: float,
                         lubrication: Literal["oil", "grease"] = "oil") -> float:
    """e_C [-] for a named contamination level (ISO 281:2007 clause 9.3, Table 13 names; the
    formulas of Annex A): e_C = a (1 - c / Dpw^(1/3)), a = k kappa^0.68 Dpw^0.55 <= 1 (Dpw in mm),
    (k, c) of oil without filtering or with off-line filters, or of grease; 'extreme_cleanliness'
    is 1 (Table 13). kappa is limited to [0.1, 4] like a_ISO's. Never negative."""
    if level == "extreme_cleanliness":
        return 1.0
    table = _EC_OIL if lubrication == "oil" else _EC_GREASE
    if level not in table:
        raise ValueError(f"contamination = {level!r}: one of extreme_cleanliness, {', '.join(table)}")
    k, c = table[level]
    dpw = pitch_diameter_m * 1e3
    kap = min(max(kappa, KAPPA_MIN), KAPPA_MAX)
    a = min(1.0, k * kap ** 0.68 * dpw ** 0.55)
    return max(0.0, a * (1.0 - c / dpw ** (1.0 / 3.0)))


def life_modification_factor(kappa: float, ec_cu_over_p: float) -> float:
    """a_ISO [-] of a radial ball bearing (ISO 281:2007 clause 9.3, the three equations for radial
    ball bearings), a_ISO = 0.1 [1 - (2.5671 - b / kappa^m)^0.83 (e_C Cu / P)^(1/3)]^-9.3 with
    (b, m) = (2.2649, 0.054381) for 0.1 <= kappa < 0.4, (1.9987, 0.19087) for 0.4 <= kappa < 1,
    (1.9987, 0.071739) for 1 <= kappa <= 4; kappa > 4 uses 4; capped at 50 (also where the bracket
    reaches 0). kappa < 0.1 is outside the standard: ValueError."""
    if not kappa >= KAPPA_MIN:
        raise ValueError(f"kappa = {kappa:g}: ISO 281 a_ISO is not applicable below {KAPPA_MIN}")
    kap = min(kappa, KAPPA_MAX)
    if kap < 0.4:
        b, m = 2.2649, 0.054381
    elif kap < 1.0:
        b, m = 1.9987, 0.19087
    else:
        b, m = 1.9987, 0.071739
    core = max(2.5671 - b / kap ** m, 0.0)
    base = 1.0 - core ** 0.83 * max(ec_cu_over_p, 0.0) ** (1.0 / 3.0)
    if base <= 0.0:
        return A_ISO_CAP
    return min(A_ISO_CAP, 0.1 * base ** -9.3)


# ---- Lundberg-Palmgren life from the contact loads -------------------------------------------
def raceway_load_rating_n(ball_diameter_m: float, pitch_diameter_m: float, groove_radius_m: float,
                          contact_angle_rad: float, ball_count: int, inner: bool) -> float:
    """Basic dynamic load rating of one raceway contact Q_c [N] (Lundberg-Palmgren, Harris &
    Kotzalas, Rolling Bearing Analysis, chapter "Fatigue life"; the raceway ratings of ISO/TS 16281):
    Q_c = A (2f / (2f - 1))^0.41 (1 -+ gamma)^1.39 / (1 +- gamma)^(1/3) (gamma / cos alpha)^0.3
    D^1.8 Z^(-1/3), upper signs inner raceway, gamma = D cos(alpha) / dm, f = groove radius / D, D in
    mm. A = 98.1 x 0.95 = 93.2 N mm^-1.8 (Lundberg-Palmgren's constant with the reduction factor
    of ISO 281's f_c) times b_m = 1.3 (ISO 281:2007 Table 1), so that the raceway ratings stand on
    the catalogue ratings' basis (tests: within 10 % of ISO 281's L10 for a deep-groove bearing)."""
    d_mm = ball_diameter_m * 1e3
    cos_a = math.cos(contact_angle_rad)
    gamma = ball_diameter_m * cos_a / pitch_diameter_m
    f = groove_radius_m / ball_diameter_m
    s = 1.0 if inner else -1.0
    a = LP_CONSTANT_N_MM * LP_REDUCTION * B_M_RADIAL_BALL
    return (a * (2.0 * f / (2.0 * f - 1.0)) ** 0.41 * (1.0 - s * gamma) ** 1.39 / (1.0 + s * gamma) ** (1.0 / 3.0)
            * (gamma / cos_a) ** 0.3 * d_mm ** 1.8 * ball_count ** (-1.0 / 3.0))


@dataclass(frozen=True)
class RacewayGeometry:
    """What the Lundberg-Palmgren raceway ratings need (SI)."""

    ball_diameter_m: float
    pitch_diameter_m: float
    inner_groove_radius_m: float
    outer_groove_radius_m: float
    ball_count: int

    @classmethod
    def of(cls, geometry) -> "RacewayGeometry":
        """From a `twin.spec.Geometry`."""
        return cls(2.0 * geometry.ball_radius_m, 2.0 * geometry.pitch_radius_m, geometry.inner_groove_radius_m,
                   geometry.outer_groove_radius_m, geometry.ball_count)


def _floats(values) -> list[float]:
    return values.tolist() if isinstance(values, np.ndarray) else [float(v) for v in values]


def contact_load_damage_per_mrev(geometry: RacewayGeometry, inner_loads_n, outer_loads_n,
                                 inner_angles_rad, outer_angles_rad) -> float:
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
        inv_li = sum(q * q * q for q in qi) / z / qci ** 3
    if se > 0.0:
        ae = sum(q * a for q, a in zip(qe, _floats(outer_angles_rad))) / se
        qce = raceway_load_rating_n(g.ball_diameter_m, g.pitch_diameter_m, g.outer_groove_radius_m, ae, z, False)
        inv_le = (sum(q ** (10.0 / 3.0) for q in qe) / z) ** 0.9 / qce ** 3
    if inv_li <= 0.0 and inv_le <= 0.0:
        return 0.0
    return float((inv_li ** (10.0 / 9.0) + inv_le ** (10.0 / 9.0)) ** 0.9)


def contact_load_life_mrev(geometry: RacewayGeometry, inner_loads_n, outer_loads_n, inner_angles_rad,
                           outer_angles_rad) -> float:
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


def contact_loads_from_equilibrium(model, radial_load_n: float, axial_load_n: float, shaft_speed_rad_s: float,
                                   cage_angle_rad: float = 0.0):
    """The same four arrays from the quasi-static equilibrium of the warm start
    (`twin.warmstart.solve_equilibrium`: Hertz contacts on the torus grooves, applied loads,
    centrifugal force of the orbit at the rolling cage speed) with ball 0 at `cage_angle_rad`."""
    from twin.kernels.contacts import groove_penetration
    from twin.warmstart import solve_equilibrium

    z = model.ball_count
    azimuths = cage_angle_rad + 2.0 * math.pi * np.arange(z) / z
    ring, d_rho, zb, ok = solve_equilibrium(model, azimuths, radial_load_n, axial_load_n,
                                            model.cage_speed_rad_s(shaft_speed_rad_s))
    if not ok:
        raise ValueError("the quasi-static equilibrium did not converge for these loads")
    race, rb = model.race_params, model.ball_radius_m
    q, ang = np.zeros((2, z)), np.zeros((2, z))
    for j in range(z):
        rho = model.pitch_radius_m + d_rho[j]
        ball = np.array([rho * math.cos(azimuths[j]), rho * math.sin(azimuths[j]), zb[j]])
        for r, centre in ((0, ring), (1, np.zeros(3))):
            rel = ball - centre
            delta, _nx, _ny, nz = groove_penetration(rel[0], rel[1], rel[2], race[r, L.R_GROOVE_CENTRE_RADIUS],
                                                     race[r, L.R_GROOVE_CENTRE_Z], race[r, L.R_GROOVE_RADIUS], rb)
            if delta > 0.0:
                q[r, j] = race[r, L.R_STIFFNESS] * delta ** 1.5
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
    damage = [contact_load_damage_per_mrev(geometry, *contact_loads_from_equilibrium(
        model, radial_load_n, axial_load_n, shaft_speed_rad_s, math.pi * k / z)) for k in range(2)]
    mean = float(np.mean(damage))
    return math.inf if mean <= 0.0 else 1.0 / mean


def dem_contact_life_mrev(designation: str, radial_load_n: float, axial_load_n: float, shaft_speed_rad_s: float,
                          oil_temperature_c: float = 40.0, diametral_clearance_m: float = 0.0,
                          settle_s: float = 0.02, average_s: float = 0.05) -> float:
    """Contact-load life [10^6 rev] from a short DEM run: a warm-started `twin.engine.Twin` at the
    operating point, `settle_s` to settle, then the damage per revolution averaged over the 1 ms
    frames of `average_s` (about 15 ball passages on a 6208 at 500 rad/s). Used where the
    quasi-static equilibrium does not converge (e.g. a deep-groove bearing under a large axial load)."""
    from twin.engine import Twin
    from twin.setpoint import Setpoint

    twin = Twin(designation, diametral_clearance_m=diametral_clearance_m,
                setpoint=Setpoint(shaft_speed_rad_s=shaft_speed_rad_s, radial_load_n=radial_load_n,
                                  axial_load_n=axial_load_n, oil_temperature_c=oil_temperature_c))
    twin.advance(settle_s)
    geometry = RacewayGeometry.of(twin.model.spec.geometry)
    damage = []
    for _ in range(max(1, int(round(average_s / 1e-3)))):
        twin.advance(1e-3)
        damage.append(contact_load_damage_per_mrev(geometry, *contact_loads_from_state(twin.state.contacts)))
    if twin.restarts:
        raise ValueError(f"the DEM run restarted {twin.restarts} time(s): {twin.status}")
    mean = float(np.mean(damage))
    return math.inf if mean <= 0.0 else 1.0 / mean


# ---- settings, ratings, one evaluation --------------------------------------------------------
class LifeSettings(BaseModel):
    """How the twin rates its life (ISO 281:2007 clause 9.3 inputs and the damage basis)."""

    model_config = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False)

    contamination: ContaminationLevel = Field(
        default="normal_cleanliness",
        description="Contamination level (ISO 281:2007 Table 13 names; e_C from the Annex A formula of the level).")
    lubrication: Literal["oil", "grease"] = Field(
        default="oil", description="Annex A formula set: oil without filtering or with off-line filters, or grease.")
    contamination_factor: float | None = Field(
        default=None, ge=0.0, le=1.0, description="e_C [-] given directly (overrides `contamination`).")
    damage_basis: Literal["iso_281", "contact_loads"] = Field(
        default="iso_281",
        description="Life the damage accrues against: the modified rating life L10m = a_ISO L10 (ISO 281), or "
        "a_ISO times the contact-load life (the twin's own ball loads, ISO/TS 16281 spirit).")
    initial_damage_fraction: float = Field(
        default=0.0, ge=0.0, le=1.0, description="Damage already accumulated when the twin starts [-] (0: new bearing).")
    refresh_s: float = Field(
        default=0.01, gt=0.0, le=1.0, description="Simulated time between two life evaluations in the engine [s].")
    averaging_s: float = Field(
        default=0.05, gt=0.0, le=10.0,
        description="Time constant of the running mean of the contact-load damage rate over the ball passages [s].")


@dataclass(frozen=True)
class BearingRatings:
    """Ratings used for one twin (catalogue where known, else computed from the geometry)."""

    dynamic_load_rating_n: float
    static_load_rating_n: float
    fatigue_load_limit_n: float
    contact_angle_deg: float
    source: str


def ratings_for(spec) -> BearingRatings:
    """Catalogue ratings of the spec's designation (`twin.catalog.load_ratings`), or, for a
    designation without them, C from ISO 281:2007 clause 5.1, C0 from ISO 76 and
    Cu = C0 (1500 / 4200)^3 (contact stress at the fatigue limit, clause 9.3, against ISO 76's)."""
    from twin import catalog

    try:
        r = catalog.load_ratings(spec.designation)
        return BearingRatings(r.dynamic_load_rating_n, r.static_load_rating_n, r.fatigue_load_limit_n,
                              r.contact_angle_deg, r.source)
    except ValueError:
        g = spec.geometry
        alpha = math.radians(g.nominal_contact_angle_deg)
        dw, dpw = 2.0 * g.ball_radius_m, 2.0 * g.pitch_radius_m
        c0 = basic_static_load_rating_n(dw, dpw, alpha, g.ball_count)
        return BearingRatings(basic_dynamic_load_rating_n(dw, dpw, alpha, g.ball_count), c0,
                              c0 * PU_CONTACT_STRESS_RATIO, g.nominal_contact_angle_deg,
                              "computed from the geometry: ISO 281:2007 clause 5.1 (C), ISO 76 (C0), Cu = C0 (1500/4200)^3")


@dataclass(frozen=True)
class IsoLife:
    """One ISO 281 evaluation (SI; inf for an unbounded life, None where the standard does not apply)."""

    dynamic_load_rating_n: float
    equivalent_load_n: float
    x: float
    y: float
    e: float
    viscosity_m2_s: float
    rated_viscosity_m2_s: float | None
    kappa: float | None
    contamination_factor: float
    a_iso: float | None
    a_iso_for_damage: float          # a_ISO, or its value at kappa = 0.1 below the standard's range
    l10_mrev: float
    l10_h: float
    l10m_h: float | None
    reasons: tuple[str, ...]


def iso_life(spec, ratings: BearingRatings, settings: LifeSettings, radial_load_n: float, axial_load_n: float,
             shaft_speed_rad_s: float, kinematic_viscosity_m2_s: float) -> IsoLife:
    """ISO 281:2007 basic and modified rating life of `spec` at one operating point."""
    g = spec.geometry
    dw, dpw = 2.0 * g.ball_radius_m, 2.0 * g.pitch_radius_m
    alpha_deg = g.nominal_contact_angle_deg
    reasons: list[str] = []
    if abs(alpha_deg - ratings.contact_angle_deg) > 1.0:
        reasons.append(f"the catalogue ratings are for the {ratings.contact_angle_deg:g} deg execution, the twin's "
                       f"geometry has {alpha_deg:g} deg")
    f0 = static_load_factor_f0(dw, dpw, math.radians(alpha_deg))
    factors = load_factors(spec.kind, alpha_deg, radial_load_n, axial_load_n, ratings.static_load_rating_n, f0)
    p = equivalent_dynamic_load_n(factors, radial_load_n, axial_load_n)
    l10 = basic_rating_life_mrev(ratings.dynamic_load_rating_n, p)
    l10_h = life_hours(l10, shaft_speed_rad_s)
    nu1 = rated_viscosity_m2_s(shaft_speed_rad_s, dpw)
    kappa = viscosity_ratio(kinematic_viscosity_m2_s, nu1) if math.isfinite(nu1) else None
    if kappa is None:
        reasons.append("shaft at rest: no fatigue cycles, the life is unbounded (kappa undefined)")
    kap_for_ec = kappa if kappa is not None else KAPPA_MAX
    ec = (settings.contamination_factor if settings.contamination_factor is not None
          else contamination_factor(settings.contamination, dpw, kap_for_ec, settings.lubrication))
    ec_cu_p = ec * ratings.fatigue_load_limit_n / p if p > 0.0 else math.inf
    a_iso: float | None
    if p <= 0.0:
        reasons.append("no load: the life is unbounded")
        a_iso = a_damage = A_ISO_CAP
    elif kappa is None:
        a_iso, a_damage = None, life_modification_factor(KAPPA_MAX, ec_cu_p)
    elif kappa < KAPPA_MIN:
        a_iso, a_damage = None, life_modification_factor(KAPPA_MIN, ec_cu_p)
        reasons.append(f"kappa = {kappa:.3g} below 0.1: ISO 281 a_ISO not applicable; damage accrues at a_ISO(0.1)")
    else:
        a_iso = a_damage = life_modification_factor(kappa, ec_cu_p)
    l10m_h = None if a_iso is None else a_iso * l10_h
    return IsoLife(dynamic_load_rating_n=ratings.dynamic_load_rating_n, equivalent_load_n=p, x=factors.x,
                   y=factors.y, e=factors.e, viscosity_m2_s=kinematic_viscosity_m2_s,
                   rated_viscosity_m2_s=nu1 if math.isfinite(nu1) else None, kappa=kappa,
                   contamination_factor=ec, a_iso=a_iso, a_iso_for_damage=a_damage, l10_mrev=l10, l10_h=l10_h,
                   l10m_h=l10m_h, reasons=tuple(reasons))


def _finite(value: float | None) -> float | None:
    return float(value) if value is not None and math.isfinite(value) else None


def damage_rate_per_s(life_h: float) -> float:
    """Palmgren-Miner: the fraction of life used per second at a life of `life_h` hours [1/s]
    (0 for an unbounded life)."""
    return 0.0 if not math.isfinite(life_h) or life_h <= 0.0 else 1.0 / (life_h * SECONDS_PER_HOUR)


def life_block(iso: IsoLife, contact_life_h: float, settings: LifeSettings, damage_fraction: float) -> dict:
    """The published `life` block (twin.snapshot.LifeState fields): hours, fractions, nulls where
    undefined, one `reason` string for the nulls and caveats."""
    basis_h = (iso.a_iso_for_damage * iso.l10_h if settings.damage_basis == "iso_281"
               else iso.a_iso_for_damage * contact_life_h)
    rate = damage_rate_per_s(basis_h)
    remaining = max(0.0, 1.0 - damage_fraction) * basis_h if math.isfinite(basis_h) else None
    return {
        "kappa": _finite(iso.kappa), "a_iso": _finite(iso.a_iso), "l10_h": _finite(iso.l10_h),
        "l10m_h": _finite(iso.l10m_h), "l10_contact_loads_h": _finite(contact_life_h),
        "damage_fraction": float(damage_fraction), "damage_rate_per_s": float(rate),
        "remaining_life_h": _finite(remaining), "dynamic_load_rating_n": float(iso.dynamic_load_rating_n),
        "equivalent_load_n": float(iso.equivalent_load_n), "contamination_factor": float(iso.contamination_factor),
        "viscosity_m2_s": float(iso.viscosity_m2_s), "rated_viscosity_m2_s": _finite(iso.rated_viscosity_m2_s),
        "damage_basis": settings.damage_basis,
        "reason": "; ".join(iso.reasons) if iso.reasons else None,
    }


# ---- the engine's accumulator ------------------------------------------------------------------
class DamageAccumulator:
    """Palmgren-Miner sum D = sum (dt / life) with a piecewise-constant rate: `set_rate` at time t
    closes the interval since the last call at the old rate and starts one at the new rate;
    `damage_at(t)` reads D without changing it (exact for a rate constant over each interval). A
    clock that goes back (a restarted scenario) starts a new interval without adding damage."""

    def __init__(self, initial_damage: float = 0.0):
        self.damage = float(initial_damage)
        self.rate_per_s = 0.0
        self.time_s: float | None = None

    def damage_at(self, time_s: float) -> float:
        """D at `time_s` [-] (the damage so far plus the open interval at the current rate)."""
        if self.time_s is None or time_s <= self.time_s:
            return self.damage
        return self.damage + self.rate_per_s * (time_s - self.time_s)

    def set_rate(self, time_s: float, rate_per_s: float) -> None:
        """Close the open interval at `time_s` and continue at `rate_per_s` [1/s]."""
        self.damage = self.damage_at(time_s)
        self.time_s = time_s
        self.rate_per_s = max(0.0, float(rate_per_s))


class LifeMonitor:
    """The twin's live rating life: the engine calls `update` after every frame (cheap: it
    re-evaluates every `settings.refresh_s` of simulated time) and `block` for the snapshot.

    The ISO part follows the setpoint loads, the current shaft speed and the oil's kinematic
    viscosity the engine passes in (the inlet viscosity at the oil temperature plus the inlet's
    current and shear heating). The contact-load part reads the DEM's ball loads and contact
    angles; its damage rate per revolution is a running mean (time constant `averaging_s`) over
    the ball passages. Damage accrues against `settings.damage_basis`. Errors never escape into
    the frame loop: they leave the life undefined with the reason."""

    def __init__(self, model, settings: LifeSettings | None = None):
        self.settings = settings or LifeSettings()
        self.spec = model.spec
        self.geometry = RacewayGeometry.of(model.spec.geometry)
        self.accumulator = DamageAccumulator(self.settings.initial_damage_fraction)
        self.error: str | None = None
        try:
            self.ratings = ratings_for(model.spec)
        except ValueError as exc:
            self.ratings, self.error = None, f"no load ratings: {exc}"
        self._iso: IsoLife | None = None
        self._contact_damage_per_mrev: float | None = None
        self._contact_life_h = math.inf
        self._last_eval_s: float | None = None

    def due(self, time_s: float) -> bool:
        """Whether `update` would re-evaluate at `time_s` (refresh_s passed, or a new clock)."""
        last = self._last_eval_s
        return self.ratings is not None and (last is None or not last <= time_s < last + self.settings.refresh_s)

    def update(self, time_s: float, shaft_speed_rad_s: float, radial_load_n: float, axial_load_n: float,
               kinematic_viscosity_m2_s: float, contacts: np.ndarray, force: bool = False) -> None:
        """Re-evaluate if `refresh_s` has passed (or `force`), and restart the damage interval at
        the new rate."""
        if self.ratings is None or not (force or self.due(time_s)):
            return
        last = self._last_eval_s
        try:
            self._iso = iso_life(self.spec, self.ratings, self.settings, radial_load_n, axial_load_n,
                                 shaft_speed_rad_s, kinematic_viscosity_m2_s)
            d = contact_load_damage_per_mrev(self.geometry, *contact_loads_from_state(contacts))
            prev = self._contact_damage_per_mrev
            if prev is None or last is None or time_s <= last:
                mean = d
            else:
                w = 1.0 - math.exp(-(time_s - last) / self.settings.averaging_s)
                mean = prev + w * (d - prev)
            self._contact_damage_per_mrev = mean
            self._contact_life_h = life_hours(math.inf if mean <= 0.0 else 1.0 / mean, shaft_speed_rad_s)
            self.error = None
        except (ValueError, ZeroDivisionError, OverflowError, FloatingPointError) as exc:
            self._iso, self.error = None, f"life not evaluated: {exc}"
        self._last_eval_s = time_s
        rate = 0.0
        if self._iso is not None:
            basis_h = (self._iso.a_iso_for_damage * (self._iso.l10_h if self.settings.damage_basis == "iso_281"
                                                     else self._contact_life_h))
            rate = damage_rate_per_s(basis_h)
        self.accumulator.set_rate(time_s, rate)

    def block(self, time_s: float) -> dict | None:
        """The snapshot's `life` fields at `time_s`, or None before the first evaluation."""
        damage = self.accumulator.damage_at(time_s)
        if self._iso is None:
            if self.error is None:
                return None
            return {"damage_fraction": float(damage), "reason": self.error}
        block = life_block(self._iso, self._contact_life_h, self.settings, damage)
        if self.error:
            block["reason"] = self.error
        return block


# ---- the CLI's evaluation ------------------------------------------------------------------------
def rate_operating_point(designation: str, radial_load_n: float, axial_load_n: float, shaft_speed_rad_s: float,
                         oil_temperature_c: float = 40.0, diametral_clearance_m: float = 0.0,
                         settings: LifeSettings | None = None, lubricant=None) -> dict:
    """`bearing-twin life`: the life block of a catalogue bearing at one steady operating point,
    the contact-load life from the quasi-static equilibrium (`equilibrium_contact_life_mrev`,
    centrifugal force included). Inputs are validated against the
    bearing's limits (SetpointError / ValidationError / ValueError naming the field)."""
    from twin import catalog
    from twin.model import make_model
    from twin.physics.viscosity import kinematic_viscosity_m2_s
    from twin.setpoint import Setpoint, SetpointLimits

    settings = settings or LifeSettings()
    spec = catalog.bearing(designation, diametral_clearance_m=diametral_clearance_m,
                           **({"lubricant": lubricant} if lubricant is not None else {}))
    model = make_model(spec)
    setpoint = Setpoint(shaft_speed_rad_s=shaft_speed_rad_s, radial_load_n=radial_load_n, axial_load_n=axial_load_n,
                        oil_temperature_c=oil_temperature_c)
    SetpointLimits.for_model(model).check(setpoint)   # the one range check, quoting the bearing's range
    lub = spec.lubricant
    nu = kinematic_viscosity_m2_s(lub.kinematic_viscosity_40c_m2_s, lub.kinematic_viscosity_100c_m2_s,
                                  oil_temperature_c)
    ratings = ratings_for(spec)
    iso = iso_life(spec, ratings, settings, radial_load_n, axial_load_n, shaft_speed_rad_s, nu)
    method = ("quasi-static equilibrium (twin.warmstart, centrifugal force included), damage averaged over the "
              "two cage positions symmetric about the load line")
    if radial_load_n <= 0.0 and axial_load_n == 0.0:
        contact_mrev = math.inf
    else:
        try:
            contact_mrev = equilibrium_contact_life_mrev(model, radial_load_n, axial_load_n, shaft_speed_rad_s)
        except ValueError:
            contact_mrev = dem_contact_life_mrev(designation, radial_load_n, axial_load_n, shaft_speed_rad_s,
                                                 oil_temperature_c, diametral_clearance_m)
            method = ("DEM run (the quasi-static equilibrium did not converge): 20 ms to settle, damage averaged "
                      "over 50 frames of 1 ms")
    block = life_block(iso, life_hours(contact_mrev, shaft_speed_rad_s), settings, settings.initial_damage_fraction)
    block.update({
        "bearing": spec.designation, "kind": spec.kind,
        "nominal_contact_angle_deg": spec.geometry.nominal_contact_angle_deg,
        "static_load_rating_n": ratings.static_load_rating_n, "fatigue_load_limit_n": ratings.fatigue_load_limit_n,
        "ratings_source": ratings.source, "x_factor": iso.x, "y_factor": iso.y, "e_factor": iso.e,
        "l10_mrev": _finite(iso.l10_mrev), "l10_contact_loads_mrev": _finite(contact_mrev),
        "radial_load_n": radial_load_n, "axial_load_n": axial_load_n, "shaft_speed_rad_s": shaft_speed_rad_s,
        "oil_temperature_c": oil_temperature_c, "diametral_clearance_m": diametral_clearance_m,
        "contamination": settings.contamination if settings.contamination_factor is None else "given",
        "contact_loads_from": method,
    })
    return block
