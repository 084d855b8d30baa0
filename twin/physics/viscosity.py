"""Lubricant viscosity against temperature: ASTM D341 (Walther) through nu_40 and nu_100.

log10 log10(nu + 0.7) = A - B log10(T), nu in mm^2/s, T in K; density by a linear expansion of
6.5e-4 /K from 15 degC (ASTM D1250 order of magnitude for mineral oils). Plain Python: evaluated
once per setpoint, never in the hot loop. At 40 degC the law returns nu_40 exactly (to rounding),
so the seed-000 oil gives eta = 0.04 Pa s.
"""

import math

_EXPANSION_PER_K = 6.5e-4


def walther_constants(nu40_m2_s: float, nu100_m2_s: float) -> tuple[float, float]:
    """(A, B) of ASTM D341 through the two reference points."""
    t1, t2 = math.log10(313.15), math.log10(373.15)
    y1 = math.log10(math.log10(nu40_m2_s * 1e6 + 0.7))
    y2 = math.log10(math.log10(nu100_m2_s * 1e6 + 0.7))
    b = (y1 - y2) / (t2 - t1)
    return y1 + b * t1, b


def kinematic_viscosity_m2_s(nu40_m2_s: float, nu100_m2_s: float, temperature_c: float) -> float:
    """nu(T) [m^2/s] by ASTM D341."""
    if temperature_c == 40.0:
        return nu40_m2_s
    a, b = walther_constants(nu40_m2_s, nu100_m2_s)
    y = a - b * math.log10(temperature_c + 273.15)
    return (10.0 ** (10.0**y) - 0.7) * 1e-6


def density_kg_m3(density_15c_kg_m3: float, temperature_c: float) -> float:
    """rho(T) = rho_15 (1 - 6.5e-4 (T - 15)) [kg/m^3]."""
    return density_15c_kg_m3 * (1.0 - _EXPANSION_PER_K * (temperature_c - 15.0))


def dynamic_viscosity_pa_s(lubricant, temperature_c: float) -> float:
    """eta(T) = nu(T) rho(T) [Pa s] for a `twin.spec.Lubricant`."""
    nu = kinematic_viscosity_m2_s(
        lubricant.kinematic_viscosity_40c_m2_s, lubricant.kinematic_viscosity_100c_m2_s, temperature_c
    )
    return nu * density_kg_m3(lubricant.density_15c_kg_m3, temperature_c)


def temperature_viscosity_coefficient_k_inv(lubricant, temperature_c: float) -> float:
    """beta = -d ln(eta) / d theta at temperature_c [1/K], from the ASTM D341 law (central
    difference over +-1 K)."""
    lo = dynamic_viscosity_pa_s(lubricant, temperature_c - 1.0)
    hi = dynamic_viscosity_pa_s(lubricant, temperature_c + 1.0)
    return (math.log(lo) - math.log(hi)) / 2.0
