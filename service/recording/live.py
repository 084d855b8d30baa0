"""`LiveWebViewer`: rerun's web viewer and gRPC server, serving the live recording to browsers.

rerun's own server (`rerun --serve-web`) runs in a process of its own, bound to `host`
(127.0.0.1 by default): it hosts the web viewer over HTTP on `web_port` and a gRPC message proxy
on `grpc_port`. The recorder sends to that proxy like to a spawned viewer (one more rerun stream,
`RerunRecorder.add_live_stream`), and the proxy buffers the recording (up to `memory_limit_mb`,
oldest rows dropped first, static data kept) for viewers that connect late. A browser opens
`url` (the web viewer with the proxy's address in its `url` query).

Why a process and not `rr.serve_grpc` / `rr.serve_web_viewer` in the service: those bind to every
interface (rerun-sdk 0.41 has no bind address for them), and they would serve the viewers on the
service's own threads. The `rerun` command takes `--bind`, and a viewer that connects or
disconnects loads that process, not the twins' process.

Access. rerun's server checks no credentials: whoever reaches its ports sees the recording (and
may log into it). The service therefore binds it to loopback by default, and with an HTTP token
set it refuses a non-loopback bind (`check_bind`): watch from another machine through an SSH
tunnel (`ssh -L PORT:127.0.0.1:PORT -L PORT+1:127.0.0.1:PORT+1 host`).
"""

from __future__ import annotations

import ipaddress
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import urllib.parse
from pathlib import Path
from typing import IO, Self

START_TIMEOUT_S = 30.0  # the rerun process must listen within this [s]


class LiveViewerError(RuntimeError):
    """The live web viewer cannot start (no `rerun` command, a port taken, a refused bind)."""


def is_loopback(host: str) -> bool:
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return host == "localhost"


def check_bind(host: str, token_set: bool) -> None:
    """A non-loopback bind is refused while the HTTP API requires a token: rerun's server would
    show the recording to anyone who reaches the port (LiveViewerError naming the field)."""
    if token_set and not is_loopback(host):
        raise LiveViewerError(
            f"rerun_web_bind = {host!r}: rerun's web viewer and gRPC server check no token, so with "
            "BEARING_TWIN_TOKEN set they bind to loopback only (127.0.0.1); watch from another "
            "machine through an SSH tunnel"
        )


def rerun_command() -> str:
    """The `rerun` command of the installed rerun-sdk (beside this Python, else on PATH)."""
    beside = Path(sys.executable).with_name("rerun")
    if beside.exists():
        return str(beside)
    found = shutil.which("rerun")
    if not found:
        raise LiveViewerError("no `rerun` command found (install rerun-sdk)")
    return found


def _listening(host: str, port: int) -> bool:
    try:
        with socket.create_connection((host, port), timeout=0.3):
            return True
    except OSError:
        return False


class LiveWebViewer:
    """A `rerun --serve-web` process (see module doc); `start()`, then `url`, `grpc_url`; `close()`."""

    def __init__(
        self, web_port: int, *, grpc_port: int | None = None, host: str = "127.0.0.1", memory_limit_mb: float = 500.0
    ):
        """`web_port`: HTTP port of the web viewer; `grpc_port`: the gRPC proxy's (default
        `web_port + 1`); `host`: the address both bind to; `memory_limit_mb` [MB]: what the proxy
        keeps for late viewers."""
        if not 1 <= int(web_port) <= 65534:
            raise ValueError(f"rerun_web_port = {web_port!r}: must be 1..65534 (the gRPC proxy takes the next port)")
        self.host = host
        self.web_port = int(web_port)
        self.grpc_port = int(grpc_port) if grpc_port else self.web_port + 1
        self.memory_limit_mb = float(memory_limit_mb)
        self._proc: subprocess.Popen | None = None
        self._err: IO[bytes] | None = None  # the rerun process's stderr (a temporary file)

    @property
    def _connect_host(self) -> str:
        return "127.0.0.1" if self.host in ("0.0.0.0", "::", "") else self.host

    @property
    def grpc_url(self) -> str:
        """Where the recorder sends (the proxy's address as seen from this host)."""
        return f"rerun+http://{self._connect_host}:{self.grpc_port}/proxy"

    def url(self, host: str | None = None) -> str:
        """The page a browser opens: the web viewer, told where the proxy is."""
        h = host or self._connect_host
        source = urllib.parse.quote(f"rerun+http://{h}:{self.grpc_port}/proxy", safe="")
        return f"http://{h}:{self.web_port}/?url={source}"

    def start(self) -> Self:
        for port in (self.web_port, self.grpc_port):
            if _listening(self._connect_host, port):
                raise LiveViewerError(f"rerun_web_port: port {port} on {self.host} is taken")
        cmd = [
            rerun_command(),
            "--bind",
            self.host,
            "--serve-web",
            "--port",
            str(self.grpc_port),
            "--web-viewer-port",
            str(self.web_port),
            "--server-memory-limit",
            f"{self.memory_limit_mb:.0f}MB",
        ]
        err_file = self._err = tempfile.TemporaryFile()
        self._proc = subprocess.Popen(
            cmd,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=err_file,
            start_new_session=True,
            env={**os.environ, "RERUN_ANALYTICS": "0"},
        )
        deadline = time.monotonic() + START_TIMEOUT_S
        while time.monotonic() < deadline:
            if self._proc.poll() is not None:
                err_file.seek(0)
                err = err_file.read().decode(errors="replace").strip().splitlines()
                self.close()
                raise LiveViewerError(f"rerun --serve-web exited: {err[-1] if err else 'no message'}")
            if _listening(self._connect_host, self.grpc_port) and _listening(self._connect_host, self.web_port):
                return self
            time.sleep(0.1)
        self.close()
        raise LiveViewerError(
            f"rerun --serve-web did not listen on {self.web_port}/{self.grpc_port} within {START_TIMEOUT_S:.0f} s"
        )

    @property
    def running(self) -> bool:
        return self._proc is not None and self._proc.poll() is None

    def close(self) -> None:
        proc, self._proc = self._proc, None
        if self._err is not None:
            self._err.close()
            self._err = None
        if proc is None or proc.poll() is not None:
            return
        try:
            os.killpg(proc.pid, signal.SIGTERM)
            proc.wait(timeout=10)
        except (ProcessLookupError, subprocess.TimeoutExpired):
            try:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait(timeout=5)
            except (ProcessLookupError, subprocess.TimeoutExpired):
                pass

    def __enter__(self) -> Self:
        return self.start()

    def __exit__(self, *exc) -> None:
        self.close()
