"""`WaveformArchive`: which housing-accelerometer samples a recording file keeps.

The accelerometer samples at 51.2 kHz: recorded whole, one twin writes about 1.2 MB per
simulated second, and the default retention (2000 MB) would hold half an hour of it. A file keeps
instead a burst of `burst_s` every `every_s` of simulated time (the waveform as it was, at full
rate, throughout the run) and everything for `after_event_s` after an event (a defect set or
cleared, an alarm raised or escalated): about 0.2 % of the samples in steady running. The
vibration indicators of every window are recorded regardless (they are computed from every
sample); the full spectra and envelope spectra (each some 20 kB) once per `spectrum_every_s`. A
live viewer gets every sample and every spectrum.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from service.recording.vibration_columns import WaveRow


@dataclass(frozen=True)
class WaveformArchive:
    burst_s: float = 0.1  # [s of simulated time] length of each burst
    every_s: float = 60.0  # [s of simulated time] a burst starts at every multiple of this
    after_event_s: float = 1.0  # [s of simulated time] kept whole after an event
    spectrum_every_s: float = 30.0  # [s of simulated time] the files get a window's spectra this often

    def __post_init__(self) -> None:
        if not (0.0 < self.burst_s <= self.every_s):
            raise ValueError(f"burst_s = {self.burst_s!r}: must be > 0 and <= every_s = {self.every_s!r}")
        if self.after_event_s < 0.0:
            raise ValueError(f"after_event_s = {self.after_event_s!r}: must be >= 0")

    def keep(self, rows: list[WaveRow], events_s: list[float]) -> list[WaveRow]:
        """The parts of `rows` a file keeps: one WaveRow per contiguous run of kept samples."""
        out: list[WaveRow] = []
        for r in rows:
            n = r.samples.size
            if not n:
                continue
            t = r.t0_s + np.arange(n) / r.sample_rate_hz
            mask = np.mod(t, self.every_s) < self.burst_s
            for te in events_s:
                mask |= (t >= te) & (t < te + self.after_event_s)
            if not mask.any():
                continue
            edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.view(np.int8), [0]])))
            for a, b in zip(edges[::2], edges[1::2], strict=True):
                out.append(
                    WaveRow(seq=r.seq, t0_s=float(t[a]), sample_rate_hz=r.sample_rate_hz, samples=r.samples[a:b])
                )
        return out


SPECTRUM_LEAVES = (
    "vibration/spectrum",
    "vibration/envelope/spectrum",
    "vibration/envelope/cursor/",
    "vibration/spectrum_envelope_band",
)


def is_spectrum(path: str) -> bool:
    """Whether an entity path is one of a twin's full spectra (or their cursors and band)."""
    return any(f"/{leaf}" in path for leaf in SPECTRUM_LEAVES)
