"""Test-support code shared by the service and hostile tests: a zenoh test peer and a real
uvicorn server in a thread, both on 127.0.0.1; every wait is bounded.

pytest runs with --import-mode=importlib and `tests` is not a package, so test modules cannot
import this file by name: tests/conftest.py loads it by path and hands it out as the
session-scoped `support` fixture (`support.Peer`, `support.ThreadServer`, ...). zenoh, uvicorn
and the service are imported lazily, so loading this module costs nothing."""

from __future__ import annotations

import json
import queue
import threading
import time
from collections.abc import Callable
from typing import Any, NamedTuple

PEER_WAIT_S = 30.0


def free_port() -> int:
    """A free TCP port on 127.0.0.1 that this test process has not been given before
    (loadtest.ports.free_port: a released port can come back for the next ask)."""
    from loadtest.ports import free_port as one_free_port

    return one_free_port()


def free_endpoint() -> str:
    """A zenoh TCP endpoint on a free loopback port."""
    return f"tcp/127.0.0.1:{free_port()}"


def strict_loads(payload) -> Any:
    """json.loads that fails on NaN / Infinity literals."""

    def reject(name):
        raise AssertionError(f"JSON carries {name}")

    return json.loads(payload, parse_constant=reject)


def wait_for(
    fetch: Callable[[], Any], predicate: Callable[[Any], bool], timeout: float = 30.0, interval: float = 0.02
) -> Any:
    """Poll `fetch()` every `interval` s until `predicate` holds on its value; at most `timeout` s."""
    deadline = time.monotonic() + timeout
    while True:
        value = fetch()
        if predicate(value):
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"condition not met within {timeout} s; last value {value!r}")
        time.sleep(interval)


def wait_until(predicate: Callable[[], bool], timeout_s: float, interval_s: float = 0.02) -> bool:
    """Poll `predicate` until true or the timeout passes; whether it became true."""
    deadline = time.monotonic() + timeout_s
    while True:
        if predicate():
            return True
        if time.monotonic() >= deadline:
            return False
        time.sleep(interval_s)


class Sample(NamedTuple):
    """One received zenoh sample: key expression, kind (PUT / DELETE) and payload bytes."""

    key: str
    kind: Any
    payload: bytes


class Peer:
    """A separate zenoh session (another process in real life): peer mode (or `mode`), connected
    to `endpoint` on loopback, multicast scouting off (service.bus.zenoh_bus.make_config), with the zenoh
    credentials of `access` (service.bus.access.ZenohAccess; default none). Subscriptions put a
    `Sample` per message in `inbox`; `wait_for` waits at most `timeout_s`. `prefix`: the twins'
    key prefix (result keys)."""

    def __init__(
        self,
        endpoint: str,
        timeout_s: float = PEER_WAIT_S,
        *,
        mode: str = "peer",
        access: Any = None,
        prefix: str = "bearing",
    ):
        import zenoh

        from service.bus.zenoh_bus import make_config

        self.timeout_s = timeout_s
        self.prefix = prefix
        self.session = zenoh.open(make_config([], [endpoint], mode, access=access))
        self.inbox: queue.Queue[Sample] = queue.Queue()
        self._subs: list = []

    def subscribe(self, keyexpr: str, liveliness: bool = False):
        """Subscribe to `keyexpr` (liveliness tokens with history when `liveliness`)."""

        def cb(sample):
            self.inbox.put(Sample(str(sample.key_expr), sample.kind, sample.payload.to_bytes()))

        if liveliness:
            sub = self.session.liveliness().declare_subscriber(keyexpr, cb, history=True)
        else:
            sub = self.session.declare_subscriber(keyexpr, cb)
        self._subs.append(sub)  # keep a reference
        return sub

    def wait_for(
        self,
        predicate: Callable[[Sample], bool],
        timeout_s: float | None = None,
        poke: Callable[[], object] | None = None,
        poke_every_s: float = 0.0,
    ) -> Sample:
        """The first sample satisfying `predicate` (samples before it are consumed); `poke()` is
        called while waiting, at most once every `poke_every_s` (0: before every inbox read)."""
        timeout_s = self.timeout_s if timeout_s is None else timeout_s
        deadline = time.monotonic() + timeout_s
        next_poke = time.monotonic()
        while time.monotonic() < deadline:
            if poke is not None and time.monotonic() >= next_poke:
                poke()
                next_poke = time.monotonic() + poke_every_s
            try:
                item = self.inbox.get(timeout=0.1)
            except queue.Empty:
                continue
            if predicate(item):
                return item
        raise AssertionError("timed out waiting for a zenoh message")

    def result_after(self, key: str, payload, bearing_id: str = "default", timeout_s: float | None = None) -> dict:
        """Put a setpoint and return the next message on its result key (strict JSON)."""
        self.drain()
        self.session.put(key, payload)
        sample = self.wait_for(lambda item: item.key == f"{self.prefix}/{bearing_id}/setpoint/result", timeout_s)
        return strict_loads(sample.payload)

    def drain(self) -> None:
        """Drop every sample received so far."""
        while True:
            try:
                self.inbox.get_nowait()
            except queue.Empty:
                return

    def close(self) -> None:
        """Undeclare the subscribers and close the session (closed even if an undeclare fails)."""
        try:
            for sub in self._subs:
                sub.undeclare()
        finally:
            self._subs = []
            self.session.close()


class ThreadServer:
    """uvicorn in a thread on 127.0.0.1, port 0 (read back), serving `create_app(settings)`.

    `with ThreadServer(settings) as srv:` waits (at most `start_timeout_s`) until uvicorn has
    started and sets `srv.url`; leaving asks it to exit and asserts the thread stopped within
    `stop_timeout_s`. `.app` is the FastAPI app, `.service` the app's service."""

    def __init__(self, settings, start_timeout_s: float = 90.0, stop_timeout_s: float = 20.0):
        import uvicorn

        from service.api.app import create_app

        self.app = create_app(settings)
        from service.api.server import uvicorn_config

        config = uvicorn_config(
            self.app,
            self.app.state.settings,
            host="127.0.0.1",
            port=0,
            log_level="warning",
            timeout_graceful_shutdown=2,
        )
        self.server = uvicorn.Server(config)
        self.thread = threading.Thread(target=self.server.run, daemon=True)
        self.start_timeout_s, self.stop_timeout_s = start_timeout_s, stop_timeout_s
        self.url: str | None = None

    @property
    def service(self):
        return self.app.state.service

    def __enter__(self) -> ThreadServer:
        self.thread.start()
        deadline = time.monotonic() + self.start_timeout_s
        while not self.server.started:
            if not self.thread.is_alive() or time.monotonic() > deadline:
                raise RuntimeError("uvicorn did not start")
            time.sleep(0.02)
        port = self.server.servers[0].sockets[0].getsockname()[1]
        self.url = f"http://127.0.0.1:{port}"
        return self

    def __exit__(self, *exc):
        self.server.should_exit = True
        self.thread.join(self.stop_timeout_s)
        assert not self.thread.is_alive(), "uvicorn did not stop"
