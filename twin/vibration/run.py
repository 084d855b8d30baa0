"""`run_vibration`: the backend of `bearing-twin vibration` on a sampled housing acceleration.

`run_vibration` takes the waveform [m/s^2] at its sample rate and the bearing's geometry, returns
the JSON-ready indicator dict (twin.vibration.indicators; defect frequencies from
twin.vibration.defect_frequencies). The twin that produces such a waveform
(`twin.validation.vibration_simulation.simulate_vibration`) sits above the engine.
"""

from __future__ import annotations

import math

import numpy as np

from twin.vibration import indicators as ind
from twin.vibration.defect_frequencies import bearing_defect_frequencies
from twin.vibration.housing import MIN_WINDOW_SAMPLES, Housing, sensor_resonance


def run_vibration(
    signal_m_s2,
    sample_rate_hz: float,
    bearing,
    shaft_speed_rad_s: float,
    *,
    contact_angle_rad: float | None = None,
    housing: Housing | None = None,
    window_s: float = 1.0,
    band: str | tuple[float, float] = "resonance",
    peak_count: int = 5,
    spectra: bool = False,
) -> dict:
    """Indicators of a housing-acceleration waveform (JSON-ready; every number finite).

    signal_m_s2: samples [m/s^2] at sample_rate_hz [Hz]; bearing: a `twin.spec.Geometry` or a
    `BearingSpec` (its geometry); shaft_speed_rad_s [rad/s]; contact_angle_rad: the loaded contact
    angle (None: nominal); housing: for the resonance band (default `Housing()`); window_s: the
    indicator window [s] (the signal is cut into whole windows; a shorter signal is one window);
    band: 'resonance' (around the housing's sensed resonance), 'kurtogram' (spectral-kurtosis
    search) or (low, high) [Hz].

    Returns sample_rate_hz, duration_s, window_s, windows, defect_frequencies_hz {ftf, bpfo, bpfi,
    bsf, two_bsf}, contact_angle_deg, envelope_band_hz [low, high], band_method,
    envelope_peaks_hz (the `peak_count` largest: frequency_hz, amplitude [m/s^2]) of the
    window-averaged envelope spectrum, kurtosis, band_kurtosis (in the envelope band), rms_m_s2, peak_m_s2,
    crest_factor,
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
    geometry = getattr(bearing, "geometry", bearing)
    freq = bearing_defect_frequencies(geometry, shaft_speed_rad_s, contact_angle_rad)
    n_win = int(round(window_s * fs))
    count = max(1, x.size // n_win)
    n_win = min(n_win, x.size)
    if n_win < MIN_WINDOW_SAMPLES:
        raise ValueError(
            f"{n_win} samples per window at {fs:g} Hz: "
            f"need at least {MIN_WINDOW_SAMPLES} ({MIN_WINDOW_SAMPLES / fs:.4g} s)"
        )
    top = max(freq.bpfi_hz, freq.two_bsf_hz)
    min_bw = 2.0 * 4.0 * top  # room for 3 harmonics and their sidebands in the envelope
    if isinstance(band, str) and band == "resonance":
        f_r, zeta = sensor_resonance(housing or Housing())
        lo, hi = ind.resonance_band(f_r, zeta, fs, min_bw)
    elif isinstance(band, str) and band == "kurtogram":
        lo, hi, _ = ind.kurtogram_band(x[: n_win * count], fs, min_bandwidth_hz=min_bw)
    elif isinstance(band, str):
        raise ValueError(f"band = {band!r}: 'resonance', 'kurtogram' or (low, high) in Hz")
    else:
        lo, hi = (float(band[0]), float(band[1]))
    windows = []
    amp_sum = None
    power_sum = None
    for k in range(count):
        seg = x[k * n_win : (k + 1) * n_win]
        row = ind.time_indicators(seg)
        row["velocity_rms_mm_s"] = ind.velocity_rms_mm_s(seg, fs)
        row["band_kurtosis"] = ind.band_kurtosis(seg, fs, (lo, hi))
        windows.append(row)
        freqs, amp = ind.envelope_spectrum(seg, fs, (lo, hi))
        amp_sum = amp if amp_sum is None else amp_sum + amp
        if spectra:
            a_start, a_step, a_amp = ind.amplitude_spectrum(seg, fs)
            power_sum = a_amp**2 if power_sum is None else power_sum + a_amp**2
    assert amp_sum is not None  # count >= 1 windows
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
        assert power_sum is not None  # summed over the same windows
        e_start, e_step, e_amp = ind.envelope_spectrum_view(freqs, amp, max_hz)
        out["envelope_spectrum"] = {"start_hz": e_start, "step_hz": e_step, "amplitude_m_s2": e_amp}
        out["amplitude_spectrum"] = {
            "start_hz": a_start,
            "step_hz": a_step,
            "amplitude_m_s2": np.sqrt(power_sum / count),
        }
    return out
