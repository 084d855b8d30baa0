"""Hertz elliptic point contact: curvature, ellipticity, stiffness, contact ellipse.

Seed 000 eq. 2 with the README's reading (the printed 2 pi k G lost the 1/(1 - nu) factor):
Q = K delta^1.5, K = pi k E' sqrt(2 Ebar R / (9 Fbar^3)); k = (Ry/Rx)^(2/pi),
Fbar = 1 + (pi/2 - 1) ln(Ry/Rx), Ebar = 1 + (pi/2 - 1) Rx/Ry, R = Rx Ry / (Rx + Ry).
Ball-ball (cage element) contacts, eq. 3: Q = 4 G sqrt(Req) / (3 (1 - nu)) delta^1.5.
"""

import math

from numba import njit

from twin.jit import JIT

_Q = math.pi / 2.0 - 1.0


@njit(**JIT)
def effective_modulus_pa(youngs_modulus_pa, poisson_ratio):
    """E' = E / (1 - nu^2) for two bodies of the same material [Pa] (seed 000 eq. 6)."""
    return youngs_modulus_pa / (1.0 - poisson_ratio * poisson_ratio)


@njit(**JIT)
def shear_modulus_pa(youngs_modulus_pa, poisson_ratio):
    """G = E / (2 (1 + nu)) [Pa] (seed 000, below eq. 2)."""
    return youngs_modulus_pa / (2.0 * (1.0 + poisson_ratio))


@njit(**JIT)
def convex_radius_m(r1_m, r2_m):
    """Effective radius of two convex surfaces, R1 R2 / (R1 + R2) [m] (seed 000 eq. 2, Rx inner)."""
    return r1_m * r2_m / (r1_m + r2_m)


@njit(**JIT)
def concave_radius_m(r_ball_m, r_hollow_m):
    """Effective radius of a ball in a hollow, Rb Rh / (Rh - Rb) [m] (seed 000 eq. 2, Rx outer, Ry)."""
    return r_ball_m * r_hollow_m / (r_hollow_m - r_ball_m)


@njit(**JIT)
def curvature_sum_radius_m(rx_m, ry_m):
    """R = Rx Ry / (Rx + Ry) [m] (seed 000 eq. 2, R_curve)."""
    return rx_m * ry_m / (rx_m + ry_m)


@njit(**JIT)
def ellipticity(rx_m, ry_m):
    """k = (Ry/Rx)^(2/pi) [-] (seed 000 eq. 2)."""
    return (ry_m / rx_m) ** (2.0 / math.pi)


@njit(**JIT)
def elliptic_integral_first_kind(rx_m, ry_m):
    """Fbar = 1 + (pi/2 - 1) ln(Ry/Rx) [-] (seed 000 eq. 2 as README reads it)."""
    return 1.0 + _Q * math.log(ry_m / rx_m)


@njit(**JIT)
def elliptic_integral_second_kind(rx_m, ry_m):
    """Ebar = 1 + (pi/2 - 1) Rx/Ry [-] (seed 000 eq. 2)."""
    return 1.0 + _Q * rx_m / ry_m


@njit(**JIT)
def raceway_stiffness_n_m15(rx_m, ry_m, effective_modulus):
    """K [N/m^1.5] in Q = K delta^1.5 for a ball-raceway contact (seed 000 eq. 2, README)."""
    k = ellipticity(rx_m, ry_m)
    fbar = elliptic_integral_first_kind(rx_m, ry_m)
    ebar = elliptic_integral_second_kind(rx_m, ry_m)
    r = curvature_sum_radius_m(rx_m, ry_m)
    return math.pi * k * effective_modulus * math.sqrt(2.0 * ebar * r / (9.0 * fbar ** 3))


@njit(**JIT)
def ball_ball_stiffness_n_m15(r1_m, r2_m, shear_modulus, poisson_ratio):
    """K [N/m^1.5] for two spheres (ball-cage element), 4 G sqrt(Req) / (3 (1 - nu)) (seed 000 eq. 3)."""
    req = convex_radius_m(r1_m, r2_m)
    return 4.0 * shear_modulus * math.sqrt(req) / (3.0 * (1.0 - poisson_ratio))


@njit(**JIT)
def semi_major_axis_m(load_n, rx_m, ry_m, effective_modulus):
    """a = (6 k^2 Ebar Q R / (pi E'))^(1/3) [m], transverse semi-axis of the Hertz ellipse
    (Hamrock-Brewe, the ref. [9] that seed 000 eq. 5 uses)."""
    if load_n <= 0.0:
        return 0.0
    k = ellipticity(rx_m, ry_m)
    ebar = elliptic_integral_second_kind(rx_m, ry_m)
    r = curvature_sum_radius_m(rx_m, ry_m)
    return (6.0 * k * k * ebar * load_n * r / (math.pi * effective_modulus)) ** (1.0 / 3.0)


@njit(**JIT)
def semi_minor_axis_m(load_n, rx_m, ry_m, effective_modulus):
    """b = (6 Ebar Q R / (pi k E'))^(1/3) [m], rolling-direction semi-axis (Hamrock-Brewe)."""
    if load_n <= 0.0:
        return 0.0
    k = ellipticity(rx_m, ry_m)
    ebar = elliptic_integral_second_kind(rx_m, ry_m)
    r = curvature_sum_radius_m(rx_m, ry_m)
    return (6.0 * ebar * load_n * r / (math.pi * k * effective_modulus)) ** (1.0 / 3.0)


@njit(**JIT)
def max_pressure_pa(load_n, semi_major_m, semi_minor_m):
    """p_max = 3 Q / (2 pi a b) [Pa] (Hertz)."""
    if semi_major_m <= 0.0 or semi_minor_m <= 0.0:
        return 0.0
    return 1.5 * load_n / (math.pi * semi_major_m * semi_minor_m)
