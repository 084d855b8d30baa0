"""Per-twin recordings and `start_file` clips free their rerun streams when they stop.

rerun-sdk 0.41 keeps every `RecordingStream` (2 threads each, ~1-2 MB) until
`flush_and_cleanup_orphaned_recordings()` runs (rerun issue #2116); a stream's recording id is
fixed, so clips are not pooled on shared streams (they would merge in the viewer): each clip
gets its own stream and recording id, and `RerunStreams.reclaim` frees it once its file is
closed. Thread counts are compared before/after many cycles (no wall-clock thresholds)."""

from __future__ import annotations

import os

import pytest

pytest.importorskip("rerun")

from service.recording import (
    RerunRecorder,
    RerunStreams,
    describe_recording,
    read_index,
    read_recording,
)
from service.recording.reader import open_reader as _reader
from twin.engine import Twin

FRAME_S = 0.002
GEOMETRY = ("inner_raceway", "outer_raceway", "pitch_circle", "load_line")

needs_proc = pytest.mark.skipif(not os.path.isdir("/proc/self/task"), reason="counts threads in /proc")


def _threads() -> int:
    return len(os.listdir("/proc/self/task"))


@pytest.fixture(scope="module")
def twin_and_snaps():
    twin = Twin("6208", bearing_id="a")
    snaps = []
    for _ in range(60):
        twin.advance(FRAME_S)
        snaps.append(twin.snapshot())
    return twin, snaps


def _assert_clip(path, seqs: list[int], footer: bool) -> str:
    """The clip holds exactly `seqs`, the static geometry and a blueprint; returns its recording id."""
    info = describe_recording(path)
    rows = read_recording(path)
    for name in GEOMETRY:
        assert info["entities"][f"bearing/a/geometry/{name}"]["static_rows"] >= 1
    assert info["blueprints"] >= 1
    assert rows["bearing/a/balls"] == len(seqs)
    assert rows["bearing/a/friction_torque_n_m"] == len(seqs)
    assert list(read_index(path, "bearing/a/balls")) == sorted(seqs)
    if footer:
        import rerun_bindings

        assert rerun_bindings.check_for_rrd_footer(str(path))
        _reader(path).store()  # random access through the footer works
    return info["recording_id"]


@needs_proc
@pytest.mark.parametrize("footer", [True, False])
def test_recorder_clips_free_their_streams(tmp_path, twin_and_snaps, footer):
    """A recorder per clip (what `TwinService.start_recording` does): many clips add no thread,
    each file is complete on its own and has its own recording id."""
    twin, snaps = twin_and_snaps
    streams = RerunStreams()

    def clip(i: int, n: int) -> list[int]:
        rec = RerunRecorder(tmp_path / f"clip-{i}.rrd", streams=streams, write_footer=footer)
        rec.add_twin_from(twin)
        part = snaps[i % 10 : i % 10 + n]
        for s in part:
            rec.publish(s)
        rec.close()
        assert rec.rows_logged == n
        return [s.seq for s in part]

    clip(0, 3)  # warm-up (rerun's own runtime threads)
    before = _threads()
    seqs = {i: clip(i, 1 + i % 7) for i in range(1, 41)}
    assert _threads() - before <= 1  # was +4 per clip (data + blueprint stream)
    assert streams.reclaim_errors == 0 and streams.reclaims >= 40
    ids = {_assert_clip(tmp_path / f"clip-{i}.rrd", s, footer) for i, s in seqs.items()}
    assert len(ids) == 40  # every clip is its own recording


@needs_proc
def test_start_file_clips_free_their_streams(tmp_path, twin_and_snaps):
    """`start_file` / `stop_file` on one recorder: no thread per clip; every clip holds exactly
    the rows published while it was open; the main file holds all of them."""
    twin, snaps = twin_and_snaps
    main = tmp_path / "main.rrd"
    rec = RerunRecorder(main, write_footer=True)
    rec.add_twin_from(twin)
    rec.start_file(tmp_path / "warm.rrd")
    rec.stop_file()
    before = _threads()
    expected: dict[int, list[int]] = {}
    open_clip = None
    k = 0

    def publish() -> None:
        nonlocal k
        s = snaps[k % 60]
        k += 1
        rec.publish(s)
        if open_clip is not None:
            expected[open_clip].append(s.seq)

    for i in range(30):
        publish()  # between clips: main file (and a clip left open)
        rec.start_file(tmp_path / f"f-{i}.rrd")  # replaces (completes) a clip left open
        open_clip = i
        expected[i] = []
        for _ in range(1 + i % 4):
            publish()
        if i % 3 != 2:  # every third clip is left open
            assert rec.stop_file() == tmp_path / f"f-{i}.rrd"
            open_clip = None
    rec.stop_file()
    assert _threads() - before <= 1
    rec.close()
    ids = set()
    for i, seqs in expected.items():
        ids.add(_assert_clip(tmp_path / f"f-{i}.rrd", seqs, footer=True))
    assert ids == {rec.recording_id}  # start_file clips share the recorder's id (doc)
    assert read_recording(main)["bearing/a/balls"] == k


@needs_proc
def test_service_clips_free_their_streams(tmp_path):
    """POST .../recording start/stop through `TwinService`: threads stay flat over many
    clips; each clip file holds the rows the recorder reports, with geometry and blueprint,
    under its own recording id."""
    from service.settings import ServiceSettings
    from service.wiring import TwinService

    s = ServiceSettings(
        enable_zenoh=False,
        enable_recording=True,
        record=tmp_path / "svc.rrd",
        record_footer=True,
        fast=True,
        publish_rate_hz=200.0,
    )
    svc = TwinService(s).open()
    try:
        entry = svc.get("default")
        for i in range(3):  # warm-up: rerun starts some pools lazily
            svc.start_recording(entry, f"warm-{i}.rrd")
            svc.stop_recording(entry)
        before = _threads()
        results = []
        for i in range(25):
            svc.start_recording(entry, f"clips/c-{i}.rrd")
            results.append(svc.stop_recording(entry))
        assert _threads() - before <= 1
        assert svc.rerun_streams().reclaim_errors == 0
        ids = set()
        for path, rows in results:
            info = describe_recording(path)
            for name in GEOMETRY:
                assert f"bearing/default/geometry/{name}" in info["entities"]
            assert info["blueprints"] >= 1
            assert read_recording(path).get("bearing/default/friction_torque_n_m", 0) == rows
            ids.add(info["recording_id"])
        assert len(ids) == 25
    finally:
        svc.close()


def test_reclaim_failure_is_counted_not_raised(monkeypatch):
    import rerun_bindings

    streams = RerunStreams()

    def boom():
        raise RuntimeError("sink cannot flush")

    monkeypatch.setattr(rerun_bindings, "flush_and_cleanup_orphaned_recordings", boom)
    assert streams.reclaim() is False and streams.reclaim() is False
    assert streams.reclaim_errors == 2
