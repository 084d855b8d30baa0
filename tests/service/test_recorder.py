"""RerunRecorder: record snapshots of real twins into .rrd files and read them back with
`rerun.chunk.RrdReader` (through service.recording.read_recording / read_column). The entity
layout is that of `service.recording.layout`: one entity per quantity, all balls / contacts of a
snapshot in one row."""

from __future__ import annotations

import logging
import math
import time
from types import SimpleNamespace

import numpy as np
import pytest

from service.recording import (
    RecordingPathError,
    RerunRecorder,
    describe_recording,
    read_column,
    read_index,
    read_recording,
    recording_segments,
    segment_path,
)
from service.recording.layout import REGIME_CODE
from service.recording.reader import open_reader as _reader
from twin.engine import Twin

N = 40  # snapshots per twin
FRAME_S = 0.002  # 2 ms frames


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
    return {
        "designation": m.spec.designation,
        "pitch_radius_m": m.pitch_radius_m,
        "ball_radius_m": m.ball_radius_m,
        "inner_raceway_radius_m": g.inner_raceway_radius_m,
        "outer_raceway_radius_m": g.outer_raceway_radius_m,
        "ball_count": m.ball_count,
    }


def _recorder(path, *twins, **kw) -> RerunRecorder:
    rec = RerunRecorder(path, **kw)
    for twin in twins:
        rec.add_twin(twin.bearing_id, **_geometry(twin))
    return rec


def _defined(snaps, i: int, side: str, attr: str = "lambda_") -> int:
    return sum(getattr(getattr(s.balls[i], side), attr) is not None for s in snaps)


FAST = (
    "balls",
    "loads",
    "friction_torque_n_m",
    "loads_n",
    "speeds_rad_s",
    "min_lambda",
    "regime_counts",
    "temperatures_c",
) + tuple(f"load_zone/{f}/{side}" for f in ("load_n", "lambda", "mu") for side in ("inner", "outer"))
SLOW = ("contacts/load_n", "contacts/lambda", "contacts/mu")


def _assert_tree(rows: dict, bearing_id: str, snaps: list, geometry: bool = True) -> None:
    """One row per snapshot in every per-snapshot entity (all balls / contacts in it)."""
    root = f"bearing/{bearing_id}"
    n = len(snaps)
    if geometry:
        for name in ("inner_raceway", "outer_raceway", "pitch_circle", "load_line"):
            assert f"{root}/geometry/{name}" in rows  # static geometry
    for leaf in FAST + SLOW:
        if not geometry and leaf in ("balls", "loads"):
            assert f"{root}/{leaf}" not in rows or rows[f"{root}/{leaf}"] == 0
            continue
        assert rows[f"{root}/{leaf}"] == n, leaf


def _ball_regime(ball) -> int:
    """The worst loaded contact's regime (boundary < mixed < full film), no contact if none."""
    loaded = [REGIME_CODE[c.regime] for c in (ball.inner, ball.outer) if c.regime != "no_contact"]
    return min(loaded) if loaded else 0


def _scalars(path, entity: str) -> np.ndarray:
    return np.array(read_column(path, entity, "Scalars:scalars"), dtype=float)


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
    assert read_column(path, "bearing/a/friction_torque_n_m", "sim_time") == [round(s.time_s * 1e9) for s in snaps]
    torque = [v[0] for v in read_column(path, "bearing/a/friction_torque_n_m", "Scalars:scalars")]
    assert torque == pytest.approx([s.friction_torque_n_m for s in snaps])

    # balls on the pitch circle at their azimuth, class id = ball regime (annotation context)
    pos = np.array(read_column(path, "bearing/a/balls", "Points3D:positions")[-1])
    last = snaps[-1]
    az = np.array([b.azimuth_rad for b in last.balls])
    rp = twin.model.pitch_radius_m
    np.testing.assert_allclose(pos[:, 0], rp * np.cos(az), atol=1e-6)
    np.testing.assert_allclose(pos[:, 1], rp * np.sin(az), atol=1e-6)
    assert read_column(path, "bearing/a/balls", "Points3D:class_ids")[-1] == [_ball_regime(b) for b in last.balls]
    assert "AnnotationContext:context" in info["entities"]["bearing/a"]["components"]

    # inner-load arrows point from the ball centre towards the inner raceway, length ~ load
    vec = np.array(read_column(path, "bearing/a/loads", "Arrows3D:vectors")[-1])
    loads = np.array([b.inner.load_n for b in last.balls])
    radial = (vec[:, :2] * pos[:, :2]).sum(axis=1)
    assert np.all(radial[loads > 0] < 0.0)
    lengths = np.linalg.norm(vec, axis=1)
    k = loads > 0
    np.testing.assert_allclose(lengths[k] / loads[k], (lengths[k] / loads[k])[0], rtol=1e-5)

    # the load zone now: one bar per ball at its azimuth [deg], inner left of outer
    for leaf, attr in (("load_n", "load_n"), ("lambda", "lambda_"), ("mu", "mu")):
        for side in ("inner", "outer"):
            entity = f"bearing/a/load_zone/{leaf}/{side}"
            values = np.array(read_column(path, entity, "BarChart:values")[-1][0]["buffer"], dtype=float)
            x = np.array(read_column(path, entity, "BarChart:abscissa")[-1][0]["buffer"], dtype=float)
            want = np.array([getattr(getattr(b, side), attr) or 0.0 for b in last.balls])
            np.testing.assert_allclose(values, want, rtol=1e-6, atol=1e-9)
            shift = np.degrees(np.angle(np.exp(1j * az))) - x
            assert np.all(shift > 0) if side == "inner" else np.all(shift < 0)
            np.testing.assert_allclose(np.abs(shift), 360.0 / len(az) * 0.15, rtol=1e-4)

    # bearing-level trends with the setpoint beside them
    lo = _scalars(path, "bearing/a/loads_n")[-1]
    qmax = max(max(b.inner.load_n, b.outer.load_n) for b in last.balls)
    np.testing.assert_allclose(lo, [qmax, last.setpoint.radial_load_n, last.setpoint.axial_load_n], rtol=1e-9)
    sp = _scalars(path, "bearing/a/speeds_rad_s")[-1]
    np.testing.assert_allclose(sp, [last.setpoint.shaft_speed_rad_s, last.shaft_speed_rad_s, last.cage_speed_rad_s])
    counts = _scalars(path, "bearing/a/regime_counts")
    assert np.all(counts.sum(axis=1) == len(az))
    ml = _scalars(path, "bearing/a/min_lambda")[-1]
    inner = [b.inner.lambda_ for b in last.balls if b.inner.lambda_ is not None and b.inner.load_n > 0]
    assert ml[0] == pytest.approx(min(inner))
    # the per-contact series: ball 0 inner, ball 0 outer, ball 1 inner, ...
    cl = np.array(read_column(path, "bearing/a/contacts/load_n", "Scalars:scalars")[-1])
    np.testing.assert_allclose(cl, [x for b in last.balls for x in (b.inner.load_n, b.outer.load_n)])
    # one blueprint, one chunk per entity for a run shorter than a send interval
    assert info["entities"]["bearing/a/friction_torque_n_m"]["chunks"] == 1


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
    assert describe_recording(path)["blueprints"] >= 1  # each send_blueprint adds a blueprint store


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
    rec.publish(snaps[5])  # after close: ignored (counted as dropped), no exception
    rec.close()
    assert rec.closed and rec.rows_logged == 5 and rec.dropped == 1
    assert read_recording(path)["bearing/a/friction_torque_n_m"] == 5
    with _recorder(tmp_path / "ctx.rrd", twin) as ctx:  # context manager closes too
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
    time.sleep(0.12)  # let the worker flush a batch on its own
    assert rec.stop_file() == extra
    assert rec.stop_file() is None and rec.recording_file is None
    for s in snaps[30:]:
        rec.publish(s)
    rec.close()

    second = snaps[10:30]
    rows = read_recording(extra)  # complete on its own: geometry, blueprint, its 20 rows
    _assert_tree(rows, "a", second)
    assert list(read_index(extra, "bearing/a/balls")) == [s.seq for s in second]
    assert describe_recording(extra)["blueprints"] == 1
    _assert_tree(read_recording(main), "a", snaps)


def test_no_main_file_then_start_file(tmp_path, twin_a):
    twin, snaps = twin_a
    rec = _recorder(None, twin)  # nothing is written until a file is started
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
    stranger = snaps[1].model_copy(update={"bearing_id": "c"})  # never added: series only
    rec.publish(stranger)
    rec.close()
    np.testing.assert_allclose(read_column(path, "bearing/a/balls", "Points3D:positions")[0], given, rtol=1e-6)
    rows = read_recording(path)
    assert rows["bearing/c/friction_torque_n_m"] == 1
    assert rows["bearing/c/contacts/load_n"] == 1
    assert rows["bearing/c/load_zone/load_n/inner"] == 1
    assert "bearing/c/balls" not in rows


def _without_electrical(s):
    """A duck-typed copy of a snapshot without the electrical fields (the schema before they were
    added): the recorder must record it all the same."""

    def strip(obj, **repl):
        d = {k: v for k, v in obj.__dict__.items() if k not in ("resistance_ohm", "capacitance_f", "electrical")}
        return SimpleNamespace(**{**d, **repl})

    balls = tuple(strip(b, inner=strip(b.inner), outer=strip(b.outer)) for b in s.balls)
    return strip(s, balls=balls)


def test_electrical_series_follow_the_snapshot(tmp_path, twin_a):
    """The electrical panel in engineering units: C in pF, R and |Z| as log10 of kohm (NaN
    where there is no conduction), the discharge risk as a state, one row per change."""
    twin, snaps = twin_a
    path = tmp_path / "elec.rrd"
    rec = _recorder(path, twin)
    for s in snaps:
        rec.publish(s)
    rec.close()
    assert rec.errors == 0
    rows = read_recording(path)
    for leaf in (
        "capacitance_pf",
        "resistance_log10_kohm",
        "shaft_voltage_v",
        "shaft_current_ma",
        "film_field_v_per_um",
        "current_density_a_per_mm2",
    ):
        assert rows[f"bearing/a/electrical/{leaf}"] == N, leaf
    c = _scalars(path, "bearing/a/electrical/capacitance_pf")[:, 0]
    np.testing.assert_allclose(
        c,
        [s.electrical.capacitance_f * 1e12 if s.electrical.capacitance_f is not None else math.nan for s in snaps],
        rtol=1e-12,
    )  # NaN (a line break) where C is null
    r = _scalars(path, "bearing/a/electrical/resistance_log10_kohm")
    want_r = [math.log10(s.electrical.resistance_ohm / 1e3) if s.electrical.resistance_ohm else math.nan for s in snaps]
    np.testing.assert_allclose(r[:, 0], want_r, rtol=1e-12)  # NaN where R is null
    np.testing.assert_allclose(r[:, 1], [math.log10(s.electrical.impedance_ohm / 1e3) for s in snaps], rtol=1e-12)
    np.testing.assert_allclose(
        _scalars(path, "bearing/a/electrical/shaft_current_ma")[:, 0],
        [s.electrical.shaft_current_a * 1e3 for s in snaps],
        rtol=1e-12,
        atol=1e-15,
    )
    # per contact: C [pF] for all 2 Z contacts
    cc = np.array(read_column(path, "bearing/a/contacts/capacitance_pf", "Scalars:scalars")[-1])
    np.testing.assert_allclose(
        cc, [x * 1e12 for b in snaps[-1].balls for x in (b.inner.capacitance_f, b.outer.capacitance_f)], rtol=1e-12
    )
    risks = [s.electrical.discharge_risk for s in snaps]
    changes = 1 + sum(a != b for a, b in zip(risks, risks[1:]))
    assert rows["bearing/a/electrical/discharge_risk"] == changes  # StateChange on change
    assert read_column(path, "bearing/a/electrical/discharge_risk", "StateChange:state")[0] == [risks[0]]


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
    # (the alarm states are logged from the first row on, the electrical-discharge alarm's too)
    assert not [
        k
        for k, v in rows.items()
        if v and ("resistance" in k or "capacitance" in k or "electrical" in k) and "/alarm_states/" not in k
    ]


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
GROUPS = (7, 13, 1, 19)  # snapshots per segment (sum = N)


def _segmented(path, twin, **kw) -> RerunRecorder:
    return _recorder(path, twin, flush_interval_s=1e6, **kw)


def _publish_in_groups(rec, snaps, groups=GROUPS) -> None:
    assert sum(groups) == len(snaps)
    i = 0
    for g in groups:
        for s in snaps[i : i + g]:
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
        assert ent["bearing/a/friction_torque_n_m"]["static_rows"] >= 1, seg  # series style
        assert list(read_index(seg, "bearing/a/balls")) == [s.seq for s in snaps[start : start + g]], seg
        _assert_tree(read_recording(seg), "a", snaps[start : start + g])
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
    _publish_in_groups(rec, snaps[: sum(GROUPS[:-1])], GROUPS[:-1])  # three segments closed by flush
    assert rec.segments == [segment_path(path, i) for i in range(4)]
    assert rec.current_path == segment_path(path, 3)
    for s in snaps[sum(GROUPS[:-1]) :]:
        rec.publish(s)
    rec.close()  # the shutdown path: drains, sends and closes the open segment
    assert rec.current_path is None and rec.segments == recording_segments(path)
    assert rec.rows_logged == N and rec.dropped == 0 and rec.errors == 0
    segs = recording_segments(path)
    assert len(segs) == 4
    _assert_segments_complete(segs, snaps)
    for seg in segs:
        if footer:  # the footer (manifest) is written when a segment is closed: it is, each one
            _reader(seg).store()
        else:
            with pytest.raises(RuntimeError, match="footer"):
                _reader(seg).store()


def test_rotation_by_age_and_explicit(tmp_path, twin_a):
    twin, snaps = twin_a
    path = tmp_path / "run.rrd"
    rec = _segmented(path, twin, segment_s=1e-9)  # due as soon as a segment holds a row
    _publish_in_groups(rec, snaps[:20], (7, 13))
    assert len(rec.segments) == 3
    rec.flush()  # no row since the rotation: no empty segment
    assert len(rec.segments) == 3
    rec.close()
    segs = recording_segments(path)
    assert len(segs) == 3 and read_recording(segs[-1]).get("bearing/a/balls", 0) == 0
    _assert_segments_complete(segs[:2], snaps[:20], (7, 13))

    rec = _segmented(tmp_path / "x.rrd", twin)  # no thresholds: rotates on request only
    for s in snaps[:5]:
        rec.publish(s)
    rec.flush()
    assert rec.segments == [tmp_path / "x.rrd"]
    assert rec.rotate() == tmp_path / "x-0001.rrd"
    with pytest.raises(ValueError):
        rec.start_file(tmp_path / "x-0001.rrd")  # a segment is not a free file
    for s in snaps[5:9]:
        rec.publish(s)
    rec.close()
    assert rec.rotate() is None
    assert [read_recording(p)["bearing/a/friction_torque_n_m"] for p in recording_segments(tmp_path / "x.rrd")] == [
        5,
        4,
    ]


def test_no_rotation_after_the_last_twin_is_removed(tmp_path, twin_a):
    """The service's shutdown removes its twins, then closes the recorder: a segment falling due
    in between must not open a segment that holds neither static geometry nor blueprint (every
    segment is a complete recording, `service.recording.segments`)."""
    twin, snaps = twin_a
    path = tmp_path / "run.rrd"
    rec = _segmented(path, twin, segment_s=1e-9)  # due as soon as a segment holds a row
    for s in snaps[:5]:
        rec.publish(s)
    assert rec.remove_twin("a")  # its 5 rows are written to the open segment
    rec.flush()  # due by age and rows, but no twin is left
    assert rec.segments == [path]
    rec.close()
    segs = recording_segments(path)
    assert segs == [path]
    info = describe_recording(path)
    assert info["blueprints"] >= 1 and info["entities"]["bearing/a/geometry/inner_raceway"]["static_rows"] == 1
    assert list(read_index(path, "bearing/a/balls")) == [s.seq for s in snaps[:5]]


def test_rotation_happens_in_the_worker(tmp_path, twin_a):
    """Without flush(): the worker sends every flush_interval_s and rotates when due."""
    twin, snaps = twin_a
    path = tmp_path / "run.rrd"
    rec = _recorder(path, twin, flush_interval_s=0.01, segment_bytes=1)
    for s in snaps[:10]:
        rec.publish(s)
    deadline = time.monotonic() + 30.0  # a liveness bound, not a performance figure
    while len(rec.segments) < 2 and time.monotonic() < deadline:
        time.sleep(0.01)
    for s in snaps[10:]:
        rec.publish(s)
    rec.close()
    segs = recording_segments(path)
    assert len(segs) >= 2 and rec.rows_logged == N
    _assert_tree(read_recording(segs), "a", snaps)
    assert list(read_index(segs, "bearing/a/balls")) == [s.seq for s in snaps]


def test_segment_names_and_earlier_runs_are_kept(tmp_path, twin_a):
    """Recordings are append-only history: a recorder on a name that exists (with segments of an
    earlier, longer recording) records under the next free `<stem>.runN.rrd` and leaves every
    earlier file as it was."""
    twin, snaps = twin_a
    path = tmp_path / "run.rrd"
    assert segment_path(path, 0) == path and segment_path(path, 12) == tmp_path / "run-0012.rrd"
    assert recording_segments(path) == []
    old = {
        name: f"old {name}".encode()
        for name in (
            "run.rrd",
            "run-0001.rrd",
            "run-0002.rrd",
            "run-0003.rrd",
            "run-x.rrd",
            "run-0001.txt",
            "other-0001.rrd",
            "run.run2-0001.rrd",
        )
    }
    for name, data in old.items():
        (tmp_path / name).write_bytes(data)
    rec = _segmented(path, twin, segment_bytes=1)
    assert rec.path == tmp_path / "run.run3.rrd"  # run.run2 is taken by a stray segment
    _publish_in_groups(rec, snaps[:10], (10,))
    rec.close()
    assert all((tmp_path / name).read_bytes() == data for name, data in old.items())
    assert recording_segments(rec.path) == [rec.path, tmp_path / "run.run3-0001.rrd"]
    assert read_recording(recording_segments(rec.path))["bearing/a/balls"] == 10
    assert recording_segments(path) == [
        path,
        tmp_path / "run-0001.rrd",
        tmp_path / "run-0002.rrd",
        tmp_path / "run-0003.rrd",
    ]
    # a missing number ends the list
    (tmp_path / "run-0005.rrd").write_bytes(b"x")
    assert len(recording_segments(path)) == 4
    # without renaming an existing name is refused, the file untouched
    with pytest.raises(RecordingPathError, match="exists"):
        RerunRecorder(path, rename_existing=False)
    assert (tmp_path / "run.rrd").read_bytes() == old["run.rrd"]
    with pytest.raises(ValueError):
        RerunRecorder(path, segment_s=-1.0)
    with pytest.raises(ValueError):
        RerunRecorder(path, segment_bytes=-5)


def test_service_settings_reach_the_recorder(tmp_path, monkeypatch):
    from service.settings import ServiceSettings
    from service.wiring import open_recorder

    s = ServiceSettings(record=tmp_path / "svc.rrd", enable_zenoh=False)
    assert s.recording.segment_s == 600.0 and s.recording.segment_mb == 1000.0 and s.recording.footer is False
    rec = open_recorder(s)
    try:
        assert rec.segment_s == 600.0 and rec.segment_bytes == 1_000_000_000 and rec.write_footer is False
        assert rec.flush_interval_s == 1.0
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
    rec.flush()  # first rotation: blueprint stream created
    before = _threads()
    for i in range(1, 31):
        rec.publish(snaps[i % N])
        rec.flush()
        _reader(rec.segments[-2]).store()  # the segment just left is complete (footer)
    assert len(rec.segments) == 32
    assert _threads() - before <= 1
    rec.close()
    assert read_recording(recording_segments(path))["bearing/a/balls"] == 31


def test_a_failed_rotation_keeps_writing_the_open_segment(tmp_path, twin_a):
    twin, snaps = twin_a
    path = tmp_path / "run.rrd"
    rec = _segmented(path, twin)
    (tmp_path / "run-0001.rrd").mkdir()  # the next segment cannot be created
    for s in snaps[:5]:
        rec.publish(s)
    assert rec.rotate() is None and rec.errors == 1
    assert rec.segments == [path] and rec.current_path == path
    for s in snaps[5:12]:
        rec.publish(s)
    rec.close()
    assert read_recording(recording_segments(path))["bearing/a/friction_torque_n_m"] == 12
    assert list(read_index(path, "bearing/a/balls")) == [s.seq for s in snaps[:12]]
