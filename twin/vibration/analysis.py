"""One analysis for measured and simulated accelerometer signals: `analyse_signal`.

A record of housing acceleration [m/s^2] at a sample rate [Hz] and the shaft frequency [Hz] give:

- time-domain indicators of the mean-removed record (`indicators.time_indicators`): RMS, peak,
  crest factor = peak / RMS, Pearson kurtosis E[(a - mean)^4] / sigma^4 (3 for Gaussian noise;
  Randall & Antoni 2011, "Rolling element bearing diagnostics - A tutorial", MSSP 25, sec. 3.1);
- the envelope band: set by hand, or chosen by Antoni's fast kurtogram (`kurtogram.fast_kurtogram`,
  MSSP 21, 2007) among the bands wide enough to carry the highest line with its shaft sidebands
  (width B >= 2 (m_max + 1) f_s, m_max the largest line multiple, so the envelope resolves up to
  B / 2) and lying above those lines (lower edge >= the same B, so the band-pass rejects the
  discrete low-order lines: Randall & Antoni 2011 sec. 3.2), capped at 0.45 fs (inside the
  acquisition's anti-aliasing passband);
- the envelope spectrum of that band (`indicators.envelope_spectrum`: 4th-order Butterworth
  band-pass, zero phase; |analytic signal|; mean removed; Hann window, amplitude-corrected)
  over the whole record;
- the defect lines (each given multiple of the shaft frequency, e.g. BPFO, BPFI, 2xBSF, FTF, and
  the shaft harmonics 1x-3x): the largest envelope bin within +-1 % of the line, its amplitude
  over the local background (the median of the envelope bins within +-20 Hz of that peak) in dB,
  20 log10(peak / background): the definition of the CWRU data's README (Case Western Reserve
  University Bearing Data Center records; its whole-record figures use a 2-5 kHz band);
- the largest envelope lines (local maxima from 3 bins above 0 Hz to the line-search limit,
  min(B / 2, 5 m_max f_s)), each labelled with the harmonic k x line (k = 1..5) or k x shaft
  (k = 1..10) it lies within +-1 % of, nearest first.

`VibrationAnalysis.to_dict` is the JSON of `bearing-twin vibration analyse` and of the live
comparison; every number in it is finite.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

import numpy as np
import scipy.io

from twin.vibration import indicators
from twin.vibration.defect_frequencies import bearing_defect_frequencies
from twin.vibration.housing import MIN_WINDOW_SAMPLES
from twin.vibration.kurtogram import fast_kurtogram

LINE_TOLERANCE = 0.01  # relative half-width of the search around a line [-]
BACKGROUND_HALF_WIDTH_HZ = 20.0  # the local background: median of +-20 Hz around the peak
SHAFT_HARMONICS = 3  # 1x, 2x, 3x shaft among the defect lines
LABEL_DEFECT_HARMONICS = 5
LABEL_SHAFT_HARMONICS = 10
MIN_SAMPLES = MIN_WINDOW_SAMPLES
# the largest sample magnitude taken [m/s^2]: about 1e5 g, the top of shock accelerometers' ranges;
# beyond it a record is corrupt or in the wrong units, and its squares would overflow the statistics
MAX_ABS_SIGNAL_M_S2 = 1.0e6
MAX_SAMPLE_RATE_HZ = 1.0e6
MAX_BAND_FRACTION = 0.45  # of fs: the highest envelope-band edge (anti-aliasing passband)
DEFAULT_MAX_MULTIPLE = 10.0  # highest line multiple assumed when no defect line is given


class AnalysisInputError(ValueError):
    """Bad input to `analyse_signal`: `field` names the argument, the message its allowed range."""

    def __init__(self, field_name: str, message: str):
        super().__init__(f"{field_name}: {message}")
        self.field = field_name


@dataclass(frozen=True)
class DefectLine:
    """One expected envelope line: `name` (BPFO, BPFI, 2xBSF, FTF, 1xshaft, ...), expected_hz [Hz],
    the peak found within +-1 %: peak_hz [Hz] (bin centre), peak_m_s2 [m/s^2] (envelope amplitude),
    background_m_s2 [m/s^2] (median of +-20 Hz around the peak) and height_db [dB] =
    20 log10(peak / background); relative_error = peak_hz / expected_hz - 1 [-]."""

    name: str
    expected_hz: float
    peak_hz: float
    peak_m_s2: float
    background_m_s2: float
    height_db: float

    @property
    def relative_error(self) -> float:
        return self.peak_hz / self.expected_hz - 1.0


@dataclass(frozen=True)
class EnvelopeLine:
    """A local maximum of the envelope spectrum: frequency_hz [Hz] (parabolic interpolation),
    amplitude_m_s2 [m/s^2], shaft_order [-] = frequency / shaft frequency, height_db [dB] over the
    median of +-20 Hz around it, label: the harmonic it lies within +-1 % of ('BPFI', '2xBPFO',
    '4xshaft') or None."""

    frequency_hz: float
    amplitude_m_s2: float
    shaft_order: float
    height_db: float
    label: str | None


@dataclass(frozen=True)
class VibrationAnalysis:
    """The analysis of one record (module docstring). Spectra [m/s^2] ride on the object
    (envelope_frequency_hz, envelope_amplitude_m_s2) and are left out of `to_dict` unless asked."""

    sample_rate_hz: float
    n_samples: int
    duration_s: float
    shaft_hz: float
    rms_m_s2: float
    peak_m_s2: float
    crest_factor: float
    kurtosis: float
    envelope_band_hz: tuple[float, float]
    envelope_band_source: str  # 'kurtogram' or 'given'
    band_spectral_kurtosis: float | None  # fast-kurtogram value of the band [-] (None if given)
    kurtogram_level: float | None
    envelope_resolution_hz: float
    line_search_max_hz: float
    defect_lines: tuple[DefectLine, ...]
    largest_lines: tuple[EnvelopeLine, ...]
    envelope_frequency_hz: np.ndarray = field(repr=False, compare=False)
    envelope_amplitude_m_s2: np.ndarray = field(repr=False, compare=False)

    def line(self, name: str) -> DefectLine:
        """The defect line called `name` (KeyError if it was not analysed)."""
        for d in self.defect_lines:
            if d.name == name:
                return d
        raise KeyError(name)

    def to_dict(self, spectrum: bool = False) -> dict:
        """JSON-ready dict (lists, floats); with spectrum=True also `envelope_spectrum`
        {start_hz, step_hz, amplitude_m_s2} from 0 Hz to the line-search limit."""
        out = {
            "sample_rate_hz": self.sample_rate_hz,
            "n_samples": self.n_samples,
            "duration_s": self.duration_s,
            "shaft_hz": self.shaft_hz,
            "rms_m_s2": self.rms_m_s2,
            "peak_m_s2": self.peak_m_s2,
            "crest_factor": self.crest_factor,
            "kurtosis": self.kurtosis,
            "envelope_band_hz": list(self.envelope_band_hz),
            "envelope_band_source": self.envelope_band_source,
            "band_spectral_kurtosis": self.band_spectral_kurtosis,
            "kurtogram_level": self.kurtogram_level,
            "envelope_resolution_hz": self.envelope_resolution_hz,
            "line_search_max_hz": self.line_search_max_hz,
            "defect_lines": [{**d.__dict__, "relative_error": d.relative_error} for d in self.defect_lines],
            "largest_lines": [dict(p.__dict__) for p in self.largest_lines],
        }
        if spectrum:
            keep = self.envelope_frequency_hz <= self.line_search_max_hz
            out["envelope_spectrum"] = {
                "start_hz": 0.0,
                "step_hz": self.envelope_resolution_hz,
                "amplitude_m_s2": self.envelope_amplitude_m_s2[keep].tolist(),
            }
        return out


def read_matlab5(path) -> dict:
    """The variables of a MATLAB 5 .mat record (the CWRU data center's files). ValueError with the
    reason for any other file (a MATLAB 7.3 file is HDF5, which scipy does not read)."""
    try:
        if scipy.io.matlab.matfile_version(path)[0] == 2:
            raise ValueError("MATLAB 7.3, HDF5")
        return scipy.io.loadmat(path)
    except scipy.io.matlab.MatReadError as exc:
        raise ValueError(str(exc)) from None


def _finite_positive(name: str, value, upper: float) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise AnalysisInputError(name, f"{value!r} is not a number; allowed (0, {upper:g}]") from None
    if not (math.isfinite(v) and 0.0 < v <= upper):
        raise AnalysisInputError(name, f"{value!r} is out of range; allowed (0, {upper:g}]")
    return v


def _checked_signal(signal_m_s2) -> np.ndarray:
    x = np.asarray(signal_m_s2)
    if x.dtype.kind not in "iuf":
        raise AnalysisInputError("signal_m_s2", f"dtype {x.dtype} is not real numbers")
    x = np.asarray(x, dtype=float)
    if x.ndim != 1:
        raise AnalysisInputError("signal_m_s2", f"shape {x.shape}: must be one-dimensional")
    if x.size < MIN_SAMPLES:
        raise AnalysisInputError("signal_m_s2", f"{x.size} samples; at least {MIN_SAMPLES} needed")
    bad = np.flatnonzero(~np.isfinite(x))
    if bad.size:
        raise AnalysisInputError(
            "signal_m_s2", f"{bad.size} non-finite samples (first at index {bad[0]}); all samples must be finite"
        )
    big = np.flatnonzero(np.abs(x) > MAX_ABS_SIGNAL_M_S2)
    if big.size:
        raise AnalysisInputError(
            "signal_m_s2",
            f"{big.size} samples beyond {MAX_ABS_SIGNAL_M_S2:g} m/s2 (first at index {big[0]}: {x[big[0]]:.3g}); "
            f"allowed [-{MAX_ABS_SIGNAL_M_S2:g}, {MAX_ABS_SIGNAL_M_S2:g}] m/s2 (about 1e5 g): check the units",
        )
    return x


def _harmonic_label(name: str, k: int) -> str:
    """'BPFI', 2 -> '2xBPFI'; '2xBSF', 2 -> '4xBSF'; 'shaft', 4 -> '4xshaft'."""
    if name == "shaft":
        return f"{k}xshaft"
    m = re.fullmatch(r"(\d+)x(.+)", name)
    if m:
        return f"{k * int(m.group(1))}x{m.group(2)}"
    return name if k == 1 else f"{k}x{name}"


def _background(freqs: np.ndarray, amp: np.ndarray, centre_hz: float, half_width_hz: float) -> float:
    sel = np.abs(freqs - centre_hz) <= half_width_hz
    return float(np.median(amp[sel]))


def _height_db(peak: float, background: float) -> float:
    if background > 0.0 and peak > 0.0:
        return 20.0 * math.log10(peak / background)
    return 0.0


def measure_line(
    freqs: np.ndarray,
    amp: np.ndarray,
    name: str,
    expected_hz: float,
    tolerance: float = LINE_TOLERANCE,
    background_half_width_hz: float = BACKGROUND_HALF_WIDTH_HZ,
) -> DefectLine:
    """The envelope line near expected_hz (module docstring): largest bin within +-tolerance
    (at least the nearest bin), its height over the median of +-background_half_width_hz."""
    half = max(tolerance * expected_hz, 0.5 * (freqs[1] - freqs[0]))
    idx = np.flatnonzero(np.abs(freqs - expected_hz) <= half)
    i = int(idx[np.argmax(amp[idx])])
    peak = float(amp[i])
    bg = _background(freqs, amp, float(freqs[i]), background_half_width_hz)
    return DefectLine(
        name=name,
        expected_hz=float(expected_hz),
        peak_hz=float(freqs[i]),
        peak_m_s2=peak,
        background_m_s2=bg,
        height_db=_height_db(peak, bg),
    )


def _label(frequency_hz: float, candidates: list[tuple[str, float]], tolerance: float) -> str | None:
    best, best_err = None, tolerance
    for label, f in candidates:
        err = abs(frequency_hz / f - 1.0)
        if err <= best_err:
            best, best_err = label, err
    return best


def analyse_signal(
    signal_m_s2,
    sample_rate_hz: float,
    shaft_hz: float,
    defect_multiples: dict[str, float] | None = None,
    band_hz: tuple[float, float] | None = None,
    *,
    peak_count: int = 5,
    line_tolerance: float = LINE_TOLERANCE,
    background_half_width_hz: float = BACKGROUND_HALF_WIDTH_HZ,
) -> VibrationAnalysis:
    """Analyse one accelerometer record (module docstring).

    signal_m_s2: 1-D samples [m/s^2] (at least 1024, all finite); sample_rate_hz (0, 1e6] [Hz];
    shaft_hz (0, fs / 20] [Hz]; defect_multiples: {name: multiple of the shaft frequency}, e.g.
    {'BPFO': 3.5848, 'BPFI': 5.4152, '2xBSF': 4.7135, 'FTF': 0.39828} (None: the shaft harmonics
    only); band_hz: the envelope band (low, high) [Hz], 0 < low < high < fs / 2 (None: fast
    kurtogram); peak_count: how many largest envelope lines. Raises AnalysisInputError (a
    ValueError; `.field` names the argument) with the allowed range."""
    x = _checked_signal(signal_m_s2)
    fs = _finite_positive("sample_rate_hz", sample_rate_hz, MAX_SAMPLE_RATE_HZ)
    f_shaft = _finite_positive("shaft_hz", shaft_hz, fs / 20.0)
    multiples = dict(defect_multiples or {})
    for name, m in multiples.items():
        _finite_positive(f"defect_multiples[{name!r}]", m, 0.45 * fs / f_shaft)
    if not (isinstance(peak_count, int) and 1 <= peak_count <= 50):
        raise AnalysisInputError("peak_count", f"{peak_count!r}; allowed integers 1-50")
    top = max(list(multiples.values()) + [float(SHAFT_HARMONICS)]) if multiples else DEFAULT_MAX_MULTIPLE
    min_band = 2.0 * (top + 1.0) * f_shaft
    if band_hz is None:
        try:
            kg = fast_kurtogram(x, fs, min_bandwidth_hz=min_band, low_edge_range_hz=(min_band, MAX_BAND_FRACTION * fs))
        except ValueError as exc:
            raise AnalysisInputError("band_hz", f"no kurtogram band fits ({exc}); give the band by hand") from None
        lo, hi = kg.band_hz[0], min(kg.band_hz[1], MAX_BAND_FRACTION * fs)
        source, sk, level = "kurtogram", kg.band_kurtosis, kg.level
    else:
        try:
            lo, hi = (float(band_hz[0]), float(band_hz[1]))
        except (TypeError, ValueError, IndexError):
            raise AnalysisInputError("band_hz", f"{band_hz!r}: need (low, high) in Hz") from None
        if not (math.isfinite(lo) and math.isfinite(hi) and 0.0 < lo < hi < 0.5 * fs):
            raise AnalysisInputError("band_hz", f"({lo:g}, {hi:g}); allowed 0 < low < high < fs / 2 = {0.5 * fs:g} Hz")
        source, sk, level = "given", None, None
    t = indicators.time_indicators(x)
    freqs, amp = indicators.envelope_spectrum(x, fs, (lo, hi))
    max_hz = min(0.5 * (hi - lo), 5.0 * top * f_shaft, float(freqs[-1]))
    lines = [(name, m * f_shaft) for name, m in multiples.items()]
    lines += [(_harmonic_label("shaft", k), k * f_shaft) for k in range(1, SHAFT_HARMONICS + 1)]
    defect_lines = tuple(
        measure_line(freqs, amp, name, f, line_tolerance, background_half_width_hz)
        for name, f in lines
        if f <= freqs[-1]
    )
    candidates = [
        (_harmonic_label(name, k), k * m * f_shaft)
        for name, m in multiples.items()
        for k in range(1, LABEL_DEFECT_HARMONICS + 1)
    ]
    candidates += [(_harmonic_label("shaft", k), k * f_shaft) for k in range(1, LABEL_SHAFT_HARMONICS + 1)]
    largest = []
    for p in indicators.envelope_peaks(freqs, amp, peak_count, max_hz=max_hz):
        f = p["frequency_hz"]
        bg = _background(freqs, amp, f, background_half_width_hz)
        largest.append(
            EnvelopeLine(
                frequency_hz=f,
                amplitude_m_s2=p["amplitude"],
                shaft_order=f / f_shaft,
                height_db=_height_db(p["amplitude"], bg),
                label=_label(f, candidates, line_tolerance),
            )
        )
    return VibrationAnalysis(
        sample_rate_hz=fs,
        n_samples=int(x.size),
        duration_s=x.size / fs,
        shaft_hz=f_shaft,
        rms_m_s2=t["rms_m_s2"],
        peak_m_s2=t["peak_m_s2"],
        crest_factor=t["crest_factor"],
        kurtosis=t["kurtosis"],
        envelope_band_hz=(float(lo), float(hi)),
        envelope_band_source=source,
        band_spectral_kurtosis=sk,
        kurtogram_level=level,
        envelope_resolution_hz=float(freqs[1] - freqs[0]),
        line_search_max_hz=float(max_hz),
        defect_lines=defect_lines,
        largest_lines=tuple(largest),
        envelope_frequency_hz=freqs,
        envelope_amplitude_m_s2=amp,
    )


def defect_multiples_of(geometry, contact_angle_rad: float | None = None) -> dict[str, float]:
    """{'BPFO', 'BPFI', '2xBSF', 'FTF'}: the kinematic line multiples of the shaft frequency [-] of a
    `twin.spec.Geometry` (twin.vibration.defect_frequencies; nominal contact angle by default)."""
    o = bearing_defect_frequencies(geometry, 2.0 * math.pi, contact_angle_rad).orders()
    return {"BPFO": o["bpfo"], "BPFI": o["bpfi"], "2xBSF": o["two_bsf"], "FTF": o["ftf"]}


__all__ = [
    "AnalysisInputError",
    "DefectLine",
    "EnvelopeLine",
    "VibrationAnalysis",
    "analyse_signal",
    "defect_multiples_of",
    "measure_line",
]
