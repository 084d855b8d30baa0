"""Figure of `bearing-twin vibration --plot`: waveform, spectrum and envelope spectrum of the
housing acceleration with the defect frequencies marked (matplotlib, Agg)."""

from __future__ import annotations

from typing import Any

import numpy as np

from service.reports.figures import pyplot, save
from twin.catalog import DEFAULT_DESIGNATION

_LINES = (
    ("ftf", "FTF", "tab:gray"),
    ("bpfo", "BPFO", "tab:red"),
    ("bpfi", "BPFI", "tab:green"),
    ("two_bsf", "2xBSF", "tab:purple"),
)


def plot_vibration(samples_m_s2: np.ndarray, result: dict, path: str, waveform_s: float = 0.05) -> None:
    """Three panels: the first `waveform_s` of the waveform [m/s^2], its amplitude spectrum (Hann,
    log scale, the envelope band shaded) and the envelope spectrum of the band
    (twin.vibration.indicators.envelope_spectrum) up to 5 x the highest defect frequency, with FTF,
    BPFO, BPFI and 2 x BSF and their first harmonics marked, and the five largest peaks."""
    from twin.vibration.indicators import envelope_spectrum

    plt = pyplot()

    x = np.asarray(samples_m_s2, dtype=float)
    fs = float(result["sample_rate_hz"])
    freq = result["defect_frequencies_hz"]
    lo, hi = result["envelope_band_hz"]
    top = max(freq["bpfi"], freq["two_bsf"])
    fig, ax = plt.subplots(3, 1, figsize=(10, 10))
    n = min(x.size, int(round(waveform_s * fs)))
    ax[0].plot(np.arange(n) / fs * 1e3, x[:n], lw=0.6)
    ax[0].set(
        xlabel="time [ms]",
        ylabel="acceleration [m/s$^2$]",
        title=f"{result['bearing']} at {result['shaft_speed_rad_s']:.0f} rad/s, Fr = {result['radial_load_n']:g} N, "
        f"Fa = {result['axial_load_n']:g} N, defect: {(result['defect'] or {}).get('kind', 'none')}; "
        f"kurtosis {result['kurtosis']:.2f}, RMS {result['rms_m_s2']:.3g} m/s$^2$",
    )
    w = np.hanning(x.size)
    spec = 2.0 * np.abs(np.fft.rfft((x - x.mean()) * w)) / np.sum(w)
    f = np.fft.rfftfreq(x.size, 1.0 / fs)
    ax[1].semilogy(f[1:], np.maximum(spec[1:], 1e-12), lw=0.5)
    ax[1].axvspan(lo, hi, color="tab:orange", alpha=0.15, label="envelope band")
    ax[1].set(xlabel="frequency [Hz]", ylabel="amplitude [m/s$^2$]", title="spectrum", xlim=(0, 0.5 * fs))
    ax[1].legend(loc="upper right")
    fe, ae = envelope_spectrum(x, fs, (lo, hi))
    keep = fe <= 5.0 * top
    ax[2].plot(fe[keep], ae[keep], lw=0.7, color="k")
    for key, label, color in _LINES:
        for k in (1, 2, 3):
            ax[2].axvline(
                k * freq[key],
                color=color,
                ls="--" if k == 1 else ":",
                lw=0.9,
                label=f"{label} {freq[key]:.1f} Hz" if k == 1 else None,
            )
    for p in result["envelope_peaks_hz"]:
        ax[2].plot(p["frequency_hz"], p["amplitude"], "o", mfc="none", color="tab:blue")
    ax[2].set(
        xlabel="frequency [Hz]",
        ylabel="envelope amplitude [m/s$^2$]",
        title=f"envelope spectrum, band {lo:.0f}-{hi:.0f} Hz (circles: five largest peaks)",
    )
    ax[2].legend(loc="upper right", fontsize=8)
    save(fig, path, dpi=100)


# ---- report section (`bearing-twin report`) --------------------------------------------------------
REPORT_SPEED_RAD_S = 523.0
REPORT_NOISE = 0.01  # background [m/s^2/sqrt(Hz)] (tests/vibration/test_engine_vibration.py)
REPORT_SIZES_M = (0.25e-3, 0.5e-3, 1e-3, 2e-3)


def vibration_section(out_dir, quick: bool = False) -> list[str]:
    """Healthy, outer, inner and ball-defect cases of the 6208 (3000 N, 523 rad/s, outer ring on
    the housing, background noise) with their figures, and the indicators against the outer
    spall's width; Markdown lines."""
    from pathlib import Path

    from twin.validation.vibration_simulation import simulate_vibration

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    duration = 0.5 if quick else 1.0
    run: dict[str, Any] = dict(
        shaft_speed_rad_s=REPORT_SPEED_RAD_S,
        radial_load_n=3000.0,
        duration_s=duration,
        noise_density_m_s2_rthz=REPORT_NOISE,
        window_s=duration,
    )
    lines = [
        "## Vibration: housing acceleration with local defects\n",
        f"6208, 3000 N, {REPORT_SPEED_RAD_S:g} rad/s, outer ring on the Sawalhi & Randall housing, accelerometer "
        f"at 51.2 kHz with a background of {REPORT_NOISE:g} m/s2/sqrt(Hz), {duration:g} s after 0.05 s; pits "
        "0.5 mm wide along the rolling direction, 0.6 Rb long across, 50 um deep (`bearing-twin vibration`). "
        "Envelope band around the housing's sensed resonance; the dashed lines mark FTF, BPFO, BPFI and "
        "2 x BSF from the geometry at the loaded contact angle.\n",
        "| case | kurtosis | band kurtosis | RMS [m/s2] | velocity RMS [mm/s] | largest envelope peaks [Hz] |",
        "|---|---|---|---|---|---|",
    ]
    for defect in (None, "outer", "inner", "ball"):
        name = defect or "healthy"
        result, x = simulate_vibration(DEFAULT_DESIGNATION, defect=defect, **run)
        png = f"vibration_{name}.png"
        plot_vibration(x, result, str(out / png))
        peaks = ", ".join(f"{p['frequency_hz']:.1f}" for p in result["envelope_peaks_hz"][:3])
        lines.append(
            f"| {name} ![{name}]({png}) | {result['kurtosis']:.2f} | {result['band_kurtosis']:.2f} | "
            f"{result['rms_m_s2']:.3g} | {result['velocity_rms_mm_s']:.3g} | {peaks} |"
        )
    f = result["defect_frequencies_hz"]
    lines += [
        "",
        f"FTF {f['ftf']:.2f}, BPFO {f['bpfo']:.2f}, BPFI {f['bpfi']:.2f}, 2 x BSF {f['two_bsf']:.2f} Hz.\n",
        "Outer spall against its width (same conditions):\n",
        "| width [mm] | kurtosis | band kurtosis | RMS [m/s2] | BPFO envelope line [m/s2] |",
        "|---|---|---|---|---|",
    ]
    for size in REPORT_SIZES_M[:2] if quick else REPORT_SIZES_M:
        result, _ = simulate_vibration(DEFAULT_DESIGNATION, defect="outer", defect_size_m=size, **run)
        lines.append(
            f"| {size * 1e3:g} | {result['kurtosis']:.2f} | {result['band_kurtosis']:.2f} | "
            f"{result['rms_m_s2']:.3g} | {result['defect_lines']['bpfo']['harmonics'][0]:.3g} |"
        )
    lines += [
        "",
        "A large spall can drive seed 000's 0.5 kg rotor into its radial mode (~3.1 kHz, ~0.5 % damping), "
        "which then carries the broadband signal: compare the broadband and the band kurtosis columns "
        "(docs/physics.md, Vibration).\n",
    ]
    return lines
