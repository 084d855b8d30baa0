"""`run_vibration`: the backend of `bearing-twin vibration` on a sampled housing acceleration.

`run_vibration` takes the waveform [m/s^2] at its sample rate and the bearing, returns the
JSON-ready indicator dict (twin.vibration.indicators; defect frequencies from
twin.vibration.defect_frequencies). `simulate_vibration` produces that waveform with the twin (outer
ring on the housing, a defect from `defect_for`) and analyses it: the backend of
`bearing-twin vibration`.
"""

from __future__ import annotations

import math

import numpy as np

from twin.vibration import indicators as ind
from twin.vibration.defect_frequencies import bearing_defect_frequencies
from twin.vibration.housing import Housing, sensor_resonance


def _geometry(bearing):
    from twin.spec import BearingSpec, Geometry

    if isinstance(bearing, Geometry):
        return bearing
    if isinstance(bearing, BearingSpec):
        return bearing.geometry
    from twin import catalog

    return catalog.bearing(str(bearing)).geometry


def run_vibration(signal_m_s2, sample_rate_hz: float, bearing, shaft_speed_rad_s: float, *,
                  contact_angle_rad: float | None = None, housing: Housing | None = None,
                  window_s: float = 1.0, band: str | tuple[float, float] = "resonance",
                  peak_count: int = 5, spectra: bool = False) -> dict:
    """Indicators of a housing-acceleration waveform (JSON-ready; every number finite).

    signal_m_s2: samples [m/s^2] at sample_rate_hz [Hz]; bearing: a designation ('6208'), a
    `BearingSpec` or a `Geometry`; shaft_speed_rad_s [rad/s]; contact_angle_rad: the loaded contact
    angle (None: nominal); housing: for the resonance band (default `Housing()`); window_s: the
    indicator window [s] (the signal is cut into whole windows; a shorter signal is one window);
    band: 'resonance' (around the housing's sensed resonance), 'kurtogram' (spectral-kurtosis
    search) or (low, high) [Hz].

    Returns sample_rate_hz, duration_s, window_s, windows, defect_frequencies_hz {ftf, bpfo, bpfi,
    bsf, two_bsf}, contact_angle_deg, envelope_band_hz [low, high], band_method,
    envelope_peaks_hz (the `peak_count` largest: frequency_hz, amplitude [m/s^2]) of the
    window-averaged envelope spectrum, kurtosis, band_kurtosis (in the envelope band), rms_m_s2, peak_m_s2, crest_factor,
    velocity_rms_mm_s (window means; RMS as the root of the mean square), noise_floor_m_s2,
    defect_lines (twin.vibration.indicators.defect_line_amplitudes) and per_window. With
    spectra=True also (not JSON-ready: numpy arrays) envelope_spectrum and amplitude_spectrum,
    each {start_hz, step_hz, amplitude_m_s2}: the envelope spectrum the peaks come from, 0 Hz to
    the peak search's limit (`indicators.envelope_spectrum_view`), and the acceleration amplitude
    spectrum 0 - fs / 2 (`indicators.amplitude_spectrum`; over several windows the root of the
    mean power of each bin)."""
    x = np.asarray(signal_m_s2, dtype=float).ravel()
    fs = float(sample_rate_hz)
    if not (fs > 0.0 and math.isfinite(fs)):
        raise ValueError(f"sample_rate_hz = {sample_rate_hz!r}: must be positive and finite")
    if not np.all(np.isfinite(x)):
        raise ValueError("signal_m_s2 holds non-finite samples")
    if not window_s > 0.0:
        raise ValueError(f"window_s = {window_s!r}: must be positive")
    geometry = _geometry(bearing)
    freq = bearing_defect_frequencies(geometry, shaft_speed_rad_s, contact_angle_rad)
    n_win = int(round(window_s * fs))
    count = max(1, x.size // n_win)
    n_win = min(n_win, x.size)
    if n_win < 1024:
        raise ValueError(f"{n_win} samples per window: need at least 1024 (1/50 s at 51.2 kHz)")
    top = max(freq.bpfi_hz, freq.two_bsf_hz)
    min_bw = 2.0 * 4.0 * top  # room for 3 harmonics and their sidebands in the envelope
    if isinstance(band, str) and band == "resonance":
        f_r, zeta = sensor_resonance(housing or Housing())
        lo, hi = ind.resonance_band(f_r, zeta, fs, min_bw)
    elif isinstance(band, str) and band == "kurtogram":
        lo, hi, _ = ind.kurtogram_band(x[:n_win * count], fs, min_bandwidth_hz=min_bw)
    elif isinstance(band, str):
        raise ValueError(f"band = {band!r}: 'resonance', 'kurtogram' or (low, high) in Hz")
    else:
        lo, hi = (float(band[0]), float(band[1]))
    windows = []
    amp_sum = None
    power_sum = None
    for k in range(count):
        seg = x[k * n_win:(k + 1) * n_win]
        row = ind.time_indicators(seg)
        row["velocity_rms_mm_s"] = ind.velocity_rms_mm_s(seg, fs)
        row["band_kurtosis"] = ind.band_kurtosis(seg, fs, (lo, hi))
        windows.append(row)
        freqs, amp = ind.envelope_spectrum(seg, fs, (lo, hi))
        amp_sum = amp if amp_sum is None else amp_sum + amp
        if spectra:
            a_start, a_step, a_amp = ind.amplitude_spectrum(seg, fs)
            power_sum = a_amp ** 2 if power_sum is None else power_sum + a_amp ** 2
    amp = amp_sum / count
    max_hz = min(0.5 * (hi - lo), 5.0 * top)
    mean = lambda key: float(np.mean([w[key] for w in windows]))  # noqa: E731
    out = {
        "sample_rate_hz": fs,
        "duration_s": x.size / fs,
        "window_s": n_win / fs,
        "windows": count,
        "defect_frequencies_hz": freq.as_dict(),
        "contact_angle_deg": math.degrees(freq.contact_angle_rad),
        "envelope_band_hz": [lo, hi],
        "band_method": band if isinstance(band, str) else "given",
        "envelope_peaks_hz": ind.envelope_peaks(freqs, amp, peak_count, max_hz=max_hz),
        "kurtosis": mean("kurtosis"),
        "band_kurtosis": mean("band_kurtosis"),
        "rms_m_s2": math.sqrt(float(np.mean([w["rms_m_s2"] ** 2 for w in windows]))),
        "peak_m_s2": max(w["peak_m_s2"] for w in windows),
        "crest_factor": mean("crest_factor"),
        "velocity_rms_mm_s": math.sqrt(float(np.mean([w["velocity_rms_mm_s"] ** 2 for w in windows]))),
        "noise_floor_m_s2": ind.noise_floor(freqs, amp, max_hz),
        "defect_lines": ind.defect_line_amplitudes(freqs, amp, freq),
        "per_window": windows,
    }
    if spectra:
        e_start, e_step, e_amp = ind.envelope_spectrum_view(freqs, amp, max_hz)
        out["envelope_spectrum"] = {"start_hz": e_start, "step_hz": e_step, "amplitude_m_s2": e_amp}
        out["amplitude_spectrum"] = {"start_hz": a_start, "step_hz": a_step,
                                     "amplitude_m_s2": np.sqrt(power_sum / count)}
    return out


# ---- the DEM producing the waveform (`bearing-twin vibration`) -----------------------------------
DEFAULT_DEFECT_SIZE_M = 0.5e-3     # width along the rolling direction [m]
DEFAULT_DEFECT_DEPTH_M = 50e-6     # [m]
DEFAULT_LENGTH_OF_BALL_RADIUS = 0.6  # length across the rolling direction, x the ball radius
SETTLE_S = 0.05                    # simulated time run and discarded before the analysis [s]


def defect_for(kind: str, geometry, size_m: float = DEFAULT_DEFECT_SIZE_M, length_m: float | None = None,
               depth_m: float = DEFAULT_DEFECT_DEPTH_M, angle_deg: float = 0.0) -> dict:
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


def simulate_vibration(bearing="6208", shaft_speed_rad_s: float = 500.0, radial_load_n: float | None = 3000.0,
                       axial_load_n: float = 0.0, *, defect: str | None = None,
                       defect_size_m: float = DEFAULT_DEFECT_SIZE_M, defect_length_m: float | None = None,
                       defect_depth_m: float = DEFAULT_DEFECT_DEPTH_M, defect_angle_deg: float = 0.0,
                       duration_s: float = 1.0,
                       settle_s: float = SETTLE_S, noise_density_m_s2_rthz: float | None = None,
                       sample_rate_hz: float | None = None, window_s: float | None = None,
                       band: str | tuple[float, float] = "resonance") -> tuple[dict, np.ndarray]:
    """Run the twin with its housing on (and a defect, `defect_for`) and analyse the accelerometer:
    `settle_s` of simulated time is discarded, then `duration_s` is sampled (in-kernel decimator)
    and passed to `run_vibration` with the loaded contact angle of the contacts at the end.

    bearing: designation or `BearingSpec` (its housing is switched on; noise density, sample rate
    and window override the spec's accelerometer when given); radial_load_n None: the rig's load of
    the designation (`twin.catalog.default_radial_load_n`, e.g. `CWRU-DE`). Returns (the `run_vibration` dict
    plus bearing, loads, speed, defect, time_step_s, status; the samples [m/s^2], float64).
    Raises pydantic.ValidationError / SetpointError / ValueError naming the field and its range, and
    RuntimeError (with the twin's status) when the twin cannot hold the setpoint (it halted)."""
    from twin import catalog
    from twin.engine import Twin
    from twin.kernels import layout as L
    from twin.setpoint import Setpoint
    from twin.spec import BearingSpec
    from twin.vibration.sensor import contact_angle_of_lanes_rad

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
    for key, value in (("noise_density_m_s2_rthz", noise_density_m_s2_rthz), ("sample_rate_hz", sample_rate_hz),
                       ("window_s", window_s)):
        if value is not None:
            acc[key] = value
    spec = BearingSpec.model_validate(data)
    twin = Twin(spec, setpoint=Setpoint(shaft_speed_rad_s=shaft_speed_rad_s, radial_load_n=radial_load_n,
                                        axial_load_n=axial_load_n))
    if defect is not None:
        twin.set_defects([defect_for(defect, spec.geometry, defect_size_m, defect_length_m, defect_depth_m,
                                     defect_angle_deg)])
    for k, span in enumerate((settle_s, duration_s)):
        if k == 1:
            twin.drain_waveform()   # the settling part is discarded
        left = twin.advance(span)
        if left or twin.halted:
            raise RuntimeError(f"bearing {spec.designation!r} at {shaft_speed_rad_s:g} rad/s, {radial_load_n:g} N: "
                               f"the twin stopped at t = {twin.time_s:.6f} s after {twin.restarts} restarts "
                               f"({twin.status})")
    blocks = twin.drain_waveform()
    x = np.concatenate([b.samples for b in blocks]).astype(float) if blocks else np.zeros(0)
    angle = contact_angle_of_lanes_rad(twin.model, twin.state)
    result = run_vibration(x, twin.model.sample_rate_hz, spec, float(twin.state.scalars[L.X_SHAFT_SPEED]),
                           contact_angle_rad=angle, housing=spec.housing,
                           window_s=spec.housing.accelerometer.window_s, band=band)
    result.update({
        "bearing": spec.designation, "shaft_speed_rad_s": float(twin.state.scalars[L.X_SHAFT_SPEED]),
        "radial_load_n": radial_load_n, "axial_load_n": axial_load_n,
        "defect": twin.defects[0].model_dump() if twin.defects else None,
        "time_step_s": twin.model.dt_s, "decimation_ratio": twin.model.decimator.ratio,
        "noise_density_m_s2_rthz": spec.housing.accelerometer.noise_density_m_s2_rthz,
        "status": twin.status,
    })
    return result, x
