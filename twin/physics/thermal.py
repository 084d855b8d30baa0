"""Electro-thermal laws of seed 003 (EV motor bearing under current discharge).

Plain Python scalars (evaluated between frames, not in the hot loop), SI units, temperatures in K
unless the name says degC.
"""

from __future__ import annotations

import math

ROELANDS_T_K = 138.0      # the 138 K of Roelands' temperature term (seed 003 eq. 3)
ROELANDS_LN_ETA_INF = 9.67  # ln(eta_inf) = -9.67 with eta in Pa s (seed 003 eq. 3)
MIN_CONTACT_ANGLE_RAD = math.radians(15.0)
MAX_CURRENT_HEATING_K = 250.0  # beyond this the oil has broken down; the twin caps the rise


def roelands_temperature_viscosity_pa_s(eta0_pa_s: float, theta0_k: float, theta_k: float,
                                        beta_k_inv: float) -> float:
    """Seed 003 eq. 3 at ambient pressure: eta = eta0 exp{(9.67 + ln eta0) [-1 +
    ((theta - 138) / (theta0 - 138))^(-S0)]}, S0 = beta (theta0 - 138) / (ln eta0 + 9.67), where
    beta = -d ln(eta) / d theta at theta0 is the temperature-viscosity coefficient."""
    lnk = math.log(eta0_pa_s) + ROELANDS_LN_ETA_INF
    s0 = beta_k_inv * (theta0_k - ROELANDS_T_K) / lnk
    ratio = (theta_k - ROELANDS_T_K) / (theta0_k - ROELANDS_T_K)
    return eta0_pa_s * math.exp(lnk * (-1.0 + ratio ** (-s0)))


def current_heating_temperature_rise_k(current_a: float, bearing_resistance_ohm: float,
                                       pitch_diameter_m: float, ball_diameter_m: float,
                                       loaded_balls: int, shaft_frequency_hz: float,
                                       crater_depth_m: float, ball_density_kg_m3: float,
                                       ball_specific_heat_j_kg_k: float, contact_angle_rad: float) -> float:
    """Instantaneous temperature rise of the race track from current discharge per shaft turn,
    seed 003 eq. 10 (eq. 9 times f_b / (2 f_s)):
    T = 1.45 I^2 R_b K (D + 2d) / (f_s H_c rho_b c_b alpha'' d^2 (D + d)) [K],
    D pitch diameter, d ball diameter, K balls in the loaded zone, alpha'' the contact angle
    [rad]. The law is written for seed 003's angular-contact EV bearing (alpha'' = 15 deg) and
    diverges for a deep-groove bearing's alpha'' = 0, so the angle is floored at 15 deg; the
    shaft frequency is floored at 1 Hz."""
    if current_a <= 0.0 or bearing_resistance_ohm <= 0.0:
        return 0.0
    f_s = max(shaft_frequency_hz, 1.0)
    alpha = max(contact_angle_rad, MIN_CONTACT_ANGLE_RAD)
    d, big_d = ball_diameter_m, pitch_diameter_m
    return (1.45 * current_a ** 2 * bearing_resistance_ohm * max(loaded_balls, 1) * (big_d + 2 * d)
            / (f_s * crater_depth_m * ball_density_kg_m3 * ball_specific_heat_j_kg_k * alpha * d * d
               * (big_d + d)))


def shear_heating_temperature_rise_k(entrainment_speed_m_s: float, inlet_temperature_k: float,
                                     thermal_expansion_k_inv: float, film_m: float,
                                     pressure_pa: float, half_width_m: float, viscosity_pa_s: float,
                                     conductivity_w_m_k: float) -> float:
    """Temperature rise of the film in the Hertz zone from compression and shear, seed 003 eq. 6:
    dT = [u theta_i alpha' h p + 2 b eta u^2 / h] / [b k' / h - u alpha' h p] [K].
    Returns inf where the conduction term no longer exceeds the compression term (the formula has
    no steady solution there)."""
    u, h = entrainment_speed_m_s, film_m
    if u <= 0.0 or h <= 0.0:
        return 0.0
    num = u * inlet_temperature_k * thermal_expansion_k_inv * h * pressure_pa + 2.0 * half_width_m * viscosity_pa_s * u * u / h
    den = half_width_m * conductivity_w_m_k / h - u * thermal_expansion_k_inv * h * pressure_pa
    return num / den if den > 0.0 else math.inf
