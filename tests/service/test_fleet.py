"""A fleet beyond one host, with real processes on loopback ports:
`bearing-twin router` (zenoh's own router mode) and two `bearing-twin serve` joined to it with
`--zenoh-connect` under the key prefix plant1/line2, three twins. The monitor (a zenoh client of
the router, prefix pattern plant1/**) lists all three; a zenoh setpoint to each lands on that twin
and no other; a twin id already running in the other process is refused (HTTP 409 and at start;
the log names the process that has it); the twins of a process stopped with SIGTERM disappear from the
monitor (their liveliness tokens go). Every wait is bounded."""

from __future__ import annotations

import io
import json
import os
import queue
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import httpx
import pytest

zenoh = pytest.importorskip("zenoh")

REPO = Path(__file__).resolve().parents[2]
START_S = 180.0
WAIT_S = 60.0
PREFIX = "plant1/line2"


class Proc:
    """A `python -m service.cli ...` subprocess; its output lines are collected by a thread."""

    def __init__(self, tmp_path: Path, *args: str, ready: str, env: dict | None = None):
        full_env = {k: v for k, v in os.environ.items() if not k.startswith("BEARING_TWIN_")}
        # the capacity admission is not what this test is about (a loaded CI host may refuse a
        # third twin): tests/service/core/test_pool.py and test_capacity cover it
        full_env.update(
            {"PYTHONUNBUFFERED": "1", "PYTHONPATH": str(REPO), "BEARING_TWIN_ADMISSION": "off", **(env or {})}
        )
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "service.cli", *args],
            cwd=tmp_path,
            env=full_env,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        self.lines: list[str] = []
        threading.Thread(target=self._read, daemon=True).start()
        if ready:
            self.wait_text(ready, START_S)

    def _read(self) -> None:
        for line in self.proc.stdout:
            self.lines.append(line)

    @property
    def text(self) -> str:
        return "".join(self.lines)

    def wait_text(self, text: str, timeout_s: float) -> None:
        deadline = time.monotonic() + timeout_s
        while text not in self.text:
            if self.proc.poll() is not None or time.monotonic() > deadline:
                self.stop()
                raise AssertionError(f"{text!r} not seen:\n{self.text}")
            time.sleep(0.05)

    def wait_exit(self, timeout_s: float) -> int:
        try:
            return self.proc.wait(timeout_s)
        except subprocess.TimeoutExpired:
            self.stop()
            raise AssertionError(f"did not exit:\n{self.text}") from None

    def stop(self) -> None:
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(20)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(10)


def _serve(tmp_path: Path, router: str, http_port: int, twin_id: str) -> Proc:
    return Proc(
        tmp_path,
        "serve",
        "--port",
        str(http_port),
        "--zenoh-connect",
        router,
        "--zenoh-prefix",
        PREFIX,
        "--twin-id",
        twin_id,
        "--no-record",
        "--publish-rate",
        "10",
        "--log-level",
        "info",
        ready="Application startup complete",
    )


def _wait(fetch, predicate, timeout_s: float = WAIT_S, what: str = "condition"):
    deadline = time.monotonic() + timeout_s
    while True:
        value = fetch()
        if predicate(value):
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"{what}: not met within {timeout_s} s; last {value!r}")
        time.sleep(0.1)


@pytest.mark.slow
def test_fleet_router_two_services_three_twins(tmp_path, support):
    from service.bus.access import ZenohAccess
    from service.bus.zenoh_bus import make_config
    from service.tools.monitor import run_monitor

    router_ep = support.free_endpoint()
    router = Proc(tmp_path, "router", "--listen", router_ep, "--prefix", "plant1/**", ready="listening on")
    procs = [router]
    monitor_stop = threading.Event()
    rows: queue.Queue = queue.Queue()
    latest: dict = {}
    writer = None
    try:
        port_a, port_b = support.free_port(), support.free_port()
        a = _serve(tmp_path, router_ep, port_a, "motor7")
        procs.append(a)
        b = _serve(tmp_path, router_ep, port_b, "fan1")
        procs.append(b)
        assert "zenoh client listening on nothing, connecting to " + router_ep in a.text
        http_a = httpx.Client(base_url=f"http://127.0.0.1:{port_a}", timeout=60.0)
        http_b = httpx.Client(base_url=f"http://127.0.0.1:{port_b}", timeout=60.0)
        r = http_a.post("/v1/bearings", json={"id": "pump3", "designation": "6205"})
        assert r.status_code == 201, r.text
        assert r.json()["zenoh_state_key"] == f"{PREFIX}/pump3/state"

        # the monitor: a zenoh client of the router, every twin under plant1/**
        def on_update(snapshot):
            latest.clear()
            latest.update(snapshot)
            rows.put(snapshot)

        th = threading.Thread(
            target=lambda: run_monitor(
                [router_ep],
                prefix="plant1/**",
                duration_s=240.0,
                forget_gone_s=1.0,
                on_update=on_update,
                stop=monitor_stop,
                access=ZenohAccess(),
                out=io.StringIO(),
            ),
            daemon=True,
        )
        th.start()
        names = {f"{PREFIX}/{i}" for i in ("motor7", "pump3", "fan1")}
        seen = _wait(
            lambda: dict(latest),
            lambda s: names <= set(s) and all(s[n]["alive"] and s[n]["messages"] >= 3 for n in names),
            what="the monitor lists the three twins",
        )
        assert seen[f"{PREFIX}/pump3"]["designation"] == "6205"
        assert seen[f"{PREFIX}/fan1"]["designation"] == "6208"

        # a zenoh setpoint to each twin lands on that twin only
        writer = zenoh.open(make_config([], [router_ep], "client"))
        results: queue.Queue = queue.Queue()
        sub = writer.declare_subscriber(
            f"{PREFIX}/*/setpoint/result", lambda s: results.put((str(s.key_expr), json.loads(s.payload.to_bytes())))
        )
        loads = {"motor7": 3100.0, "pump3": 1100.0, "fan1": 3300.0}
        where = {"motor7": http_a, "pump3": http_a, "fan1": http_b}
        time.sleep(0.5)
        for twin_id, load in loads.items():
            writer.put(f"{PREFIX}/{twin_id}/setpoint", json.dumps({"radial_load_n": load}))
        got = {}
        deadline = time.monotonic() + WAIT_S
        while len(got) < 3 and time.monotonic() < deadline:
            try:
                key, msg = results.get(timeout=0.5)
            except queue.Empty:
                continue
            got[msg["bearing_id"]] = (key, msg)
        assert set(got) == set(loads), got
        for twin_id, (key, msg) in got.items():
            assert key == f"{PREFIX}/{twin_id}/setpoint/result" and msg["accepted"] is True, msg
            assert msg["setpoint"]["radial_load_n"] == loads[twin_id]
            state = _wait(
                lambda t=twin_id: where[t].get(f"/v1/bearings/{t}/state").json(),
                lambda s, t=twin_id: s["setpoint"]["radial_load_n"] == loads[t],
                what=twin_id,
            )
            assert state["bearing_id"] == twin_id
        sub.undeclare()

        # one twin id per prefix across the fleet: the other process is named
        clash = http_a.post("/v1/bearings", json={"id": "fan1", "designation": "6208"})
        assert clash.status_code == 409, clash.text
        (err,) = clash.json()["detail"]
        # the answer names the zenoh id zenoh reports; what B says of itself is only in A's log
        assert err["field"] == "id" and "zenoh id " in err["message"] and f"{port_b}" not in err["message"]
        a.wait_text(f"in process '{b.proc.pid}'", WAIT_S)
        assert f"(HTTP 'http://127.0.0.1:{port_b}')" in a.text
        assert [t["id"] for t in http_a.get("/v1/bearings").json()] == ["motor7", "pump3"]
        third = Proc(
            tmp_path,
            "serve",
            "--port",
            str(support.free_port()),
            "--zenoh-connect",
            router_ep,
            "--zenoh-prefix",
            PREFIX,
            "--twin-id",
            "motor7",
            "--no-record",
            ready="",
        )
        procs.append(third)
        assert third.wait_exit(START_S) == 2
        assert f"twin 'motor7' already runs under '{PREFIX}' in process '{a.proc.pid}'" in third.text, third.text

        # SIGTERM: the twins of B disappear from the monitor, the others stay
        b.proc.send_signal(signal.SIGTERM)
        assert b.wait_exit(30.0) in (0, -signal.SIGTERM)
        gone = _wait(lambda: dict(latest), lambda s: f"{PREFIX}/fan1" not in s, what="fan1 leaves the monitor")
        assert {f"{PREFIX}/motor7", f"{PREFIX}/pump3"} <= set(gone)
        assert all(gone[n]["alive"] for n in (f"{PREFIX}/motor7", f"{PREFIX}/pump3"))
    finally:
        monitor_stop.set()
        if writer is not None:
            writer.close()
        for p in reversed(procs):
            p.stop()
