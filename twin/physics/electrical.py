"""Electrical RC-equivalent of a lubricated ball-raceway contact (seed 000 end of section 2.2:
asperity contacts are resistive, the film is capacitive, the apparent contact is a parallel RC
whose dissipative properties follow the regime; seed 004 conclusion; seed 003 eq. 2 density).

Scalar laws, SI in and out, never NaN for non-negative inputs.
"""

import math

from numba import njit

from twin.jit import JIT

VACUUM_PERMITTIVITY_F_M = 8.8541878128e-12


@njit(**JIT)
def dowson_higginson_density_ratio(pressure_pa):
    """rho / rho_0 = 1 + 0.6e-9 p / (1 + 1.7e-9 p) (seed 003 eq. 2, isothermal part)."""
    p = max(pressure_pa, 0.0)
    return 1.0 + 0.6e-9 * p / (1.0 + 1.7e-9 * p)


@njit(**JIT)
def clausius_mossotti_permittivity(relative_permittivity_0, density_ratio):
    """Relative permittivity of the compressed oil: (eps - 1)/(eps + 2) proportional to density
    (Clausius-Mossotti), so (eps - 1)/(eps + 2) = rho/rho_0 (eps_0r - 1)/(eps_0r + 2)."""
    k = density_ratio * (relative_permittivity_0 - 1.0) / (relative_permittivity_0 + 2.0)
    return (1.0 + 2.0 * k) / (1.0 - k)


@njit(**JIT)
def hertz_zone_capacitance_f(relative_permittivity, semi_major_m, semi_minor_m, central_film_m):
    """Plate capacitor over the Hertz ellipse on the central film: eps0 eps_r pi a b / h_c [F]."""
    if central_film_m <= 0.0:
        return 0.0
    return VACUUM_PERMITTIVITY_F_M * relative_permittivity * math.pi * semi_major_m * semi_minor_m / central_film_m


@njit(**JIT)
def outer_zone_capacitance_f(relative_permittivity_0, rx_m, ry_m, gap_m, gap_limit_m):
    """Oil-filled gap around the contact: the gap grows from `gap_m` like x^2/(2 Rx) + y^2/(2 Ry);
    with s that increment, dA = 2 pi sqrt(Rx Ry) ds, so
    C = eps0 eps_r0 2 pi sqrt(Rx Ry) ln((gap + gap_limit) / gap) [F], integrated out to where the
    gap has grown by gap_limit (the oil meniscus). Finite for any gap > 0; the log keeps the
    result insensitive to the exact limit."""
    if gap_m <= 0.0:
        return 0.0
    return (VACUUM_PERMITTIVITY_F_M * relative_permittivity_0 * 2.0 * math.pi * math.sqrt(rx_m * ry_m)
            * math.log((gap_m + gap_limit_m) / gap_m))


@njit(**JIT)
def asperity_resistance_ohm(full_contact_resistance_ohm, asperity_share):
    """Metallic conduction through the asperities: the fully metallic contact's resistance divided
    by the share of the load they carry (seed 001 eq. A2); infinite without asperity contact."""
    if asperity_share <= 0.0:
        return math.inf
    return full_contact_resistance_ohm / asperity_share


@njit(**JIT)
def oil_film_resistance_ohm(resistivity_ohm_m, central_film_m, semi_major_m, semi_minor_m):
    """Leakage through the oil film over the Hertz ellipse: rho_e h_c / (pi a b) [ohm]."""
    area = math.pi * semi_major_m * semi_minor_m
    if area <= 0.0:
        return math.inf
    return resistivity_ohm_m * max(central_film_m, 0.0) / area


@njit(**JIT)
def parallel_resistance_ohm(r1, r2):
    """R1 || R2 with infinities allowed."""
    if math.isinf(r1):
        return r2
    if math.isinf(r2):
        return r1
    return r1 * r2 / (r1 + r2)
