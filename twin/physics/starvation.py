"""Kinematic starvation of the ball-raceway contacts: the oil a ball pushes aside is not
replenished before the next ball arrives, so at high speed and viscosity the inlet runs short
of oil and the film (and with it the inlet's rolling resistance) falls below the fully flooded
one.

The law is the kinematic replenishment factor of the SKF model for the frictional moment (SKF,
Rolling bearings catalogue PUB BU/P1 10000/2 EN, 2016, 'Kinematic replenishment/starvation
reduction factor'; the same since the General Catalogue 6000 EN, 2003):

    phi_rs = exp(-K_rs nu n (d + D) sqrt(K_z / (2 (D - d))))                            [-]

n [r/min], nu [mm^2/s] the operating kinematic viscosity, d and D the bore and outside diameter
[mm], K_z = 3.1 for deep-groove and 4.4 for angular-contact ball bearings, K_rs = 3e-8 for oil
jet and low-level oil bath, 6e-8 for oil-air (and grease). The catalogue applies phi_rs to the
rolling moment; Chevalier, Lubrecht, Cann, Colin and Dalmaz (1998, 'Film thickness in starved
EHL point contacts', J. Tribol. 120, 126-133) show that the rolling resistance of a starved
contact follows its film, so the twin applies it to the film of every contact (the inlet's
rolling force of seed 001 scales as the film, (eta u)^(2/3..3/4) against h ~ (eta u)^0.68).
"""

from __future__ import annotations

import math

K_Z = {"deep_groove": 3.1, "angular_contact": 4.4}
K_RS = {"oil_bath": 3e-8, "jet": 3e-8, "oil_air": 6e-8}


def kinematic_replenishment_factor(
    shaft_speed_rad_s: float,
    kinematic_viscosity_m2_s: float,
    bore_m: float,
    outside_diameter_m: float,
    k_rs: float,
    k_z: float,
) -> float:
    """phi_rs [-] of the SKF model (module docstring) in SI inputs: shaft speed [rad/s],
    kinematic viscosity [m^2/s], bore and outside diameter [m]. 1 at rest."""
    n_rpm = abs(shaft_speed_rad_s) * 30.0 / math.pi
    nu_mm2_s = kinematic_viscosity_m2_s * 1e6
    d_mm, big_d_mm = bore_m * 1e3, outside_diameter_m * 1e3
    if not (big_d_mm > d_mm > 0.0):
        raise ValueError(f"outside_diameter_m = {outside_diameter_m!r} must exceed bore_m = {bore_m!r} > 0")
    return math.exp(-k_rs * nu_mm2_s * n_rpm * (d_mm + big_d_mm) * math.sqrt(k_z / (2.0 * (big_d_mm - d_mm))))
