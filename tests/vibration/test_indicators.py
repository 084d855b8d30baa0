"""Indicators (twin.vibration.indicators) on synthetic signals with known answers."""

import math

import numpy as np
import pytest

from twin import catalog
from twin.vibration import indicators as ind
from twin.vibration.defect_frequencies import bearing_defect_frequencies

FS = 51200.0
G = catalog.bearing("6208").geometry
FREQ = bearing_defect_frequencies(G, 500.0)  # 6208 at 500 rad/s: BPFO 283.7, BPFI 432.5 Hz


def test_gaussian_noise_has_kurtosis_three():
    """10 s of Gaussian noise at 51.2 kHz: kurtosis 3 +- 0.1 (its standard error is sqrt(24/N) =
    0.007), crest factor ~4.5-5.5 (the max of 5e5 normal samples)."""
    x = np.random.default_rng(0).normal(0.0, 2.0, int(10 * FS))
    t = ind.time_indicators(x)
    assert t["kurtosis"] == pytest.approx(3.0, abs=0.1)
    assert t["rms_m_s2"] == pytest.approx(2.0, rel=0.01)
    assert 4.0 < t["crest_factor"] < 6.0


def test_sine_time_indicators():
    """A sine of amplitude A: RMS A/sqrt(2), peak A, crest factor sqrt(2), kurtosis 1.5 (1e-3)."""
    t = np.arange(int(FS)) / FS
    x = 3.0 * np.sin(2 * np.pi * 50.0 * t) + 7.0  # the offset is removed
    r = ind.time_indicators(x)
    assert r["rms_m_s2"] == pytest.approx(3.0 / math.sqrt(2), rel=1e-3)
    assert r["peak_m_s2"] == pytest.approx(3.0, rel=1e-3)
    assert r["crest_factor"] == pytest.approx(math.sqrt(2), rel=1e-3)
    assert r["kurtosis"] == pytest.approx(1.5, rel=1e-3)


@pytest.mark.parametrize(
    "f_hz, expected_mm_s",
    [
        (100.0, 10.0 / (2 * math.pi * 100.0) / math.sqrt(2) * 1e3),  # 11.254 mm/s
        (1000.0, 10.0 / (2 * math.pi * 1000.0) / math.sqrt(2) * 1e3),  # band edge, inside
        (159.3, 10.0 / (2 * math.pi * 159.3) / math.sqrt(2) * 1e3),  # not a whole number of periods
        (5.0, 0.0),
        (2000.0, 0.0),  # outside 10-1000 Hz
    ],
)
def test_velocity_rms_of_a_sine(f_hz, expected_mm_s):
    """ISO 20816-1 velocity RMS (10-1000 Hz) of a 10 m/s^2 sine: A / (2 pi f sqrt 2) by hand,
    within 0.1 % (1 % when the window does not hold whole periods); below 1 % of the 100 Hz value
    for tones outside the band."""
    t = np.arange(int(FS)) / FS
    v = ind.velocity_rms_mm_s(10.0 * np.sin(2 * np.pi * f_hz * t), FS)
    if expected_mm_s == 0.0:
        assert v < 0.01 * 11.254
    else:
        tol = 1e-3 if float(f_hz).is_integer() else 0.01
        assert v == pytest.approx(expected_mm_s, rel=tol)


def test_envelope_spectrum_of_an_am_carrier():
    """A 10 kHz carrier (amplitude 2) modulated by 1 + 0.5 cos(2 pi 97 t): its envelope is
    2 + cos(2 pi 97 t), so the envelope spectrum has a 1.0 m/s^2 line at 97 Hz (2 %)."""
    t = np.arange(int(FS)) / FS
    x = 2.0 * (1 + 0.5 * np.cos(2 * np.pi * 97.0 * t)) * np.sin(2 * np.pi * 10000.0 * t)
    f, a = ind.envelope_spectrum(x, FS, (8000.0, 12000.0))
    peaks = ind.envelope_peaks(f, a, 1)
    assert peaks[0]["frequency_hz"] == pytest.approx(97.0, abs=0.05)
    assert peaks[0]["amplitude"] == pytest.approx(1.0, rel=0.02)


def test_envelope_peaks_rank_by_interpolated_height():
    """Two lines: one at bins 9-11 (0.60, 0.90, 0.85), whose parabola through the three peaks at
    bin 10.357 with 0.922, and one at bins 19-21 (0.50, 0.91, 0.50), 0.91 at bin 20. The first has
    the lower raw bin and the higher interpolated height, so it comes first."""
    f = np.arange(64, dtype=float)
    a = np.zeros(64)
    a[9:12] = (0.60, 0.90, 0.85)
    a[19:22] = (0.50, 0.91, 0.50)
    peaks = ind.envelope_peaks(f, a, 2)
    # by hand: vertex d = (a - c) / (2 (a - 2 b + c)) bins, height b - (a - c) d / 4
    d = 0.5 * (0.60 - 0.85) / (0.60 - 1.80 + 0.85)
    assert peaks[0]["frequency_hz"] == pytest.approx(10.0 + d, abs=1e-12)
    assert peaks[0]["amplitude"] == pytest.approx(0.90 - 0.25 * (0.60 - 0.85) * d, abs=1e-12)
    assert peaks[1]["frequency_hz"] == pytest.approx(20.0, abs=1e-12)
    assert peaks[1]["amplitude"] == pytest.approx(0.91, abs=1e-12)


def test_outer_race_impulses_give_bpfo_and_its_harmonics(fault_signal):
    """Impulses at BPFO (1 % random slip) ringing a 6 kHz, 5 % damped resonance in noise: the
    kurtogram band holds 6 kHz, the largest envelope peak is within 1 % of BPFO, 2x and 3x BPFO
    stand 5x above the noise floor (measured 40-90x), kurtosis > 3.3 (measured 3.6)."""
    x = fault_signal(FS, 2.0, FREQ.bpfo_hz, 6000.0, jitter=0.01, noise=0.3, seed=1)
    lo, hi, sk = ind.kurtogram_band(x, FS, min_bandwidth_hz=8 * FREQ.bpfi_hz)
    assert lo < 6000.0 < hi and sk > 0.5
    f, a = ind.envelope_spectrum(x, FS, (lo, hi))
    top = ind.envelope_peaks(f, a, 5, max_hz=0.5 * (hi - lo))
    assert top[0]["frequency_hz"] == pytest.approx(FREQ.bpfo_hz, rel=0.01)
    floor = ind.noise_floor(f, a, 0.5 * (hi - lo))
    lines = ind.defect_line_amplitudes(f, a, FREQ)
    assert all(h > 5 * floor for h in lines["bpfo"]["harmonics"])
    assert ind.time_indicators(x)["kurtosis"] > 3.3  # Gaussian: 3 +- 0.015 (sqrt(24 / N))


def test_inner_race_gives_bpfi_with_shaft_sidebands(fault_signal):
    """Impulses at BPFI whose amplitude follows the load zone, 1 + 0.8 cos(2 pi f_s t): the
    largest envelope peak within 1 % of BPFI, sidebands at BPFI -+ f_s 5x above the floor and
    above the spectrum midway between them and BPFI."""
    x = fault_signal(
        FS, 2.0, FREQ.bpfi_hz, 6000.0, modulation_hz=FREQ.shaft_hz, modulation_depth=0.8, jitter=0.01, noise=0.3, seed=2
    )
    band = (3000.0, 9000.0)
    f, a = ind.envelope_spectrum(x, FS, band)
    top = ind.envelope_peaks(f, a, 5, max_hz=3000.0)
    assert top[0]["frequency_hz"] == pytest.approx(FREQ.bpfi_hz, rel=0.01)
    floor = ind.noise_floor(f, a, 3000.0)
    side = ind.defect_line_amplitudes(f, a, FREQ)["bpfi"]["sidebands"]
    between = ind.line_amplitude(f, a, FREQ.bpfi_hz - 0.5 * FREQ.shaft_hz, tolerance=0.0)
    for s in side.values():
        assert s > 5 * floor and s > 3 * between


def test_ball_defect_gives_two_bsf_with_cage_sidebands(fault_signal):
    """Impulses at 2 x BSF modulated at FTF (the defective ball travels with the cage through the
    load zone): the largest envelope peak within 1 % of 2 x BSF, sidebands at 2 x BSF -+ FTF 5x
    above the floor."""
    x = fault_signal(
        FS,
        3.0,
        FREQ.two_bsf_hz,
        6000.0,
        modulation_hz=FREQ.ftf_hz,
        modulation_depth=0.8,
        jitter=0.01,
        noise=0.3,
        seed=3,
    )
    f, a = ind.envelope_spectrum(x, FS, (3000.0, 9000.0))
    top = ind.envelope_peaks(f, a, 5, max_hz=3000.0)
    assert top[0]["frequency_hz"] == pytest.approx(FREQ.two_bsf_hz, rel=0.01)
    floor = ind.noise_floor(f, a, 3000.0)
    side = ind.defect_line_amplitudes(f, a, FREQ)["two_bsf"]["sidebands"]
    assert side["lower"] > 5 * floor and side["upper"] > 5 * floor


def test_healthy_noise_has_no_defect_line():
    """Gaussian noise alone: no defect-frequency line (or harmonic) is significant, i.e. exceeds
    ind.SIGNIFICANCE = 4 times the median floor of its envelope spectrum (Rayleigh bins: the largest
    of the ~700 inspected bins is typically ~3 x the median)."""
    x = np.random.default_rng(4).normal(0.0, 1.0, int(2 * FS))
    f, a = ind.envelope_spectrum(x, FS, (3000.0, 9000.0))
    floor = ind.noise_floor(f, a, 3000.0)
    lines = ind.defect_line_amplitudes(f, a, FREQ)
    worst = max(max(v["harmonics"]) for v in lines.values())
    assert worst < ind.SIGNIFICANCE * floor


def test_resonance_band_and_bad_band():
    lo, hi = ind.resonance_band(16000.0, 0.05, FS, min_bandwidth_hz=3000.0)
    assert (lo, hi) == pytest.approx((13600.0, 18400.0))
    with pytest.raises(ValueError, match="band_hz"):
        ind.envelope_spectrum(np.zeros(4096), FS, (100.0, 30000.0))


def test_amplitude_spectrum_parseval_and_a_line_reads_its_amplitude():
    """The window's acceleration spectrum (0 - fs/2, power-summed bins): 1 s at 51.2 kHz gives
    ceil(25601 / 2000) = 13 FFT bins per bin (13 Hz, 1970 bins). Parseval (Oppenheim & Schafer,
    Table 8.2, one-sided): sum A^2 / 2 = the mean-removed window's mean square, to rounding
    (rel 1e-9). A sine of 2 m/s^2 off the FFT grid (1234.37 Hz) in noise: its bin and the two
    beside it hold its power, sqrt(sum A^2) = 2 within 1 % (the rectangular window's leakage beyond
    +-13 FFT bins is ~2/(pi^2 13) = 1.6 % of the power; the noise adds 0.05 %), and the largest bin
    is the one holding 1234.37 Hz."""
    rng = np.random.default_rng(5)
    t = np.arange(int(FS)) / FS
    x = 2.0 * np.sin(2 * np.pi * 1234.37 * t + 0.3) + rng.normal(0.0, 0.2, t.size) + 4.0
    start, step, a = ind.amplitude_spectrum(x, FS)
    assert (a.size, step, start) == (1970, 13.0, 6.0)
    ms = ind.time_indicators(x)["rms_m_s2"] ** 2
    assert np.sum(a**2) / 2.0 == pytest.approx(ms, rel=1e-9)
    j = int(np.argmax(a))
    assert abs(start + j * step - 1234.37) <= 0.5 * step
    assert math.sqrt(np.sum(a[j - 1 : j + 2] ** 2)) == pytest.approx(2.0, rel=0.01)
    # no binning below max_bins: 2 |X_k| / N on the FFT grid, Parseval with the Nyquist bin's weight
    y = x[:4096]
    start, step, b = ind.amplitude_spectrum(y, FS, max_bins=5000)
    assert (start, step, b.size) == (0.0, FS / 4096, 2049)
    spec = np.fft.rfft(y - y.mean())
    assert b[1:-1] == pytest.approx(2.0 * np.abs(spec[1:-1]) / y.size, rel=1e-12)
    assert np.sum(b**2) / 2.0 == pytest.approx(np.mean((y - y.mean()) ** 2), rel=1e-9)


def test_envelope_spectrum_view_keeps_the_bins_up_to_the_limit_or_peak_holds():
    """Up to max_hz the envelope spectrum's own values (same array, same bins); more than max_bins
    bins are peak-held (a line keeps its height)."""
    f = np.arange(3001) * 0.5
    a = np.random.default_rng(1).random(f.size)
    a[2001] = 7.0  # 1000.5 Hz
    start, step, v = ind.envelope_spectrum_view(f, a, 1200.0)
    assert (start, step, v.size) == (0.0, 0.5, 2401) and np.array_equal(v, a[:2401])
    start, step, v = ind.envelope_spectrum_view(f, a, 1200.0, max_bins=1000)
    assert (step, v.size, start) == (1.5, 801, 0.5)
    assert v.max() == 7.0 and abs(start + np.argmax(v) * step - 1000.5) <= 0.5 * step
