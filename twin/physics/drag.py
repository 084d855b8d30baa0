"""Drag (churning) of the balls in the oil of the bearing cavity: two laws.

Oil bath: the SKF model's drag term for ball bearings (SKF, Rolling bearings catalogue PUB BU/P1
17000/1 EN, 2018, 'Drag losses in oil bath lubrication'), fitted on bearings turning in an oil
bath, where the balls move through oil the cage and the rings already carry along
(`oil_bath_drag_moment_n_m`):

    M_drag = 0.4 V_M K_ball d_m^5 n^2 + 1.093e-7 n^2 d_m^3 (n d_m^2 f_t / nu)^-1.379 R_s     [N mm]
    K_ball = i_rw K_z (d + D) / (D - d) 1e-12,   f_A = 0.05 K_z (D + d) / (D - d)
    t = 2 acos((0.6 d_m - H) / (0.6 d_m)),  f_t = sin(t/2) for t <= pi, 1 beyond,
    R_s = 0.36 d_m^2 (t - sin t) f_A

n [r/min], d, D, d_m, H [mm] (H the oil level above the bottom of the outer raceway, taken at
most 1.2 d_m), nu [mm^2/s], V_M the drag loss factor of the catalogue's diagram against H/d_m
(ball bearings; `BALL_DRAG_LOSS_FACTOR`), K_z = 3.1 deep-groove, 4.4 angular-contact.

Oil-air mixture (jet, oil-air): each ball orbits at the pitch radius through a medium of
effective density rho_e and is braked by the fluid drag of a sphere (Harris and Kotzalas, Advanced Concepts of Bearing
Technology,
5th ed., 2007, ch. 3 'High-speed operation of ball bearings', ball drag force):

    F_D = (1/2) C_D rho_e (pi D^2 / 4) v^2,   v = d_m omega_c / 2                        [N]

(H&K write it pi rho_e C_D D^2 (d_m omega_m)^2 / 32), with the drag coefficient of a sphere at
the ball Reynolds number Re = rho v D / eta from Clift and Gauvin's correlation (Clift, Grace and
Weber, Bubbles, Drops and Particles, 1978, Table 5.2; within 6 % of the standard drag curve up to
Re = 3e5):

    C_D = 24/Re (1 + 0.15 Re^0.687) + 0.42 / (1 + 4.25e4 Re^-1.16)

The power a ball loses is F_D v; the shaft supplies it. In an oil bath a ball churns oil only
while it dips into the bath: the immersed part of its frontal disc (a circular segment,
`immersed_area_fraction`) shares out the bath's drag among the balls.
"""

from __future__ import annotations

import math

AIR_DENSITY_KG_M3 = 1.2  # at 20 degC, 1 atm
# (H / d_m, V_M) of ball bearings: the SKF catalogue's diagram 'Drag loss factor V_M' (2018,
# 'Drag losses in oil bath lubrication') read at rounded H / d_m from its digitisation in
# github.com/JRaposo-m/SKF-Bearing-Selection-Tool (Graficos/Friction Moments/Drag Moment/Drag Loss
# Factor Vm/ball_bearing*.csv); linear between the points
BALL_DRAG_LOSS_FACTOR = (
    (0.0, 0.0),
    (0.02, 6.1e-6),
    (0.05, 1.86e-5),
    (0.1, 7.3e-5),
    (0.15, 1.58e-4),
    (0.2, 2.46e-4),
    (0.3, 3.81e-4),
    (0.4, 4.78e-4),
    (0.5, 5.66e-4),
    (0.6, 6.39e-4),
    (0.8, 7.78e-4),
    (1.0, 9.48e-4),
    (1.2, 1.235e-3),
)
MAX_OIL_LEVEL_OVER_DM = 1.2  # the catalogue takes H = 1.2 d_m for any deeper bath
AIR_VISCOSITY_PA_S = 1.8e-5  # at 20 degC


def sphere_drag_coefficient(reynolds: float) -> float:
    """C_D of a sphere at Reynolds number Re (Clift and Gauvin; module docstring) [-]; the
    Stokes limit 24/Re is its first term. Re <= 0 gives 0 (no motion, no drag)."""
    if not (reynolds > 0.0):
        return 0.0
    return 24.0 / reynolds * (1.0 + 0.15 * reynolds**0.687) + 0.42 / (1.0 + 4.25e4 * reynolds**-1.16)


def ball_drag_force_n(
    ball_diameter_m: float, orbital_speed_m_s: float, density_kg_m3: float, viscosity_pa_s: float
) -> float:
    """F_D = C_D(Re) rho pi D^2 v^2 / 8 [N] of a ball moving at v [m/s] through a fluid of the
    given density and dynamic viscosity (Harris and Kotzalas; module docstring)."""
    v = abs(orbital_speed_m_s)
    if v == 0.0:
        return 0.0
    re = density_kg_m3 * v * ball_diameter_m / viscosity_pa_s
    return sphere_drag_coefficient(re) * density_kg_m3 * math.pi * ball_diameter_m**2 * v * v / 8.0


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


def drag_loss_factor(oil_level_over_dm: float) -> float:
    """V_M of ball bearings at H / d_m (SKF diagram, `BALL_DRAG_LOSS_FACTOR`) [-]; H / d_m is
    clipped to [0, 1.2]."""
    x = min(max(oil_level_over_dm, 0.0), MAX_OIL_LEVEL_OVER_DM)
    pts = BALL_DRAG_LOSS_FACTOR
    for (x0, y0), (x1, y1) in zip(pts, pts[1:]):
        if x <= x1:
            return y0 + (y1 - y0) * (x - x0) / (x1 - x0)
    return pts[-1][1]


def oil_bath_drag_moment_n_m(
    bore_m: float,
    outside_diameter_m: float,
    oil_level_m: float,
    shaft_speed_rad_s: float,
    kinematic_viscosity_m2_s: float,
    k_z: float,
    rows: int = 1,
) -> float:
    """M_drag of the SKF model for a ball bearing in an oil bath [N m] (module docstring), SI in:
    bore d, outside diameter D, oil level H above the bottom of the outer raceway [m], shaft
    speed [rad/s], the oil's kinematic viscosity [m^2/s], K_z [-], ball rows i_rw. 0 without
    oil (H <= 0) or speed."""
    d, big_d, h = bore_m * 1e3, outside_diameter_m * 1e3, oil_level_m * 1e3
    if not (big_d > d > 0.0):
        raise ValueError(f"outside_diameter_m = {outside_diameter_m!r} must exceed bore_m = {bore_m!r} > 0")
    if not (kinematic_viscosity_m2_s > 0.0):
        raise ValueError(f"kinematic_viscosity_m2_s = {kinematic_viscosity_m2_s!r} must be > 0")
    n = abs(shaft_speed_rad_s) * 30.0 / math.pi
    if n == 0.0 or not (h > 0.0):
        return 0.0
    nu = kinematic_viscosity_m2_s * 1e6
    dm = 0.5 * (d + big_d)
    h = min(h, MAX_OIL_LEVEL_OVER_DM * dm)
    t = 2.0 * math.acos(max(-1.0, (0.6 * dm - h) / (0.6 * dm)))
    f_t = math.sin(0.5 * t) if t <= math.pi else 1.0
    f_a = 0.05 * k_z * (big_d + d) / (big_d - d)
    r_s = 0.36 * dm * dm * (t - math.sin(t)) * f_a
    k_ball = rows * k_z * (d + big_d) / (big_d - d) * 1e-12
    churning = 0.4 * drag_loss_factor(h / dm) * k_ball * dm**5 * n * n
    viscous = 1.093e-7 * n * n * dm**3 * (n * dm * dm * f_t / nu) ** -1.379 * r_s
    return (churning + viscous) * 1e-3
