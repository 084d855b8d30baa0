"""Between frames (Python): the accelerometer samples the kernel wrote into its ring become
waveform blocks (for the service to publish, `twin.vibration.waveform`) and, every window, the
indicators of the snapshot's `vibration` block.

The kernel pushes one housing acceleration per step into the anti-aliasing decimator
(`twin.vibration.signal.sensor_push_direct`); the engine calls `SensorReader.after_frame` after
every frame, which drains the ring every DRAIN_EVERY_S of signal (and `flush` when asked).
Output sample k (counted from the decimator's reset) stands for the time
`DecimatorDesign.sample_time_s(k, t_first_input)`: the filter's group delay is taken out, so the
waveform's t0 is the simulated time the sample describes. The first K - 1 outputs after a reset
are the filter's start-up (partly filled) and are dropped. White sensor noise of the accelerometer's
one-sided density rho (variance rho^2 f_s / 2, `signal.noise_sigma`) is added here, from a numpy
generator per twin seeded with `Accelerometer.noise_seed` (reproducible whatever the thread).

Every `Accelerometer.window_s` of samples the indicators are computed (`run_vibration`, envelope
band around the housing's sensed resonance; with the window's full envelope and amplitude spectra,
`VibrationState.envelope_spectrum` / `amplitude_spectrum`, kept out of the snapshot's JSON) with the defect frequencies
of the window's mean shaft
speed and the loaded contact angle measured on the contact lanes at the window's end
(`defect_frequencies.loaded_contact_angle_rad`; the nominal angle while no ball is loaded).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np

from twin.kernels import layout as L
from twin.snapshot import DefectFrequenciesHz, DefectLine, EnvelopePeak, Spectrum, VibrationState
from twin.vibration.defect_frequencies import loaded_contact_angle_rad
from twin.vibration.run import run_vibration
from twin.vibration.signal import noise_sigma, read_ring

WAVEFORM_QUEUE_S = 10.0  # undrained waveform kept for `drain_waveform` [s of signal]; older is dropped
# The engine drains the ring after every frame only once this much signal has accumulated (or when
# asked: `flush`, called by Twin.vibration and Twin.drain_waveform): a drain costs ~35 us of Python
# (numpy calls), ~110 ns per step if it were done after every 1 ms of simulated time.
DRAIN_EVERY_S = 0.01


@dataclass(frozen=True)
class WaveformBlock:
    """Contiguous accelerometer samples: sample k at t0_s + k / sample_rate_hz."""

    t0_s: float
    sample_rate_hz: float
    samples: np.ndarray  # float32 [m/s^2]
    lost_before: int = 0  # samples dropped just before this block (queue full or ring overrun)

    @property
    def times_s(self) -> np.ndarray:
        """Sample times [s]."""
        return self.t0_s + np.arange(self.samples.size) / self.sample_rate_hz


class SensorReader:
    """Drains the kernel's sample ring of one twin (module docstring)."""

    def __init__(self, model):
        self.model = model
        self.design = model.decimator
        acc = model.spec.housing.accelerometer
        self.sample_rate_hz = self.design.output_rate_hz
        self.window_s = acc.window_s
        self.window_samples = int(round(acc.window_s * self.sample_rate_hz))
        self._window = np.zeros(self.window_samples)
        self._queue: deque[list] = deque()  # [t0_s, list of float32 arrays, size, lost_before]
        self._queued = 0
        self._queue_cap = int(round(WAVEFORM_QUEUE_S * self.sample_rate_hz))
        self.lost = 0
        self.latest = None  # the last window's VibrationState
        # white sensor noise of the stated one-sided density, added to every drained sample
        self.noise_sigma_m_s2 = noise_sigma(acc.noise_density_m_s2_rthz, self.sample_rate_hz)
        self._rng = np.random.default_rng(acc.noise_seed)
        self._drain_steps = max(1, int(round(DRAIN_EVERY_S / model.dt_s)))
        self.reset(0.0)

    def reset(self, time_s: float) -> None:
        """The decimator and the ring restart at `time_s` [s] (a warm start or restart): the next
        step's acceleration is the filter's first input. The partial window is dropped."""
        self._cursor = 0
        self._first_input_s = time_s + self.model.dt_s
        self._fill = 0
        self._speed_sum = 0.0
        self._break = True
        self._pending_steps = 0
        self._pending_speed = 0.0

    def after_frame(self, state, steps: int, shaft_speed_rad_s: float) -> None:
        """After a frame of `steps` steps at `shaft_speed_rad_s` [rad/s]: drain once DRAIN_EVERY_S
        of steps are pending (their samples get the mean shaft speed of those frames)."""
        self._pending_steps += steps
        self._pending_speed += steps * shaft_speed_rad_s
        if self._pending_steps >= self._drain_steps:
            self.flush(state)

    def flush(self, state) -> bool:
        """Drain what the frames since the last drain wrote (`drain`); returns whether a window
        completed."""
        if self._pending_steps == 0:
            return False
        speed = self._pending_speed / self._pending_steps
        self._pending_steps = 0
        self._pending_speed = 0.0
        return self.drain(state, speed)

    def drain(self, state, shaft_speed_rad_s: float) -> bool:
        """Move the samples written since the last call out of the ring; returns whether a window
        completed (its indicators are then in `latest`)."""
        samples, written, lost = read_ring(state.sample_ring_m_s2, state.sample_ring_state, self._cursor)
        self._cursor = written
        if lost:
            self.lost += lost
            self._break = True
        k0 = written - samples.size
        skip = max(0, self.design.ring - 1 - k0)
        if skip >= samples.size:
            return False
        samples = samples[skip:]
        k0 += skip
        if self.noise_sigma_m_s2 > 0.0:
            samples = samples + (self.noise_sigma_m_s2 * self._rng.standard_normal(samples.size)).astype(np.float32)
        t0 = self.design.sample_time_s(k0, self._first_input_s)
        self._enqueue(t0, samples, lost)
        return self._feed_window(samples, t0, state, shaft_speed_rad_s)

    def _enqueue(self, t0: float, samples: np.ndarray, lost: int) -> None:
        if self._break or not self._queue:
            self._queue.append([t0, [samples], samples.size, lost])
            self._break = False
        else:
            block = self._queue[-1]
            block[1].append(samples)
            block[2] += samples.size
        self._queued += samples.size
        while self._queued > self._queue_cap and self._queue:
            oldest = self._queue[0]
            excess = self._queued - self._queue_cap
            if excess >= oldest[2]:
                self._queue.popleft()
                self._queued -= oldest[2]
                self.lost += oldest[2]
                if self._queue:
                    self._queue[0][3] += oldest[2] + oldest[3]
                continue
            data = np.concatenate(oldest[1])[excess:]
            oldest[0] += excess / self.sample_rate_hz
            oldest[1] = [data]
            oldest[2] = data.size
            oldest[3] += excess
            self._queued -= excess
            self.lost += excess

    def drain_waveform(self) -> list[WaveformBlock]:
        """The samples not yet taken, as contiguous blocks (oldest first); empties the queue."""
        out = [
            WaveformBlock(
                t0_s=float(t0),
                sample_rate_hz=self.sample_rate_hz,
                samples=np.concatenate(parts).astype(np.float32, copy=False),
                lost_before=int(lost),
            )
            for t0, parts, _, lost in self._queue
        ]
        self._queue.clear()
        self._queued = 0
        self._break = True
        return out

    def _feed_window(self, samples: np.ndarray, t0: float, state, shaft_speed_rad_s: float) -> bool:
        done = False
        i = 0
        n = samples.size
        while i < n:
            take = min(n - i, self.window_samples - self._fill)
            self._window[self._fill : self._fill + take] = samples[i : i + take]
            self._speed_sum += take * shaft_speed_rad_s
            self._fill += take
            i += take
            if self._fill == self.window_samples:
                end = t0 + (i - 1) / self.sample_rate_hz
                self.latest = window_indicators(
                    self.model, self._window, self._speed_sum / self.window_samples, state, end
                )
                self._fill = 0
                self._speed_sum = 0.0
                done = True
        return done


def contact_angle_of_lanes_rad(model, state) -> float:
    """Loaded contact angle [rad] of the state's lanes (nominal while no ball is loaded)."""
    c = state.contacts
    try:
        return loaded_contact_angle_rad(c[L.G_NZ], c[L.C_LOAD])
    except ValueError:
        return model.contact_angle_rad


def window_indicators(model, window_m_s2: np.ndarray, shaft_speed_rad_s: float, state, end_time_s: float):
    """`twin.snapshot.VibrationState` of one window (module docstring)."""
    fs = model.decimator.output_rate_hz
    angle = contact_angle_of_lanes_rad(model, state)
    r = run_vibration(
        window_m_s2,
        fs,
        model.spec,
        shaft_speed_rad_s,
        contact_angle_rad=angle,
        housing=model.spec.housing,
        window_s=window_m_s2.size / fs,
        spectra=True,
    )
    lines = {
        name: DefectLine(
            frequency_hz=v["frequency_hz"],
            harmonics=tuple(v["harmonics"]),
            sidebands=(v["sidebands"]["lower"], v["sidebands"]["upper"]) if "sidebands" in v else None,
        )
        for name, v in r["defect_lines"].items()
    }
    return VibrationState(
        window_end_s=float(end_time_s),
        window_s=r["window_s"],
        sample_rate_hz=fs,
        shaft_speed_rad_s=float(shaft_speed_rad_s),
        contact_angle_rad=float(angle),
        rms_m_s2=r["rms_m_s2"],
        peak_m_s2=r["peak_m_s2"],
        crest_factor=r["crest_factor"],
        kurtosis=r["kurtosis"],
        band_kurtosis=r["band_kurtosis"],
        velocity_rms_mm_s=r["velocity_rms_mm_s"],
        defect_frequencies_hz=DefectFrequenciesHz(**r["defect_frequencies_hz"]),
        envelope_band_hz=tuple(r["envelope_band_hz"]),
        envelope_peaks_hz=tuple(EnvelopePeak(**p) for p in r["envelope_peaks_hz"]),
        envelope_noise_floor_m_s2=r["noise_floor_m_s2"],
        envelope_lines=lines,
        envelope_spectrum=_spectrum(Spectrum, r["envelope_spectrum"]),
        amplitude_spectrum=_spectrum(Spectrum, r["amplitude_spectrum"]),
    )


def _spectrum(cls, s: dict):
    return cls(
        start_hz=float(s["start_hz"]),
        step_hz=float(s["step_hz"]),
        amplitude_m_s2=tuple(np.asarray(s["amplitude_m_s2"], dtype=float).tolist()),
    )
