"""Heat-transfer correlations of the network, one law per function, SI.

Each returns a heat-transfer coefficient [W/(m^2 K)] or a conductance [W/K]; the network
(twin.thermal.network) multiplies by the areas.
"""

from __future__ import annotations

import math

from twin.thermal.materials import (
    AIR_CONDUCTIVITY_W_M_K,
    AIR_KINEMATIC_VISCOSITY_M2_S,
    AIR_PRANDTL,
    GRAVITY_M_S2,
    STEFAN_BOLTZMANN_W_M2_K4,
)

ISO_15312_REFERENCE_FLUX_W_MM2 = 0.016  # q_r for A_r <= 50 000 mm^2 (ISO 15312:2018 clause 5)
ISO_15312_AREA_KNEE_MM2 = 50_000.0
ISO_15312_REFERENCE_RISE_K = 50.0  # outer ring 70 degC over ambient 20 degC (ISO 15312 clause 4)


def churchill_chu_cylinder_w_m2_k(diameter_m: float, surface_c: float, ambient_c: float) -> float:
    """Natural convection from a horizontal cylinder in air, Churchill and Chu 1975 (Int. J. Heat
    Mass Transfer 18, 1049-1053; Incropera and DeWitt eq. 9.34), valid for Ra_D <= 1e12:
    Nu_D = {0.60 + 0.387 Ra^(1/6) / [1 + (0.559/Pr)^(9/16)]^(8/27)}^2, air at the film
    temperature, beta = 1 / T_film."""
    dt = abs(surface_c - ambient_c)
    t_film_k = 0.5 * (surface_c + ambient_c) + 273.15
    nu, pr = AIR_KINEMATIC_VISCOSITY_M2_S, AIR_PRANDTL
    ra = GRAVITY_M_S2 * dt / t_film_k * diameter_m**3 / (nu * nu / pr)
    nusselt = (0.60 + 0.387 * ra ** (1.0 / 6.0) / (1.0 + (0.559 / pr) ** (9.0 / 16.0)) ** (8.0 / 27.0)) ** 2
    return nusselt * AIR_CONDUCTIVITY_W_M_K / diameter_m


def rotating_cylinder_w_m2_k(diameter_m: float, speed_rad_s: float) -> float:
    """Forced convection from a cylinder rotating in still air, Becker 1963 (Int. J. Heat Mass
    Transfer 6, 1053-1062; as used for shafts by Harris and Kotzalas, Advanced Concepts, ch. 7):
    Nu = 0.133 Re^(2/3) Pr^(1/3), Re = omega D^2 / (2 nu) (surface speed x diameter / nu),
    Re < 4.3e5."""
    re = abs(speed_rad_s) * diameter_m * diameter_m / (2.0 * AIR_KINEMATIC_VISCOSITY_M2_S)
    return 0.133 * re ** (2.0 / 3.0) * AIR_PRANDTL ** (1.0 / 3.0) * AIR_CONDUCTIVITY_W_M_K / diameter_m


def radiation_w_m2_k(emissivity: float, surface_c: float, ambient_c: float) -> float:
    """Linearised grey-body radiation to large surroundings, h_r = eps sigma (Ts^2 + Ta^2)(Ts + Ta)
    (Incropera and DeWitt eq. 1.9)."""
    ts, ta = surface_c + 273.15, ambient_c + 273.15
    return emissivity * STEFAN_BOLTZMANN_W_M2_K4 * (ts * ts + ta * ta) * (ts + ta)


def flat_plate_laminar_w_m2_k(
    speed_m_s: float, length_m: float, conductivity_w_m_k: float, kinematic_viscosity_m2_s: float, prandtl: float
) -> float:
    """Mean coefficient of a laminar flat plate, Pohlhausen: Nu_L = 0.664 Re_L^(1/2) Pr^(1/3)
    (Incropera and DeWitt eq. 7.30). Harris and Kotzalas (Advanced Concepts, ch. 7) treat the
    bearing's surfaces sweeping the oil the same way, with the surface speed relative to the oil."""
    re = abs(speed_m_s) * length_m / kinematic_viscosity_m2_s
    return 0.664 * math.sqrt(re) * prandtl ** (1.0 / 3.0) * conductivity_w_m_k / length_m


def hertz_constriction_w_k(semi_major_m: float, semi_minor_m: float, conductivity_w_m_k: float) -> float:
    """Conductance of a Hertz contact between two half-spaces of the same steel: each side's
    steady constriction resistance of a circular spot is 1/(4 k a) (Carslaw and Jaeger; Holm),
    in series 1/(2 k a), with the ellipse's equivalent radius a = sqrt(a b) (Yovanovich 1971,
    AIAA 71-447). Conservative: a moving source conducts more (higher Peclet)."""
    if semi_major_m <= 0.0 or semi_minor_m <= 0.0:
        return 0.0
    return 2.0 * conductivity_w_m_k * math.sqrt(semi_major_m * semi_minor_m)


def cylindrical_shell_w_k(
    inner_radius_m: float, outer_radius_m: float, length_m: float, conductivity_w_m_k: float
) -> float:
    """Radial conduction through a cylindrical shell, G = 2 pi k L / ln(r2 / r1) (Fourier)."""
    return 2.0 * math.pi * conductivity_w_m_k * length_m / math.log(outer_radius_m / inner_radius_m)


def iso_15312_reference_area_mm2(bore_mm: float, outside_diameter_mm: float, width_mm: float) -> float:
    """Reference heat-emitting surface of a radial bearing, A_r = pi B (D + d) [mm^2]
    (ISO 15312:2018 clause 3 / 5: the seating surfaces of the rings)."""
    return math.pi * width_mm * (outside_diameter_mm + bore_mm)


def iso_15312_reference_flux_w_mm2(area_mm2: float) -> float:
    """Reference heat-flow density q_r of a radial bearing [W/mm^2] (ISO 15312:2018 clause 5):
    0.016 up to A_r = 50 000 mm^2, 0.016 (A_r / 50 000)^-0.34 above."""
    if area_mm2 <= ISO_15312_AREA_KNEE_MM2:
        return ISO_15312_REFERENCE_FLUX_W_MM2
    return ISO_15312_REFERENCE_FLUX_W_MM2 * (area_mm2 / ISO_15312_AREA_KNEE_MM2) ** -0.34


def iso_15312_dissipation_w_k(bore_mm: float, outside_diameter_mm: float, width_mm: float) -> float:
    """The standard's dissipation conductance from the bearing to the surroundings [W/K]: the
    reference heat flow q_r A_r carried off at the reference rise of 50 K (outer ring 70 degC,
    ambient 20 degC; ISO 15312:2018 clauses 4-5)."""
    area = iso_15312_reference_area_mm2(bore_mm, outside_diameter_mm, width_mm)
    return iso_15312_reference_flux_w_mm2(area) * area / ISO_15312_REFERENCE_RISE_K
