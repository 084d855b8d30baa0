"""Elastohydrodynamic film thickness and the film parameter.

Dimensionless groups of seed 000 eq. 6: U = eta u / (E' Rx), G = xi E', W = Q / (E' Rx^2), with u
the entrainment speed (mean of the two surface speeds relative to the contact, docs/physics.md).
"""

import math

from numba import njit

from twin.jit import JIT


@njit(**JIT)
def speed_parameter(viscosity_pa_s, entrainment_speed_m_s, effective_modulus_pa, rx_m):
    """U = eta u / (E' Rx) [-] (seed 000 eq. 6)."""
    return viscosity_pa_s * entrainment_speed_m_s / (effective_modulus_pa * rx_m)


@njit(**JIT)
def load_parameter(load_n, effective_modulus_pa, rx_m):
    """W = Q / (E' Rx^2) [-] (seed 000 eq. 6)."""
    return load_n / (effective_modulus_pa * rx_m * rx_m)


# Exponents of the dimensionless speed U (proportional to eta u) and load W (to Q) of the
# Hamrock-Dowson films; twin.kernels.tribology compiles the in-loop power laws from them.
HD_HMIN_U_EXP = 0.68  # seed 000 eq. 6
HD_HMIN_W_EXP = -0.073
HD_HC_U_EXP = 0.67  # Hamrock-Dowson 1977 central film
HD_HC_W_EXP = -0.067


@njit(**JIT)
def masjedi_khonsari_exponents(k_ellipticity):
    """(exponent of U, exponent of W) of Masjedi-Khonsari's h_min (seed 004 eq. 6): 0.711 k^-0.023,
    -0.09 k^-0.15."""
    return 0.711 * k_ellipticity**-0.023, -0.09 * k_ellipticity**-0.15


@njit(**JIT)
def hamrock_dowson_h_min_m(rx_m, u_param, g_param, w_param, k_ellipticity):
    """h_min = 3.63 Rx U^0.68 G^0.49 W^-0.073 (1 - exp(-0.68 k)) [m] (seed 000 eq. 6)."""
    if u_param <= 0.0 or w_param <= 0.0:
        return 0.0
    return (
        3.63
        * rx_m
        * u_param**HD_HMIN_U_EXP
        * g_param**0.49
        * w_param**HD_HMIN_W_EXP
        * (1.0 - math.exp(-0.68 * k_ellipticity))
    )


@njit(**JIT)
def hamrock_dowson_h_c_m(rx_m, u_param, g_param, w_param, k_ellipticity):
    """Central film h_c = 2.69 Rx U^0.67 G^0.53 W^-0.067 (1 - 0.61 exp(-0.73 k)) [m]
    (Hamrock-Dowson 1977, the companion of seed 000 eq. 6, ref. [9])."""
    if u_param <= 0.0 or w_param <= 0.0:
        return 0.0
    return (
        2.69
        * rx_m
        * u_param**HD_HC_U_EXP
        * g_param**0.53
        * w_param**HD_HC_W_EXP
        * (1.0 - 0.61 * math.exp(-0.73 * k_ellipticity))
    )


@njit(**JIT)
def masjedi_khonsari_h_min_m(rx_m, u_param, g_param, w_param, k_ellipticity):
    """h_min = 1.637 Rx U^(0.711 k^-0.023) G^(0.65 k^-0.045) W^(-0.09 k^-0.15)
    (1 - 0.974 exp(-0.676 k)) [m] (seed 004 eq. 6, smooth surfaces, exponents as products per
    docs/physics.md)."""
    if u_param <= 0.0 or w_param <= 0.0:
        return 0.0
    u_exp, w_exp = masjedi_khonsari_exponents(k_ellipticity)
    return (
        1.637
        * rx_m
        * u_param**u_exp
        * g_param ** (0.65 * k_ellipticity**-0.045)
        * w_param**w_exp
        * (1.0 - 0.974 * math.exp(-0.676 * k_ellipticity))
    )


@njit(**JIT)
def film_parameter(h_min_m, composite_roughness_m):
    """Lambda = h_min / (1.25 sqrt(sigma_a1^2 + sigma_a2^2)) [-] (seed 000 eq. 7); the caller
    passes the denominator (3.75e-7 m for the seed's 0.3 um races)."""
    return h_min_m / composite_roughness_m
