"""Seed 000's lubrication studies as plain computations (used by tests and `bearing-twin report`).

Each study warm-starts a twin, lets it settle, then samples the ball passing azimuth 0 (the most
loaded position) or a whole cage revolution. No plotting here (twin/ stays free of I/O).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from twin import catalog
from twin.engine import Twin
from twin.kernels import layout as L
from twin.setpoint import Setpoint
from twin.spec import BearingSpec, Lubricant, Lubrication, ModelOptions, Thermal

SETTLE_S = 0.005


@dataclass(frozen=True)
class AzimuthZeroSample:
    """Contact state of the ball nearest azimuth 0 (inner r = 0, outer r = 1)."""

    shaft_speed_rad_s: float
    radial_load_n: float
    clearance_m: float
    azimuth_rad: float
    lambda_inner: float
    lambda_outer: float
    load_inner_n: float
    load_outer_n: float
    h_min_inner_m: float
    h_min_outer_m: float
    epsilon: float


def isothermal_spec(designation: str = "6208", diametral_clearance_m: float = 0.0) -> BearingSpec:
    """The catalog bearing with an isothermal inlet (Thermal.shear_heating off): seed 000 solves
    Hamrock-Dowson's isothermal film (section 2.3, eq. 6), so its Table 3 and Figs. 8-12 are
    reproduced under that assumption; the twin's default heats the inlet (Murch-Wilson)."""
    base = catalog.bearing(designation, diametral_clearance_m=diametral_clearance_m)
    return BearingSpec.model_validate(
        {**base.model_dump(), "thermal": {**base.thermal.model_dump(), "shear_heating": False}}
    )


def _new_twin(speed, load, clearance, options, designation="6208"):
    # seed 000's studies: its isothermal inlet (isothermal_spec)
    return Twin(
        isothermal_spec(designation, clearance),
        options=options,
        setpoint=Setpoint(shaft_speed_rad_s=speed, radial_load_n=load),
    )


def sample_at_azimuth_zero(
    shaft_speed_rad_s: float,
    radial_load_n: float = 3000.0,
    clearance_m: float = 0.0,
    options: ModelOptions | None = None,
    designation: str = "6208",
) -> AzimuthZeroSample:
    """Track the balls over one ball pitch after settling and keep the sample closest to
    azimuth 0 (seed 000 Table 3 and Figs. 9-12 report the contact at psi = 0)."""
    twin = _new_twin(shaft_speed_rad_s, radial_load_n, clearance_m, options, designation)
    twin.advance(SETTLE_S)
    cage = max(twin.model.cage_speed_rad_s(shaft_speed_rad_s), 1e-3)
    window = 2.0 * math.pi / twin.model.ball_count / cage
    dt_sample = min(5e-5, window / 40.0)
    best: tuple[float, np.ndarray, np.ndarray, float] | None = None
    for _ in range(int(math.ceil(window / dt_sample)) + 1):
        twin.advance(dt_sample, frame_steps=max(1, int(round(dt_sample / twin.model.dt_s))))
        az = twin.ball_azimuths_rad()
        j = int(np.argmin(np.abs(az)))
        if best is None or abs(az[j]) < abs(best[0]):
            c = twin.state.contacts
            best = (
                float(az[j]),
                c[:, 2 * j].copy(),
                c[:, 2 * j + 1].copy(),
                np.hypot(*twin.state.inner_ring_offset_m[:2]),
            )
    assert best is not None  # the loop samples at least once
    az0, ci, co, shift = best
    eps = 0.5 * (1.0 - clearance_m / (2.0 * shift)) if shift > 0 else float("nan")
    return AzimuthZeroSample(
        shaft_speed_rad_s=shaft_speed_rad_s,
        radial_load_n=radial_load_n,
        clearance_m=clearance_m,
        azimuth_rad=az0,
        lambda_inner=float(ci[L.C_LAMBDA]),
        lambda_outer=float(co[L.C_LAMBDA]),
        load_inner_n=float(ci[L.C_LOAD]),
        load_outer_n=float(co[L.C_LOAD]),
        h_min_inner_m=float(ci[L.C_H_MIN]),
        h_min_outer_m=float(co[L.C_H_MIN]),
        epsilon=eps,
    )


def lambda_over_revolution(
    shaft_speed_rad_s: float = 500.0,
    radial_load_n: float = 3000.0,
    clearance_m: float = 0.0,
    options: ModelOptions | None = None,
    samples: int = 400,
) -> dict[str, np.ndarray]:
    """Every ball's azimuth and inner/outer Lambda and load over one cage revolution (seed 000
    Figs. 8, 10a, 11). Lambda is NaN where the contact is open."""
    twin = _new_twin(shaft_speed_rad_s, radial_load_n, clearance_m, options)
    twin.advance(SETTLE_S)
    period = 2.0 * math.pi / max(twin.model.cage_speed_rad_s(shaft_speed_rad_s), 1e-3)
    dt_sample = period / samples
    z = twin.model.ball_count
    az = np.empty((samples, z))
    lam = np.empty((samples, z, 2))
    load = np.empty((samples, z, 2))
    for k in range(samples):
        twin.advance(dt_sample, frame_steps=max(1, int(round(dt_sample / twin.model.dt_s))))
        az[k] = twin.ball_azimuths_rad()
        c = twin.state.contacts
        for r in range(2):
            lam_r = c[L.C_LAMBDA, r::2].copy()
            lam_r[c[L.C_LOAD, r::2] <= 0.0] = np.nan
            lam[k, :, r] = lam_r
            load[k, :, r] = c[L.C_LOAD, r::2]
    return {
        "azimuth_rad": az.ravel(),
        "lambda_inner": lam[:, :, 0].ravel(),
        "lambda_outer": lam[:, :, 1].ravel(),
        "load_inner_n": load[:, :, 0].ravel(),
        "load_outer_n": load[:, :, 1].ravel(),
    }


def log_slope(x, y) -> float:
    """Least-squares slope of ln y against ln x."""
    return float(np.polyfit(np.log(np.asarray(x)), np.log(np.asarray(y)), 1)[0])


# ---- seed 003: the EV motor bearing under shaft current --------------------------------------
EV_BEARING = "6200"  # the catalog bearing whose speed limit covers seed 003's 50 000 rpm
EV_RADIAL_LOAD_N = 200.0
EV_SETTLE_S = 0.02


@dataclass(frozen=True)
class EVSample:
    """Electro-thermal state of the EV twin at one operating point (inner contact of the ball
    nearest azimuth 0), SI units."""

    shaft_speed_rpm: float
    shaft_current_a: float
    oil_temperature_c: float
    equivalent_resistance_ohm: float | None
    h_min_inner_m: float | None  # None without contact
    lambda_inner: float
    current_temperature_rise_k: float
    shear_temperature_rise_k: float
    film_thermal_factor: float
    bearing_capacitance_f: float | None  # None where the network is not capacitive
    current_density_a_m2: float
    discharge_risk: str


def ev_operating_point(
    shaft_current_a: float,
    shaft_speed_rpm: float,
    *,
    oil_temperature_c: float = 40.0,
    equivalent_resistance_ohm: float | None = None,
    shear_heating: bool = True,
    radial_load_n: float = EV_RADIAL_LOAD_N,
    settle_s: float = EV_SETTLE_S,
    options: ModelOptions | None = None,
):
    """Seed 003's EV case on the 6200 twin (seed-000 oil, shear and current heating on unless
    told otherwise): warm start at the operating point, settle, return (EVSample, snapshot)."""
    fields: dict[str, Any] = {"shear_heating": shear_heating}
    if equivalent_resistance_ohm is not None:
        fields["equivalent_resistance_ohm"] = equivalent_resistance_ohm
    base = catalog.bearing(EV_BEARING)
    spec = BearingSpec.model_validate({**base.model_dump(), "thermal": Thermal(**fields).model_dump()})
    twin = Twin(
        spec,
        options=options,
        setpoint=Setpoint(
            shaft_speed_rad_s=shaft_speed_rpm * math.pi / 30.0,
            radial_load_n=radial_load_n,
            shaft_current_a=shaft_current_a,
            oil_temperature_c=oil_temperature_c,
        ),
    )
    twin.advance(settle_s)
    snap = twin.snapshot()
    ball = min(snap.balls, key=lambda b: abs(b.azimuth_rad))
    e = snap.electrical
    sample = EVSample(
        shaft_speed_rpm=shaft_speed_rpm,
        shaft_current_a=shaft_current_a,
        oil_temperature_c=oil_temperature_c,
        equivalent_resistance_ohm=spec.thermal.equivalent_resistance_ohm,
        h_min_inner_m=ball.inner.h_min_m,
        lambda_inner=ball.inner.lambda_ if ball.inner.lambda_ is not None else 0.0,
        current_temperature_rise_k=e.current_temperature_rise_k,
        shear_temperature_rise_k=e.shear_temperature_rise_k,
        film_thermal_factor=e.film_thermal_factor,
        bearing_capacitance_f=e.capacitance_f,
        current_density_a_m2=e.current_density_a_m2,
        discharge_risk=e.discharge_risk,
    )
    return sample, snap


# ---- friction torque (the SKF comparison of `bearing-twin report`) ---------------------------
TORQUE_SETTLE_S = 0.015
TORQUE_BALL_PASSAGES = 3


def mean_friction_torque_n_m(
    shaft_speed_rad_s: float,
    radial_load_n: float,
    *,
    designation: str = "6208",
    axial_load_n: float = 0.0,
    shear_heating: bool = False,
    oil_temperature_c: float = 40.0,
    options: ModelOptions | None = None,
    settle_s: float = TORQUE_SETTLE_S,
    passages: int = TORQUE_BALL_PASSAGES,
    lubrication: Lubrication | None = None,
    lubricant: Lubricant | None = None,
    limiting_speed_rad_s: float | None = None,
) -> tuple[float, Twin]:
    """Shaft torque [N m] averaged over whole ball passages (`passages` ball pitches of the cage,
    at least 10 ms) after `settle_s` from the warm start, and the twin. `shear_heating` turns the
    Murch-Wilson inlet heating on (Thermal.shear_heating); `lubrication` (default: flooded) and
    `lubricant` (default: the seed oil) and `limiting_speed_rad_s` as in BearingSpec."""
    base = catalog.bearing(designation, lubricant=lubricant)
    spec = BearingSpec.model_validate(
        {
            **base.model_dump(),
            "thermal": Thermal(shear_heating=shear_heating).model_dump(),
            "lubrication": (lubrication or Lubrication()).model_dump(),
            "limiting_speed_rad_s": limiting_speed_rad_s,
        }
    )
    twin = Twin(
        spec,
        options=options,
        setpoint=Setpoint(
            shaft_speed_rad_s=shaft_speed_rad_s,
            radial_load_n=radial_load_n,
            axial_load_n=axial_load_n,
            oil_temperature_c=oil_temperature_c,
        ),
    )
    twin.advance(settle_s)
    pitch = 2.0 * math.pi / twin.model.ball_count / max(twin.model.cage_speed_rad_s(shaft_speed_rad_s), 1e-3)
    window = max(passages * pitch, 0.01)
    steps = int(round(window / twin.model.dt_s))
    twin.advance(steps * twin.model.dt_s, frame_steps=steps)  # one frame: its mean torque
    return float(twin.snapshot().friction_torque_n_m), twin
