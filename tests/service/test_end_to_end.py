"""`bearing-twin serve` as a subprocess (HTTP on a free loopback port, zenoh listening on a free
loopback port, --record into tmp) against a real zenoh peer: HTTP setpoints show up in the zenoh
stream, zenoh setpoints take effect, malformed ones are refused while the twin keeps running,
the queryable answers, liveliness follows the twins, SIGTERM stops the service within a few
seconds and the .rrd reads back with rows. Every wait is bounded."""

from __future__ import annotations

import json
import os
import queue
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from loadtest.ports import free_port

zenoh = pytest.importorskip("zenoh")
pytest.importorskip("rerun")
httpx = pytest.importorskip("httpx")

from twin.snapshot import Snapshot  # noqa: E402

REPO = Path(__file__).resolve().parents[2]
WAIT_S = 30.0


def strict_loads(payload: bytes) -> dict:
    def reject(name):
        raise AssertionError(f"JSON carries {name}")

    return json.loads(payload, parse_constant=reject)


class Service:
    def __init__(self, tmp_path: Path, *extra: str, record: bool = True):
        self.zenoh_endpoint = f"tcp/127.0.0.1:{free_port()}"
        self.rrd = tmp_path / "x.rrd"
        cmd = [
            sys.executable,
            "-m",
            "service.cli",
            "serve",
            "--port",
            "0",
            "--zenoh-listen",
            self.zenoh_endpoint,
            "--log-level",
            "info",
            *extra,
        ]
        cmd += ["--record", str(self.rrd)] if record else ["--no-record"]
        env = {**os.environ, "PYTHONUNBUFFERED": "1"}
        env = {k: v for k, v in env.items() if not k.startswith("BEARING_TWIN_")}
        env["BEARING_TWIN_ADMISSION"] = "off"  # twins whatever this machine's speed (tests/conftest.py)
        self.proc = subprocess.Popen(
            cmd, cwd=REPO, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True
        )
        self.lines: queue.Queue = queue.Queue()
        self.log: list[str] = []
        threading.Thread(target=self._read, daemon=True).start()
        self.url = self._wait_url()

    def _read(self):
        for line in self.proc.stdout:
            self.log.append(line)
            self.lines.put(line)

    def _wait_url(self) -> str:
        deadline = time.monotonic() + 90.0
        url = None
        while time.monotonic() < deadline:
            try:
                line = self.lines.get(timeout=0.5)
            except queue.Empty:
                if self.proc.poll() is not None:
                    break
                continue
            m = re.search(r"Uvicorn running on (http://127\.0\.0\.1:\d+)", line)
            if m:
                url = m.group(1)
            if url and "Application startup complete" in "".join(self.log):
                return url
        raise AssertionError("service did not start:\n" + "".join(self.log))

    def terminate(self, timeout: float) -> float:
        t0 = time.monotonic()
        self.proc.send_signal(signal.SIGTERM)
        try:
            self.proc.wait(timeout)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait(10)
            raise AssertionError("service did not stop on SIGTERM:\n" + "".join(self.log)) from None
        return time.monotonic() - t0

    def kill(self):
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait(10)


@pytest.fixture
def service(tmp_path):
    svc = Service(tmp_path)
    yield svc
    svc.kill()


def state_where(peer, predicate, bearing_id="default"):
    key = f"bearing/{bearing_id}/state"

    def match(item):
        k, _, payload = item
        return k == key and predicate(strict_loads(payload))

    return strict_loads(peer.wait_for(match)[2])


def test_serve_http_zenoh_rerun_sigterm(service, support):
    peer = support.Peer(service.zenoh_endpoint, timeout_s=WAIT_S)  # multicast off
    http = httpx.Client(base_url=service.url, timeout=30.0)
    try:
        peer.subscribe("bearing/**")
        peer.subscribe("bearing/*/alive", liveliness=True)

        # the stream validates against the contract
        state = state_where(peer, lambda s: True)
        snap = Snapshot.model_validate(state)
        assert snap.designation == "6208" and len(snap.balls) == 9
        _, _, ball = peer.wait_for(lambda item: item[0] == "bearing/default/ball/3")
        ball = strict_loads(ball)
        assert ball["schema"] == "bearing-twin/state/1" and ball["bearing_id"] == "default"
        assert ball["index"] == 3 and "time_s" in ball and "lambda" in ball["inner"]

        # HTTP PUT -> zenoh stream
        r = http.put("/v1/bearings/default/setpoint", json={"radial_load_n": 4321.0})
        assert r.status_code == 200, r.text
        state_where(peer, lambda s: s["setpoint"]["radial_load_n"] == 4321.0)

        # zenoh setpoint -> takes effect (result reported, stream and HTTP state follow)
        peer.session.put("bearing/default/setpoint", json.dumps({"shaft_speed_rad_s": 600.0}))
        _, _, result = peer.wait_for(lambda item: item[0] == "bearing/default/setpoint/result")
        result = strict_loads(result)
        assert result["accepted"] is True and result["setpoint"]["shaft_speed_rad_s"] == 600.0
        state_where(
            peer, lambda s: s["setpoint"]["shaft_speed_rad_s"] == 600.0 and s["setpoint"]["radial_load_n"] == 4321.0
        )
        assert http.get("/v1/bearings/default/state").json()["setpoint"]["shaft_speed_rad_s"] == 600.0

        # malformed setpoints are refused with the field named; the twin keeps running
        for payload, field in (
            (b'{"radial_load_n": -5}', "radial_load_n"),
            (b'{"shaft_speed_rad_s": NaN}', "shaft_speed_rad_s"),
            (b"garbage", None),
        ):
            peer.session.put("bearing/default/setpoint", payload)
            _, _, result = peer.wait_for(lambda item: item[0] == "bearing/default/setpoint/result")
            result = strict_loads(result)
            assert result["accepted"] is False, result
            if field:
                assert field in result["error"]
        last = state_where(peer, lambda s: True)["seq"]
        state_where(peer, lambda s: s["seq"] > last + 5)
        health = http.get("/health").json()
        assert health["status"] == "ok" and health["zenoh"] is True
        assert http.get("/v1/bearings/default/state").json()["setpoint"]["radial_load_n"] == 4321.0

        # the queryable answers with the latest snapshot
        replies = []
        deadline = time.monotonic() + WAIT_S
        while not replies and time.monotonic() < deadline:
            replies = [r for r in peer.session.get("bearing/default/snapshot", timeout=2.0) if r.ok]
        assert replies
        Snapshot.model_validate(strict_loads(replies[0].ok.payload.to_bytes()))

        # liveliness: a second twin appears, then disappears
        r = http.post("/v1/bearings", json={"id": "second", "designation": "6205"})
        assert r.status_code == 201, r.text
        peer.wait_for(lambda item: item[0] == "bearing/second/alive" and item[1] == zenoh.SampleKind.PUT)
        state_where(peer, lambda s: s["designation"] == "6205", bearing_id="second")
        assert http.delete("/v1/bearings/second").status_code == 200
        peer.wait_for(lambda item: item[0] == "bearing/second/alive" and item[1] == zenoh.SampleKind.DELETE)

        rows_before = http.get("/health").json()["recording_rows"]
    finally:
        http.close()

    # SIGTERM: graceful stop within a few seconds; the token goes, the recording is complete
    took = service.terminate(timeout=15.0)
    try:
        peer.wait_for(
            lambda item: item[0] == "bearing/default/alive" and item[1] == zenoh.SampleKind.DELETE, timeout_s=5.0
        )
    finally:
        peer.close()
    # uvicorn re-raises the captured SIGTERM once its graceful shutdown (our lifespan `finally`)
    # is complete, so the exit status is the conventional "terminated by SIGTERM"
    assert service.proc.returncode in (0, -signal.SIGTERM), "".join(service.log)
    assert "Application shutdown complete" in "".join(service.log)
    assert took < 10.0, f"SIGTERM took {took:.1f} s"
    log = "".join(service.log)
    assert "Traceback" not in log, log

    from rerun.chunk import RrdReader

    rows: dict[str, int] = {}
    for chunk in RrdReader(str(service.rrd)).stream():
        if not chunk.is_static:
            rows[chunk.entity_path] = rows.get(chunk.entity_path, 0) + chunk.num_rows
    # the service records a trend row per 0.2 s window of its 50 Hz snapshots and the bearing now
    # every 0.5 s (RerunRecorder.SERVICE_OPTIONS): every snapshot counted is in a window
    torque = rows.get("/bearing/default/friction_torque_n_m", 0)
    assert torque >= max(rows_before // 10, 1)
    assert rows.get("/bearing/default/balls", 0) >= max(rows_before // 25, 1)
    assert rows.get("/bearing/second/friction_torque_n_m", 0) > 0


def test_two_services_on_one_zenoh_network_seen_by_one_monitor(tmp_path):
    """Service A listens; service B listens on its own port and connects to A; a monitor that
    connects to A only sees A's two twins and B's twin (gossip over the configured links)."""
    from service.tools.monitor import run_monitor

    a = Service(tmp_path / "a", "--twin-id", "pump-a", "--publish-rate", "20", record=False)
    b = None
    try:
        b = Service(
            tmp_path / "b",
            "--twin-id",
            "pump-b",
            "--publish-rate",
            "20",
            "--zenoh-connect",
            a.zenoh_endpoint,
            record=False,
        )
        with httpx.Client(base_url=a.url, timeout=30.0) as http:
            assert http.post("/v1/bearings", json={"id": "pump-a2", "designation": "6204"}).status_code == 201
        seen: dict = {}
        deadline = time.monotonic() + 60.0
        with open(os.devnull, "w") as devnull:
            while not {"pump-a", "pump-a2", "pump-b"} <= set(seen) and time.monotonic() < deadline:
                rows = run_monitor([a.zenoh_endpoint], duration_s=3.0, out=devnull)
                seen.update({k: v for k, v in rows.items() if v.get("messages")})
        assert {"pump-a", "pump-a2", "pump-b"} <= set(seen), seen
        assert seen["pump-a2"]["designation"] == "6204"
        for svc in (a, b):
            assert svc.terminate(timeout=15.0) < 10.0
    finally:
        a.kill()
        if b is not None:
            b.kill()
