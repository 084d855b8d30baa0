"""Inputs of the point-contact EHL solver: seed 003 Appendix 2, the choices the seed leaves open,
and the derived Hertz scales.

Seed 003 Appendix 2 (as printed, text-extraction garbling resolved as noted):

- ball radius R1 = 2.39 mm, race radius of curvature R2 = 11.28 mm (outer race ring, so the
  contact is concave: R = R1 R2 / (R2 - R1) = 3.0326 mm); eq. 4 writes the gap with one R in
  both directions (x^2/2R + y^2/2R), so the default contact is circular, Rx = Ry = R;
- E = 200 GPa, nu = 0.28 for ball and race -> E' = E / (1 - nu^2) = 217.0 GPa;
- pressure-viscosity coefficient alpha = 2.08e-8 1/Pa; load on the ball w = 27.67 N;
- ball density 7.7e3 kg/m^3, specific heat 460 J/(kg K), pitch diameter D = 8.9 mm,
  slip-band/crater depth Hc printed "3x10-0" m (read as 3e-6 m: a micrometre-scale corrugation
  depth; 3 m is not a depth), contact angle alpha'' = 15 deg (used in radians in eq. 10, the only
  dimensionally consistent reading), K = 3 balls in the loaded zone;
- lubricant thermal expansion alpha' = 6.4e-4 1/degC, thermal conductivity k' = 0.145 W/(m K),
  density-temperature dependency Dt = 1.15 (read as kg/(m^3 K) on the absolute density, i.e.
  Dt / rho0 = 1.3e-3 1/K relative, with rho0 = 870 kg/m^3 the oil below);
- entrainment speeds 0.832-4.16 m/s "corresponding to shaft rotation speeds of 10,000 rpm to
  50,000 rpm" (Fig. 1): the shaft frequency in eq. 10 is taken proportional,
  f_s = (u / 0.832 m/s) * 10000 / 60 Hz.

Choices the seed leaves open (documented in the module and in every result's `inputs`):

- base oil: the project's `seed-000` lubricant (twin.spec.Lubricant defaults: eta = 0.04 Pa s at
  40 degC, seed 000 eq. 5 / ref. [37], with an ISO VG 46 mineral-oil viscosity-temperature slope,
  nu_100 = 6.8 mm^2/s, rho_15 = 870 kg/m^3). An ISO VG 32-68 mineral/PAO base oil is what
  electric-motor bearing greases and EV e-axle fluids typically carry, so this is a typical
  EV-bearing base oil and keeps the twin's lubricant in one place. Base temperature 40 degC (the
  ISO VG reference temperature). eta0 at another base temperature follows the ASTM D341 law of
  twin.physics.viscosity; the Roelands temperature-viscosity coefficient beta of eq. 3 is the
  local slope -d ln(eta)/dT of the same law at the base temperature (0.047 1/K at 40 degC),
  so Roelands' temperature term reproduces ASTM D341 within ~10 % up to +100 K.
- equivalent bearing resistance R_b of eq. 10: not given. It is the one parameter anchored to the
  seed's results: R_b = DEFAULT_BEARING_RESISTANCE_OHM = 2.92e-4 ohm makes the minimum film at
  30 A and the default speed 84.8 % thinner than the isothermal film (the top of the 57.6-84.8 %
  band of seed 003 Fig. 2; Fig. 5 says 30 A is the largest current), on the 257 x 257 grid.
  Everything else about the current response (its rise with current, the current at which
  57.6 % is reached, the speed and temperature dependence) follows from eqs. 3, 6 and 10 and is
  not fitted. A fraction of a milliohm is the resistance of a conducting (broken-down, metallic)
  contact, not of an intact insulating film; with the other eq. 10 inputs as printed, that is
  what it takes to heat the contact by tens of kelvin at 10-30 A.
- default entrainment speed 2.496 m/s (30,000 rpm): the middle of the range of Fig. 1.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq
from scipy.special import ellipe, ellipk

from twin.physics import ehl
from twin.physics.viscosity import dynamic_viscosity_pa_s
from twin.spec import Lubricant

# --- seed 003 Appendix 2 -------------------------------------------------------------------
BALL_RADIUS_M = 2.39e-3
RACE_RADIUS_M = 11.28e-3
YOUNGS_MODULUS_PA = 200e9
POISSON_RATIO = 0.28
E_PRIME_PA = YOUNGS_MODULUS_PA / (1.0 - POISSON_RATIO**2)
CONTACT_RADIUS_M = BALL_RADIUS_M * RACE_RADIUS_M / (RACE_RADIUS_M - BALL_RADIUS_M)
RX_M = CONTACT_RADIUS_M
RY_M = CONTACT_RADIUS_M
ALPHA_PA_INV = 2.08e-8
LOAD_N = 27.67
BALL_DENSITY_KG_M3 = 7.7e3
BALL_SPECIFIC_HEAT_J_KG_K = 4.6e2
PITCH_DIAMETER_M = 8.9e-3
BALL_DIAMETER_M = 2.0 * BALL_RADIUS_M
SLIP_BAND_DEPTH_M = 3e-6
CONTACT_ANGLE_RAD = math.radians(15.0)
THERMAL_EXPANSION_PER_K = 6.4e-4
OIL_CONDUCTIVITY_W_M_K = 0.145
DENSITY_TEMPERATURE_KG_M3_K = 1.15
BALLS_IN_LOADED_ZONE = 3
SEED_SPEEDS_M_S = (0.832, 1.664, 2.496, 3.328, 4.16)  # 10,000-50,000 rpm in 10,000 rpm steps
RPM_PER_M_S = 10000.0 / 0.832

# --- choices the seed leaves open ------------------------------------------------------------
BASE_TEMPERATURE_C = 40.0
OIL_DENSITY_KG_M3 = 870.0
DEFAULT_ENTRAINMENT_SPEED_M_S = 2.496  # 30,000 rpm, the middle of Fig. 1's range
# Anchored by `calibration.anchor_bearing_resistance` (see the module docstring): 84.8 %
# minimum-film reduction at 30 A and the default speed (2.496 m/s), grid 257, default inputs
# (secant iteration: 2.5e-4 -> 0.1856, 3.0e-4 -> 0.1468, 2.9197e-4 -> 0.1520; target 0.152).
# On the solver's domain X in [-3, 1.5], Y in [-2, 2] (the lateral spacing resolves the side lobes).
DEFAULT_BEARING_RESISTANCE_OHM = 2.92e-4


def oil_viscosity_pa_s(temperature_c: float) -> float:
    """Dynamic viscosity of the project's seed-000 oil at ambient pressure [Pa s] (ASTM D341)."""
    return dynamic_viscosity_pa_s(Lubricant(), temperature_c)


def oil_temperature_viscosity_coefficient(temperature_c: float) -> float:
    """beta = -d ln(eta) / dT of the seed-000 oil at temperature_c [1/K] (central difference)."""
    lo = oil_viscosity_pa_s(temperature_c - 0.5)
    hi = oil_viscosity_pa_s(temperature_c + 0.5)
    return -(math.log(hi) - math.log(lo))


def shaft_frequency_hz(entrainment_speed_m_s: float) -> float:
    """f_s of eq. 10 from the speed mapping of seed 003 Fig. 1 (0.832 m/s <-> 10,000 rpm)."""
    return entrainment_speed_m_s * RPM_PER_M_S / 60.0


def current_temperature_rise_k(
    current_a: float,
    entrainment_speed_m_s: float,
    bearing_resistance_ohm: float,
    *,
    balls_in_zone: float = BALLS_IN_LOADED_ZONE,
    pitch_diameter_m: float = PITCH_DIAMETER_M,
    ball_diameter_m: float = BALL_DIAMETER_M,
    slip_band_depth_m: float = SLIP_BAND_DEPTH_M,
    ball_density_kg_m3: float = BALL_DENSITY_KG_M3,
    specific_heat_j_kg_k: float = BALL_SPECIFIC_HEAT_J_KG_K,
    contact_angle_rad: float = CONTACT_ANGLE_RAD,
) -> float:
    """Instantaneous temperature rise of the outer-race contact per shaft rotation, seed 003
    eq. 10: T_obn = 1.45 I^2 R_b K (D + 2d) / (f_s H_c rho c alpha'' d^2 (D + d)) [K].

    Eq. 10 is eq. 9 (Prashad's energy balance I^2 R t = pi W L H T rho c, eqs. 7-8) multiplied by
    f_b / 2 f_s; it is added to the shear-heating rise of eq. 6 (the seed says "added to
    Equation (7)", a misprint: eq. 7 is an energy).
    """
    if current_a == 0.0 or bearing_resistance_ohm == 0.0:
        return 0.0
    f_s = shaft_frequency_hz(entrainment_speed_m_s)
    d, big_d = ball_diameter_m, pitch_diameter_m
    num = 1.45 * current_a**2 * bearing_resistance_ohm * balls_in_zone * (big_d + 2.0 * d)
    den = f_s * slip_band_depth_m * ball_density_kg_m3 * specific_heat_j_kg_k * contact_angle_rad * d * d * (big_d + d)
    return num / den


@dataclass(frozen=True)
class HertzScales:
    """Dry Hertz contact of the same load and curvatures: the solver's length/pressure scales."""

    ax_m: float  # semi-axis along x (rolling direction)
    ay_m: float  # semi-axis along y
    p_hertz_pa: float  # maximum Hertz pressure
    approach_m: float  # rigid-body approach of the dry contact


def hertz_scales(load_n: float, rx_m: float, ry_m: float, e_prime_pa: float) -> HertzScales:
    """Exact Hertz ellipse (complete elliptic integrals) of gap x^2/2Rx + y^2/2Ry.

    E* = E'/2 (Johnson's reduced modulus, E' of Hamrock-Dowson). Circle: a^3 = 3 w R / (2 E')."""
    e_star = 0.5 * e_prime_pa
    if abs(rx_m - ry_m) <= 1e-12 * max(rx_m, ry_m):
        a = (3.0 * load_n * rx_m / (4.0 * e_star)) ** (1.0 / 3.0)
        p0 = 3.0 * load_n / (2.0 * math.pi * a * a)
        return HertzScales(a, a, p0, a * a / rx_m)
    r_major_dir, r_minor_dir = max(rx_m, ry_m), min(rx_m, ry_m)
    ratio = r_major_dir / r_minor_dir  # gap curvature along the minor axis / along the major axis

    def g(m):
        k, e = ellipk(m), ellipe(m)
        return (e / (1.0 - m) - k) / (k - e) - ratio

    m = brentq(g, 1e-12, 1.0 - 1e-14, xtol=1e-15, rtol=1e-14, maxiter=500)
    k, e = ellipk(m), ellipe(m)
    b_gap_major = 1.0 / (2.0 * r_major_dir)
    a_major = (3.0 * load_n * (k - e) / (2.0 * math.pi * e_star * m * b_gap_major)) ** (1.0 / 3.0)
    b_minor = a_major * math.sqrt(1.0 - m)
    p0 = 3.0 * load_n / (2.0 * math.pi * a_major * b_minor)
    approach = 3.0 * load_n * k / (2.0 * math.pi * e_star * a_major)
    if rx_m <= ry_m:  # minor axis along x
        return HertzScales(b_minor, a_major, p0, approach)
    return HertzScales(a_major, b_minor, p0, approach)


def hamrock_dowson_film_m(
    load_n: float,
    entrainment_speed_m_s: float,
    *,
    rx_m: float,
    ry_m: float,
    e_prime_pa: float,
    eta0_pa_s: float,
    alpha_pa_inv: float,
) -> tuple[float, float]:
    """(h_min, h_c) of Hamrock-Dowson (seed 003 ref. [7], seed 000 eq. 6) via twin.physics.ehl."""
    k = (ry_m / rx_m) ** (2.0 / math.pi)
    u = ehl.speed_parameter(eta0_pa_s, entrainment_speed_m_s, e_prime_pa, rx_m)
    w = ehl.load_parameter(load_n, e_prime_pa, rx_m)
    g = alpha_pa_inv * e_prime_pa
    return (float(ehl.hamrock_dowson_h_min_m(rx_m, u, g, w, k)), float(ehl.hamrock_dowson_h_c_m(rx_m, u, g, w, k)))


def moes_parameters(
    load_n: float,
    entrainment_speed_m_s: float,
    *,
    rx_m: float,
    e_prime_pa: float,
    eta0_pa_s: float,
    alpha_pa_inv: float,
) -> tuple[float, float]:
    """Moes dimensionless load M = W (2U)^-3/4 and material L = G (2U)^1/4 (circular contact,
    U on the mean speed): the two numbers that set how hard the EHL problem is."""
    u = eta0_pa_s * entrainment_speed_m_s / (e_prime_pa * rx_m)
    w = load_n / (e_prime_pa * rx_m**2)
    g = alpha_pa_inv * e_prime_pa
    return w * (2.0 * u) ** -0.75, g * (2.0 * u) ** 0.25


def hertz_pressure(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Dimensionless Hertz pressure sqrt(1 - X^2 - Y^2) (X, Y in semi-axis units), 0 outside."""
    return np.sqrt(np.clip(1.0 - x * x - y * y, 0.0, None))
