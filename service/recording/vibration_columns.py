"""The accelerometer's windows and samples to rerun columns: the vibration indicators, the
envelope spectra as bar charts with their defect-line cursors, and the waveform with its breaks."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import rerun as rr

from service.recording.arrow import bar_columns
from service.recording.columns import Batch
from service.recording.layout import (
    CURSOR_HARMONICS,
    CURSOR_NAMES,
    CURSOR_WIDTH_FRACTION,
    SEQ,
    SIM_TIME,
    SPECTRUM_PIXELS,
    VIB_LINES,
    TwinLayout,
)


# ---- vibration ------------------------------------------------------------------------------------
def vibration_columns(tw: TwinLayout, batch: Batch) -> None:
    """The indicators of every new accelerometer window (a row at the snapshot that first
    carries it): `vibration/...` Scalars and the envelope bar charts (layout.VIBRATION_SERIES)."""
    last = tw.last
    sel, blocks = [], []
    for j, r in enumerate(batch.rows):
        v = r.vibration
        if v is None or v.window_end_s == last.get("window_end_s"):
            continue
        last["window_end_s"] = v.window_end_s
        sel.append(j)
        blocks.append(v)
    if not sel:
        return
    idx = np.array(sel)
    root = tw.root
    n = len(blocks)

    def scalars(leaf: str, values) -> None:
        v = np.asarray(values, dtype=np.float64).reshape(n, -1)
        batch.out.append(
            (
                f"{root}/vibration/{leaf}",
                batch.index(idx),
                rr.Scalars.columns(scalars=v.reshape(-1)).partition(np.full(n, v.shape[1])),
            )
        )

    scalars("acceleration_rms_peak_m_s2", [[b.rms_m_s2, b.peak_m_s2] for b in blocks])
    scalars("velocity_rms_mm_s", [[b.velocity_rms_mm_s] for b in blocks])
    scalars("kurtosis", [[b.kurtosis, b.band_kurtosis, b.crest_factor] for b in blocks])
    freqs = np.array([[getattr(b.defect_frequencies_hz, k) for k in VIB_LINES] for b in blocks])
    amps = np.array([[_line_fundamental(b, k) for k in VIB_LINES] for b in blocks])
    floor = np.array([[b.envelope_noise_floor_m_s2] for b in blocks])
    scalars("defect_frequencies_hz", freqs)
    scalars("envelope_lines_m_s2", np.hstack([amps, floor]))
    # the envelope spectrum as the snapshot has it: its largest peaks, and the defect lines (markers)
    k = max(1, max(len(b.envelope_peaks_hz) for b in blocks))
    peak_f = np.zeros((n, k))
    peak_a = np.zeros((n, k))
    for i, b in enumerate(blocks):
        for m, p in enumerate(b.envelope_peaks_hz):
            peak_f[i, m], peak_a[i, m] = p.frequency_hz, p.amplitude
    batch.out.append((f"{root}/vibration/envelope/peaks", batch.index(idx), bar_columns(peak_a, peak_f)))
    batch.out.append(
        (f"{root}/vibration/envelope/defect_lines", batch.index(idx), bar_columns(np.nan_to_num(amps), freqs))
    )
    _spectrum_columns(tw, batch, idx, blocks)


def _spectrum_columns(tw: TwinLayout, batch: Batch, idx: np.ndarray, blocks: list) -> None:
    """The windows' full spectra (VibrationState.envelope_spectrum / amplitude_spectrum; windows
    without them are skipped) as bar charts against frequency [Hz], bars a bin wide or (range /
    SPECTRUM_PIXELS), whichever is wider:
    `vibration/envelope/spectrum` with the defect-frequency cursors
    `vibration/envelope/cursor/{FTF,BPFO,BPFI,BSF,2xBSF}` (1x, 2x, 3x each, as tall as the spectrum), and
    `vibration/spectrum` with the envelope band `vibration/spectrum_envelope_band`."""
    root = tw.root
    env = [(j, b.envelope_spectrum) for j, b in enumerate(blocks) if getattr(b, "envelope_spectrum", None) is not None]
    if env:
        sel = idx[[j for j, _ in env]]
        amps = [np.asarray(e.amplitude_m_s2) for _, e in env]
        tops = [float(a.max()) if a.size else 0.0 for a in amps]
        batch.out.append(
            (
                f"{root}/vibration/envelope/spectrum",
                batch.index(sel),
                bar_columns(
                    amps,
                    [e.frequencies_hz for _, e in env],
                    [np.full(a.size, _bar_width(e)) for a, (_, e) in zip(amps, env, strict=True)],
                ),
            )
        )
        for name, label in zip(VIB_LINES, CURSOR_NAMES, strict=True):
            fs, hs, ws = [], [], []
            for (j, e), top in zip(env, tops, strict=True):
                f0 = getattr(blocks[j].defect_frequencies_hz, name)
                f = np.array([k * f0 for k in range(1, CURSOR_HARMONICS + 1) if k * f0 <= e.max_hz])
                fs.append(f)
                hs.append(np.full(f.size, top))
                ws.append(np.full(f.size, max(2.0 * e.step_hz, e.max_hz / CURSOR_WIDTH_FRACTION)))
            batch.out.append((f"{root}/vibration/envelope/cursor/{label}", batch.index(sel), bar_columns(hs, fs, ws)))
    acc = [
        (j, b.amplitude_spectrum) for j, b in enumerate(blocks) if getattr(b, "amplitude_spectrum", None) is not None
    ]
    if acc:
        sel = idx[[j for j, _ in acc]]
        amps = [np.asarray(a.amplitude_m_s2) for _, a in acc]
        batch.out.append(
            (
                f"{root}/vibration/spectrum",
                batch.index(sel),
                bar_columns(
                    amps,
                    [a.frequencies_hz for _, a in acc],
                    [np.full(x.size, _bar_width(a)) for x, (_, a) in zip(amps, acc, strict=True)],
                ),
            )
        )
        band = [blocks[j].envelope_band_hz for j, _ in acc]
        batch.out.append(
            (
                f"{root}/vibration/spectrum_envelope_band",
                batch.index(sel),
                bar_columns(
                    [np.array([float(a.max()) if a.size else 0.0]) for a in amps],
                    [np.array([0.5 * (lo + hi)]) for lo, hi in band],
                    [np.array([hi - lo]) for lo, hi in band],
                ),
            )
        )


def _bar_width(spectrum) -> float:
    """Bar width [Hz] of a spectrum's bins: a bin, or (its range / SPECTRUM_PIXELS) when wider."""
    return max(spectrum.step_hz, (spectrum.max_hz + 0.5 * spectrum.step_hz) / SPECTRUM_PIXELS)


def _line_fundamental(block, name: str) -> float:
    line = (block.envelope_lines or {}).get(name)
    return float(line.harmonics[0]) if line is not None and line.harmonics else math.nan


@dataclass(slots=True)
class WaveRow:
    """Accelerometer samples that came with one snapshot (twin.accelerometer.WaveformBlock)."""

    seq: int
    t0_s: float
    sample_rate_hz: float
    samples: np.ndarray  # float32 [m/s^2]


def waveform_columns(tw: TwinLayout, rows: list[WaveRow], offset_s: float) -> list:
    """`vibration/acceleration_m_s2`: one Scalars row per sample at its own simulated time (the
    `seq` of the snapshot it came with), all of a send in one call."""
    rows = [r for r in rows if r.samples.size]
    if not rows:
        return []
    t = np.concatenate(
        [np.round((r.t0_s + offset_s + np.arange(r.samples.size) / r.sample_rate_hz) * 1e9) for r in rows]
    ).astype(np.int64)
    seq = np.concatenate([np.full(r.samples.size, r.seq, dtype=np.int64) for r in rows])
    x = np.concatenate([r.samples for r in rows]).astype(np.float64)
    index = [rr.TimeColumn(SIM_TIME, duration=t.astype("timedelta64[ns]")), rr.TimeColumn(SEQ, sequence=seq)]
    return [(f"{tw.root}/vibration/acceleration_m_s2", index, rr.Scalars.columns(scalars=x))]


def waveform_breaks(tw: TwinLayout, rows: list[WaveRow], offset_s: float) -> list:
    """An empty row (a line break) half a sample before each of `rows` (bursts kept apart by
    `service.recording.archive`: no line drawn across the samples not kept), on sim_time only."""
    at = np.array([round((r.t0_s + offset_s - 0.5 / r.sample_rate_hz) * 1e9) for r in rows], dtype=np.int64)
    index = [rr.TimeColumn(SIM_TIME, duration=at.astype("timedelta64[ns]"))]
    return [
        (
            f"{tw.root}/vibration/acceleration_m_s2",
            index,
            rr.Scalars.columns(scalars=np.zeros(0)).partition(np.zeros(at.size, np.int32)),
        )
    ]
