"""`bearing-twin-loadtest soak`, the short CI version: 18 s against its own `serve` subprocess
(free loopback ports, token, recording in a temp dir), then SIGTERM and the recording read back.
The figures are reported, not judged against wall-clock thresholds (a shared, noisy machine):
what must hold is no 5xx, no unexpected answer, no lost zenoh result, a finite state stream and
a complete recording."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from loadtest.soak import SoakConfig, _memory, format_report, run_soak
from service.settings import ServiceSettings

# `python -m loadtest` from any folder finds this tree's package
LOADTEST_ENV = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[2])}


def test_soak_short_run_with_its_own_service(hostile, tmp_path):
    pytest.importorskip("zenoh")
    pytest.importorskip("rerun")
    # the service's recording rotates every 4 s: the check reads every segment back
    cmd = [
        sys.executable,
        "-m",
        "loadtest",
        "soak",
        "--minutes",
        "0.3",
        "--start",
        "--json",
        "--seed",
        "7",
        "--rate",
        "12",
        "--record-segment-s",
        "4",
    ]
    proc = subprocess.run(cmd, cwd=tmp_path, capture_output=True, text=True, timeout=300, env=LOADTEST_ENV)
    assert proc.stdout.strip(), proc.stderr
    r = json.loads(proc.stdout)
    detail = json.dumps(r, indent=1) + "\n" + proc.stderr[-3000:]
    assert r["started_service"] and r["token"] == "generated"
    sp = r["setpoints"]
    assert min(sp["http_valid"], sp["http_invalid"], sp["zenoh_valid"], sp["zenoh_invalid"]) > 0, detail
    assert r["http"]["server_errors"] == 0 and r["http"]["transport_errors"] == 0, detail
    assert r["unexpected_count"] == 0, detail
    z = r["zenoh_results"]
    assert z["unexpected"] == 0 and z["missing"] == 0 and z["received"] == sp["zenoh_valid"] + sp["zenoh_invalid"], (
        detail
    )
    s = r["stream"]
    assert s["messages"] > 0 and s["non_finite"] == 0 and s["out_of_order"] == 0, detail
    # gaps would mean dropped snapshots; loopback at 50 Hz should lose none, but a stalled
    # shared machine is not this test's subject: allow a sliver, report the figure
    assert s["dropped_messages"] <= max(2, s["messages"] // 100), detail
    assert r["runner"]["errors"] == 0, detail
    m = r["memory"]
    assert m["samples"] >= 3 and m["baseline_mb"] > 0 and m["growth_pct"] is not None, detail
    assert r["real_time_factor"]["median"] is not None
    assert r["shutdown"]["exit_code"] in (0, -15) and not r["shutdown"]["killed"], detail
    rec = r["recording"]
    # a trend row per window of `snapshots_per_row` snapshots (the service's recordings hold window means)
    per_row = rec["snapshots_per_row"]
    assert rec["complete"] and rec["rows_read"] * per_row >= rec["rows_reported"] - per_row > 0, detail
    assert rec["seq_gaps"] == 0, detail
    assert rec["segments"] >= 2 and rec["duplicates"] == 0 and rec["recording_ids"] == 1, detail
    assert all(f["blueprints"] and f["static_geometry"] for f in rec["segment_files"]), detail
    assert sum(f["rows"] for f in rec["segment_files"]) == rec["rows_read"], detail
    assert r.get("service_dir_removed")
    assert "OK" in format_report(r) or r["failures"], detail


def test_soak_against_a_running_service_http_only(hostile, tmp_path):
    """Without --start: drives an existing service (here an in-process one, no zenoh)."""
    settings = ServiceSettings(
        enable_zenoh=False, enable_recording=False, scenario_dir=hostile.SCENARIOS, token="tok-123"
    )
    with hostile.ThreadServer(settings) as srv:
        r = run_soak(SoakConfig(minutes=0.08, url=srv.url, token="tok-123", seed=3, rate_hz=20.0, sample_s=0.5))
    assert r["stream"] is None and r["zenoh"] is None
    assert r["setpoints"]["http_valid"] > 0 and r["setpoints"]["http_invalid"] > 0
    assert r["http"]["server_errors"] == 0 and r["unexpected_count"] == 0, r["unexpected"]
    assert r["memory"]["samples"] > 0 and r["memory"]["source"] in ("psutil", "proc")
    assert (
        "401" in r["http"]["status_counts"]
        or "413" in r["http"]["status_counts"]
        or "422" in r["http"]["status_counts"]
    )


def test_memory_growth_uses_the_first_sample_after_the_warm_up():
    mib = 2**20
    m = _memory(
        [(0.0, 50 * mib), (5.0, 100 * mib), (10.0, 101 * mib), (15.0, 104 * mib), (20.0, 102 * mib)],
        warmup=5.0,
        source="proc",
    )
    assert m["baseline_mb"] == 100.0 and m["final_mb"] == 102.0 and m["growth_pct"] == pytest.approx(2.0)
    assert _memory([], 5.0, None)["growth_pct"] is None


def test_soak_refuses_unbounded_runs():
    with pytest.raises(ValueError):
        run_soak(SoakConfig(minutes=float("inf")))
    proc = subprocess.run(
        [sys.executable, "-m", "loadtest", "soak", "--minutes", "0"],
        capture_output=True,
        text=True,
        timeout=60,
        env=LOADTEST_ENV,
    )
    assert proc.returncode == 2 and "--minutes" in proc.stderr


def _segmented_recording(tmp_path, groups):
    """A recording of `groups` snapshots per segment, rotated with `rotate()`."""
    from service.recording import RerunRecorder
    from twin.engine import Twin

    twin = Twin("6208", bearing_id="default")
    rec = RerunRecorder(tmp_path / "soak.rrd", flush_interval_s=1e6)
    rec.add_twin_from(twin)
    for i, g in enumerate(groups):
        if i:
            rec.rotate()
        for _ in range(g):
            twin.advance(0.002)
            rec.publish(twin.snapshot())
    rec.close()
    return rec


def test_recording_check_reads_every_segment(tmp_path):
    pytest.importorskip("rerun")
    from loadtest.soak import _check_recording

    rec = _segmented_recording(tmp_path, (4, 6, 5))
    r = _check_recording(tmp_path / "soak.rrd", "default", rows_reported=15, last_stream_seq=None, snapshots_per_row=1)
    assert r["error"] is None and r["complete"], r
    assert r["segments"] == 3 and [f["rows"] for f in r["segment_files"]] == [4, 6, 5]
    assert r["rows_read"] == 15 and r["seq_gaps"] == 0 and r["duplicates"] == 0 and r["recording_ids"] == 1
    # a lost segment in the middle: a gap, incomplete
    rec.segments[1].rename(tmp_path / "soak-0001.rrd.bak")
    r = _check_recording(tmp_path / "soak.rrd", "default", rows_reported=15, last_stream_seq=None, snapshots_per_row=1)
    assert r["segments"] == 1 and not r["complete"]


def test_short_runs_report_memory_growth_without_judging_it():
    """A 30 s soak: the warm-up is 10 s and the 20 s after it are too short to tell a leak from
    a one-off settling step (a +28 MB step 28 s into a run, flat afterwards, was seen), so the
    growth is reported, not judged; a run with 60 s or more after its warm-up is judged."""
    from loadtest.soak import MIN_JUDGED_WINDOW_S, warmup_s

    mib = 2**20
    assert warmup_s(30.0) == 10.0 and warmup_s(120.0) == 30.0 and warmup_s(600.0) == 60.0
    short = _memory([(0.0, 360 * mib), (10.0, 360 * mib), (20.0, 388 * mib), (30.0, 388 * mib)], warmup_s(30.0), "x")
    assert short["growth_pct"] == pytest.approx(100 * 28 / 360, rel=1e-3) and short["judged"] is False
    t_end = warmup_s(180.0) + MIN_JUDGED_WINDOW_S
    long = _memory([(t, 360 * mib) for t in range(0, int(t_end) + 11, 10)], warmup_s(180.0), "x")
    assert long["judged"] is True and long["growth_pct"] == 0.0


def test_a_clean_sigterm_shutdown_reads_as_such():
    from loadtest.soak import _shutdown_text

    assert _shutdown_text({"killed": False, "exit_code": -15, "seconds": 0.2}) == "clean shutdown in 0.2 s"
    assert _shutdown_text({"killed": False, "exit_code": 0, "seconds": 0.2}) == "clean shutdown in 0.2 s"
    assert "not a clean shutdown" in _shutdown_text({"killed": False, "exit_code": 1, "seconds": 0.2})
    assert "killed" in _shutdown_text({"killed": True, "exit_code": -9, "seconds": 30.0})
