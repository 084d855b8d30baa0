"""Helpers of the hostile-input, fault and long-run tests (issue 6): a uvicorn server in a thread
and `bearing-twin serve` as a subprocess, both on 127.0.0.1 free ports; zenoh peers with
multicast scouting off. Every wait is bounded. Exposed as fixtures (pytest runs with
--import-mode=importlib, so test modules do not import each other)."""

from __future__ import annotations

import json
import os
import queue
import re
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
SCENARIOS = REPO / "scenarios"
WAIT_S = 30.0


def free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def strict_loads(payload) -> object:
    """json.loads that fails on NaN / Infinity literals."""
    def reject(name):
        raise AssertionError(f"JSON carries {name}")
    return json.loads(payload, parse_constant=reject)


def wait_for(fetch, predicate, timeout=WAIT_S, interval=0.02):
    deadline = time.monotonic() + timeout
    while True:
        value = fetch()
        if predicate(value):
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"condition not met within {timeout} s; last value {value!r}")
        time.sleep(interval)


class ThreadServer:
    """uvicorn in a thread on 127.0.0.1, port 0 (read back); `.app` is the FastAPI app."""

    def __init__(self, settings):
        import uvicorn

        from service.app import create_app

        self.app = create_app(settings)
        config = uvicorn.Config(self.app, host="127.0.0.1", port=0, log_level="warning",
                                lifespan="on", timeout_graceful_shutdown=2)
        self.server = uvicorn.Server(config)
        self.thread = threading.Thread(target=self.server.run, daemon=True)
        self.url = None

    @property
    def service(self):
        return self.app.state.service

    def __enter__(self) -> ThreadServer:
        self.thread.start()
        deadline = time.monotonic() + 90.0
        while not self.server.started:
            if not self.thread.is_alive() or time.monotonic() > deadline:
                raise RuntimeError("uvicorn did not start")
            time.sleep(0.02)
        port = self.server.servers[0].sockets[0].getsockname()[1]
        self.url = f"http://127.0.0.1:{port}"
        return self

    def __exit__(self, *exc):
        self.server.should_exit = True
        self.thread.join(20.0)
        assert not self.thread.is_alive(), "uvicorn did not stop"


class ServeProcess:
    """`bearing-twin serve` (python -m service.cli serve) as a subprocess on loopback ports."""

    def __init__(self, tmp_path: Path, *extra: str, port: int | None = None,
                 zenoh_port: int | None = None, record: Path | None = None, env: dict | None = None):
        self.port = port or free_port()
        self.zenoh_endpoint = f"tcp/127.0.0.1:{zenoh_port or free_port()}"
        self.rrd = record
        cmd = [sys.executable, "-m", "service.cli", "serve", "--port", str(self.port),
               "--zenoh-listen", self.zenoh_endpoint, "--log-level", "info", *extra]
        cmd += ["--record", str(record)] if record is not None else ["--no-record"]
        full_env = {k: v for k, v in os.environ.items() if not k.startswith("BEARING_TWIN_")}
        full_env.update({"PYTHONUNBUFFERED": "1", **(env or {})})
        self.proc = subprocess.Popen(cmd, cwd=tmp_path, env={**full_env, "PYTHONPATH": str(REPO)},
                                     stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        self.lines: queue.Queue = queue.Queue()
        self.log: list[str] = []
        threading.Thread(target=self._read, daemon=True).start()
        self.url = f"http://127.0.0.1:{self.port}"
        self._wait_started()

    def _read(self):
        for line in self.proc.stdout:
            self.log.append(line)
            self.lines.put(line)

    @property
    def text(self) -> str:
        return "".join(self.log)

    def _wait_started(self) -> None:
        deadline = time.monotonic() + 120.0
        while time.monotonic() < deadline:
            if "Application startup complete" in self.text and re.search(r"Uvicorn running on", self.text):
                return
            if self.proc.poll() is not None:
                break
            time.sleep(0.05)
        self.kill()
        raise AssertionError("service did not start:\n" + self.text)

    def signal(self, sig: int, timeout: float) -> float:
        """Send `sig`, wait for the exit (bounded); returns how long it took."""
        t0 = time.monotonic()
        self.proc.send_signal(sig)
        try:
            self.proc.wait(timeout)
        except subprocess.TimeoutExpired:
            self.kill()
            raise AssertionError(f"service did not stop on signal {sig}:\n" + self.text) from None
        time.sleep(0.1)   # let the reader thread take the last lines
        return time.monotonic() - t0

    def kill(self) -> None:
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGKILL)
            self.proc.wait(15)


class Peer:
    """A zenoh peer connected to one endpoint, multicast scouting off."""

    def __init__(self, endpoint: str):
        import zenoh

        from service.bus import make_config

        self.session = zenoh.open(make_config([], [endpoint], "peer"))
        self.inbox: queue.Queue = queue.Queue()
        self._subs = []

    def subscribe(self, keyexpr: str):
        def cb(sample):
            self.inbox.put((str(sample.key_expr), sample.payload.to_bytes()))
        self._subs.append(self.session.declare_subscriber(keyexpr, cb))

    def wait_for(self, predicate, timeout_s: float = WAIT_S):
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            try:
                item = self.inbox.get(timeout=0.1)
            except queue.Empty:
                continue
            if predicate(item):
                return item
        raise AssertionError("timed out waiting for a zenoh message")

    def result_after(self, key: str, payload, bearing_id: str = "default", timeout_s: float = WAIT_S) -> dict:
        """Put a setpoint and return the next message on its result key."""
        self.drain()
        self.session.put(key, payload)
        _, data = self.wait_for(lambda item: item[0] == f"bearing/{bearing_id}/setpoint/result", timeout_s)
        return strict_loads(data)

    def drain(self) -> None:
        while True:
            try:
                self.inbox.get_nowait()
            except queue.Empty:
                return

    def close(self):
        for sub in self._subs:
            try:
                sub.undeclare()
            except Exception:
                pass
        self.session.close()


@pytest.fixture(scope="session")
def hostile():
    """The helpers as one namespace (fixtures cannot be imported across test modules here)."""
    class H:
        pass
    h = H()
    h.REPO, h.SCENARIOS, h.WAIT_S = REPO, SCENARIOS, WAIT_S
    h.free_port, h.strict_loads, h.wait_for = free_port, strict_loads, wait_for
    h.ThreadServer, h.ServeProcess, h.Peer = ThreadServer, ServeProcess, Peer
    return h
