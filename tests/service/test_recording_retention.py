"""Retention: the newest segments of the service-wide recordings are kept up to a size
or age limit, older ones deleted - only files of the recording's own family, never the open
segment, never a link, never a per-twin recording. A recorder applies it after each segment."""

from __future__ import annotations

import os
import time

import pytest

from service.recording.retention import Retention, family_of


def _file(path, size: int, age_s: float, now: float) -> None:
    path.write_bytes(b"x" * size)
    os.utime(path, (now - age_s, now - age_s))


def test_family_of_default_and_operator_names():
    default = family_of("recordings/bearing-twin-20260101T000000Z.rrd")
    for name in (
        "bearing-twin-20251231T235959Z.rrd",
        "bearing-twin-20260101T000000Z-0003.rrd",
        "bearing-twin-20260101T000000Z.run2.rrd",
    ):
        assert default.match(name), name
    for name in ("pump-1.rrd", "bearing-twin.txt", "default-20260101T000000Z.rrd"):
        assert not default.match(name), name
    own = family_of("/data/run.rrd")
    for name in ("run.rrd", "run-0001.rrd", "run.run2.rrd", "run.run12-0004.rrd"):
        assert own.match(name), name
    for name in ("run-x.rrd", "runner.rrd", "run.rrd.bak", "other-0001.rrd", "run-01.rrd"):
        assert not own.match(name), name


def test_size_and_age_limits_keep_the_newest(tmp_path):
    now = time.time()
    sizes = {f"run-{i:04d}.rrd": (1000, 100.0 * (10 - i)) for i in range(1, 10)}  # run-0009 newest
    for name, (size, age) in sizes.items():
        _file(tmp_path / name, size, age, now)
    _file(tmp_path / "run.rrd", 1000, 2000.0, now)  # the oldest, but open: protected
    _file(tmp_path / "clip.rrd", 5000, 5000.0, now)  # a per-twin recording: not ours
    (tmp_path / "run-0010.rrd").symlink_to(tmp_path / "clip.rrd")  # a link: never deleted
    r = Retention.for_recording(tmp_path / "run.rrd", keep_bytes=4500)
    r.protect(tmp_path / "run.rrd")
    deleted = r.apply(now)
    # kept: the open run.rrd (1000) + the three newest (3000); 4500 leaves no room for a fourth
    assert sorted(p.name for p in deleted) == [f"run-{i:04d}.rrd" for i in range(1, 7)]
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "clip.rrd",
        "run-0007.rrd",
        "run-0008.rrd",
        "run-0009.rrd",
        "run-0010.rrd",
        "run.rrd",
    ]
    assert r.deleted == 6 and r.deleted_bytes == 6000
    # age: older than 150 s goes (run-0008 is 200 s old), the open one stays
    r = Retention.for_recording(tmp_path / "run.rrd", keep_age_s=150.0)
    r.protect(tmp_path / "run.rrd")
    assert [p.name for p in r.apply(now)] == ["run-0008.rrd", "run-0007.rrd"]
    assert (tmp_path / "run.rrd").exists() and (tmp_path / "run-0009.rrd").exists()
    # no limits: nothing is deleted
    assert Retention.for_recording(tmp_path / "run.rrd").apply(now) == []


def test_a_rotating_recorder_applies_retention(tmp_path):
    pytest.importorskip("rerun")
    from service.recording import RerunRecorder, recording_segments
    from twin.engine import Twin

    twin = Twin("6208", bearing_id="a")
    old = tmp_path / "run-old.rrd"  # not of the family: stays
    old.write_bytes(b"keep me")
    path = tmp_path / "run.rrd"
    rec = RerunRecorder(
        path, flush_interval_s=1e6, segment_bytes=1, retention=Retention.for_recording(path, keep_bytes=1)
    )  # keep only what is open
    rec.add_twin_from(twin)
    for _ in range(4):
        twin.advance(0.002)
        rec.publish(twin.snapshot())
        rec.flush()  # writes and rotates: the closed segment is deleted
    rec.close()
    left = sorted(p.name for p in tmp_path.iterdir())
    assert left == ["run-0004.rrd", "run-old.rrd"], left
    assert rec.retention.deleted == 4
    assert recording_segments(path) == []  # run.rrd itself was deleted once closed
