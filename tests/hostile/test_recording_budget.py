"""The recording's budget: a 30 s `bearing-twin serve` with the default settings (a
real subprocess on loopback ports) writes at most 7.5 MB of recording (0.25 MB per wall second),
`rerun rrd stats` counts at most 30 chunks per wall second, and the file read back holds every
published snapshot once (in its trend window: no window missing, no seq twice, the last window
at or past the snapshots the runner had published before SIGTERM). The figures are printed for the README."""

from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import httpx
import pytest

pytest.importorskip("rerun")

from service.recording import read_index, recording_segments
from service.recording.reader import snapshots_per_trend_window, window_seq_gaps
from service.recording.recorder import RerunRecorder
from service.settings import ServiceSettings

RUN_S = 30.0
TORQUE = "bearing/default/friction_torque_n_m"


def _rerun() -> str | None:
    here = Path(sys.executable).with_name("rerun")
    return str(here) if here.exists() else shutil.which("rerun")


def _stat(text: str, name: str) -> int:
    m = re.search(rf"^{name} = ([\d\s\u202f\u00a0,]+)$", text, re.MULTILINE)
    assert m, text[:2000]
    return int(re.sub(r"\D", "", m.group(1)))


def test_30_s_serve_stays_within_the_recording_budget(hostile, tmp_path):
    rerun = _rerun()
    if rerun is None:
        pytest.skip("the `rerun` command of rerun-sdk is not installed")
    rec = tmp_path / "rec" / "budget.rrd"
    svc = hostile.ServeProcess(tmp_path, record=rec)
    try:
        t0 = time.monotonic()
        with httpx.Client(base_url=svc.url, timeout=30.0) as c:
            time.sleep(RUN_S)  # the run being measured, not a bound
            published = c.get("/health").json()["twins"][0]["published"]
        svc.signal(signal.SIGTERM, timeout=30.0)
        wall_s = time.monotonic() - t0
    finally:
        svc.kill()
    assert "Traceback" not in svc.text, svc.text
    segs = recording_segments(rec)
    size = sum(p.stat().st_size for p in segs)
    env = {**os.environ, "RERUN_TELEMETRY_ENABLED": "false", "RUST_LOG": "warn"}
    chunks = 0
    for seg in segs:
        out = subprocess.run([rerun, "rrd", "stats", str(seg)], capture_output=True, text=True, timeout=300, env=env)
        assert out.returncode == 0, out.stderr
        chunks += _stat(out.stdout, "num_chunks")
    seqs = read_index(segs, TORQUE)
    print(
        f"\n{wall_s:.1f} s of serve: {size / 1e6:.2f} MB ({size / 1e6 / wall_s:.3f} MB/s), {chunks} chunks "
        f"({chunks / wall_s:.1f} per s), {len(seqs)} snapshots recorded of {published}+ published"
    )
    assert size <= 7.5e6 and size <= 0.25e6 * wall_s
    assert chunks <= 30 * wall_s
    # trends are window means (RerunRecorder.SERVICE_OPTIONS): a row per window of `per_window`
    # snapshots carrying its last seq; every published snapshot is in a recorded window
    per_window = snapshots_per_trend_window(
        ServiceSettings().runner.publish_rate_hz, RerunRecorder.SERVICE_OPTIONS["trend_window_s"]
    )
    assert seqs[-1] >= published and len(seqs) * per_window >= published - per_window
    assert len(set(seqs.tolist())) == len(seqs) and window_seq_gaps(seqs, per_window) == 0
