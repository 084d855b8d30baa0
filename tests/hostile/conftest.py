"""Helpers of the hostile-input, fault and long-run tests: `bearing-twin serve` as a
subprocess on 127.0.0.1 free ports, plus the shared uvicorn-in-a-thread server and zenoh peer
(multicast scouting off) of tests/support.py. Every wait is bounded. Exposed as fixtures (pytest
runs with --import-mode=importlib, so test modules do not import each other)."""

from __future__ import annotations

import functools
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

REPO = Path(__file__).resolve().parents[2]
SCENARIOS = REPO / "scenarios"
WAIT_S = 30.0


class ServeProcess:
    """`bearing-twin serve` (python -m service.cli serve) as a subprocess on loopback ports."""

    def __init__(
        self,
        tmp_path: Path,
        *extra: str,
        port: int | None = None,
        zenoh_port: int | None = None,
        record: Path | None = None,
        env: dict | None = None,
    ):
        self.port = port or free_port()
        self.zenoh_endpoint = f"tcp/127.0.0.1:{zenoh_port or free_port()}"
        self.rrd = record
        cmd = [
            sys.executable,
            "-m",
            "service.cli",
            "serve",
            "--port",
            str(self.port),
            "--zenoh-listen",
            self.zenoh_endpoint,
            "--log-level",
            "info",
            *extra,
        ]
        cmd += ["--record", str(record)] if record is not None else ["--no-record"]
        full_env = {k: v for k, v in os.environ.items() if not k.startswith("BEARING_TWIN_")}
        full_env.update({"PYTHONUNBUFFERED": "1", "BEARING_TWIN_ADMISSION": "off", **(env or {})})
        self.proc = subprocess.Popen(
            cmd,
            cwd=tmp_path,
            env={**full_env, "PYTHONPATH": str(REPO)},
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
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
        time.sleep(0.1)  # let the reader thread take the last lines
        return time.monotonic() - t0

    def kill(self) -> None:
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGKILL)
            self.proc.wait(15)


@pytest.fixture(scope="session")
def hostile(support):
    """The helpers as one namespace (fixtures cannot be imported across test modules here);
    `ThreadServer`, `Peer`, `strict_loads` and `wait_for` are the shared ones of tests/support.py."""

    class H:
        pass

    h = H()
    h.REPO, h.SCENARIOS, h.WAIT_S = REPO, SCENARIOS, WAIT_S
    h.free_port, h.strict_loads = free_port, support.strict_loads
    h.wait_for = functools.partial(support.wait_for, timeout=WAIT_S)
    h.ThreadServer, h.ServeProcess, h.Peer = support.ThreadServer, ServeProcess, support.Peer
    return h
