"""Shutdown and restart, with a real `bearing-twin serve` subprocess on free loopback
ports: SIGTERM and SIGINT flush and close the recordings (service-wide and per-twin) and zenoh
(the liveliness token goes away), the process exits (bounded wait) and the .rrd files read back
completely; after a kill -9 every file of the killed run is left intact and readable, and the
service started again with the same --record on the same ports writes beside them, never over them."""

from __future__ import annotations

import hashlib
import json
import math
import signal

import httpx
import pytest

zenoh = pytest.importorskip("zenoh")
pytest.importorskip("rerun")

from service.recording import (  # noqa: E402
    describe_recording,
    read_index,
    read_recording,
    recording_segments,
)
from service.recording.reader import open_reader as _reader  # noqa: E402
from service.recording.reader import snapshots_per_trend_window, window_seq_gaps  # noqa: E402
from service.recording.recorder import RerunRecorder  # noqa: E402
from service.settings import ServiceSettings  # noqa: E402

TOKEN = "shutdown-test-token"
AUTH = {"Authorization": f"Bearer {TOKEN}"}
EXIT_BOUND_S = 20.0  # a liveness bound, not a performance figure
TORQUE = "bearing/default/friction_torque_n_m"


# the service's trends are window means (RerunRecorder.SERVICE_OPTIONS): a row per window of
# PER_WINDOW snapshots, carrying the seq of the window's last snapshot
PER_WINDOW = snapshots_per_trend_window(
    ServiceSettings().runner.publish_rate_hz, RerunRecorder.SERVICE_OPTIONS["trend_window_s"]
)


def _windows(snapshots: int) -> range:
    """Trend rows that `snapshots` consecutive snapshots fill: ceil(n / PER_WINDOW), one more where
    the first window is cut by the start."""
    n = math.ceil(snapshots / PER_WINDOW)
    return range(n, n + 2)


def _seq_gaps(path) -> tuple[int, int]:
    """(trend rows, windows missing between them)."""
    seqs = read_index(path, TORQUE)
    return len(seqs), window_seq_gaps(seqs, PER_WINDOW)


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_signal_flushes_recordings_and_closes_zenoh(hostile, tmp_path, sig):
    rrd = tmp_path / "service.rrd"
    svc = hostile.ServeProcess(tmp_path, record=rrd, env={"BEARING_TWIN_TOKEN": TOKEN})
    peer = None
    try:
        # the service said where it binds and that a token is required
        assert f"HTTP on http://127.0.0.1:{svc.port} (loopback only" in svc.text
        assert "access: bearer token required" in svc.text
        peer = hostile.Peer(svc.zenoh_endpoint)
        peer.subscribe("bearing/*/alive", liveliness=True)
        with httpx.Client(base_url=svc.url, timeout=30.0) as c:
            assert (
                c.post(
                    "/v1/bearings/default/recording", json={"action": "start", "path": "clip.rrd"}, headers=AUTH
                ).status_code
                == 200
            )
            assert (
                c.put("/v1/bearings/default/setpoint", json={"radial_load_n": 4000.0}, headers=AUTH).status_code == 200
            )
            hostile.wait_for(lambda: c.get("/health").json(), lambda h: h["recording_rows"] >= 20, timeout=60)
            rows_before = c.get("/health").json()["recording_rows"]
        peer.wait_for(lambda item: item.key == "bearing/default/alive")

        took = svc.signal(sig, timeout=EXIT_BOUND_S)
        # uvicorn re-raises the signal after its graceful shutdown: SIGTERM ends the process
        # "terminated by SIGTERM", SIGINT is caught by `serve` and exits 130 (128 + SIGINT)
        assert svc.proc.returncode in (0, -sig, 128 + sig), svc.text
        log = svc.text
        assert "Application shutdown complete" in log and "Traceback" not in log, log
        # zenoh was closed properly: the twin's liveliness token was withdrawn
        peer.wait_for(
            lambda item: item.key == "bearing/default/alive" and item.kind == zenoh.SampleKind.DELETE, timeout_s=10
        )
    finally:
        if peer is not None:
            peer.close()
        svc.kill()
    assert took < EXIT_BOUND_S
    # both recordings are complete: every row the service counted, no seq gap
    rows = read_recording(rrd)
    assert rows[TORQUE] * PER_WINDOW >= rows_before and rows.get("bearing/default/balls", 0) > 0
    n, gaps = _seq_gaps(rrd)
    assert n == rows[TORQUE] and gaps == 0
    clip = tmp_path / "clip.rrd"
    clip_rows = read_recording(clip)
    assert clip_rows[TORQUE] > 0 and _seq_gaps(clip)[1] == 0


def _digests(folder) -> dict[str, str]:
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(folder.glob("*.rrd"))}


def test_kill_9_keeps_every_file_and_restarts_beside_them_on_the_same_ports(hostile, tmp_path):
    """kill -9 while recording (service-wide, rotating every second, and a per-twin clip open),
    then a restart with the same --record: the killed run's files are byte for byte as the kill
    left them and readable; the new run records under a new name beside them."""
    rec = tmp_path / "rec"
    first = hostile.ServeProcess(tmp_path, record=rec / "first.rrd", env={"BEARING_TWIN_RECORD_SEGMENT_S": "1"})
    port, endpoint = first.port, first.zenoh_endpoint
    assert "access: no token (BEARING_TWIN_TOKEN unset)" in first.text, first.text
    try:
        with httpx.Client(base_url=first.url, timeout=30.0) as c:
            r = c.post("/v1/bearings/default/recording", json={"action": "start", "path": "closed.rrd"})
            assert r.status_code == 200, r.text
            hostile.wait_for(lambda: c.get("/health").json(), lambda h: h["recording_rows"] >= 30, timeout=60)
            stop = c.post("/v1/bearings/default/recording", json={"action": "stop"})
            assert stop.status_code == 200, stop.text
            rows_logged = stop.json()["rows_logged"]
            assert rows_logged > 0
            # an open one at the moment of the kill
            assert (
                c.post("/v1/bearings/default/recording", json={"action": "start", "path": "open.rrd"}).status_code
                == 200
            )
            hostile.wait_for(lambda: len(recording_segments(rec / "first.rrd")), lambda n: n >= 3, timeout=60)
    finally:
        first.proc.send_signal(signal.SIGKILL)
        first.proc.wait(15)
    assert first.proc.returncode == -signal.SIGKILL
    killed = _digests(rec)
    assert {"first.rrd", "first-0001.rrd", "closed.rrd", "open.rrd"} <= set(killed)

    closed = recording_segments(rec / "closed.rrd")  # it rotated too (1 s segments)
    rows = read_recording(closed)
    # every window the logged snapshots fill is in the file, once, none missing; more rows only
    # where the recorder's bounded queue dropped snapshots under load (counted, a line break that
    # closes its window early, as under a full suite's load on 2 cores)
    assert rows[TORQUE] >= _windows(rows_logged).start
    clip_seqs = read_index(closed, TORQUE)
    assert len(set(clip_seqs.tolist())) == len(clip_seqs)
    assert _seq_gaps(closed) == (rows[TORQUE], 0)
    # the killed run's service-wide segments (the last one cut by the kill) read back, no seq twice
    segs = recording_segments(rec / "first.rrd")
    seqs = read_index(segs, TORQUE)
    assert len(seqs) > 0 and len(set(seqs.tolist())) == len(seqs)
    assert read_recording(rec / "open.rrd").get(TORQUE, 0) >= 0

    # the same ports and the same --record, at once: HTTP answers, zenoh streams, no stale state
    second = hostile.ServeProcess(
        tmp_path, port=port, zenoh_port=int(endpoint.rsplit(":", 1)[1]), record=rec / "first.rrd"
    )
    try:
        assert second.url.endswith(f":{port}") and second.zenoh_endpoint == endpoint
        assert "first.run2.rrd" in second.text, second.text
        peer = hostile.Peer(endpoint)
        try:
            peer.subscribe("bearing/default/state")
            _, _, data = peer.wait_for(lambda item: item[0] == "bearing/default/state", timeout_s=60)
            state = hostile.strict_loads(data)
            assert state["restarts"] == 0 and state["status"] == "ok"
        finally:
            peer.close()
        with httpx.Client(base_url=second.url, timeout=30.0) as c:
            h = c.get("/health").json()
            assert h["status"] == "ok" and h["zenoh"] is True
            assert h["recording"] == str(rec / "first.run2.rrd")
            assert c.put("/v1/bearings/default/setpoint", json={"radial_load_n": 3500.0}).status_code == 200
            # the killed run's names are taken: a clip may not reuse one
            r = c.post("/v1/bearings/default/recording", json={"action": "start", "path": "open.rrd"})
            assert r.status_code == 422 and r.json()["detail"][0]["field"] == "path"
            hostile.wait_for(lambda: c.get("/health").json(), lambda h: h["recording_rows"] >= 10, timeout=60)
        second.signal(signal.SIGTERM, timeout=EXIT_BOUND_S)
        assert "Traceback" not in second.text, second.text
    finally:
        second.kill()
    after = _digests(rec)
    assert {k: after[k] for k in killed} == killed  # every file of the killed run untouched
    assert read_recording(rec / "first.run2.rrd")[TORQUE] > 0
    json.dumps(rows)


def test_sigterm_closes_the_open_segment_of_a_rotating_recording(hostile, tmp_path):
    """The service-wide recording rotates (BEARING_TWIN_RECORD_SEGMENT_S, here 1 s): SIGTERM closes
    the open segment; the segments together hold every row the service counted, each once, and
    each is a complete recording of its own (same recording id, static geometry, blueprint)."""
    rrd = tmp_path / "rot.rrd"
    svc = hostile.ServeProcess(
        tmp_path, record=rrd, env={"BEARING_TWIN_RECORD_SEGMENT_S": "1", "BEARING_TWIN_RECORD_FOOTER": "true"}
    )
    try:
        with httpx.Client(base_url=svc.url, timeout=30.0) as c:
            hostile.wait_for(lambda: len(recording_segments(rrd)), lambda n: n >= 3, timeout=60)
            # a per-twin recording may not take the name of a future segment of the service-wide one
            clash = c.post("/v1/bearings/default/recording", json={"action": "start", "path": "rot-0042.rrd"})
            assert clash.status_code == 422 and clash.json()["detail"][0]["field"] == "path", clash.text
            rows_before = c.get("/health").json()["recording_rows"]
        svc.signal(signal.SIGTERM, timeout=EXIT_BOUND_S)
        assert svc.proc.returncode in (0, -signal.SIGTERM), svc.text
        assert "Traceback" not in svc.text, svc.text
    finally:
        svc.kill()
    segs = recording_segments(rrd)
    assert len(segs) >= 3
    ids = set()
    for seg in segs:
        info = describe_recording(seg)
        ids.add(info["recording_id"])
        assert info["blueprints"] >= 1 and "bearing/default/geometry/inner_raceway" in info["entities"], seg
        assert "bearing/default/events" in info["entities"], seg  # each segment logs the state again
        _reader(seg).store()  # footer on: every segment, the last one too, was closed properly
    assert len(ids) == 1
    rows = read_recording(segs)
    seqs = read_index(segs, TORQUE)
    assert rows[TORQUE] * PER_WINDOW >= rows_before and rows[TORQUE] == len(seqs) and rows["bearing/default/balls"] > 0
    assert len(set(seqs.tolist())) == len(seqs) and window_seq_gaps(seqs, PER_WINDOW) == 0
