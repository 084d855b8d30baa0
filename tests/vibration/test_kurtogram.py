"""Antoni's fast kurtogram (twin.vibration.kurtogram; J. Antoni, MSSP 21 (2007) 108-124)."""

import math

import numpy as np
import pytest
import scipy.signal

from twin.vibration import kurtogram as K

FS = 12000.0


@pytest.mark.parametrize(
    "taps, factor, column",
    [(K._BINARY_TAPS, 2, 0), (K._BINARY_TAPS, 2, 1), (K._TERNARY_TAPS, 3, 0), (K._TERNARY_TAPS, 3, 2)],
)
def test_filter_bank_is_the_reference_filter_and_decimation(taps, factor, column):
    """Each split is the reference implementation's filter(h, 1, x) kept at x(factor:factor:N)
    (Fast_Kurtogram.m, DBFB / TBFB), to round-off (1e-12)."""
    x = np.random.default_rng(3).standard_normal((2, 1001)) + 0j
    ref = scipy.signal.lfilter(taps[:, column], 1.0, x, axis=1)[:, factor - 1 :: factor][:, : 1001 // factor]
    assert np.max(np.abs(K._filter_bank(x, taps, factor)[:, :, column] - ref)) < 1e-12


def test_levels_and_bandwidths_of_the_tree():
    """Levels 0, 1, log2 3, 2, 1 + log2 3, ..., nlevel (Antoni 2007 fig. 4) with bands fs / 2^(k+1)
    wide; 2 nlevel rows of 3 x 2^nlevel columns."""
    kg = K.fast_kurtogram(np.random.default_rng(0).standard_normal(2**13), FS, nlevel=4)
    expected = [0, 1, math.log2(3), 2, 1 + math.log2(3), 3, 2 + math.log2(3), 4]
    assert kg.levels == pytest.approx(expected, abs=1e-12)
    assert kg.bandwidth_hz == pytest.approx(FS * 2.0 ** -(np.array(expected) + 1.0), rel=1e-12)
    assert kg.kurtosis.shape == (8, 3 * 2**4)


def test_gaussian_noise_is_not_impulsive():
    """White Gaussian noise: the complex envelope of a band is circular Gaussian, kurtosis 0
    (eq. 8). The bands at 0 Hz and fs / 2 are not quite analytic (the short filters' skirts pass
    the mirror frequencies), which biases them up: the largest value over the 12 levels of 10 s at
    12 kHz is 0.20-0.22 (three seeds), below 0.3, against > 1 for the impulses of the next test."""
    kg = K.fast_kurtogram(np.random.default_rng(1).standard_normal(int(10 * FS)), FS, nlevel=6)
    assert kg.band_kurtosis < 0.3


def test_impulses_ringing_a_resonance_are_found(fault_signal):
    """Impulses at 100 Hz (1 % jitter) ringing a 3.5 kHz, 2 % damped resonance in noise of the same
    RMS as the impulses' response: the chosen band holds 3.5 kHz and is impulsive (K > 1)."""
    x = fault_signal(FS, 5.0, 100.0, 3500.0, damping_ratio=0.02, jitter=0.01, noise=0.0, seed=4)
    x = x + np.std(x) * np.random.default_rng(5).standard_normal(x.size)
    kg = K.fast_kurtogram(x, FS, min_bandwidth_hz=400.0)
    lo, hi = kg.band_hz
    assert lo < 3500.0 < hi and kg.band_kurtosis > 1.0


def test_short_signal_and_impossible_band_are_refused():
    with pytest.raises(ValueError, match="signal"):
        K.fast_kurtogram(np.zeros(200), FS)
    with pytest.raises(ValueError, match="min_bandwidth_hz"):
        K.fast_kurtogram(np.random.default_rng(0).standard_normal(4096), FS, min_bandwidth_hz=7000.0)
