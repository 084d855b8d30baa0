"""The SKF model for the frictional moment of a deep-groove ball bearing: an independent
reference for the twin's friction torque.

SKF, Rolling bearings catalogue (PUB BU/P1 10000/2 EN, 2016; the same model since the 2003
General Catalogue 6000 EN), section 'The SKF model for calculating the frictional moment':

    M = M_rr + M_sl + M_seal + M_drag                                  [N mm]
    M_rr = phi_ish phi_rs G_rr (nu n)^0.6                              (rolling)
    M_sl = G_sl mu_sl                                                  (sliding)
    deep-groove ball bearings, F_a = 0:  G_rr = R1 dm^1.96 F_r^0.54,   G_sl = S1 dm^-0.26 F_r^(5/3)
    (F_a > 0: G_rr = R1 dm^1.96 (F_r + R2/sin(alpha_F) F_a)^0.54,
     G_sl = S1 dm^-0.145 (F_r^5 + S2 dm^1.5 / sin(alpha_F) F_a^4)^(1/3), alpha_F = 24.6 (F_a/C0)^0.24 deg)
    mu_sl = phi_bl mu_bl + (1 - phi_bl) mu_EHL,  phi_bl = exp(-2.6e-8 (n nu)^1.4 dm),
    mu_bl = 0.15, mu_EHL = 0.05 (mineral oil)
    phi_ish = 1 / (1 + 1.84e-9 (n dm)^1.28 nu^0.64)                  (inlet shear heating)
    phi_rs = exp(-K_rs nu n (d + D) sqrt(K_z / (2 (D - d))))           (kinematic replenishment)

with n in r/min, nu the operating kinematic viscosity in mm^2/s, dm = (d + D)/2, d, D, F in N.
Geometry constants for deep-groove ball bearings (catalogue table 'Geometry constants for
rolling and sliding frictional moments'): series 62 (and 622): R1 = 3.9e-7, R2 = 1.7,
S1 = 3.23e-3, S2 = 36.5; series 60: R1 = 4.1e-7, R2 = 1.7, S1 = 3.73e-3, S2 = 14.6; series 63:
R1 = 3.7e-7, R2 = 1.7, S1 = 2.84e-3, S2 = 92.8. K_z = 3.1 for deep-groove ball bearings;
K_rs = 3e-8 for oil jet / low-level oil bath, 6e-8 for grease and oil-air.

M_seal = 0 and M_drag = 0 here: the comparison takes the twin's contact friction
(Twin.contact_friction_torque_n_m) against M_rr + M_sl. The twin's seal and oil-bath drag laws are
the same model's M_seal and M_drag, written once in twin.physics.seals and twin.physics.drag. This
module knows nothing of the twin's engine; it takes the designation's boundary dimensions.

Readings that differ between editions: mu_bl = 0.15 (General Catalogue 6000 EN, 2003, taken here);
the 2018 catalogue's transcription (github.com/JRaposo-m/SKF-Bearing-Selection-Tool) has 0.12 while
turning and 0.15 at start. Over 100-1500 rad/s with the seed oil at 40 degC phi_bl <= 0.04
(6205 at 100 rad/s), so M_sl moves by 2 % at most. The deep-groove G_rr and G_sl carry no centrifugal load; the same
table's
angular-contact and self-aligning rows add F_g = R3 d_m^4 n^2 (tests/physics/test_skf_high_speed.py).

The model's domain has a lower edge in load: the same catalogue asks a deep-groove ball bearing for
a minimum radial load (section 'Loads', 'Minimum load'),

    F_rm = k_r (nu n / 1000)^(2/3) (d_m / 100)^2                        [kN]

with nu the operating viscosity [mm^2/s], n [r/min], d_m [mm] and the minimum load factor k_r of
the product tables: 0.025 for the 60 and 62 series (6200: 0.03), 0.03 for the 63 series (the 2018
catalogue's product tables as transcribed in github.com/JRaposo-m/SKF-Bearing-Selection-Tool,
skf_model/bearings/data/deep_groove_ball/deep_groove_ball.csv, column kr: 6000-6012 and
6201-6212 0.025, 6200 0.03, 6300-6312 0.03; also github.com/gumyr/bd_warehouse, column SKT:kr).
Below F_rm the
catalogue states that the balls' inertia and the lubricant's friction govern the rolling and the
balls may skid; the frictional-moment formula, fitted to loaded bearings, is outside its domain
there (minimum_radial_load_n).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

# (R1, R2, S1, S2) per deep-groove series (SKF catalogue table above)
SERIES_CONSTANTS = {
    "60": (4.1e-7, 1.7, 3.73e-3, 14.6),
    "62": (3.9e-7, 1.7, 3.23e-3, 36.5),
    "63": (3.7e-7, 1.7, 2.84e-3, 92.8),
}
# minimum load factor k_r per deep-groove series, and the designations that differ from their series
# (SKF product tables, see the module docstring)
MINIMUM_LOAD_FACTOR = {"60": 0.025, "62": 0.025, "63": 0.03}
MINIMUM_LOAD_FACTOR_EXCEPTIONS = {"6200": 0.03}
K_Z_DEEP_GROOVE = 3.1
K_RS_OIL_JET = 3e-8
MU_BL = 0.15
MU_EHL_MINERAL = 0.05


@dataclass(frozen=True)
class SKFMoment:
    """Frictional moment and its parts [N m]."""

    total_n_m: float
    rolling_n_m: float
    sliding_n_m: float
    phi_ish: float
    phi_rs: float
    phi_bl: float
    mu_sl: float


def series_of(designation: str) -> str:
    """'62' for '6208', '60' for '6010' (four-digit deep-groove designations)."""
    d = designation.strip()
    if len(d) != 4 or not d.isdigit() or d[0] != "6":
        raise ValueError(
            f"designation = {designation!r}: the SKF constants here cover four-digit 60/62/63 deep-groove designations"
        )
    series = d[:2]
    if series not in SERIES_CONSTANTS:
        raise ValueError(f"designation = {designation!r}: series {series} not in {sorted(SERIES_CONSTANTS)}")
    return series


def inlet_shear_heating_factor(n_rpm: float, dm_mm: float, nu_mm2_s: float) -> float:
    """phi_ish = 1 / (1 + 1.84e-9 (n dm)^1.28 nu^0.64) [-] (SKF catalogue)."""
    return 1.0 / (1.0 + 1.84e-9 * (n_rpm * dm_mm) ** 1.28 * nu_mm2_s**0.64)


def replenishment_factor(
    n_rpm: float,
    nu_mm2_s: float,
    bore_mm: float,
    od_mm: float,
    k_rs: float = K_RS_OIL_JET,
    k_z: float = K_Z_DEEP_GROOVE,
) -> float:
    """phi_rs = exp(-K_rs nu n (d + D) sqrt(K_z / (2 (D - d)))) [-] (SKF catalogue)."""
    return math.exp(-k_rs * nu_mm2_s * n_rpm * (bore_mm + od_mm) * math.sqrt(k_z / (2.0 * (od_mm - bore_mm))))


def sliding_friction_coefficient(
    n_rpm: float, nu_mm2_s: float, dm_mm: float, mu_bl: float = MU_BL, mu_ehl: float = MU_EHL_MINERAL
) -> tuple[float, float]:
    """(mu_sl, phi_bl): mu_sl = phi_bl mu_bl + (1 - phi_bl) mu_EHL, phi_bl = exp(-2.6e-8 (n nu)^1.4 dm)."""
    phi_bl = math.exp(-2.6e-8 * (n_rpm * nu_mm2_s) ** 1.4 * dm_mm)
    return phi_bl * mu_bl + (1.0 - phi_bl) * mu_ehl, phi_bl


def frictional_moment(
    designation: str,
    bore_mm: float,
    od_mm: float,
    radial_load_n: float,
    shaft_speed_rad_s: float,
    kinematic_viscosity_mm2_s: float,
    *,
    axial_load_n: float = 0.0,
    static_load_rating_n: float | None = None,
    inlet_shear: bool = True,
    k_rs: float = K_RS_OIL_JET,
) -> SKFMoment:
    """SKF frictional moment of an open, oil-lubricated deep-groove ball bearing without oil
    bath (M_seal = M_drag = 0) [N m]. `inlet_shear=False` sets phi_ish = 1 (the isothermal
    comparison). Axial load needs the static load rating C0 [N] for alpha_F."""
    r1, r2, s1, s2 = SERIES_CONSTANTS[series_of(designation)]
    if not (radial_load_n >= 0.0 and shaft_speed_rad_s >= 0.0 and kinematic_viscosity_mm2_s > 0.0):
        raise ValueError("radial_load_n and shaft_speed_rad_s must be >= 0, kinematic_viscosity_mm2_s > 0")
    dm = 0.5 * (bore_mm + od_mm)
    n = shaft_speed_rad_s * 30.0 / math.pi
    nu = kinematic_viscosity_mm2_s
    if axial_load_n > 0.0:
        if static_load_rating_n is None:
            raise ValueError("axial_load_n > 0 needs static_load_rating_n (C0) for alpha_F")
        sin_af = math.sin(math.radians(24.6 * (axial_load_n / static_load_rating_n) ** 0.24))
        g_rr = r1 * dm**1.96 * (radial_load_n + r2 / sin_af * axial_load_n) ** 0.54
        g_sl = s1 * dm**-0.145 * (radial_load_n**5 + s2 * dm**1.5 / sin_af * axial_load_n**4) ** (1.0 / 3.0)
    else:
        g_rr = r1 * dm**1.96 * radial_load_n**0.54
        g_sl = s1 * dm**-0.26 * radial_load_n ** (5.0 / 3.0)
    phi_ish = inlet_shear_heating_factor(n, dm, nu) if inlet_shear else 1.0
    phi_rs = replenishment_factor(n, nu, bore_mm, od_mm, k_rs)
    m_rr = phi_ish * phi_rs * g_rr * (nu * n) ** 0.6
    mu_sl, phi_bl = sliding_friction_coefficient(n, nu, dm)
    m_sl = g_sl * mu_sl
    return SKFMoment(
        total_n_m=(m_rr + m_sl) * 1e-3,
        rolling_n_m=m_rr * 1e-3,
        sliding_n_m=m_sl * 1e-3,
        phi_ish=phi_ish,
        phi_rs=phi_rs,
        phi_bl=phi_bl,
        mu_sl=mu_sl,
    )


def minimum_radial_load_n(
    designation: str, bore_mm: float, od_mm: float, shaft_speed_rad_s: float, kinematic_viscosity_mm2_s: float
) -> float:
    """SKF's requisite minimum radial load of a deep-groove ball bearing [N]:
    F_rm = k_r (nu n / 1000)^(2/3) (d_m / 100)^2 kN (SKF Rolling bearings catalogue, deep groove ball
    bearings, 'Minimum load'; k_r from MINIMUM_LOAD_FACTOR and its exceptions). A radial load below it is outside the
    domain of the frictional-moment model (frictional_moment)."""
    k_r = MINIMUM_LOAD_FACTOR_EXCEPTIONS.get(designation.strip(), MINIMUM_LOAD_FACTOR[series_of(designation)])
    if not (shaft_speed_rad_s >= 0.0 and kinematic_viscosity_mm2_s > 0.0 and od_mm > bore_mm > 0.0):
        raise ValueError(
            "shaft_speed_rad_s must be >= 0, kinematic_viscosity_mm2_s > 0 and od_mm > bore_mm > 0 "
            f"(got {shaft_speed_rad_s}, {kinematic_viscosity_mm2_s}, {bore_mm}, {od_mm})"
        )
    n_rpm = shaft_speed_rad_s * 30.0 / math.pi
    dm_mm = 0.5 * (bore_mm + od_mm)
    return 1e3 * k_r * (kinematic_viscosity_mm2_s * n_rpm / 1000.0) ** (2.0 / 3.0) * (dm_mm / 100.0) ** 2
