"""Drag (churning) of the balls in the oil of the bearing cavity.

Each ball orbits at the pitch radius through a medium of effective density rho_e and is braked
by the fluid drag of a sphere (Harris and Kotzalas, Advanced Concepts of Bearing Technology,
5th ed., 2007, ch. 3 'High-speed operation of ball bearings', ball drag force):

    F_D = (1/2) C_D rho_e (pi D^2 / 4) v^2,   v = d_m omega_c / 2                        [N]

(H&K write it pi rho_e C_D D^2 (d_m omega_m)^2 / 32), with the drag coefficient of a sphere at
the ball Reynolds number Re = rho v D / eta from Clift and Gauvin's correlation (Clift, Grace and
Weber, Bubbles, Drops and Particles, 1978, Table 5.2; within 6 % of the standard drag curve up to
Re = 3e5):

    C_D = 24/Re (1 + 0.15 Re^0.687) + 0.42 / (1 + 4.25e4 Re^-1.16)

The power a ball loses is F_D v; the shaft supplies it. In an oil bath a ball churns oil only
while it dips into the bath: the immersed part of its frontal disc (a circular segment) sees the
oil, the rest air (`immersed_area_fraction`).
"""

from __future__ import annotations

import math

AIR_DENSITY_KG_M3 = 1.2      # at 20 degC, 1 atm
AIR_VISCOSITY_PA_S = 1.8e-5  # at 20 degC


def sphere_drag_coefficient(reynolds: float) -> float:
    """C_D of a sphere at Reynolds number Re (Clift and Gauvin; module docstring) [-]; the
    Stokes limit 24/Re is its first term. Re <= 0 gives 0 (no motion, no drag)."""
    if not (reynolds > 0.0):
        return 0.0
    return 24.0 / reynolds * (1.0 + 0.15 * reynolds ** 0.687) + 0.42 / (1.0 + 4.25e4 * reynolds ** -1.16)


def ball_drag_force_n(ball_diameter_m: float, orbital_speed_m_s: float, density_kg_m3: float,
                      viscosity_pa_s: float) -> float:
    """F_D = C_D(Re) rho pi D^2 v^2 / 8 [N] of a ball moving at v [m/s] through a fluid of the
    given density and dynamic viscosity (Harris and Kotzalas; module docstring)."""
    v = abs(orbital_speed_m_s)
    if v == 0.0:
        return 0.0
    re = density_kg_m3 * v * ball_diameter_m / viscosity_pa_s
    return sphere_drag_coefficient(re) * density_kg_m3 * math.pi * ball_diameter_m ** 2 * v * v / 8.0


def immersed_area_fraction(depth_m: float, ball_diameter_m: float) -> float:
    """Share of a ball's frontal disc below the oil surface when its lowest point lies `depth_m`
    under it (circular segment of height h = clip(depth, 0, D)): [R^2 acos((R-h)/R) - (R-h)
    sqrt(2 R h - h^2)] / (pi R^2) [-]."""
    r = 0.5 * ball_diameter_m
    h = min(max(depth_m, 0.0), ball_diameter_m)
    if h <= 0.0:
        return 0.0
    if h >= ball_diameter_m:
        return 1.0
    c = r - h
    return (r * r * math.acos(c / r) - c * math.sqrt(max(2.0 * r * h - h * h, 0.0))) / (math.pi * r * r)


def ball_depth_in_bath_m(oil_level_m: float, azimuth_from_bottom_rad: float, pitch_radius_m: float) -> float:
    """Depth of a ball's lowest point under the oil surface [m]: the oil stands `oil_level_m` above
    the lowest point of the lowest ball's path (the bottom of the outer raceway), the ball's
    centre at `azimuth_from_bottom_rad` from the bottom on the pitch circle."""
    return oil_level_m - pitch_radius_m * (1.0 - math.cos(azimuth_from_bottom_rad))
