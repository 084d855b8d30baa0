"""In-kernel sampling of the accelerometer: anti-aliased decimation by an integer ratio, sensor noise.

The engine produces one acceleration per DEM step (1/dt: ~1 MHz at dt = 1 us, 200-500 kHz at
2-5 us); the sensor is read at f_out (51.2 kHz by default). Decimation by R = f_in / f_out needs
a low-pass first, or everything above f_out / 2 folds into the band (Oppenheim & Schafer,
Discrete-Time Signal Processing, 3rd ed., sec. 4.6.1; Crochiere & Rabiner, Multirate Digital
Signal Processing, 1983, ch. 3 polyphase structures).

Design (`design_decimator`, Python, once per model): a linear-phase FIR low-pass at the input
rate, Kaiser window (scipy.signal.kaiserord / firwin), passband to 0.4 f_out (like the 0.45 f_s
of a DAQ's delta-sigma converter; the 15-16 kHz housing resonance is inside it at 51.2 kHz),
stopband from 0.5 f_out: nothing folds back into [0, f_out / 2); ripple and attenuation
`attenuation_db` (80 dB: 1e-4, i.e. 0.001 dB passband ripple). Taps: ~ (A - 7.95) /
(2.285 * 2 pi * 0.1 / R), e.g. 1000 at R = 20, 200 at R = 4.

Streaming (`decimator_push`, numba, one input sample per call, no allocation): a transposed
polyphase form: each input is multiplied into the K = ceil(N / R) outputs it belongs to, held in
an accumulator ring; every R-th input completes one output. The work per input is the same K
multiply-adds at every step (no burst every R steps), ~N / R = 50 at the default design.

The ratio R must be an integer: the time step is snapped to dt = 1 / (R f_out)
(`integer_ratio_time_step`) so that the output rate is exactly f_out; the waveform header carries
the rate.

Sensor noise (`noise_sigma`, `add_sensor_noise`): white noise of one-sided density rho
[m/s^2/sqrt(Hz)] sampled at f_out has variance rho^2 f_out / 2 (its power spread over 0..f_out/2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.signal
from numba import njit

from twin.jit import JIT

JIT_INLINE = dict(JIT, inline="always")  # called by the kernel every step (twin.vibration.housing)

PASSBAND_FRACTION = 0.4  # of the output rate
STOPBAND_FRACTION = 0.5

# decimator state vector layout (float64): counters, then the accumulator ring
DS_PHASE = 0  # input index modulo R
DS_POS = 1  # ring slot of the newest output (output index modulo K)
DS_OUTPUTS = 2  # outputs produced since reset
N_DS_HEADER = 3


@dataclass(frozen=True)
class DecimatorDesign:
    """FIR decimator: taps (length K R, zero-padded), ratio R, ring length K, rates [Hz]."""

    taps: np.ndarray
    ratio: int
    ring: int
    input_rate_hz: float
    output_rate_hz: float

    taps_used: int = 0

    @property
    def delay_s(self) -> float:
        """Group delay of the linear-phase filter [s]: (N - 1) / 2 input samples."""
        return 0.5 * (self.taps_used - 1) / self.input_rate_hz

    @property
    def phases(self) -> np.ndarray:
        """Polyphase taps (R, K), contiguous: phases[r, i] = taps[K R - 1 - r - i R], the tap input
        n (n mod R = r) contributes to the i-th newest pending output."""
        idx = self.ring * self.ratio - 1 - np.arange(self.ratio)[:, None] - self.ratio * np.arange(self.ring)[None, :]
        out = np.ascontiguousarray(self.taps[idx])
        out.setflags(write=False)
        return out

    def sample_time_s(self, k: int, first_input_time_s: float = 0.0) -> float:
        """Time [s] that output k stands for, given the time of the first input: output k is the
        filtered signal at input (k + 1) R - 1, whose content is centred (N - 1) / 2 inputs earlier.
        The first K - 1 outputs are start-up (filter partly filled)."""
        n = (k + 1) * self.ratio - 1 - 0.5 * (self.taps_used - 1)
        return first_input_time_s + n / self.input_rate_hz

    def new_state(self) -> np.ndarray:
        """A zeroed state vector for `decimator_push`."""
        return np.zeros(N_DS_HEADER + self.ring)

    @property
    def reversed_taps(self) -> np.ndarray:
        """The K R taps reversed, contiguous (`decimator_push_direct`): reversed_taps[j] multiplies
        the j-th oldest of the last K R inputs."""
        out = np.ascontiguousarray(self.taps[::-1])
        out.setflags(write=False)
        return out

    def new_direct_state(self) -> np.ndarray:
        """A zeroed state vector for `decimator_push_direct` (counters + a doubled input history)."""
        return np.zeros(N_DD_HEADER + 2 * self.ring * self.ratio)


def integer_ratio_time_step(max_time_step_s: float, output_rate_hz: float) -> tuple[float, int]:
    """(dt [s], R): the largest time step <= max_time_step_s with 1 / dt an integer multiple R of
    output_rate_hz. E.g. (1 us, 51.2 kHz) -> (0.9766 us, 20); (5 us, 51.2 kHz) -> (4.883 us, 4)."""
    if not (max_time_step_s > 0.0 and output_rate_hz > 0.0):
        raise ValueError("max_time_step_s and output_rate_hz must be positive")
    ratio = math.ceil(1.0 / (max_time_step_s * output_rate_hz) - 1e-9)
    if ratio < 2:
        raise ValueError(
            f"output_rate_hz = {output_rate_hz:g} Hz: needs a time step below "
            f"{0.5 / output_rate_hz:g} s (at least 2 steps per sample), got {max_time_step_s:g} s"
        )
    return 1.0 / (ratio * output_rate_hz), ratio


def design_decimator(
    input_rate_hz: float,
    output_rate_hz: float,
    attenuation_db: float = 80.0,
    passband_fraction: float = PASSBAND_FRACTION,
    stopband_fraction: float = STOPBAND_FRACTION,
) -> DecimatorDesign:
    """Kaiser-window FIR low-pass for decimation from input_rate_hz to output_rate_hz (module
    docstring). The ratio must be an integer within 1e-6 (see `integer_ratio_time_step`)."""
    ratio_f = input_rate_hz / output_rate_hz
    ratio = int(round(ratio_f))
    if ratio < 2 or abs(ratio_f - ratio) > 1e-6 * ratio_f:
        raise ValueError(
            f"input_rate_hz / output_rate_hz = {ratio_f:.6g}: must be an integer >= 2 "
            "(snap the time step with integer_ratio_time_step)"
        )
    if not 0.0 < passband_fraction < stopband_fraction <= 0.5 * ratio:
        raise ValueError("need 0 < passband_fraction < stopband_fraction")
    nyq = 0.5 * input_rate_hz
    width = (stopband_fraction - passband_fraction) * output_rate_hz / nyq
    n, beta = scipy.signal.kaiserord(attenuation_db, width)
    n |= 1  # odd length: type I linear phase
    cutoff = 0.5 * (passband_fraction + stopband_fraction) * output_rate_hz
    h = scipy.signal.firwin(n, cutoff, window=("kaiser", beta), fs=input_rate_hz)
    ring = -(-n // ratio)
    taps = np.zeros(ring * ratio)
    taps[:n] = h
    taps.setflags(write=False)
    return DecimatorDesign(
        taps=taps,
        ratio=ratio,
        ring=ring,
        input_rate_hz=float(input_rate_hz),
        output_rate_hz=float(output_rate_hz),
        taps_used=int(n),
    )


@njit(**JIT)
def decimator_push(phases, state, x):
    """Push one input sample x into the decimator (transposed polyphase form, module docstring).

    phases: the (R, K) polyphase taps of `DecimatorDesign.phases`; state: the N_DS_HEADER + K
    float64 of `DecimatorDesign.new_state` (zeros to reset). Returns (ready, y): ready on every
    R-th input; the k-th output (k = 0, 1, ...) is the filtered signal at input (k + 1) R - 1.
    No division, no allocation: K multiply-adds per call."""
    ratio = phases.shape[0]
    ring = phases.shape[1]
    r = int(state[DS_PHASE])
    p = int(state[DS_POS])
    row = phases[r]
    # output slots p, p-1, ..., 0, K-1, ..., p+1 take taps i = 0 .. K-1 of this phase
    for i in range(p + 1):
        state[N_DS_HEADER + p - i] += row[i] * x
    for i in range(p + 1, ring):
        state[N_DS_HEADER + ring + p - i] += row[i] * x
    if r == ratio - 1:
        slot = N_DS_HEADER + (p + 1 if p + 1 < ring else 0)  # the oldest output: p - (K - 1)
        y = state[slot]
        state[slot] = 0.0
        state[DS_PHASE] = 0.0
        state[DS_POS] = float(p + 1 if p + 1 < ring else 0)
        state[DS_OUTPUTS] += 1.0
        return True, y
    state[DS_PHASE] = float(r + 1)
    return False, 0.0


@njit(**JIT)
def decimate_block(phases, state, x, out):
    """`decimator_push` over an array x; writes the completed outputs to out (length >= len(x) //
    ratio + 1) and returns how many (offline use and tests; the kernel pushes one per step)."""
    k = 0
    for i in range(x.shape[0]):
        ready, y = decimator_push(phases, state, x[i])
        if ready:
            out[k] = y
            k += 1
    return k


def noise_sigma(noise_density_m_s2_rthz: float, sample_rate_hz: float) -> float:
    """Standard deviation [m/s^2] of white noise of one-sided density rho sampled at f_s:
    rho sqrt(f_s / 2)."""
    return noise_density_m_s2_rthz * math.sqrt(0.5 * sample_rate_hz)


@njit(**JIT)
def seed_sensor_noise(seed):
    """Seed numba's generator (per thread) for reproducible sensor noise."""
    np.random.seed(seed)


@njit(**JIT)
def add_sensor_noise(y, sigma):
    """y + N(0, sigma^2) [m/s^2] (sigma from `noise_sigma`; 0 leaves y unchanged)."""
    if sigma > 0.0:
        return y + sigma * np.random.standard_normal()
    return y


# ---- direct form: the kernel's decimator ---------------------------------------------------------
# The transposed polyphase form above spreads K multiply-adds over every input, in a ring whose
# wrap-around LLVM cannot vectorise (measured ~150 ns per input on the 2-core test machine). The
# direct form keeps the last K R inputs twice in a row (written at pos and pos + K R), so that the
# history is always one contiguous slice, and computes an output every R-th input as one dot
# product that LLVM vectorises (reassociation allowed for that sum only; the same outputs as the
# polyphase form to rounding, tests/vibration/test_signal.py): K R / R = K multiply-adds per input
# on average, in SIMD. Its outputs come in a burst every R steps, which a frame of the engine does not see.
DD_POS = 0  # next history slot (input index modulo K R)
DD_PHASE = 1  # input index modulo R
DD_OUTPUTS = 2  # outputs produced since reset
N_DD_HEADER = 3


@njit(**dict(JIT, fastmath={"reassoc", "contract"}))
def _dot(taps, history, start):
    """sum_j taps[j] history[start + j] (reassociation allowed: vectorised)."""
    acc = 0.0
    for j in range(taps.shape[0]):
        acc += taps[j] * history[start + j]
    return acc


@njit(**JIT_INLINE)
def decimator_push_direct(reversed_taps, ratio, state, x):
    """Push one input sample x into the direct-form decimator (comment above): reversed_taps from
    `DecimatorDesign.reversed_taps`, ratio R, state from `new_direct_state` (zeros to reset).
    Returns (ready, y): ready on every R-th input; the k-th output is the filtered signal at input
    (k + 1) R - 1, as `decimator_push`."""
    n = reversed_taps.shape[0]
    pos = int(state[DD_POS])
    state[N_DD_HEADER + pos] = x
    state[N_DD_HEADER + pos + n] = x
    pos += 1
    if pos == n:
        pos = 0
    state[DD_POS] = float(pos)
    r = int(state[DD_PHASE]) + 1
    if r < ratio:
        state[DD_PHASE] = float(r)
        return False, 0.0
    state[DD_PHASE] = 0.0
    state[DD_OUTPUTS] += 1.0
    # the last n inputs, oldest first, are history[pos .. pos + n)
    return True, _dot(reversed_taps, state, N_DD_HEADER + pos)


# ---- the sensor as the kernel sees it: decimator + noise + a ring of output samples ---------------
RS_WRITTEN = 0  # ring state: output samples written since reset (the reader's cursor is its own)
N_RS_HEADER = 1


@njit(**JIT)
def sensor_push(phases, dec_state, a_m_s2, sigma, ring, ring_state):
    """One DEM step of the accelerometer (the one call the kernel makes per step): push the sensed
    acceleration a [m/s^2] into the decimator; when an output sample completes, add the sensor
    noise (sigma [m/s^2], `noise_sigma`) and write it into `ring` (1-D, float32 or float64, written
    modulo its length) at ring_state[RS_WRITTEN], which then counts up. Returns True when a sample
    was written."""
    ready, y = decimator_push(phases, dec_state, a_m_s2)
    if ready:
        k = int(ring_state[RS_WRITTEN])
        ring[k % ring.shape[0]] = add_sensor_noise(y, sigma)
        ring_state[RS_WRITTEN] = k + 1
    return ready


@njit(**JIT_INLINE)
def sensor_push_direct(reversed_taps, ratio, dec_state, a_m_s2, ring, ring_state):
    """The kernel's call: `sensor_push` with the direct-form decimator (`decimator_push_direct`)
    and without noise. The engine adds the sensor noise to the drained samples between frames
    (twin.accelerometer, numpy, a generator per twin): a call site of numba's generator in the
    kernel cost ~90 ns per step on the test machine even with the noise off."""
    ready, y = decimator_push_direct(reversed_taps, ratio, dec_state, a_m_s2)
    if ready:
        k = int(ring_state[RS_WRITTEN])
        ring[k % ring.shape[0]] = y
        ring_state[RS_WRITTEN] = k + 1
    return ready


def read_ring(ring: np.ndarray, ring_state: np.ndarray, cursor: int) -> tuple[np.ndarray, int, int]:
    """Samples written since `cursor` (a count of samples, the reader's own): (samples in order,
    new cursor, samples lost because the ring wrapped over them before they were read). Python,
    between frames."""
    written = int(ring_state[RS_WRITTEN])
    size = ring.shape[0]
    lost = max(0, written - cursor - size)
    start = cursor + lost
    a, b = start % size, written % size
    if written - start == 0:
        out = ring[:0].copy()
    elif a < b:
        out = ring[a:b].copy()
    else:  # wraps (or exactly one full ring)
        out = np.concatenate((ring[a:], ring[:b]))
    return out, written, lost
