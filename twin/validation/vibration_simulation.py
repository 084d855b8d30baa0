"""The twin producing a housing acceleration: `defect_for` (the defect of `bearing-twin vibration
--defect KIND`) and `simulate_vibration` (a twin with its outer ring on the housing, run, settled and
sampled, its waveform analysed by `twin.vibration.run.run_vibration`). The backend of
`bearing-twin vibration`, the CWRU validation, the benchmark's vibration cases and the report.
Drivers that build a `Twin` live here, above the engine."""

from __future__ import annotations

import math

import numpy as np

from twin import catalog
from twin.accelerometer import contact_angle_of_lanes_rad
from twin.engine import Twin
from twin.kernels import layout as L
from twin.setpoint import Setpoint
from twin.spec import BearingSpec
from twin.vibration.housing import MIN_WINDOW_SAMPLES
from twin.vibration.run import run_vibration

DEFAULT_DEFECT_SIZE_M = 0.5e-3  # width along the rolling direction [m]
DEFAULT_DEFECT_DEPTH_M = 50e-6  # [m]
DEFAULT_LENGTH_OF_BALL_RADIUS = 0.6  # length across the rolling direction, x the ball radius
SETTLE_S = 0.05  # simulated time run and discarded before the analysis [s]


def defect_for(
    kind: str,
    geometry,
    size_m: float = DEFAULT_DEFECT_SIZE_M,
    length_m: float | None = None,
    depth_m: float = DEFAULT_DEFECT_DEPTH_M,
    angle_deg: float = 0.0,
) -> dict:
    """The defect of `bearing-twin vibration --defect KIND --defect-size SIZE`: a pit `size_m`
    wide along the rolling direction, `length_m` across it (default 0.6 x the ball radius, 3.8 mm
    on the 6208: a pit shorter across than the contact ellipse takes only the load of its strip,
    `twin.vibration.defects`), `depth_m` deep, sharp edges; outer spall at azimuth
    `angle_deg` from the load direction (0 = the centre of the load zone; the CWRU positions 6:00,
    3:00 and 12:00 are 0, 90 and 180 deg), inner spall at `angle_deg` from the ring's reference mark,
    ball defect on ball 0's equator (body +x; `angle_deg` its longitude). Plain data for
    `Twin.set_defects` (validated there)."""
    if kind not in ("outer", "inner", "ball"):
        raise ValueError(f"defect = {kind!r}: one of 'outer', 'inner', 'ball'")
    if not (math.isfinite(angle_deg) and -360.0 < angle_deg < 360.0):
        raise ValueError(f"defect_angle_deg = {angle_deg!r}: must be in (-360, 360) deg")
    length = DEFAULT_LENGTH_OF_BALL_RADIUS * geometry.ball_radius_m if length_m is None else length_m
    out = {"kind": kind, "width_m": size_m, "length_m": length, "depth_m": depth_m}
    angle = angle_deg % 360.0
    out[{"outer": "azimuth_deg", "inner": "ring_angle_deg", "ball": "longitude_deg"}[kind]] = angle
    return out


def simulate_vibration(
    bearing="6208",
    shaft_speed_rad_s: float = 500.0,
    radial_load_n: float | None = 3000.0,
    axial_load_n: float = 0.0,
    *,
    defect: str | None = None,
    defect_size_m: float = DEFAULT_DEFECT_SIZE_M,
    defect_length_m: float | None = None,
    defect_depth_m: float = DEFAULT_DEFECT_DEPTH_M,
    defect_angle_deg: float = 0.0,
    duration_s: float = 1.0,
    settle_s: float = SETTLE_S,
    noise_density_m_s2_rthz: float | None = None,
    sample_rate_hz: float | None = None,
    window_s: float | None = None,
    band: str | tuple[float, float] = "resonance",
    diametral_clearance_m: float | None = None,
    noise_seed: int | None = None,
) -> tuple[dict, np.ndarray]:
    """Run the twin with its housing on (and a defect, `defect_for`) and analyse the accelerometer:
    `settle_s` of simulated time is discarded, then `duration_s` is sampled (in-kernel decimator)
    and passed to `run_vibration` with the loaded contact angle of the contacts at the end.
    `diametral_clearance_m`: the mounted clearance [m] in place of the spec's
    (`Mounting.diametral_clearance_m`; negative = preload), for a study of its unknown value.
    `noise_seed`: the sensor noise's seed in place of the spec's (reproducible runs).

    bearing: designation or `BearingSpec` (its housing is switched on; noise density, sample rate
    and window override the spec's accelerometer when given); radial_load_n None: the rig's load of
    the designation (`twin.catalog.default_radial_load_n`, e.g. `CWRU-DE`). Returns (the `run_vibration` dict
    plus bearing, loads, speed, defect, time_step_s, status; the samples [m/s^2], float64).
    Raises pydantic.ValidationError / SetpointError / ValueError naming the field and its range, and
    RuntimeError (with the twin's status) when the twin cannot hold the setpoint (it halted)."""

    if not (math.isfinite(duration_s) and duration_s > 0.0):
        raise ValueError(f"duration_s = {duration_s!r}: must be positive")
    if not (math.isfinite(settle_s) and settle_s >= 0.0):
        raise ValueError(f"settle_s = {settle_s!r}: must be >= 0")
    spec = bearing if isinstance(bearing, BearingSpec) else catalog.bearing(str(bearing))
    if radial_load_n is None:
        radial_load_n = catalog.default_radial_load_n(spec.designation)
        if radial_load_n is None:
            raise ValueError(f"radial_load_n: bearing {spec.designation!r} has no rig load; give the radial load [N]")
    data = spec.model_dump()
    acc = data["housing"]["accelerometer"]
    data["housing"]["enabled"] = True
    for key, value in (
        ("noise_density_m_s2_rthz", noise_density_m_s2_rthz),
        ("sample_rate_hz", sample_rate_hz),
        ("window_s", window_s),
        ("noise_seed", noise_seed),
    ):
        if value is not None:
            acc[key] = value
    if diametral_clearance_m is not None:
        data["mounting"]["diametral_clearance_m"] = diametral_clearance_m
    spec = BearingSpec.model_validate(data)
    rate = spec.housing.accelerometer.sample_rate_hz
    if duration_s * rate < MIN_WINDOW_SAMPLES:
        raise ValueError(
            f"duration_s = {duration_s:g} s: {duration_s * rate:.0f} samples at {rate:g} Hz; the analysis needs "
            f"at least {MIN_WINDOW_SAMPLES}, a duration of at least {MIN_WINDOW_SAMPLES / rate:.4g} s"
        )
    twin = Twin(
        spec,
        setpoint=Setpoint(shaft_speed_rad_s=shaft_speed_rad_s, radial_load_n=radial_load_n, axial_load_n=axial_load_n),
    )
    if defect is not None:
        twin.set_defects(
            [defect_for(defect, spec.geometry, defect_size_m, defect_length_m, defect_depth_m, defect_angle_deg)]
        )
    for k, span in enumerate((settle_s, duration_s)):
        if k == 1:
            twin.drain_waveform()  # the settling part is discarded
        left = twin.advance(span)
        if left or twin.halted:
            raise RuntimeError(
                f"bearing {spec.designation!r} at {shaft_speed_rad_s:g} rad/s, {radial_load_n:g} N: "
                f"the twin stopped at t = {twin.time_s:.6f} s after {twin.restarts} restarts "
                f"({twin.status})"
            )
    blocks = twin.drain_waveform()
    x = np.concatenate([b.samples for b in blocks]).astype(float) if blocks else np.zeros(0)
    angle = contact_angle_of_lanes_rad(twin.model, twin.state)
    decimator = twin.model.decimator
    assert decimator is not None  # the housing is on
    result = run_vibration(
        x,
        decimator.output_rate_hz,
        spec,
        float(twin.state.scalars[L.X_SHAFT_SPEED]),
        contact_angle_rad=angle,
        housing=spec.housing,
        window_s=spec.housing.accelerometer.window_s,
        band=band,
    )
    result.update(
        {
            "bearing": spec.designation,
            "shaft_speed_rad_s": float(twin.state.scalars[L.X_SHAFT_SPEED]),
            "radial_load_n": radial_load_n,
            "axial_load_n": axial_load_n,
            "diametral_clearance_m": spec.mounting.diametral_clearance_m,
            "defect": twin.defects[0].model_dump() if twin.defects else None,
            "time_step_s": twin.model.dt_s,
            "decimation_ratio": decimator.ratio,
            "noise_density_m_s2_rthz": spec.housing.accelerometer.noise_density_m_s2_rthz,
            "status": twin.status,
        }
    )
    return result, x
