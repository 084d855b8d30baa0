"""Normal damping of ball-raceway contacts (seed 000 eqs. 4-5, Table 2)."""

import math

from numba import njit

from twin.jit import JIT
from twin.physics.friction import BOUNDARY_LAMBDA_MAX, MIXED_LAMBDA_MAX


@njit(**JIT)
def hysteretic_damping_n_s_m(restitution_s_m, stiffness_n_m15, penetration_m):
    """C_hyst = 3 alpha_e Kn delta / 2 with Kn = K delta^0.5 (seed 000 eq. 4) [N s/m]."""
    if penetration_m <= 0.0:
        return 0.0
    return 1.5 * restitution_s_m * stiffness_n_m15 * penetration_m * math.sqrt(penetration_m)


@njit(**JIT)
def fluid_damping_n_s_m(viscosity_pa_s, semi_major_m, ball_radius_m, h_min_m):
    """C_fluid = 3 pi eta a / sqrt(2) (Rb / h_min)^1.5 (seed 000 eq. 5) [N s/m]."""
    if h_min_m <= 0.0:
        return 0.0
    ratio = ball_radius_m / h_min_m
    return 3.0 * math.pi * viscosity_pa_s * semi_major_m / math.sqrt(2.0) * ratio * math.sqrt(ratio)


@njit(**JIT)
def regime_damping_n_s_m(film_parameter, c_hyst, c_fluid):
    """C_n(Lambda) of seed 000 Table 2: C_hyst (Lambda <= 1), series (1, 3], C_fluid above."""
    if film_parameter <= BOUNDARY_LAMBDA_MAX or c_fluid <= 0.0:
        return c_hyst
    if film_parameter <= MIXED_LAMBDA_MAX:
        if c_hyst <= 0.0:
            return 0.0
        return c_hyst * c_fluid / (c_hyst + c_fluid)
    return c_fluid
