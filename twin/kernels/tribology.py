"""Per-contact tribology in the loop, evaluated in log form.

Every in-loop law is a power law in the load Q and the product eta u (viscosity x entrainment
speed): h = A (eta u)^a Q^b. `tribology_coefficients` takes A from the law functions of
`twin.physics` themselves (evaluated at Q = 1 N, eta u = 1 N/m) at model build, so the hot loop
needs two logarithms and one exponential per output instead of ~20 general powers (measured:
~285 ns -> ~80 ns per contact refresh). `tests/kernels/test_tribology_fast.py` checks that this
path equals the law functions.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from twin.jit import JIT
from twin.kernels.layout import FRICTION_ASPERITY_SHARE
from twin.physics import ehl, rolling
from twin.physics.electrical import (
    asperity_resistance_ohm,
    clausius_mossotti_permittivity,
    dowson_higginson_density_ratio,
    hertz_zone_capacitance_f,
    oil_film_resistance_ohm,
    outer_zone_capacitance_f,
    parallel_resistance_ohm,
)
from twin.physics.friction import regime_code, stribeck_line_mu
from twin.physics.rolling import asperity_load_share, sliding_friction_coefficient_asperity_share

# indices of race_tribology[r, :]
T_LN_HMIN = 0  # ln A of h_min [m]
T_HMIN_EXP_EU = 1  # exponent of eta u
T_HMIN_EXP_Q = 2  # exponent of Q
T_LN_HC = 3  # Hamrock-Dowson central film
T_HC_EXP_EU = 4
T_HC_EXP_Q = 5
T_SEMI_MAJOR = 6  # a = coef Q^(1/3) [m]
T_SEMI_MINOR = 7
T_FLUID_DAMPING = 8  # C_fluid = coef eta a h^-1.5: 3 pi Rb^1.5 / sqrt(2)  (seed 000 eq. 5)
T_LN_IVR = 9  # Biboulet IVR force ~ (eta u)^(2/3) Q^(1/3) (seed 001 eq. 1)
T_LN_EHL = 10  # EHL force ~ (eta u)^(3/4) Q^(1/3) (seed 001 eq. 2)
T_LN_M = 11  # M ~ Q (eta u)^-0.75 (seed 001 eq. 4)
T_LN_HYST = 12  # hysteresis moment / Rb ~ Q^1.33 (seed 001 eq. 9) [N]
T_HYST_EXP_Q = 13
T_PIVOT = 14  # pivoting moment / (mu Q a) (seed 001 eq. 11)
T_RX = 15  # Rx [m] (for the outer-zone capacitance)
T_RY = 16  # Ry [m]
N_TRIBOLOGY = 17

_ONE_EU = 1.0  # eta u = 1 N/m (eta = 1 Pa s, u = 1 m/s)


def tribology_coefficients(
    rx_m: float,
    ry_m: float,
    k_ellipticity: float,
    e_prime_pa: float,
    g_param: float,
    ball_radius_m: float,
    semi_major_coef: float,
    semi_minor_coef: float,
    film_formula: str,
) -> np.ndarray:
    """Prefactors and exponents of one race's in-loop laws, from the law functions."""
    t = np.zeros(N_TRIBOLOGY)
    u1 = ehl.speed_parameter(1.0, 1.0, e_prime_pa, rx_m)
    w1 = ehl.load_parameter(1.0, e_prime_pa, rx_m)
    k = k_ellipticity
    if film_formula == "hamrock_dowson":
        t[T_LN_HMIN] = math.log(ehl.hamrock_dowson_h_min_m(rx_m, u1, g_param, w1, k))
        t[T_HMIN_EXP_EU], t[T_HMIN_EXP_Q] = ehl.HD_HMIN_U_EXP, ehl.HD_HMIN_W_EXP
    else:
        t[T_LN_HMIN] = math.log(ehl.masjedi_khonsari_h_min_m(rx_m, u1, g_param, w1, k))
        t[T_HMIN_EXP_EU], t[T_HMIN_EXP_Q] = ehl.masjedi_khonsari_exponents(k)
    t[T_LN_HC] = math.log(ehl.hamrock_dowson_h_c_m(rx_m, u1, g_param, w1, k))
    t[T_HC_EXP_EU], t[T_HC_EXP_Q] = ehl.HD_HC_U_EXP, ehl.HD_HC_W_EXP
    t[T_SEMI_MAJOR] = semi_major_coef
    t[T_SEMI_MINOR] = semi_minor_coef
    t[T_FLUID_DAMPING] = 3.0 * math.pi / math.sqrt(2.0) * ball_radius_m**1.5
    ratio = ry_m / rx_m
    t[T_LN_IVR] = math.log(rolling.rolling_force_ivr_n(e_prime_pa, rx_m, ratio, 1.0, 1.0, 1.0))
    t[T_LN_EHL] = math.log(rolling.rolling_force_ehl_n(e_prime_pa, rx_m, ratio, 1.0, 1.0, 1.0))
    t[T_LN_M] = math.log(rolling.ehl_parameter_m(e_prime_pa, rx_m, ratio, 1.0, 1.0, 1.0))
    t[T_LN_HYST] = math.log(rolling.hysteresis_moment_n_m(2.0 * ball_radius_m, 1.0, ratio) / ball_radius_m)
    t[T_HYST_EXP_Q] = rolling.HYSTERESIS_LOAD_EXP
    t[T_PIVOT] = rolling.pivoting_moment_n_m(1.0, 1.0, 1.0, ratio)
    t[T_RX], t[T_RY] = rx_m, ry_m
    return t


@njit(**JIT)
def contact_tribology(
    load_n,
    entrainment_m_s,
    viscosity_pa_s,
    roughness_m,
    t0,
    t1,
    t2,
    t3,
    t4,
    t5,
    t6,
    t7,
    t8,
    t9,
    t10,
    t11,
    t12,
    t13,
    t14,
    friction_model,
    rolling_on,
):
    """Film, Lambda, regime, mu, fluid damping and rolling resistance of one contact (seed 000
    eqs. 5-7 and Table 2 with the film formula compiled into t0-t2, seed 001 eqs. 1-5, 9, 11,
    A1-A2); t0..t14 = race_tribology[r, :].

    Returns (h_min [m], h_c [m], Lambda, regime code, mu, a [m], b [m], C_fluid [N s/m],
    rolling force [N], pivoting moment [N m], ln(h_min / 1 m)); the last lets the caller take
    ln Lambda = ln h_min - ln sigma without another logarithm. Without entrainment
    (u <= 0) the film is zero: boundary lubrication, hysteretic damping only (ln h_min = -inf)."""
    ln_q = math.log(load_n)
    cube = math.exp(ln_q / 3.0)
    a = t6 * cube
    b = t7 * cube
    eu = viscosity_pa_s * entrainment_m_s
    if not (eu > 0.0):
        return 0.0, 0.0, 0.0, regime_code(0.0), _mu(0.0, friction_model), a, b, 0.0, 0.0, 0.0, -math.inf
    ln_eu = math.log(eu)
    ln_h = t0 + t1 * ln_eu + t2 * ln_q
    h_min = math.exp(ln_h)
    h_c = math.exp(t3 + t4 * ln_eu + t5 * ln_q)
    lam = h_min / roughness_m
    mu = _mu(lam, friction_model)
    c_fluid = t8 * viscosity_pa_s * a / (h_min * math.sqrt(h_min))  # h^-1.5 without an exp
    fr = 0.0
    mp = 0.0
    if rolling_on:
        f_ivr = math.exp(t9 + (2.0 / 3.0) * ln_eu + ln_q / 3.0)
        f_ehl = math.exp(t10 + 0.75 * ln_eu + ln_q / 3.0)
        m = math.exp(t11 + ln_q - 0.75 * ln_eu) / 6.6
        share = m / (1.0 + m)
        fr = (1.0 - share) * f_ivr + share * f_ehl + math.exp(t12 + t13 * ln_q)
        mp = t14 * mu * load_n * a
    return h_min, h_c, lam, regime_code(lam), mu, a, b, c_fluid, fr, mp, ln_h


@njit(**JIT)
def _mu(film_parameter, friction_model):
    # the Stribeck line; with the friction over the ellipse mu is not used (the refresh takes the
    # contact's traction capacity, twin.kernels.traction.limiting_traction_coefficient, and seed
    # 001's pivoting moment is off): the line, without powers
    if friction_model != FRICTION_ASPERITY_SHARE:
        return stribeck_line_mu(film_parameter)
    return sliding_friction_coefficient_asperity_share(asperity_load_share(film_parameter), 0.03, 0.11)


@njit(**JIT)
def contact_electrical(
    load_n,
    film_parameter,
    h_c_m,
    semi_major_m,
    semi_minor_m,
    rx_m,
    ry_m,
    oil_permittivity,
    gap_limit_m,
    metallic_resistance_ohm,
    oil_resistivity_ohm_m,
):
    """Parallel RC of one loaded contact (seed 000 end of section 2.2): capacitance of the
    Hertz zone on the central film, with the permittivity raised by the mean Hertz pressure
    (Dowson-Higginson density, seed 003 eq. 2, through Clausius-Mossotti), plus the oil-filled gap
    around it; resistance of the asperity contacts (metallic resistance / asperity load share,
    seed 001 eq. A2) in parallel with the oil's leakage. Returns (R [ohm], C [F])."""
    mean_pressure = load_n / (math.pi * semi_major_m * semi_minor_m)
    eps = clausius_mossotti_permittivity(oil_permittivity, dowson_higginson_density_ratio(mean_pressure))
    capacitance = hertz_zone_capacitance_f(eps, semi_major_m, semi_minor_m, h_c_m) + outer_zone_capacitance_f(
        oil_permittivity, rx_m, ry_m, h_c_m, gap_limit_m
    )
    share = asperity_load_share(film_parameter)
    resistance = parallel_resistance_ohm(
        asperity_resistance_ohm(metallic_resistance_ohm, share),
        oil_film_resistance_ohm(oil_resistivity_ohm_m, h_c_m, semi_major_m, semi_minor_m),
    )
    return resistance, capacitance
