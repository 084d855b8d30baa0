"""ISO 281:2007 rating life and ISO 76 static rating of ball bearings, in SI.

- Basic rating life (ISO 281:2007 clause 5.3): L10 = (C/P)^3 [10^6 revolutions], in hours at the
  shaft speed. The inner ring rotates, the outer ring stands still (the twin's mounting).
- Equivalent dynamic load (clause 5.2, Table 3): P = X Fr + Y Fa, e and Y of deep-groove and
  15 deg angular-contact bearings interpolated on f0 Fa / C0, f0 from Dw cos(alpha) / Dpw (ISO 76).
- Modified rating life (clause 9): L10m = a_ISO L10 (a1 = 1, 90 % reliability, Table 12), a_ISO
  from the radial-ball-bearing equations of clause 9.3 in kappa = nu / nu1 and e_C Cu / P, capped
  at 50; nu1 the rated viscosity of clause 9.3 (two speed ranges), e_C from Table 13 / Annex A.

The ISO formulas are written in the standard's own units (N, mm, r/min, mm^2/s) inside each
function; every argument and result is SI. The clause, table and equation numbers cited are those
of ISO 281:2007 as the project reads them; the standard's text is not part of this repository.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from twin import catalog
from twin.life.settings import LifeSettings

SECONDS_PER_HOUR = 3600.0
LIFE_EXPONENT_BALL = 3.0  # ISO 281:2007 eq. for L10 of ball bearings, p = 3
B_M_RADIAL_BALL = 1.3  # ISO 281:2007 Table 1: rating factor b_m, radial ball bearings
A_ISO_CAP = 50.0  # ISO 281:2007 clause 9.3: a_ISO <= 50
KAPPA_MIN, KAPPA_MAX = 0.1, 4.0  # ISO 281:2007 clause 9.3: valid from 0.1; above 4 use 4
LP_CONSTANT_N_MM = 98.1  # Lundberg-Palmgren A for point contact in N and mm (Harris & Kotzalas)
LP_REDUCTION = 0.95  # reduction factor lambda of ISO 281's f_c: 98.1 x 0.95 = 93.2 (Harris & Kotzalas)
PU_CONTACT_STRESS_RATIO = (
    1500.0 / 4200.0
) ** 3  # Cu / C0 when no catalogue Pu: 1500 MPa (clause 9.3.2) vs 4200 MPa (ISO 76)

# ISO 76: f0 for radial (deep-groove and angular-contact) ball bearings against Dw cos(alpha) / Dpw
_F0_GAMMA = np.round(np.arange(0.0, 0.4001, 0.01), 2)
_F0_VALUES = np.array(
    [
        14.7,
        14.9,
        15.1,
        15.3,
        15.5,
        15.7,
        15.9,
        16.1,
        16.3,
        16.5,
        16.4,
        16.1,
        15.9,
        15.6,
        15.4,
        15.2,
        14.9,
        14.7,
        14.4,
        14.2,
        14.0,
        13.7,
        13.5,
        13.2,
        13.0,
        12.8,
        12.5,
        12.3,
        12.1,
        11.8,
        11.6,
        11.4,
        11.2,
        10.9,
        10.7,
        10.5,
        10.3,
        10.0,
        9.8,
        9.6,
        9.4,
    ]
)

# ISO 281:2007 Table 2: f_c of radial ball bearings (deep-groove, angular-contact) against Dw cos(alpha) / Dpw
_FC_GAMMA = np.array(
    [
        0.01,
        0.02,
        0.03,
        0.04,
        0.05,
        0.06,
        0.07,
        0.08,
        0.09,
        0.10,
        0.12,
        0.14,
        0.16,
        0.18,
        0.20,
        0.22,
        0.24,
        0.26,
        0.28,
        0.30,
        0.32,
        0.34,
        0.36,
        0.38,
        0.40,
    ]
)
_FC_VALUES = np.array(
    [
        29.1,
        35.8,
        40.3,
        43.8,
        46.7,
        49.1,
        51.1,
        52.8,
        54.3,
        55.5,
        57.5,
        58.8,
        59.6,
        59.9,
        59.9,
        59.6,
        59.0,
        58.2,
        57.1,
        56.0,
        54.6,
        53.2,
        51.7,
        50.0,
        48.4,
    ]
)

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
_AC_FIXED = {
    20.0: (0.57, 0.43, 1.00),
    25.0: (0.68, 0.41, 0.87),
    30.0: (0.80, 0.39, 0.76),
    35.0: (0.95, 0.37, 0.66),
    40.0: (1.14, 0.35, 0.57),
    45.0: (1.34, 0.33, 0.50),
}

# ISO 281:2007 Annex A: e_C = a (1 - c / Dpw^(1/3)), a = k kappa^0.68 Dpw^0.55 <= 1, Dpw in mm;
# (k, c) per contamination level. Oil without filtering or with off-line filters (ISO 4406
# -/13/10, -/15/12, -/17/14, -/19/16, -/21/18) and grease.
_EC_OIL = {
    "high_cleanliness": (0.0864, 0.6796),
    "normal_cleanliness": (0.0432, 1.141),
    "slight_to_typical_contamination": (0.0288, 1.67),
    "severe_contamination": (0.0216, 2.5164),
    "very_severe_contamination": (0.0132, 3.8974),
}
_EC_GREASE = {
    "high_cleanliness": (0.0864, 0.6796),
    "normal_cleanliness": (0.0432, 1.141),
    "slight_to_typical_contamination": (0.0177, 1.887),
    "severe_contamination": (0.0115, 2.662),
    "very_severe_contamination": (0.00617, 4.06),
}


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


def basic_static_load_rating_n(
    ball_diameter_m: float, pitch_diameter_m: float, contact_angle_rad: float, ball_count: int
) -> float:
    """C0 = f0 i Z Dw^2 cos(alpha) [N], single row, Dw in mm (ISO 76, radial ball bearings)."""
    f0 = static_load_factor_f0(ball_diameter_m, pitch_diameter_m, contact_angle_rad)
    return f0 * ball_count * (ball_diameter_m * 1e3) ** 2 * math.cos(contact_angle_rad)


def basic_dynamic_load_rating_n(
    ball_diameter_m: float, pitch_diameter_m: float, contact_angle_rad: float, ball_count: int
) -> float:
    """C = b_m f_c (i cos(alpha))^0.7 Z^(2/3) Dw^1.8 [N], single row (i = 1), Dw <= 25.4 mm in mm
    (ISO 281:2007 clause 5.1, eq. for radial ball bearings; b_m = 1.3, Table 1; f_c, Table 2)."""
    dw_mm = ball_diameter_m * 1e3
    if dw_mm > 25.4:
        raise ValueError(f"ball diameter {dw_mm:g} mm: the Dw^1.8 form of ISO 281 holds up to 25.4 mm")
    gamma = ball_diameter_m * math.cos(contact_angle_rad) / pitch_diameter_m
    if not _FC_GAMMA[0] <= gamma <= _FC_GAMMA[-1]:
        raise ValueError(f"Dw cos(alpha) / Dpw = {gamma:g} outside ISO 281 Table 2 [0.01, 0.4]")
    fc = float(np.interp(gamma, _FC_GAMMA, _FC_VALUES))
    return B_M_RADIAL_BALL * fc * math.cos(contact_angle_rad) ** 0.7 * ball_count ** (2.0 / 3.0) * dw_mm**1.8


@dataclass(frozen=True)
class LoadFactors:
    """X, Y and e of ISO 281:2007 Table 3 for one load case."""

    x: float
    y: float
    e: float


def load_factors(
    kind: str,
    contact_angle_deg: float,
    radial_load_n: float,
    axial_load_n: float,
    static_load_rating_n: float,
    f0: float,
) -> LoadFactors:
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
            raise ValueError(
                f"nominal_contact_angle_deg = {a:g}: ISO 281 Table 3 factors are implemented "
                "for angular-contact bearings of 15 to 45 deg"
            )
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
    nu1_mm2_s = 45000.0 * n**-0.83 * dpw**-0.5 if n < 1000.0 else 4500.0 * n**-0.5 * dpw**-0.5
    return nu1_mm2_s * 1e-6


def viscosity_ratio(kinematic_viscosity_m2_s: float, rated_viscosity: float) -> float:
    """kappa = nu / nu1 [-] (ISO 281:2007 clause 9.3); 0 when nu1 is infinite (shaft at rest)."""
    return kinematic_viscosity_m2_s / rated_viscosity if math.isfinite(rated_viscosity) else 0.0


def contamination_factor(
    level: str, pitch_diameter_m: float, kappa: float, lubrication: Literal["oil", "grease"] = "oil"
) -> float:
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
    a = min(1.0, k * kap**0.68 * dpw**0.55)
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
    core = max(2.5671 - b / kap**m, 0.0)
    base = 1.0 - core**0.83 * max(ec_cu_over_p, 0.0) ** (1.0 / 3.0)
    if base <= 0.0:
        return A_ISO_CAP
    return min(A_ISO_CAP, 0.1 * base**-9.3)


# ---- Lundberg-Palmgren life from the contact loads -------------------------------------------
def raceway_load_rating_n(
    ball_diameter_m: float,
    pitch_diameter_m: float,
    groove_radius_m: float,
    contact_angle_rad: float,
    ball_count: int,
    inner: bool,
) -> float:
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
    return (
        a
        * (2.0 * f / (2.0 * f - 1.0)) ** 0.41
        * (1.0 - s * gamma) ** 1.39
        / (1.0 + s * gamma) ** (1.0 / 3.0)
        * (gamma / cos_a) ** 0.3
        * d_mm**1.8
        * ball_count ** (-1.0 / 3.0)
    )


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

    try:
        r = catalog.load_ratings(spec.designation)
        return BearingRatings(
            r.dynamic_load_rating_n, r.static_load_rating_n, r.fatigue_load_limit_n, r.contact_angle_deg, r.source
        )
    except ValueError:
        g = spec.geometry
        alpha = math.radians(g.nominal_contact_angle_deg)
        dw, dpw = 2.0 * g.ball_radius_m, 2.0 * g.pitch_radius_m
        c0 = basic_static_load_rating_n(dw, dpw, alpha, g.ball_count)
        return BearingRatings(
            basic_dynamic_load_rating_n(dw, dpw, alpha, g.ball_count),
            c0,
            c0 * PU_CONTACT_STRESS_RATIO,
            g.nominal_contact_angle_deg,
            "computed from the geometry: ISO 281:2007 clause 5.1 (C), ISO 76 (C0), Cu = C0 (1500/4200)^3",
        )


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
    a_iso_for_damage: float  # a_ISO, or its value at kappa = 0.1 below the standard's range
    l10_mrev: float
    l10_h: float
    l10m_h: float | None
    reasons: tuple[str, ...]


def iso_life(
    spec,
    ratings: BearingRatings,
    settings: LifeSettings,
    radial_load_n: float,
    axial_load_n: float,
    shaft_speed_rad_s: float,
    kinematic_viscosity_m2_s: float,
) -> IsoLife:
    """ISO 281:2007 basic and modified rating life of `spec` at one operating point."""
    g = spec.geometry
    dw, dpw = 2.0 * g.ball_radius_m, 2.0 * g.pitch_radius_m
    alpha_deg = g.nominal_contact_angle_deg
    reasons: list[str] = []
    if abs(alpha_deg - ratings.contact_angle_deg) > 1.0:
        reasons.append(
            f"the catalogue ratings are for the {ratings.contact_angle_deg:g} deg execution, the twin's "
            f"geometry has {alpha_deg:g} deg"
        )
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
    ec = (
        settings.contamination_factor
        if settings.contamination_factor is not None
        else contamination_factor(settings.contamination, dpw, kap_for_ec, settings.lubrication)
    )
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
    return IsoLife(
        dynamic_load_rating_n=ratings.dynamic_load_rating_n,
        equivalent_load_n=p,
        x=factors.x,
        y=factors.y,
        e=factors.e,
        viscosity_m2_s=kinematic_viscosity_m2_s,
        rated_viscosity_m2_s=nu1 if math.isfinite(nu1) else None,
        kappa=kappa,
        contamination_factor=ec,
        a_iso=a_iso,
        a_iso_for_damage=a_damage,
        l10_mrev=l10,
        l10_h=l10_h,
        l10m_h=l10m_h,
        reasons=tuple(reasons),
    )
