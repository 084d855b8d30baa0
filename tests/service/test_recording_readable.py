"""Recordings a tribologist can read: trends as window means with min / max, change markers on
every trend, alarm states from the first row, a robust capacitance scale with its outliers marked,
the accelerometer archive, the blueprint (whole-run trends, units, min-max waveform), and closed
files compacted in rerun's current format. Real twins, files read back."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

pytest.importorskip("rerun")

from service.core.alarm_rules import ALARM_IDS
from service.recording import RerunRecorder, describe_recording, read_column, read_index
from service.recording.archive import WaveformArchive
from service.recording.blueprint import blueprint
from service.recording.layout import SERIES, TREND_BANDS, TwinLayout
from service.recording.trends import OFF_SCALE_DECADES, _capacitance_scale, split_windows
from service.recording.vibration_columns import WaveRow
from twin.engine import Twin

FRAME_S = 0.02  # 50 Hz snapshots
WINDOW_S = 0.2  # 10 snapshots per trend window


@pytest.fixture(scope="module")
def run():
    """60 snapshots (1.2 s); a radial-load step at snapshot 25, a shaft-speed step at 45."""
    twin = Twin("6208", bearing_id="a")
    snaps = []
    for k in range(60):
        if k == 25:
            twin.set_setpoint(radial_load_n=4000.0)
        if k == 45:
            twin.set_setpoint(shaft_speed_rad_s=300.0)
        twin.advance(FRAME_S)
        snaps.append(twin.snapshot())
    return twin, snaps


def _record(path, twin, snaps, **kw):
    rec = RerunRecorder(path, trend_window_s=WINDOW_S, **kw)
    rec.add_twin_from(twin)
    for s in snaps:
        rec.publish(s)
    rec.close()
    assert rec.errors == 0
    return rec


def test_trends_are_window_means_with_min_and_max(tmp_path, run):
    """Each trend row is one window of simulated time: the mean of its snapshots, then the
    smallest and largest value of the banded series (exact, to float rounding)."""
    twin, snaps = run
    path = tmp_path / "w.rrd"
    _record(path, twin, snaps)
    t = np.array([s.time_s for s in snaps])
    keys = np.floor(t / WINDOW_S).astype(int)
    torque = np.array([s.friction_torque_n_m for s in snaps])
    rows = read_column(path, "bearing/a/friction_torque_n_m", "Scalars:scalars")
    assert len(rows) == len(set(keys.tolist()))  # a row per window, not per snapshot
    for row, k in zip(rows, sorted(set(keys.tolist())), strict=True):
        sel = torque[keys == k]
        assert row == pytest.approx([sel.mean(), sel.min(), sel.max()], rel=1e-12)
    # the row sits at the mean time of its snapshots, and carries the seq of its last one
    times = np.array(read_column(path, "bearing/a/friction_torque_n_m", "sim_time"))
    first = keys == keys[0]
    assert times[0] == pytest.approx(t[first].mean() * 1e9, abs=2)
    assert read_index(path, "bearing/a/friction_torque_n_m")[0] == snaps[int(np.flatnonzero(first)[-1])].seq
    # every trend: its series means, then min and max of the banded ones
    for leaf, (names, _colors) in SERIES.items():
        if leaf.startswith("electrical/"):
            continue
        vals = read_column(path, f"bearing/a/{leaf}", "Scalars:scalars")
        assert {len(v) for v in vals} == {len(names) + 2 * len(TREND_BANDS.get(leaf, ()))}, leaf


def test_regime_counts_are_averaged_not_aliased(tmp_path, run):
    """Balls per regime: the window mean of the counts (a fraction, summing to the ball count),
    not a sample flipping between 4 and 5."""
    twin, snaps = run
    path = tmp_path / "r.rrd"
    _record(path, twin, snaps)
    rows = np.array(read_column(path, "bearing/a/regime_counts", "Scalars:scalars"))
    assert rows.shape[1] == 4
    assert np.allclose(rows.sum(axis=1), twin.model.ball_count)


def test_setpoint_changes_are_marked_on_every_trend(tmp_path, run):
    twin, snaps = run
    path = tmp_path / "m.rrd"
    _record(path, twin, snaps)
    changed = [snaps[25].seq, snaps[45].seq]
    for leaf in SERIES:
        if leaf.startswith("electrical/"):
            continue
        assert read_index(path, f"bearing/a/{leaf}/changes").tolist() == changed, leaf


def test_every_alarm_state_is_recorded_from_the_first_row(tmp_path, run):
    twin, snaps = run
    path = tmp_path / "a.rrd"
    _record(path, twin, snaps)
    for alarm_id in ALARM_IDS:
        seqs = read_index(path, f"bearing/a/alarm_states/{alarm_id}")
        states = read_column(path, f"bearing/a/alarm_states/{alarm_id}", "StateChange:state")
        assert seqs[0] == snaps[0].seq and states[0] == ["inactive"], alarm_id


def test_windows_split_at_gaps_and_carry_the_open_one():
    class R:
        def __init__(self, t, gap=None):
            self.time_s, self.gap_before = t, gap

    rows = [R(0.01), R(0.05), R(0.21), R(0.25, gap="lost rows"), R(0.33), R(0.41)]
    done, carry = split_windows(rows, 0.2, final=False)
    assert [[r.time_s for r in w] for w in done] == [[0.01, 0.05], [0.21], [0.25, 0.33]]
    assert [r.time_s for r in carry] == [0.41]
    done, carry = split_windows(rows, 0.2, final=True)
    assert carry == [] and [r.time_s for r in done[-1]] == [0.41]


def test_an_off_scale_capacitance_and_a_broken_film_are_marked_not_plotted():
    """One value 10^7 times the others would flatten a 200 pF trace to zero: it leaves the line
    and becomes a marker at the line's edge; a missing capacitance (metal contact) becomes a
    film-broken marker; each change of state is an event saying why."""
    tw = TwinLayout(bearing_id="a", designation="6208", ball_count=9)
    c = np.array([200.0, 210.0, 2.5e9, 205.0, math.nan, math.nan, 202.0])
    has_el = np.ones(c.size, dtype=bool)
    out: list = []
    notes = _capacitance_scale(tw, c, has_el, np.arange(c.size) * 30_000_000_000, np.arange(c.size), out)  # 30 s apart
    assert np.isnan(c[[2, 4, 5]]).all() and np.isfinite(c[[0, 1, 3, 6]]).all()
    paths = [p for p, _i, _c in out]
    assert paths == ["bearing/a/electrical/capacitance_pf/off_scale", "bearing/a/electrical/capacitance_pf/film_broken"]
    assert [j for j, _ in notes] == [2, 4, 6]
    assert "off scale" in notes[0][1] and f"{OFF_SCALE_DECADES:g} decade" in notes[0][1]
    assert "film broken" in notes[1][1] and "empty" in notes[1][1]
    assert "again" in notes[2][1]
    # a film that breaks and heals every snapshot: a marker at each break, one note a minute
    c = np.array([200.0, math.nan] * 10)
    out = []
    notes = _capacitance_scale(
        tw, c, np.ones(c.size, dtype=bool), 300_000_000_000 + np.arange(c.size) * 20_000_000, np.arange(c.size), out
    )
    assert len(notes) == 1 and [len(idx[1].as_arrow_array()) for _p, idx, _cols in out] == [10]


def test_the_waveform_archive_keeps_bursts_and_the_second_after_an_event():
    fs = 51_200.0
    row = WaveRow(seq=1, t0_s=9.95, sample_rate_hz=fs, samples=np.arange(int(fs), dtype=np.float32))  # 9.95..10.95 s
    arch = WaveformArchive(burst_s=0.1, every_s=10.0, after_event_s=0.2)
    kept = arch.keep([row], events_s=[])
    assert len(kept) == 1 and kept[0].t0_s == pytest.approx(10.0, abs=1 / fs)
    assert kept[0].samples.size == pytest.approx(0.1 * fs, abs=1)
    kept = arch.keep([row], events_s=[10.5])
    assert [k.samples.size for k in kept] == pytest.approx([0.1 * fs, 0.2 * fs], abs=1)
    assert kept[1].t0_s == pytest.approx(10.5, abs=1 / fs)
    assert kept[1].samples[0] == row.samples[round(0.55 * fs)]
    with pytest.raises(ValueError, match="burst_s"):
        WaveformArchive(burst_s=0.0)


def _views(container):
    for item in getattr(container, "contents", None) or []:
        if hasattr(item, "properties"):
            yield item
        else:
            yield from _views(item)


def test_the_blueprint_shows_whole_runs_with_short_titles_opens_files_paused_and_follows_live():
    tw = TwinLayout(bearing_id="a", designation="6208", ball_count=9, vibration=True)
    file_bp, live_bp = blueprint([tw], None), blueprint([tw], None, live=True)
    assert str(file_bp.time_panel.play_state) == "paused" and str(live_bp.time_panel.play_state) == "following"
    live_names = [str(v.name) for v in _views(live_bp.root_container)]
    assert "housing acceleration [m/s^2] (last 0.1 s)" in live_names  # live: the newest samples
    series = [v for v in _views(file_bp.root_container) if type(v).__name__ == "TimeSeriesView"]
    assert len(series) >= 16
    for view in series:
        ranges = repr(view.properties["VisibleTimeRanges"])
        # the whole recording: both boundaries infinite, whatever the time cursor
        assert "'start': None" in ranges and "'end': None" in ranges, (view.name, ranges)
        # a short title with its unit: readable at 1600 x 1000 (a third of the width is ~250 px)
        assert len(str(view.name)) <= (40 if str(view.name).startswith("housing") else 28), view.name  # a wide one
        leaf = next((k for k in SERIES if f"{k}/**" in repr(view.contents)), None)
        if leaf is not None:  # a key where there are several quantities
            keyed = "True" in repr(view.properties["PlotLegend"])
            assert keyed == (len(SERIES[leaf][0]) > 1), view.name
    for leaf, (names, _colors) in SERIES.items():
        if leaf != "regime_counts":
            assert all("[" in n for n in names), leaf  # every series says its unit


def test_the_waveform_is_drawn_min_max(tmp_path):
    """Averaged per pixel, a +-47 m/s^2 waveform shows as +-20: the series is min-max aggregated."""
    import rerun as rr

    from service.recording.layout import send_static

    tw = TwinLayout(bearing_id="v", designation="6208", ball_count=9, vibration=True)
    stream = rr.RecordingStream("t", recording_id="x")
    path = tmp_path / "s.rrd"
    stream.save(str(path))
    send_static(stream, tw)
    stream.flush()
    stream.disconnect()
    info = describe_recording(path)
    assert "SeriesLines:aggregation_policy" in info["entities"]["bearing/v/vibration/acceleration_m_s2"]["components"]


def test_closed_files_are_compacted_in_rerun_s_current_format(tmp_path, run):
    twin, snaps = run
    plain, packed = tmp_path / "plain.rrd", tmp_path / "packed.rrd"
    for path, compact in ((plain, False), (packed, True)):
        rec = RerunRecorder(path, trend_window_s=WINDOW_S, flush_interval_s=1e6, compact_segments=compact)
        rec.add_twin_from(twin)
        for k in range(0, len(snaps), 5):  # 12 sends: 12 chunks per entity before compaction
            for s in snaps[k : k + 5]:
                rec.publish(s)
            rec.flush()
        rec.close()
    a, b = describe_recording(plain), describe_recording(packed)
    assert sum(e["chunks"] for e in b["entities"].values()) * 3 < sum(e["chunks"] for e in a["entities"].values())
    assert {k: e["rows"] for k, e in a["entities"].items()} == {k: e["rows"] for k, e in b["entities"].items()}
    assert packed.stat().st_size < plain.stat().st_size
    from rerun.chunk import RrdReader

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        RrdReader(str(packed))
    assert not [w for w in caught if "footer" in str(w.message) or "legacy" in str(w.message)]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["packed.rrd", "plain.rrd"]  # no temporary left


def test_a_file_keeps_waveform_bursts_with_line_breaks_between(tmp_path):
    """A recorder with a WaveformArchive writes the kept bursts, each after an empty row."""
    from types import SimpleNamespace

    path = tmp_path / "v.rrd"
    rec = RerunRecorder(path, waveform_archive=WaveformArchive(burst_s=0.01, every_s=0.05, after_event_s=0.0))
    rec.add_twin(
        "v",
        designation="6208",
        pitch_radius_m=0.02,
        ball_radius_m=0.006,
        inner_raceway_radius_m=0.014,
        outer_raceway_radius_m=0.026,
        ball_count=9,
        vibration=True,
    )
    fs = 10_000.0
    block = SimpleNamespace(t0_s=0.0, sample_rate_hz=fs, samples=np.ones(int(0.2 * fs), dtype=np.float32))
    rec.publish_waveform("v", [block], seq=1)
    rec.close()
    rows = read_column(path, "bearing/v/vibration/acceleration_m_s2", "Scalars:scalars")
    kept = [r for r in rows if r]
    assert len(kept) == pytest.approx(4 * 0.01 * fs, abs=4)  # bursts at 0, 0.05, 0.1, 0.15 s, 0.01 s each
    from service.recording import describe_recording as _d

    assert _d(path)["entities"]["bearing/v/vibration/acceleration_m_s2"]["breaks"] == 4
