"""In-kernel decimation and sensor noise (twin.vibration.signal) on synthetic tones."""

import math

import numpy as np
import pytest
import scipy.signal

from twin.vibration.signal import (
    add_sensor_noise,
    decimate_block,
    design_decimator,
    integer_ratio_time_step,
    noise_sigma,
    seed_sensor_noise,
)

F_OUT = 51200.0


def test_time_step_is_snapped_to_an_integer_ratio():
    dt, r = integer_ratio_time_step(1e-6, F_OUT)
    assert r == 20 and dt == pytest.approx(1 / (20 * F_OUT), rel=1e-15) and dt <= 1e-6
    dt, r = integer_ratio_time_step(5e-6, F_OUT)
    assert r == 4 and dt == pytest.approx(4.8828125e-6, rel=1e-15)
    dt, r = integer_ratio_time_step(1 / (8 * F_OUT), F_OUT)  # exact already: kept
    assert r == 8
    with pytest.raises(ValueError, match="time step"):
        integer_ratio_time_step(20e-6, F_OUT)
    with pytest.raises(ValueError, match="integer"):
        design_decimator(1e6, F_OUT)  # 19.53: not an integer


@pytest.mark.parametrize("ratio", [20, 8, 4])
def test_streaming_form_equals_the_direct_convolution(ratio):
    """decimator_push (one sample per call, transposed polyphase) gives exactly the FIR output
    (np.convolve) at every R-th input: out[k] = (h * x)[(k + 1) R - 1] (1e-12)."""
    d = design_decimator(ratio * F_OUT, F_OUT)
    x = np.random.default_rng(ratio).standard_normal(30_000)
    out = np.zeros(x.size // ratio + 1)
    k = decimate_block(d.phases, d.new_state(), x, out)
    ref = np.convolve(x, d.taps)[(np.arange(k) + 1) * ratio - 1]
    assert k == x.size // ratio
    assert np.max(np.abs(out[:k] - ref)) < 1e-12


@pytest.mark.parametrize("ratio", [20, 6, 4])
def test_direct_form_equals_the_polyphase_form(ratio):
    """decimator_push_direct (the kernel's: doubled history, one vectorised dot product every R-th
    input) gives the outputs of decimator_push, and of the convolution, to rounding (1e-12)."""
    from numba import njit

    from twin.vibration.signal import decimator_push_direct

    @njit
    def block(taps, r, state, x, out):
        k = 0
        for i in range(x.shape[0]):
            ready, y = decimator_push_direct(taps, r, state, x[i])
            if ready:
                out[k] = y
                k += 1
        return k

    d = design_decimator(ratio * F_OUT, F_OUT)
    x = np.random.default_rng(7 + ratio).standard_normal(20_000)
    direct = np.zeros(x.size // ratio + 1)
    poly = np.zeros_like(direct)
    k = block(d.reversed_taps, ratio, d.new_direct_state(), x, direct)
    assert k == decimate_block(d.phases, d.new_state(), x, poly) == x.size // ratio
    assert np.max(np.abs(direct[:k] - poly[:k])) < 1e-12
    ref = np.convolve(x, d.taps)[(np.arange(k) + 1) * ratio - 1]
    assert np.max(np.abs(direct[:k] - ref)) < 1e-12


def _tone_gain(d, f_hz, seconds=0.05):
    """Amplitude of the decimated output of a unit tone at f_hz, least-squares fitted at its
    (possibly aliased) output frequency, start-up discarded."""
    n = int(seconds * d.input_rate_hz)
    t = np.arange(n) / d.input_rate_hz
    x = np.sin(2 * np.pi * f_hz * t + 0.3)
    out = np.zeros(n // d.ratio + 1)
    k = decimate_block(d.phases, d.new_state(), x, out)
    y = out[d.ring : k]
    f_alias = abs(((f_hz + 0.5 * F_OUT) % F_OUT) - 0.5 * F_OUT)
    tt = np.arange(y.size) / F_OUT
    basis = np.column_stack([np.sin(2 * np.pi * f_alias * tt), np.cos(2 * np.pi * f_alias * tt)])
    coef, *_ = np.linalg.lstsq(basis, y, rcond=None)
    residual = y - basis @ coef
    return math.hypot(*coef), float(np.sqrt(np.mean(residual**2)))


@pytest.mark.parametrize("ratio", [20, 4])
def test_passband_is_flat_and_stopband_does_not_alias(ratio):
    """Kaiser FIR, 80 dB design: tones up to 0.4 f_out = 20.48 kHz come through with gain 1 +- 2e-4
    (0.002 dB) and nothing else; tones from 0.5 f_out = 25.6 kHz up to the input Nyquist come out
    below -78 dB (1.26e-4), where plain sample-dropping would fold them into the band at full
    amplitude (e.g. 40 kHz -> 11.2 kHz)."""
    d = design_decimator(ratio * F_OUT, F_OUT)
    for f in (100.0, 5000.0, 15000.0, 16090.0, 20000.0):
        gain, residual = _tone_gain(d, f)
        assert gain == pytest.approx(1.0, abs=2e-4), f
        assert residual < 1e-4, f
    nyq_in = 0.5 * d.input_rate_hz
    for f in (25700.0, 30000.0, 40000.0, 61000.0, 0.77 * nyq_in, 0.97 * nyq_in):
        gain, _ = _tone_gain(d, f)
        assert gain < 1.26e-4, (f, gain)
    # the same 40 kHz tone, decimated without the filter, lands at 11.2 kHz with unit amplitude
    t = np.arange(int(0.05 * d.input_rate_hz)) / d.input_rate_hz
    naive = np.sin(2 * np.pi * 40000.0 * t)[::ratio]
    assert np.max(np.abs(np.fft.rfft(naive))) * 2 / naive.size > 0.9


def test_design_size_and_delay():
    """~1000 taps at R = 20 (K = 51 multiply-adds per input step), ~200 at R = 4; group delay
    (N - 1) / 2 input samples (~0.5 ms at 1 MHz)."""
    d20 = design_decimator(20 * F_OUT, F_OUT)
    d4 = design_decimator(4 * F_OUT, F_OUT)
    assert 900 < d20.taps_used < 1100 and d20.ring == -(-d20.taps_used // 20)
    assert 180 < d4.taps_used < 230
    assert d20.delay_s == pytest.approx(0.5 * (d20.taps_used - 1) / (20 * F_OUT))
    assert d20.sample_time_s(0) == pytest.approx((20 - 1 - 0.5 * (d20.taps_used - 1)) / (20 * F_OUT))


def test_sensor_noise_has_the_stated_density():
    """White noise of rho = 1e-3 m/s^2/sqrt(Hz) at 51.2 kHz: sigma = rho sqrt(fs/2) = 0.16 m/s^2,
    Welch one-sided PSD flat at rho^2 (mean within 2 %); sigma 0 adds nothing; seeded: reproducible."""
    rho = 1e-3
    sigma = noise_sigma(rho, F_OUT)
    assert sigma == pytest.approx(rho * math.sqrt(F_OUT / 2))
    seed_sensor_noise(7)
    y = np.array([add_sensor_noise(0.0, sigma) for _ in range(2**17)])
    f, psd = scipy.signal.welch(y, fs=F_OUT, nperseg=4096)
    assert np.mean(psd[1:-1]) == pytest.approx(rho**2, rel=0.02)
    seed_sensor_noise(7)
    again = np.array([add_sensor_noise(0.0, sigma) for _ in range(100)])
    assert np.array_equal(again, y[:100])
    assert add_sensor_noise(1.5, 0.0) == 1.5


def test_sensor_push_fills_a_ring_the_reader_drains():
    """sensor_push = decimator + noise + ring: the samples read back in order equal the block
    decimation; a reader that falls more than a ring behind is told how many it lost."""
    from twin.vibration.signal import read_ring, sensor_push

    d = design_decimator(8 * F_OUT, F_OUT)
    x = np.random.default_rng(1).standard_normal(8 * 700)
    ref = np.zeros(800)
    k = decimate_block(d.phases, d.new_state(), x, ref)
    state = d.new_state()
    ring = np.zeros(256)
    ring_state = np.zeros(1)
    got, cursor = [], 0
    for i, xi in enumerate(x):
        sensor_push(d.phases, state, xi, 0.0, ring, ring_state)
        if i % 1000 == 999:  # a reader between frames
            new, cursor, lost = read_ring(ring, ring_state, cursor)
            assert lost == 0
            got.append(new)
    new, cursor, lost = read_ring(ring, ring_state, cursor)
    got.append(new)
    assert np.array_equal(np.concatenate(got), ref[:k]) and cursor == k == 700
    new, cursor, lost = read_ring(ring, ring_state, 0)  # a reader 700 behind a 256 ring
    assert lost == 700 - 256 and np.array_equal(new, ref[700 - 256 : 700])
