"""The vibration of a twin with the housing on in the rerun recording: the accelerometer
samples (`vibration/acceleration_m_s2`, one row per sample at its own simulated time, sent with
send_columns), the indicators of each window, the envelope bar charts at the defect frequencies, the window's full
envelope and acceleration spectra (bar charts, a row per window, with the defect-frequency cursors),
and the defects as event rows. A real 6208 twin (housing on, outer spall, 0.05 s windows); the
.rrd is read back."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("rerun")

from service.recording import RerunRecorder, describe_recording, read_column
from twin import catalog
from twin.engine import Twin
from twin.setpoint import Setpoint
from twin.spec import BearingSpec

FRAME_S = 0.01
WINDOW_S = 0.05


def _spec(enabled=True):
    data = catalog.bearing("6208").model_dump()
    data["housing"]["enabled"] = enabled
    data["housing"]["accelerometer"].update(window_s=WINDOW_S, noise_density_m_s2_rthz=0.01, noise_seed=3)
    return BearingSpec.model_validate(data)


@pytest.fixture(scope="module")
def run():
    """16 frames of 10 ms: healthy for 4, an outer spall from frame 4, cleared at frame 12; the
    snapshots and the waveform blocks drained after each frame."""
    twin = Twin(_spec(), bearing_id="v", setpoint=Setpoint(shaft_speed_rad_s=523.0, radial_load_n=3000.0))
    rb = twin.model.spec.geometry.ball_radius_m
    frames = []
    for k in range(16):
        if k == 4:
            twin.set_defects([{"kind": "outer", "width_m": 0.5e-3, "length_m": 0.6 * rb, "depth_m": 50e-6}])
        if k == 12:
            twin.clear_defects()
        twin.advance(FRAME_S)
        frames.append((twin.snapshot(), twin.drain_waveform()))
    return twin, frames


def test_samples_indicators_and_defects_are_recorded(tmp_path, run):
    twin, frames = run
    path = tmp_path / "vib.rrd"
    rec = RerunRecorder(path)
    rec.add_twin_from(twin)
    for snap, blocks in frames:
        rec.publish(snap)
        rec.publish_waveform("v", blocks, seq=snap.seq)
    rec.close()
    assert rec.errors == 0 and rec.waveform_dropped == 0

    blocks = [b for _s, bs in frames for b in bs]
    samples = np.concatenate([b.samples for b in blocks])
    entity = "bearing/v/vibration/acceleration_m_s2"
    values = np.array([v[0] for v in read_column(path, entity, "Scalars:scalars")])
    times = np.array(read_column(path, entity, "sim_time"))
    assert values.size == samples.size > 0.1 * 51200.0  # every sample, one row each
    order = np.argsort(times, kind="stable")
    assert np.array_equal(values[order].astype(np.float32), samples)
    expected_t = np.concatenate(
        [np.round((b.t0_s + np.arange(b.samples.size) / b.sample_rate_hz) * 1e9) for b in blocks]
    )
    assert np.array_equal(times[order], expected_t.astype(np.int64))

    # one indicator row per window, at the first snapshot that carries it
    windows = {}
    for snap, _b in frames:
        if snap.vibration is not None and snap.vibration.window_end_s not in windows:
            windows[snap.vibration.window_end_s] = snap
    assert len(windows) >= 2
    seqs = read_column(path, "bearing/v/vibration/velocity_rms_mm_s", "seq")
    assert seqs == [s.seq for s in windows.values()]
    velocity = [v[0] for v in read_column(path, "bearing/v/vibration/velocity_rms_mm_s", "Scalars:scalars")]
    assert velocity == pytest.approx([s.vibration.velocity_rms_mm_s for s in windows.values()])
    lines = read_column(path, "bearing/v/vibration/envelope_lines_m_s2", "Scalars:scalars")
    assert [row[1] for row in lines] == pytest.approx(
        [s.vibration.envelope_lines["bpfo"].harmonics[0] for s in windows.values()]
    )  # BPFO second
    bars = read_column(path, "bearing/v/vibration/envelope/defect_lines", "BarChart:abscissa")
    assert len(bars) == len(windows)
    # the full spectra, a bar chart row per window: the window's own bins on their frequency axis
    for leaf, key in (("envelope/spectrum", "envelope_spectrum"), ("spectrum", "amplitude_spectrum")):
        entity_ = f"bearing/v/vibration/{leaf}"
        assert read_column(path, entity_, "seq") == [s.seq for s in windows.values()]
        values = read_column(path, entity_, "BarChart:values")
        abscissa = read_column(path, entity_, "BarChart:abscissa")
        widths = read_column(path, entity_, "BarChart:widths")
        for snap, got_v, got_f, got_w in zip(windows.values(), values, abscissa, widths, strict=True):
            want = getattr(snap.vibration, key)
            got_v, got_f = _tensor(got_v), _tensor(got_f)
            assert got_v.size == got_f.size == len(want.amplitude_m_s2) == len(got_w)
            assert np.array_equal(got_v, np.float32(want.amplitude_m_s2))
            assert np.array_equal(got_f, np.float32(want.frequencies_hz))
            # a bar is a bin wide, or 1/700 of the range when that is wider (layout.SPECTRUM_PIXELS)
            width = max(want.step_hz, (want.max_hz + 0.5 * want.step_hz) / 700.0)
            assert np.all(np.float32(got_w) == np.float32(width))
    # 0.05 s windows at 51.2 kHz: 2560 samples, 1281 bins of 20 Hz up to 25.6 kHz (no summing below 2000)
    acc = next(iter(windows.values())).vibration.amplitude_spectrum
    assert (len(acc.amplitude_m_s2), acc.start_hz, acc.step_hz) == (1281, 0.0, 20.0)
    # the BPFO cursors of the first faulty window: 1x, 2x, 3x BPFO, as tall as its envelope spectrum
    faulty = next(s for s in windows.values() if s.defects)
    rows = dict(
        zip(
            read_column(path, "bearing/v/vibration/envelope/cursor/BPFO", "seq"),
            read_column(path, "bearing/v/vibration/envelope/cursor/BPFO", "BarChart:abscissa"),
            strict=True,
        )
    )
    bpfo = faulty.vibration.defect_frequencies_hz.bpfo
    assert _tensor(rows[faulty.seq]) == pytest.approx([bpfo, 2 * bpfo, 3 * bpfo], rel=1e-6)

    events = list(
        zip(
            read_column(path, "bearing/v/events", "seq"),
            [t[0] for t in read_column(path, "bearing/v/events", "TextLog:text")],
            strict=True,
        )
    )
    defect_rows = [(seq, text) for seq, text in events if text.startswith("defects")]
    assert defect_rows[0][0] == frames[4][0].seq and defect_rows[0][1].startswith("defects: outer spall 0.5 x")
    assert defect_rows[1] == (frames[12][0].seq, "defects cleared")
    info = describe_recording(path)["entities"]
    assert info[entity]["rows"] == samples.size


def _tensor(cell) -> np.ndarray:
    """The numbers of a TensorData cell as read back (`read_column`)."""
    cell = cell[0] if isinstance(cell, list) and len(cell) == 1 and isinstance(cell[0], dict) else cell
    buffer = cell["buffer"] if isinstance(cell, dict) else cell
    return np.asarray(buffer, dtype=np.float32).ravel()


def test_the_vibration_views_only_with_the_housing():
    import rerun.blueprint as rrb

    from service.recording.blueprint import twin_blueprint
    from service.recording.layout import TwinLayout

    def names(tw):
        out = []

        def walk(node):
            for child in node.contents or []:
                if isinstance(child, rrb.View):
                    out.append(child.name)
                else:
                    walk(child)

        walk(twin_blueprint(tw, 10.0))
        return out

    with_housing = names(TwinLayout("v", "6208", 9, vibration=True))
    assert "housing acceleration [m/s^2] (last 0.1 s)" in with_housing
    assert any(n.startswith("envelope spectrum [m/s^2] vs [Hz]") for n in with_housing)
    assert any(n.startswith("acceleration spectrum [m/s^2] vs [Hz]") for n in with_housing)
    assert not [n for n in names(TwinLayout("v", "6208", 9)) if "acceleration" in n or "envelope" in n]
