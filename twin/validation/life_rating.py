"""Rating life at one steady operating point (`bearing-twin life`): drivers that build a model or
a `twin.engine.Twin` and evaluate `twin.life` on it."""

from __future__ import annotations

import math

import numpy as np

from twin import catalog
from twin.engine import Twin
from twin.life.contact_loads import (
    RacewayGeometry,
    contact_load_damage_per_mrev,
    contact_loads_from_state,
    equilibrium_contact_life_mrev,
)
from twin.life.iso281 import iso_life, life_hours, ratings_for
from twin.life.monitor import _finite, life_block
from twin.life.settings import LifeSettings
from twin.model import make_model
from twin.physics.viscosity import kinematic_viscosity_m2_s
from twin.setpoint import Setpoint, SetpointLimits
from twin.spec import BearingSpec


def dem_contact_life_mrev(
    designation: str | BearingSpec,
    radial_load_n: float,
    axial_load_n: float,
    shaft_speed_rad_s: float,
    oil_temperature_c: float = 40.0,
    diametral_clearance_m: float = 0.0,
    settle_s: float = 0.02,
    average_s: float = 0.05,
) -> float:
    """Contact-load life [10^6 rev] from a short DEM run: a warm-started `twin.engine.Twin` at the
    operating point, `settle_s` to settle, then the damage per revolution averaged over the 1 ms
    frames of `average_s` (about 15 ball passages on a 6208 at 500 rad/s). Used where the
    quasi-static equilibrium does not converge (e.g. a deep-groove bearing under a large axial load)."""

    twin = Twin(
        designation,
        diametral_clearance_m=diametral_clearance_m,
        setpoint=Setpoint(
            shaft_speed_rad_s=shaft_speed_rad_s,
            radial_load_n=radial_load_n,
            axial_load_n=axial_load_n,
            oil_temperature_c=oil_temperature_c,
        ),
    )
    twin.advance(settle_s)
    geometry = RacewayGeometry.of(twin.model.spec.geometry)
    damage = []
    for _ in range(max(1, int(round(average_s / 1e-3)))):
        twin.advance(1e-3)
        damage.append(contact_load_damage_per_mrev(geometry, *contact_loads_from_state(twin.state.contacts)))
    if twin.restarts:
        raise ValueError(f"the DEM run restarted {twin.restarts} time(s): {twin.status}")
    mean = float(np.mean(damage))
    return math.inf if mean <= 0.0 else 1.0 / mean


def rate_operating_point(
    designation: str | BearingSpec,
    radial_load_n: float,
    axial_load_n: float,
    shaft_speed_rad_s: float,
    oil_temperature_c: float = 40.0,
    diametral_clearance_m: float = 0.0,
    settings: LifeSettings | None = None,
    lubricant=None,
) -> dict:
    """`bearing-twin life`: the life block of a catalogue bearing (or of a spec, with the clearance
    and lubricant given here in place of its own) at one steady operating point,
    the contact-load life from the quasi-static equilibrium (`equilibrium_contact_life_mrev`,
    centrifugal force included). Inputs are validated against the
    bearing's limits (SetpointError / ValidationError / ValueError naming the field)."""

    settings = settings or LifeSettings()
    if isinstance(designation, BearingSpec):
        data = designation.model_dump()
        data["mounting"]["diametral_clearance_m"] = diametral_clearance_m
        if lubricant is not None:
            data["lubricant"] = lubricant
        spec = BearingSpec.model_validate(data)
    else:
        spec = catalog.bearing(
            designation,
            diametral_clearance_m=diametral_clearance_m,
            **({"lubricant": lubricant} if lubricant is not None else {}),
        )
    model = make_model(spec)
    setpoint = Setpoint(
        shaft_speed_rad_s=shaft_speed_rad_s,
        radial_load_n=radial_load_n,
        axial_load_n=axial_load_n,
        oil_temperature_c=oil_temperature_c,
    )
    SetpointLimits.for_model(model).check(setpoint)  # the one range check, quoting the bearing's range
    lub = spec.lubricant
    nu = kinematic_viscosity_m2_s(
        lub.kinematic_viscosity_40c_m2_s, lub.kinematic_viscosity_100c_m2_s, oil_temperature_c
    )
    ratings = ratings_for(spec)
    iso = iso_life(spec, ratings, settings, radial_load_n, axial_load_n, shaft_speed_rad_s, nu)
    method = (
        "quasi-static equilibrium (twin.warmstart, centrifugal force included), damage averaged over the "
        "two cage positions symmetric about the load line"
    )
    if radial_load_n <= 0.0 and axial_load_n == 0.0:
        contact_mrev = math.inf
    else:
        try:
            contact_mrev = equilibrium_contact_life_mrev(model, radial_load_n, axial_load_n, shaft_speed_rad_s)
        except ValueError:
            contact_mrev = dem_contact_life_mrev(
                spec, radial_load_n, axial_load_n, shaft_speed_rad_s, oil_temperature_c, diametral_clearance_m
            )
            method = (
                "DEM run (the quasi-static equilibrium did not converge): 20 ms to settle, damage averaged "
                "over 50 frames of 1 ms"
            )
    block = life_block(iso, life_hours(contact_mrev, shaft_speed_rad_s), settings, settings.initial_damage_fraction)
    block.update(
        {
            "bearing": spec.designation,
            "kind": spec.kind,
            "nominal_contact_angle_deg": spec.geometry.nominal_contact_angle_deg,
            "static_load_rating_n": ratings.static_load_rating_n,
            "fatigue_load_limit_n": ratings.fatigue_load_limit_n,
            "ratings_source": ratings.source,
            "x_factor": iso.x,
            "y_factor": iso.y,
            "e_factor": iso.e,
            "l10_mrev": _finite(iso.l10_mrev),
            "l10_contact_loads_mrev": _finite(contact_mrev),
            "radial_load_n": radial_load_n,
            "axial_load_n": axial_load_n,
            "shaft_speed_rad_s": shaft_speed_rad_s,
            "oil_temperature_c": oil_temperature_c,
            "diametral_clearance_m": diametral_clearance_m,
            "contamination": settings.contamination if settings.contamination_factor is None else "given",
            "contact_loads_from": method,
        }
    )
    return block
