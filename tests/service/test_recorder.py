"""RerunRecorder: record snapshots of real twins into .rrd files and read them back with
`rerun.chunk.RrdReader` (through service.recorder.read_recording / read_column)."""

from __future__ import annotations

import logging
import time
from types import SimpleNamespace

import numpy as np
import pytest

from service.recorder import (
    RerunRecorder,
    _reader,
    describe_recording,
    read_column,
    read_index,
    read_recording,
    recording_segments,
    segment_path,
)
from twin.engine import Twin

N = 40            # snapshots per twin
FRAME_S = 0.002   # 2 ms frames


def _run(twin: Twin, n: int = N) -> list:
    snaps = []
    for _ in range(n):
        twin.advance(FRAME_S)
        snaps.append(twin.snapshot())
    return snaps


@pytest.fixture(scope="module")
def twin_a():
    twin = Twin("6208", bearing_id="a")
    return twin, _run(twin)


@pytest.fixture(scope="module")
def twin_b():
    twin = Twin("6208", bearing_id="b")
    twin.set_setpoint(radial_load_n=1500.0)
    return twin, _run(twin)


def _geometry(twin: Twin) -> dict:
    m = twin.model
    g = m.spec.geometry
    return {"designation": m.spec.designation, "pitch_radius_m": m.pitch_radius_m,
            "ball_radius_m": m.ball_radius_m, "inner_raceway_radius_m": g.inner_raceway_radius_m,
            "outer_raceway_radius_m": g.outer_raceway_radius_m, "ball_count": m.ball_count}


def _recorder(path, *twins, **kw) -> RerunRecorder:
    rec = RerunRecorder(path, **kw)
    for twin in twins:
        rec.add_twin(twin.bearing_id, **_geometry(twin))
    return rec


def _defined(snaps, i: int, side: str, attr: str = "lambda_") -> int:
    return sum(getattr(getattr(s.balls[i], side), attr) is not None for s in snaps)


def _assert_tree(rows: dict, bearing_id: str, snaps: list) -> None:
    root = f"bearing/{bearing_id}"
    n = len(snaps)
    for name in ("inner_raceway", "outer_raceway", "pitch_circle", "load_line"):
        assert f"{root}/geometry/{name}" in rows            # static geometry
    assert rows[f"{root}/balls"] == n
    assert rows[f"{root}/loads/inner"] == n
    assert rows[f"{root}/loads/outer"] == n
    assert rows[f"{root}/friction_torque_n_m"] == n
    assert rows[f"{root}/cage_speed_rad_s"] == n
    for i in range(len(snaps[0].balls)):
        for side in ("inner", "outer"):
            assert rows[f"{root}/ball/{i}/{side}/load_n"] == n
            assert rows[f"{root}/ball/{i}/{side}/mu"] == n
            # null Lambda (no contact) is not logged for that row
            assert rows.get(f"{root}/ball/{i}/{side}/lambda", 0) == _defined(snaps, i, side)


def test_one_twin_round_trip(tmp_path, twin_a):
    twin, snaps = twin_a
    # the run must exercise the null-Lambda path: some unloaded inner contacts, some loaded
    nulls = sum(b.inner.lambda_ is None for s in snaps for b in s.balls)
    assert 0 < nulls < N * len(snaps[0].balls)

    path = tmp_path / "run.rrd"
    rec = _recorder(path, twin)
    for s in snaps:
        rec.publish(s)
    rec.close()
    assert rec.rows_logged == N and rec.dropped == 0 and rec.errors == 0

    rows = read_recording(path)
    _assert_tree(rows, "a", snaps)
    info = describe_recording(path)
    assert info["application_id"] == "bearing-twin"
    assert info["blueprints"] == 1
    assert info["entities"]["bearing/a/balls"]["timelines"] == ["seq", "sim_time"]
    assert "Points3D:radii" in info["entities"]["bearing/a/balls"]["components"]

    # timelines: seq = snapshot.seq, sim_time = snapshot.time_s (integer ns, rounded)
    assert list(read_index(path, "bearing/a/friction_torque_n_m")) == [s.seq for s in snaps]
    assert read_column(path, "bearing/a/friction_torque_n_m", "sim_time") == \
        [round(s.time_s * 1e9) for s in snaps]
    torque = [v[0] for v in read_column(path, "bearing/a/friction_torque_n_m", "Scalars:scalars")]
    assert torque == pytest.approx([s.friction_torque_n_m for s in snaps])

    # balls on the pitch circle at their azimuth, coloured by the inner-contact regime
    pos = np.array(read_column(path, "bearing/a/balls", "Points3D:positions")[-1])
    last = snaps[-1]
    az = np.array([b.azimuth_rad for b in last.balls])
    rp = twin.model.pitch_radius_m
    np.testing.assert_allclose(pos[:, 0], rp * np.cos(az), atol=1e-6)
    np.testing.assert_allclose(pos[:, 1], rp * np.sin(az), atol=1e-6)
    colors = read_column(path, "bearing/a/balls", "Points3D:colors")[-1]
    palette = {"no_contact": 0x969696FF, "boundary": 0xDC2828FF, "mixed": 0xFF9600FF, "full_film": 0x28B446FF}
    assert colors == [palette[b.inner.regime] for b in last.balls]

    # inner-load arrows point from the ball centre towards the inner raceway, length ~ load
    vec = np.array(read_column(path, "bearing/a/loads/inner", "Arrows3D:vectors")[-1])
    loads = np.array([b.inner.load_n for b in last.balls])
    radial = (vec[:, :2] * pos[:, :2]).sum(axis=1)
    assert np.all(radial[loads > 0] < 0.0)
    lengths = np.linalg.norm(vec, axis=1)
    k = loads > 0
    np.testing.assert_allclose(lengths[k] / loads[k], (lengths[k] / loads[k])[0], rtol=1e-5)


def test_two_twins_in_one_recording(tmp_path, twin_a, twin_b):
    (ta, sa), (tb, sb) = twin_a, twin_b
    path = tmp_path / "two.rrd"
    rec = _recorder(path, ta, tb)
    for x, y in zip(sa, sb):
        rec.publish(x)
        rec.publish(y)
    rec.close()
    assert rec.rows_logged == 2 * N and rec.dropped == 0
    rows = read_recording(path)
    _assert_tree(rows, "a", sa)
    _assert_tree(rows, "b", sb)
    assert describe_recording(path)["blueprints"] >= 1   # each send_blueprint adds a blueprint store


def test_publish_never_blocks_and_drops_oldest(tmp_path, twin_a):
    twin, snaps = twin_a
    path = tmp_path / "drops.rrd"
    rec = _recorder(path, twin, queue_size=8)
    # stall the recorder's I/O (as a slow disk or viewer would): publish must still return at once
    with rec._io_lock:
        times = []
        for s in snaps:
            t0 = time.perf_counter()
            rec.publish(s)
            times.append(time.perf_counter() - t0)
        assert rec.queued == 8
        assert rec.dropped == N - 8
    assert max(times) < 0.01 and float(np.median(times)) < 5e-4
    rec.close()
    assert rec.rows_logged == 8
    # drop-oldest: the newest 8 made it
    assert list(read_index(path, "bearing/a/friction_torque_n_m")) == [s.seq for s in snaps[-8:]]


def test_close_is_idempotent(tmp_path, twin_a):
    twin, snaps = twin_a
    path = tmp_path / "close.rrd"
    rec = _recorder(path, twin)
    for s in snaps[:5]:
        rec.publish(s)
    rec.close()
    rec.close()
    rec.publish(snaps[5])              # after close: ignored (counted as dropped), no exception
    rec.close()
    assert rec.closed and rec.rows_logged == 5 and rec.dropped == 1
    assert read_recording(path)["bearing/a/friction_torque_n_m"] == 5
    with _recorder(tmp_path / "ctx.rrd", twin) as ctx:   # context manager closes too
        ctx.publish(snaps[0])
    assert ctx.closed and read_recording(tmp_path / "ctx.rrd")["bearing/a/balls"] == 1


def test_start_and_stop_file_while_running(tmp_path, twin_a):
    twin, snaps = twin_a
    main, extra = tmp_path / "main.rrd", tmp_path / "extra.rrd"
    rec = _recorder(main, twin, flush_interval_s=0.05)
    for s in snaps[:10]:
        rec.publish(s)
    with pytest.raises(ValueError):
        rec.start_file(main)
    assert rec.start_file(extra) == extra
    assert rec.recording_file == extra
    for s in snaps[10:30]:
        rec.publish(s)
    time.sleep(0.12)                   # let the worker flush a batch on its own
    assert rec.stop_file() == extra
    assert rec.stop_file() is None and rec.recording_file is None
    for s in snaps[30:]:
        rec.publish(s)
    rec.close()

    second = snaps[10:30]
    rows = read_recording(extra)       # complete on its own: geometry, blueprint, its 20 rows
    _assert_tree(rows, "a", second)
    assert list(read_index(extra, "bearing/a/balls")) == [s.seq for s in second]
    assert describe_recording(extra)["blueprints"] == 1
    _assert_tree(read_recording(main), "a", snaps)


def test_no_main_file_then_start_file(tmp_path, twin_a):
    twin, snaps = twin_a
    rec = _recorder(None, twin)        # nothing is written until a file is started
    for s in snaps[:5]:
        rec.publish(s)
    rec.flush()
    assert rec.rows_logged == 0 and rec.skipped == 5
    path = rec.start_file(tmp_path / "later.rrd")
    for s in snaps[5:15]:
        rec.publish(s)
    rec.stop_file()
    rec.close()
    assert rec.rows_logged == 10
    _assert_tree(read_recording(path), "a", snaps[5:15])


def test_min_interval_decimates(tmp_path, twin_a):
    twin, snaps = twin_a
    path = tmp_path / "dec.rrd"
    rec = _recorder(path, twin, min_interval_s=2.5 * FRAME_S)
    for s in snaps:
        rec.publish(s)
    rec.close()
    kept = rec.rows_logged
    assert kept + rec.skipped == N and N // 3 <= kept <= N // 3 + 1
    assert read_recording(path)["bearing/a/friction_torque_n_m"] == kept


def test_positions_override_and_unregistered_twin(tmp_path, twin_a):
    twin, snaps = twin_a
    path = tmp_path / "pos.rrd"
    rec = _recorder(path, twin)
    z = len(snaps[0].balls)
    given = np.arange(3 * z, dtype=float).reshape(z, 3) * 1e-3
    rec.publish(snaps[0], positions_m=given)
    stranger = snaps[1].model_copy(update={"bearing_id": "c"})   # never added: series only
    rec.publish(stranger)
    rec.close()
    np.testing.assert_allclose(read_column(path, "bearing/a/balls", "Points3D:positions")[0], given, rtol=1e-6)
    rows = read_recording(path)
    assert rows["bearing/c/friction_torque_n_m"] == 1
    assert rows["bearing/c/ball/0/inner/load_n"] == 1
    assert "bearing/c/balls" not in rows


def _without_electrical(s):
    """A duck-typed copy of a snapshot without the electrical fields (the schema before they were
    added): the recorder must record it all the same."""
    def strip(obj, **repl):
        d = {k: v for k, v in obj.__dict__.items() if k not in ("resistance_ohm", "capacitance_f", "electrical")}
        return SimpleNamespace(**{**d, **repl})
    balls = tuple(strip(b, inner=strip(b.inner), outer=strip(b.outer)) for b in s.balls)
    return strip(s, balls=balls)


def _count(snaps, i: int, side: str | None, leaf: str) -> int:
    """Snapshots in which ball i's `leaf` (of its `side` contact, or of the ball) is not null."""
    return sum(getattr(getattr(s.balls[i], side) if side else s.balls[i], leaf) is not None for s in snaps)


def test_electrical_series_follow_the_snapshot(tmp_path, twin_a):
    twin, snaps = twin_a
    if getattr(snaps[0].balls[0].inner, "resistance_ohm", "absent") == "absent":
        pytest.skip("the snapshot schema has no electrical fields yet")
    path = tmp_path / "elec.rrd"
    rec = _recorder(path, twin)
    for s in snaps:
        rec.publish(s)
    rec.close()
    assert rec.errors == 0
    rows = read_recording(path)
    for i in range(len(snaps[0].balls)):
        for side in ("inner", "outer"):
            for leaf in ("resistance_ohm", "capacitance_f"):   # null R (open circuit) is not logged
                expected = _count(snaps, i, side, leaf)
                assert rows.get(f"bearing/a/ball/{i}/{side}/{leaf}", 0) == expected
        assert rows.get(f"bearing/a/ball/{i}/resistance_ohm", 0) == _count(snaps, i, None, "resistance_ohm")
        assert rows[f"bearing/a/ball/{i}/capacitance_f"] == N
    assert rows.get("bearing/a/electrical/capacitance_f", 0) == \
        sum(s.electrical.capacitance_f is not None for s in snaps)   # null where not capacitive
    assert rows["bearing/a/electrical/shaft_voltage_v"] == N
    assert rows.get("bearing/a/electrical/resistance_ohm", 0) == \
        sum(s.electrical.resistance_ohm is not None for s in snaps)
    assert rows["bearing/a/electrical/discharge_risk"] >= 1          # TextLog on change
    text = read_column(path, "bearing/a/electrical/discharge_risk", "TextLog:text")[0][0]
    assert text.startswith(snaps[0].electrical.discharge_risk)


def test_snapshots_without_electrical_fields(tmp_path, twin_a):
    twin, snaps = twin_a
    path = tmp_path / "plain.rrd"
    rec = _recorder(path, twin)
    for s in snaps[:10]:
        rec.publish(_without_electrical(s))
    rec.close()
    assert rec.errors == 0 and rec.rows_logged == 10
    rows = read_recording(path)
    _assert_tree(rows, "a", snaps[:10])
    assert not [k for k in rows if "resistance" in k or "capacitance" in k or "electrical" in k]


def test_spawn_viewer_headless_falls_back_to_file(tmp_path, twin_a, monkeypatch, caplog):
    twin, snaps = twin_a
    for var in ("DISPLAY", "WAYLAND_DISPLAY", "WAYLAND_SOCKET"):
        monkeypatch.delenv(var, raising=False)
    with caplog.at_level(logging.WARNING, logger="service.recorder"):
        rec = _recorder(tmp_path / "headless.rrd", twin, spawn_viewer=True)
    assert "not spawning a viewer" in caplog.text
    # a display but no viewer executable on PATH: spawn fails, the file sink carries on
    monkeypatch.setenv("DISPLAY", ":99")
    monkeypatch.setenv("PATH", str(tmp_path))
    caplog.clear()
    with caplog.at_level(logging.WARNING, logger="service.recorder"):
        rec2 = _recorder(tmp_path / "noviewer.rrd", twin, spawn_viewer=True)
    assert "could not spawn a viewer" in caplog.text
    for s in snaps[:3]:
        rec.publish(s)
        rec2.publish(s)
    rec.close()
    rec2.close()
    assert read_recording(tmp_path / "headless.rrd")["bearing/a/balls"] == 3
    assert read_recording(tmp_path / "noviewer.rrd")["bearing/a/balls"] == 3


# ---- segments (rotation of the main file) ------------------------------------------------------
# The rotation is checked after each send; `flush()` sends, waits until the file holds it, then
# rotates if due, so with tiny thresholds every flush that wrote rows closes a segment: the number
# of segments does not depend on timing (the worker never sends: flush_interval_s is huge).
GROUPS = (7, 13, 1, 19)     # snapshots per segment (sum = N)


def _segmented(path, twin, **kw) -> RerunRecorder:
    return _recorder(path, twin, flush_interval_s=1e6, **kw)


def _publish_in_groups(rec, snaps, groups=GROUPS) -> None:
    assert sum(groups) == len(snaps)
    i = 0
    for g in groups:
        for s in snaps[i:i + g]:
            rec.publish(s)
        i += g
        rec.flush()


def _assert_segments_complete(segs, snaps, groups=GROUPS) -> None:
    """Every segment is a complete recording on its own (one recording id, the static geometry,
    the series styles, a blueprint) holding exactly its group of rows; together they hold every
    row once."""
    assert [p.name for p in segs[1:]] == [f"run-{i:04d}.rrd" for i in range(1, len(segs))]
    ids = set()
    start = 0
    for seg, g in zip(segs, groups, strict=True):
        info = describe_recording(seg)
        ids.add((info["application_id"], info["recording_id"]))
        assert info["blueprints"] >= 1, seg
        ent = info["entities"]
        assert ent["bearing/a/geometry/inner_raceway"]["static_rows"] == 1, seg
        assert ent["bearing/a/friction_torque_n_m"]["static_rows"] >= 1, seg       # series style
        assert list(read_index(seg, "bearing/a/balls")) == [s.seq for s in snaps[start:start + g]], seg
        _assert_tree(read_recording(seg), "a", snaps[start:start + g])
        start += g
    assert len(ids) == 1
    # across the boundaries: per entity, the rows of all segments = the snapshots published
    rows = read_recording(segs)
    _assert_tree(rows, "a", snaps)
    assert list(read_index(segs, "bearing/a/friction_torque_n_m")) == [s.seq for s in snaps]
    assert read_column(segs, "bearing/a/friction_torque_n_m", "sim_time") == [round(s.time_s * 1e9) for s in snaps]
    assert describe_recording(segs)["segments"] == len(segs)


@pytest.mark.parametrize("footer", [False, True], ids=["no-footer", "footer"])
def test_rotation_by_size_loses_no_row(tmp_path, twin_a, footer):
    twin, snaps = twin_a
    path = tmp_path / "run.rrd"
    rec = _segmented(path, twin, segment_bytes=1, write_footer=footer)
    _publish_in_groups(rec, snaps[:sum(GROUPS[:-1])], GROUPS[:-1])   # three segments closed by flush
    assert rec.segments == [segment_path(path, i) for i in range(4)]
    assert rec.current_path == segment_path(path, 3)
    for s in snaps[sum(GROUPS[:-1]):]:
        rec.publish(s)
    rec.close()              # the shutdown path: drains, sends and closes the open segment
    assert rec.current_path is None and rec.segments == recording_segments(path)
    assert rec.rows_logged == N and rec.dropped == 0 and rec.errors == 0
    segs = recording_segments(path)
    assert len(segs) == 4
    _assert_segments_complete(segs, snaps)
    for seg in segs:
        if footer:      # the footer (manifest) is written when a segment is closed: it is, each one
            _reader(seg).store()
        else:
            with pytest.raises(RuntimeError, match="footer"):
                _reader(seg).store()


def test_rotation_by_age_and_explicit(tmp_path, twin_a):
    twin, snaps = twin_a
    path = tmp_path / "run.rrd"
    rec = _segmented(path, twin, segment_s=1e-9)       # due as soon as a segment holds a row
    _publish_in_groups(rec, snaps[:20], (7, 13))
    assert len(rec.segments) == 3
    rec.flush()                                     # no row since the rotation: no empty segment
    assert len(rec.segments) == 3
    rec.close()
    segs = recording_segments(path)
    assert len(segs) == 3 and read_recording(segs[-1]).get("bearing/a/balls", 0) == 0
    _assert_segments_complete(segs[:2], snaps[:20], (7, 13))

    rec = _segmented(tmp_path / "x.rrd", twin)             # no thresholds: rotates on request only
    for s in snaps[:5]:
        rec.publish(s)
    rec.flush()
    assert rec.segments == [tmp_path / "x.rrd"]
    assert rec.rotate() == tmp_path / "x-0001.rrd"
    with pytest.raises(ValueError):
        rec.start_file(tmp_path / "x-0001.rrd")       # a segment is not a free file
    for s in snaps[5:9]:
        rec.publish(s)
    rec.close()
    assert rec.rotate() is None
    assert [read_recording(p)["bearing/a/friction_torque_n_m"] for p in recording_segments(tmp_path / "x.rrd")] == [5, 4]


def test_rotation_happens_in_the_worker(tmp_path, twin_a):
    """Without flush(): the worker sends every flush_interval_s and rotates when due."""
    twin, snaps = twin_a
    path = tmp_path / "run.rrd"
    rec = _recorder(path, twin, flush_interval_s=0.01, segment_bytes=1)
    for s in snaps[:10]:
        rec.publish(s)
    deadline = time.monotonic() + 30.0        # a liveness bound, not a performance figure
    while len(rec.segments) < 2 and time.monotonic() < deadline:
        time.sleep(0.01)
    for s in snaps[10:]:
        rec.publish(s)
    rec.close()
    segs = recording_segments(path)
    assert len(segs) >= 2 and rec.rows_logged == N
    _assert_tree(read_recording(segs), "a", snaps)
    assert list(read_index(segs, "bearing/a/balls")) == [s.seq for s in snaps]


def test_segment_names_and_stale_segments(tmp_path, twin_a):
    twin, snaps = twin_a
    path = tmp_path / "run.rrd"
    assert segment_path(path, 0) == path and segment_path(path, 12) == tmp_path / "run-0012.rrd"
    assert recording_segments(path) == []
    # with rotation on, segments of an earlier, longer recording to the same name are removed
    # (run.rrd itself is overwritten), other files are left alone; without rotation nothing is
    for name in ("run-0001.rrd", "run-0002.rrd", "run-0003.rrd", "run-x.rrd", "run-0001.txt", "other-0001.rrd"):
        (tmp_path / name).write_bytes(b"old")
    _segmented(path, twin).close()
    assert (tmp_path / "run-0002.rrd").exists()
    rec = _segmented(path, twin, segment_bytes=1)
    assert not (tmp_path / "run-0002.rrd").exists() and not (tmp_path / "run-0003.rrd").exists()
    assert all((tmp_path / n).exists() for n in ("run-x.rrd", "run-0001.txt", "other-0001.rrd"))
    _publish_in_groups(rec, snaps[:10], (10,))
    rec.close()
    assert recording_segments(path) == [path, tmp_path / "run-0001.rrd"]
    # a missing number ends the list
    (tmp_path / "run-0003.rrd").write_bytes(b"x")
    assert recording_segments(path) == [path, tmp_path / "run-0001.rrd"]
    with pytest.raises(ValueError):
        RerunRecorder(path, segment_s=-1.0)
    with pytest.raises(ValueError):
        RerunRecorder(path, segment_bytes=-5)


def test_service_settings_reach_the_recorder(tmp_path, monkeypatch):
    from service.settings import ServiceSettings
    from service.wiring import open_recorder

    s = ServiceSettings(record=tmp_path / "svc.rrd", enable_zenoh=False)
    assert s.record_segment_s == 600.0 and s.record_segment_mb == 1000.0 and s.record_footer is False
    rec = open_recorder(s)
    try:
        assert rec.segment_s == 600.0 and rec.segment_bytes == 1_000_000_000 and rec.write_footer is False
        assert rec.flush_interval_s == 0.1
    finally:
        rec.close()
    monkeypatch.setenv("BEARING_TWIN_RECORD_SEGMENT_S", "0")
    monkeypatch.setenv("BEARING_TWIN_RECORD_SEGMENT_MB", "0.5")
    monkeypatch.setenv("BEARING_TWIN_RECORD_FOOTER", "true")
    s = ServiceSettings(record=tmp_path / "svc2.rrd", enable_zenoh=False)
    rec = open_recorder(s)
    try:
        assert rec.segment_s is None and rec.segment_bytes == 500_000 and rec.write_footer is True
    finally:
        rec.close()


def _threads() -> int:
    import os

    return len(os.listdir("/proc/self/task"))


def test_rotation_keeps_one_stream_and_closes_the_old_segment_at_once(tmp_path, twin_a):
    """rerun-sdk 0.41 never frees a RecordingStream (its threads keep running): the rotation
    re-points the same stream (and the same blueprint stream) at the next file, so rotating adds
    no thread; and the segment it leaves is closed right away (its footer is written)."""
    pytest.importorskip("rerun")
    import os

    if not os.path.isdir("/proc/self/task"):
        pytest.skip("counts threads in /proc")
    twin, snaps = twin_a
    path = tmp_path / "run.rrd"
    rec = _segmented(path, twin, segment_bytes=1, write_footer=True)
    rec.publish(snaps[0])
    rec.flush()                                   # first rotation: blueprint stream created
    before = _threads()
    for i in range(1, 31):
        rec.publish(snaps[i % N])
        rec.flush()
        _reader(rec.segments[-2]).store()         # the segment just left is complete (footer)
    assert len(rec.segments) == 32
    assert _threads() - before <= 1
    rec.close()
    assert read_recording(recording_segments(path))["bearing/a/balls"] == 31


def test_a_failed_rotation_keeps_writing_the_open_segment(tmp_path, twin_a):
    twin, snaps = twin_a
    path = tmp_path / "run.rrd"
    (tmp_path / "run-0001.rrd").mkdir()           # the next segment cannot be created
    rec = _segmented(path, twin)
    for s in snaps[:5]:
        rec.publish(s)
    assert rec.rotate() is None and rec.errors == 1
    assert rec.segments == [path] and rec.current_path == path
    for s in snaps[5:12]:
        rec.publish(s)
    rec.close()
    assert read_recording(recording_segments(path))["bearing/a/friction_torque_n_m"] == 12
    assert list(read_index(path, "bearing/a/balls")) == [s.seq for s in snaps[:12]]
