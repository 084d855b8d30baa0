"""`run_vibration` (backend of `bearing-twin vibration`) on a synthetic housing signal."""

import json

import numpy as np
import pytest

from twin import catalog
from twin.vibration.defect_frequencies import bearing_defect_frequencies
from twin.vibration.housing import Housing, sensor_resonance
from twin.vibration.run import run_vibration

FS = 51200.0
G6208 = catalog.bearing("6208").geometry


@pytest.fixture(scope="module")
def outer_signal(fault_signal):
    """3 s of a 6208 outer-race fault at 500 rad/s ringing the default housing's sensed resonance."""
    freq = bearing_defect_frequencies(catalog.bearing("6208").geometry, 500.0)
    f_r, zeta = sensor_resonance(Housing())
    return freq, fault_signal(FS, 3.0, freq.bpfo_hz, f_r, damping_ratio=zeta, jitter=0.01, noise=0.3, seed=5)


@pytest.mark.parametrize("band", ["resonance", "kurtogram"])
def test_outer_race_signal_reports_bpfo(outer_signal, band):
    """The CLI JSON: defect frequencies from the geometry, three 1 s windows, the largest of the
    five envelope peaks within 1 % of BPFO, kurtosis above Gaussian, finite JSON."""
    freq, x = outer_signal
    r = run_vibration(x, FS, G6208, 500.0, band=band)
    assert r["sample_rate_hz"] == FS and r["windows"] == 3
    assert set(r["defect_frequencies_hz"]) >= {"ftf", "bpfo", "bpfi", "bsf"}
    assert r["defect_frequencies_hz"]["bpfo"] == pytest.approx(freq.bpfo_hz, rel=1e-12)
    peaks = r["envelope_peaks_hz"]
    assert len(peaks) == 5 and peaks[0]["amplitude"] >= peaks[-1]["amplitude"]
    assert peaks[0]["frequency_hz"] == pytest.approx(freq.bpfo_hz, rel=0.01)
    assert r["kurtosis"] > 3.2
    assert r["rms_m_s2"] > 0 and r["velocity_rms_mm_s"] > 0
    lo, hi = r["envelope_band_hz"]
    assert lo < sensor_resonance(Housing())[0] < hi
    json.dumps(r, allow_nan=False)


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="non-finite"):
        run_vibration(np.array([0.0, np.nan] * 4096), FS, G6208, 500.0)
    with pytest.raises(ValueError, match="samples per window"):
        run_vibration(np.zeros(100), FS, G6208, 500.0)
    with pytest.raises(ValueError, match="band"):
        run_vibration(np.zeros(51200), FS, G6208, 500.0, band="wideband")
    with pytest.raises(ValueError, match="window_s"):
        run_vibration(np.zeros(51200), FS, G6208, 500.0, window_s=0.0)
