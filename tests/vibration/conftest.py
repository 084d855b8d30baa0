"""Synthetic housing signals with known answers (tests of twin.vibration)."""

import numpy as np
import pytest


def _fault_signal(
    sample_rate_hz,
    duration_s,
    rate_hz,
    resonance_hz,
    *,
    damping_ratio=0.05,
    amplitude=1.0,
    modulation_hz=None,
    modulation_depth=0.0,
    jitter=0.0,
    noise=0.0,
    seed=0,
):
    """Impulse train at rate_hz (period jitter: std as a fraction of the period, not cumulative,
    the 1-2 % random slip of real bearings, Randall & Antoni 2011 sec. 2.1), each impulse ringing
    a single-degree-of-freedom resonance (resonance_hz, damping_ratio), amplitudes modulated by
    (1 + depth cos 2 pi f_mod t) (the load zone: Randall & Antoni 2011 sec. 2.1, McFadden & Smith
    1984), plus white Gaussian noise of std `noise` [m/s^2]."""
    import scipy.signal

    rng = np.random.default_rng(seed)
    fs = float(sample_rate_hz)
    n = int(round(duration_s * fs))
    times = np.arange(0.0, duration_s, 1.0 / rate_hz)
    times = times + jitter / rate_hz * rng.standard_normal(times.size)
    times = times[(times >= 0.0) & (times < duration_s)]
    amps = np.full(times.size, amplitude)
    if modulation_hz:
        amps *= 1.0 + modulation_depth * np.cos(2.0 * np.pi * modulation_hz * times)
    pulses = np.zeros(n)
    np.add.at(pulses, np.minimum((times * fs).round().astype(int), n - 1), amps)
    w = 2.0 * np.pi * resonance_hz
    t = np.arange(int(12.0 / (damping_ratio * w) * fs)) / fs
    h = np.exp(-damping_ratio * w * t) * np.sin(w * np.sqrt(1.0 - damping_ratio**2) * t)
    x = scipy.signal.fftconvolve(pulses, h)[:n]
    return x + noise * rng.standard_normal(n)


@pytest.fixture(scope="session")
def fault_signal():
    """fault_signal(fs, duration, rate_hz, resonance_hz, **kw) -> samples [m/s^2]."""
    return _fault_signal
