"""Condition indicators of one window of housing acceleration (1 s by default).

Time domain (acceleration a [m/s^2], mean removed): RMS, peak |a|, crest factor peak / RMS,
kurtosis E[(a - mean)^4] / sigma^4 (3 for Gaussian noise; impulsive signals from local defects
raise it: Randall & Antoni 2011, "Rolling element bearing diagnostics - A tutorial", MSSP 25,
sec. 3.1).

Velocity RMS over 10-1000 Hz [mm/s]: the broadband severity measure of ISO 20816-1:2016
(sec. 4 and Annex; band of ISO 2954 instruments, 10-1000 Hz for machines above 600 r/min).
Integrated in the frequency domain: V(f) = A(f) / (j 2 pi f) on the band, zero outside, RMS by
Parseval (an ideal band-pass; the ISO instrument's filter skirts are not modelled).

Envelope analysis (Randall & Antoni 2011, sec. 3.2-3.3): band-pass around a structural resonance
excited by the impacts (4th-order Butterworth, zero phase: scipy.signal.butter + sosfiltfilt),
envelope |analytic signal| (scipy.signal.hilbert), mean removed, amplitude spectrum with a Hann
window (amplitude-corrected, [m/s^2]). The band is either given, centred on the housing's sensed
resonance, or chosen by spectral kurtosis: the fast kurtogram of Antoni 2007 (MSSP 21, 108-124;
twin.vibration.kurtogram), the band of highest kurtosis wins. The analysis of a whole measured
or simulated record (twin.vibration.analysis) is built on these functions.

Full spectra of a window (`amplitude_spectrum`, `envelope_spectrum_view`), for the snapshot's
`vibration` block and the sinks, never its JSON: the acceleration amplitude spectrum from 0 to
fs / 2 (no window: the whole window is the record, mean removed), its FFT bins power-summed into at
most AMPLITUDE_MAX_BINS bins, so that Parseval holds on it (sum A_j^2 / 2 = mean square of the
window: Parseval's relation of the DFT, sum |x[n]|^2 = (1/N) sum |X[k]|^2, Oppenheim & Schafer,
"Discrete-Time Signal Processing", Table 8.2, taken one-sided as in `velocity_rms_mm_s`) and a line of amplitude A
reads A (its leakage falls in the bin or the next); the
envelope spectrum (the one the peaks, lines and noise floor come from, same bins and values) from
0 Hz to the limit of the peak search and the noise floor, min(half the envelope band width,
5 x max(BPFI, 2 x BSF)), peak-held (max of each group) into at most ENVELOPE_MAX_BINS bins only
for windows longer than ~1.8 s.

Defect lines: the envelope amplitude at FTF, BPFO, BPFI, BSF, 2 x BSF, their harmonics, and the
sidebands that mark each fault (Randall & Antoni 2011 sec. 2.1: BPFI +- shaft frequency (the
inner-race spall moves through the load zone), 2 x BSF +- FTF (the ball defect does, with the
cage)), each the largest bin within +-tolerance of the line, and the ratio to the noise floor
(median of the envelope spectrum).
"""

from __future__ import annotations

import math

import numpy as np
import scipy.signal

from twin.vibration.defect_frequencies import DefectFrequencies
from twin.vibration.kurtogram import fast_kurtogram

ISO_20816_BAND_HZ = (10.0, 1000.0)

# A line is "above the noise floor" when it exceeds this many times the median envelope amplitude:
# the envelope-spectrum bins of Gaussian noise are Rayleigh distributed, P(A > 4 median) =
# exp(-(4 x 1.1774)^2 / 2) = 1.5e-5 per bin, i.e. ~1 % of false alarms over the ~700 bins the 15
# defect lines and harmonics inspect in a 1 s window (+-1 % each).
SIGNIFICANCE = 4.0

# at most this many bins in the full spectra of a window (module docstring): the acceleration
# spectrum of a 1 s window at 51.2 kHz has 25 601 FFT bins, summed 13 by 13 into 1970 of 13 Hz;
# the envelope spectrum of a 1 s window (1 Hz bins up to ~2.3 kHz) is kept as computed.
AMPLITUDE_MAX_BINS = 2000
ENVELOPE_MAX_BINS = 4096


def time_indicators(a_m_s2: np.ndarray) -> dict[str, float]:
    """{'rms_m_s2', 'peak_m_s2', 'crest_factor', 'kurtosis'} of a window (mean removed)."""
    x = np.asarray(a_m_s2, dtype=float)
    if x.size < 4:
        raise ValueError(f"a window needs at least 4 samples, got {x.size}")
    x = x - x.mean()
    ms = float(np.mean(x * x))
    rms = math.sqrt(ms)
    peak = float(np.max(np.abs(x)))
    kurt = float(np.mean(x**4) / (ms * ms)) if ms > 0.0 else 0.0
    return {"rms_m_s2": rms, "peak_m_s2": peak, "crest_factor": peak / rms if rms > 0.0 else 0.0, "kurtosis": kurt}


def band_pass(a_m_s2: np.ndarray, sample_rate_hz: float, band_hz: tuple[float, float]) -> np.ndarray:
    """The window [m/s^2], mean removed, band-passed to band_hz: the envelope band's filter
    (module docstring: 4th-order Butterworth, zero phase)."""
    x = np.asarray(a_m_s2, dtype=float)
    fs = float(sample_rate_hz)
    lo, hi = band_hz
    if not 0.0 < lo < hi < 0.5 * fs:
        raise ValueError(f"band_hz = ({lo:g}, {hi:g}): need 0 < low < high < fs / 2 = {0.5 * fs:g} Hz")
    sos = scipy.signal.butter(4, [lo, hi], btype="bandpass", fs=fs, output="sos")
    return scipy.signal.sosfiltfilt(sos, x - x.mean())


def band_kurtosis(a_m_s2: np.ndarray, sample_rate_hz: float, band_hz: tuple[float, float]) -> float:
    """Kurtosis [-] of the window band-passed to band_hz (`band_pass`: the envelope band's filter,
    as in `envelope_spectrum`): the impulsiveness where the impacts ring the structure,
    which a strong low-frequency response (a lightly damped shaft mode, the load-zone modulation)
    hides from the broadband kurtosis (Antoni & Randall 2006: the kurtosis as a function of the
    band, the idea of the spectral kurtosis)."""
    return time_indicators(band_pass(a_m_s2, sample_rate_hz, band_hz))["kurtosis"]


def velocity_rms_mm_s(
    a_m_s2: np.ndarray, sample_rate_hz: float, band_hz: tuple[float, float] = ISO_20816_BAND_HZ
) -> float:
    """RMS velocity [mm/s] in band_hz (ISO 20816-1: 10-1000 Hz) from acceleration [m/s^2], by
    integration in the frequency domain (module docstring)."""
    x = np.asarray(a_m_s2, dtype=float)
    n = x.size
    spec = np.fft.rfft(x - x.mean())
    f = np.fft.rfftfreq(n, 1.0 / sample_rate_hz)
    keep = (f >= band_hz[0]) & (f <= band_hz[1]) & (f > 0.0)
    v = spec[keep] / (2j * math.pi * f[keep])
    # one-sided Parseval: mean square = (|X0|^2 + 2 sum |Xk|^2 (+ |X_N/2|^2)) / n^2
    weight = np.where(f[keep] == 0.5 * sample_rate_hz, 1.0, 2.0)
    ms = float(np.sum(weight * np.abs(v) ** 2)) / (n * n)
    return 1e3 * math.sqrt(ms)


def kurtogram_band(
    a_m_s2: np.ndarray, sample_rate_hz: float, min_bandwidth_hz: float = 0.0, max_frequency_hz: float | None = None
) -> tuple[float, float, float]:
    """(low [Hz], high [Hz], SK [-]) of the band of highest spectral kurtosis: Antoni's fast
    kurtogram (twin.vibration.kurtogram, MSSP 21, 2007) among its bands at least min_bandwidth_hz
    wide that neither reach 0 Hz nor pass max_frequency_hz (default: 0.45 fs, inside the
    anti-aliasing passband)."""
    fs = float(sample_rate_hz)
    fmax = 0.45 * fs if max_frequency_hz is None else min(max_frequency_hz, 0.5 * fs)
    kg = fast_kurtogram(
        a_m_s2,
        fs,
        min_bandwidth_hz=min_bandwidth_hz,
        low_edge_range_hz=(np.nextafter(0.0, 1.0), fmax),
        max_high_edge_hz=fmax,
    )
    return kg.band_hz[0], kg.band_hz[1], kg.band_kurtosis


def resonance_band(
    resonance_hz: float, damping_ratio: float, sample_rate_hz: float, min_bandwidth_hz: float = 0.0
) -> tuple[float, float]:
    """Band [Hz] centred on a structural resonance: +-3 half-power half-widths (3 zeta f_r), at
    least min_bandwidth_hz wide, kept inside (0, 0.45 fs)."""
    half = max(3.0 * damping_ratio * resonance_hz, 0.5 * min_bandwidth_hz)
    lo = max(resonance_hz - half, 0.01 * sample_rate_hz)
    hi = min(resonance_hz + half, 0.45 * sample_rate_hz)
    if not lo < hi:
        raise ValueError(
            f"resonance at {resonance_hz:g} Hz is outside the usable band of a {sample_rate_hz:g} Hz signal"
        )
    return lo, hi


def envelope_spectrum(
    a_m_s2: np.ndarray, sample_rate_hz: float, band_hz: tuple[float, float]
) -> tuple[np.ndarray, np.ndarray]:
    """(frequencies [Hz], amplitude [m/s^2]) of the envelope of a band-passed to band_hz
    (module docstring: Butterworth 4 zero-phase, Hilbert, Hann, amplitude-corrected)."""
    y = band_pass(a_m_s2, sample_rate_hz, band_hz)
    env = np.abs(scipy.signal.hilbert(y))
    env -= env.mean()
    w = np.hanning(env.size)
    amp = 2.0 * np.abs(np.fft.rfft(env * w)) / np.sum(w)
    return np.fft.rfftfreq(env.size, 1.0 / float(sample_rate_hz)), amp


def amplitude_spectrum(
    a_m_s2: np.ndarray, sample_rate_hz: float, max_bins: int = AMPLITUDE_MAX_BINS
) -> tuple[float, float, np.ndarray]:
    """(start [Hz], step [Hz], amplitude [m/s^2]) of the window's one-sided amplitude spectrum
    from 0 to fs / 2 (module docstring): the mean-removed window's DFT X_k, power P_k = w_k
    |X_k|^2 / N^2 (w = 2, 1 at 0 Hz and at fs / 2 for even N: sum P_k = mean square, Parseval),
    summed over groups of g = ceil((N // 2 + 1) / max_bins) bins, amplitude sqrt(2 sum P_k)
    (2 |X_k| / N for g = 1). Bin j stands for the g FFT bins from j g: centre start + j step with
    start = (g - 1) / 2 df, step = g df (df = fs / N)."""
    x = np.asarray(a_m_s2, dtype=float)
    n = x.size
    if n < 4:
        raise ValueError(f"a window needs at least 4 samples, got {n}")
    if max_bins < 1:
        raise ValueError(f"max_bins = {max_bins}: must be >= 1")
    spec = np.fft.rfft(x - x.mean())
    power = (spec.real**2 + spec.imag**2) * (2.0 / (n * n))
    power[0] *= 0.5
    if n % 2 == 0:
        power[-1] *= 0.5
    g = -(-power.size // max_bins)
    m = -(-power.size // g)
    padded = np.zeros(m * g)
    padded[: power.size] = power
    df = float(sample_rate_hz) / n
    return 0.5 * (g - 1) * df, g * df, np.sqrt(2.0 * padded.reshape(m, g).sum(axis=1))


def envelope_spectrum_view(
    freqs: np.ndarray, amp: np.ndarray, max_hz: float, max_bins: int = ENVELOPE_MAX_BINS
) -> tuple[float, float, np.ndarray]:
    """(start [Hz], step [Hz], amplitude [m/s^2]) of an envelope spectrum (`envelope_spectrum`)
    from 0 Hz to max_hz (the bins at or below it): the values themselves when they are at most
    max_bins, else the largest of each group of g = ceil(bins / max_bins) (peak hold: a line keeps
    its height), centre start + j step as in `amplitude_spectrum`."""
    df = float(freqs[1] - freqs[0])
    keep = int(np.searchsorted(freqs, max_hz, side="right"))
    a = np.asarray(amp[: max(keep, 1)], dtype=float)
    g = -(-a.size // max_bins)
    if g == 1:
        return 0.0, df, a.copy()
    m = -(-a.size // g)
    padded = np.zeros(m * g)
    padded[: a.size] = a
    return 0.5 * (g - 1) * df, g * df, padded.reshape(m, g).max(axis=1)


def envelope_peaks(
    freqs: np.ndarray, amp: np.ndarray, count: int = 5, min_hz: float | None = None, max_hz: float | None = None
) -> list[dict[str, float]]:
    """The `count` largest local maxima of an envelope spectrum in [min_hz, max_hz], largest
    first by their interpolated amplitude: [{'frequency_hz', 'amplitude'}]. Each maximum is
    interpolated by the parabola through its bin and the two beside it (vertex at
    d = (a - c) / (2 (a - 2 b + c)) bins, height b - (a - c) d / 4) before they are ranked.
    Defaults: from 3 bins above 0 Hz to the end."""
    df = freqs[1] - freqs[0]
    lo = 3.0 * df if min_hz is None else min_hz
    hi = freqs[-1] if max_hz is None else max_hz
    idx, _ = scipy.signal.find_peaks(amp)  # interior bins only
    idx = idx[(freqs[idx] >= lo) & (freqs[idx] <= hi)]
    a, b, c = amp[idx - 1], amp[idx], amp[idx + 1]
    den = a - 2.0 * b + c
    curved = den < 0.0
    shift = np.where(curved, 0.5 * (a - c) / np.where(curved, den, -1.0), 0.0)
    peak_hz = freqs[idx] + shift * df
    peak_amp = b - 0.25 * (a - c) * shift
    order = np.argsort(-peak_amp, kind="stable")[:count]
    return [{"frequency_hz": float(peak_hz[k]), "amplitude": float(peak_amp[k])} for k in order]


def noise_floor(freqs: np.ndarray, amp: np.ndarray, max_hz: float) -> float:
    """Median envelope amplitude from 3 bins to max_hz [m/s^2] (robust to the lines; a line is
    significant above SIGNIFICANCE times it)."""
    df = freqs[1] - freqs[0]
    sel = (freqs >= 3.0 * df) & (freqs <= max_hz)
    return float(np.median(amp[sel])) if np.any(sel) else 0.0


def line_amplitude(freqs: np.ndarray, amp: np.ndarray, f_hz: float, tolerance: float = 0.01) -> float:
    """Largest envelope amplitude within f_hz (1 +- tolerance), at least +-2 bins [m/s^2]; 0 beyond
    the spectrum."""
    df = freqs[1] - freqs[0]
    half = max(tolerance * f_hz, 2.0 * df)
    sel = (freqs >= f_hz - half) & (freqs <= f_hz + half)
    return float(np.max(amp[sel])) if np.any(sel) else 0.0


def defect_line_amplitudes(
    freqs: np.ndarray, amp: np.ndarray, freq: DefectFrequencies, harmonics: int = 3, tolerance: float = 0.01
) -> dict[str, dict]:
    """Envelope amplitudes [m/s^2] at each defect frequency: {'ftf', 'bpfo', 'bpfi', 'bsf',
    'two_bsf'} -> {'frequency_hz', 'harmonics': [1x, 2x, ...], 'sidebands': {'lower', 'upper'}
    (BPFI +- shaft frequency, 2 x BSF +- FTF, at the fundamental; absent for the others)}."""
    side = {"bpfi": freq.shaft_hz, "two_bsf": freq.ftf_hz}
    out = {}
    for name, f in freq.as_dict().items():
        entry = {
            "frequency_hz": f,
            "harmonics": [line_amplitude(freqs, amp, k * f, tolerance) for k in range(1, harmonics + 1)],
        }
        if name in side:
            entry["sidebands"] = {
                "lower": line_amplitude(freqs, amp, f - side[name], tolerance),
                "upper": line_amplitude(freqs, amp, f + side[name], tolerance),
            }
        out[name] = entry
    return out
