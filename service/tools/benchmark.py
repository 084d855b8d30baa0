"""Service benchmark (`bearing-twin bench-service`): the real-time factor of a twin in real-time
mode with publishing (zenoh) and recording (rerun) on, and the delay from an HTTP setpoint to the
first published snapshot that reflects it.

It starts the real service in this process (uvicorn on a free loopback port, zenoh listening on a
free loopback port, a recording into a temporary directory), connects a zenoh peer, and PUTs a new
radial load every 1/rate seconds. Two delays are measured for each setpoint:

* client: from just before the HTTP PUT is sent to the arrival, at the zenoh subscriber, of the
  first `bearing/default/state` message carrying it (HTTP + mailbox + frame + zenoh);
* runner: from the moment the runner accepted it to the moment it published the first snapshot
  reflecting it (TwinRunner.setpoint_latencies(), seq recorded).

Wall-clock figures belong here and in README, never in tests.
"""

from __future__ import annotations

import json
import queue
import socket
import statistics
import tempfile
import threading
import time
from pathlib import Path


def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _percentile(values: list[float], q: float) -> float | None:
    if not values:
        return None
    values = sorted(values)
    k = min(len(values) - 1, max(0, round(q / 100.0 * (len(values) - 1))))
    return values[k]


def run_service_benchmark(seconds: float = 10.0, rate_hz: float = 20.0, bearing: str = "6208",
                          record: bool = True, zenoh_on: bool = True) -> dict:
    import httpx
    import uvicorn

    from service.api.app import create_app
    from service.settings import ServiceSettings

    endpoint = f"tcp/127.0.0.1:{_free_port()}"
    with tempfile.TemporaryDirectory(prefix="bearing-twin-bench-") as tmp:
        settings = ServiceSettings(port=0, bearing=bearing, zenoh_listen=[endpoint], enable_zenoh=zenoh_on,
                                   enable_recording=record, record=Path(tmp) / "bench.rrd")
        app = create_app(settings)
        server = uvicorn.Server(uvicorn.Config(app, host="127.0.0.1", port=0, log_level="warning",
                                               lifespan="on", timeout_graceful_shutdown=2))
        thread = threading.Thread(target=server.run, daemon=True)
        thread.start()
        deadline = time.monotonic() + 120.0
        while not server.started:
            if not thread.is_alive() or time.monotonic() > deadline:
                raise RuntimeError("the service did not start")
            time.sleep(0.02)
        url = f"http://127.0.0.1:{server.servers[0].sockets[0].getsockname()[1]}"
        runner = app.state.service.get(settings.twin_id).runner
        inbox: queue.SimpleQueue = queue.SimpleQueue()
        session = sub = None
        if zenoh_on:
            import zenoh

            from service.bus.zenoh_bus import client_config

            # a zenoh client with the credentials of the environment (BEARING_TWIN_ZENOH_USER ...)
            session = zenoh.open(client_config([endpoint], prefix=settings.zenoh_prefix))

            def on_state(sample):  # zenoh thread: hand off only
                inbox.put((time.perf_counter(), sample.payload.to_bytes()))

            sub = session.declare_subscriber(f"{settings.zenoh_prefix}/{settings.twin_id}/state", on_state)
        client_latencies: list[float] = []
        lost = 0
        rtf_samples: list[float] = []
        try:
            with httpx.Client(base_url=url, timeout=10.0) as http:
                time.sleep(1.0)  # let the twin settle into its pace
                frames0, overruns0 = runner.frames, runner.overruns
                t_end = time.perf_counter() + seconds
                k = 0
                while time.perf_counter() < t_end:
                    k += 1
                    load = 3000.0 + (k % 200)            # a new value every time
                    t0 = time.perf_counter()
                    r = http.put(f"/v1/bearings/{settings.twin_id}/setpoint", json={"radial_load_n": load})
                    r.raise_for_status()
                    if zenoh_on:
                        seen = None
                        wait_until = t0 + 1.0
                        while seen is None and time.perf_counter() < wait_until:
                            try:
                                t_msg, payload = inbox.get(timeout=max(0.0, wait_until - time.perf_counter()))
                            except queue.Empty:
                                break
                            if json.loads(payload)["setpoint"]["radial_load_n"] == load:
                                seen = t_msg
                        if seen is None:
                            lost += 1
                        else:
                            client_latencies.append(seen - t0)
                    if runner.real_time_factor is not None:
                        rtf_samples.append(runner.real_time_factor)
                    time.sleep(max(0.0, t0 + 1.0 / rate_hz - time.perf_counter()))
                health = http.get("/health").json()
                frames, overruns = runner.frames - frames0, runner.overruns - overruns0
            runner_latencies = [t.latency_s for t in runner.setpoint_latencies() if t.latency_s is not None]
        finally:
            if sub is not None:
                sub.undeclare()
            if session is not None:
                session.close()
            server.should_exit = True
            thread.join(30.0)
    twin = next(t for t in health["twins"] if t["id"] == settings.twin_id)
    ms = lambda v: None if v is None else 1e3 * v
    return {
        "bearing": bearing, "seconds": seconds, "setpoints": k, "rate_hz": rate_hz,
        "zenoh": zenoh_on, "recording": record,
        "real_time_factor_median": statistics.median(rtf_samples) if rtf_samples else None,
        "real_time_factor_min": min(rtf_samples) if rtf_samples else None,
        "frames": frames, "overruns": overruns, "overrun_fraction": overruns / frames if frames else None,
        "dropped": twin["dropped"], "recording_rows": health["recording_rows"],
        "client_latency_ms_p50": ms(_percentile(client_latencies, 50)),
        "client_latency_ms_p99": ms(_percentile(client_latencies, 99)),
        "client_latency_ms_max": ms(max(client_latencies)) if client_latencies else None,
        "client_lost": lost,
        "runner_latency_ms_p50": ms(_percentile(runner_latencies, 50)),
        "runner_latency_ms_p99": ms(_percentile(runner_latencies, 99)),
    }
