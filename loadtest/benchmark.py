"""Service benchmark (`bearing-twin bench-service --twins N [--seconds S] [--json]`): N twins of
different designations in one real-time service with zenoh and the recording on; per twin the
median real-time factor and the late fraction, and the delay from an HTTP setpoint to the zenoh
state that carries it.

It starts `bearing-twin serve` as a SUBPROCESS (as deployed: the benchmark's own HTTP and zenoh
clients do not share the service's GIL; they do share the machine's cores) on free loopback
ports, recording into a temporary directory; the first twin is the service's configured twin,
the others are created with POST /v1/bearings, through the admission by measured capacity (a
refused twin is listed under `refused` with the service's answer; `force=True` turns the
admission off to measure what happens beyond the capacity). The twins, in turn (cycled for
N > 4): 6208, 6205, 7208 (3000 N radial), 6208 with 5 A of shaft current.

Measured over `seconds` after the twins have settled:

* per twin: `real_time_factor_median` / `_min` (the `real_time_factor` of /health, sampled every
  0.5 s), `late_fraction` = frames that ended more than the service's lateness (5 ms) after
  their wall-clock deadline / frames in the window (from the /health counters), frames,
  snapshots dropped by the sinks, its measured CPU cost;
* `client_latency_ms_p50` / `_p99` / `_max`: a PUT of a new radial load every 1/rate s (the
  twins in turn), from just before the request is sent to the arrival at a zenoh subscriber of
  the first `bearing/{id}/state` message carrying it (HTTP + mailbox + frame + snapshot +
  zenoh); `client_lost`: none arrived within 1 s.

The client's priority (`client_nice`, default -5: the service's `io_thread_nice`). The client's
threads (its HTTP requests, its zenoh subscriber) run at that nice where the process may raise its
priority (root or CAP_SYS_NICE; the result's `client_nice` says what was in force), set once the
service runs (the service does not inherit it). Why: on a host shared with other jobs a client at
the default nice waits for a core behind them at each of its two hops (sending the PUT, taking the
zenoh sample), which measured the host's load rather than the service: one twin on the 2-core EPYC
VM at load average 2-5, two runs at nice 0 and two at -5, the client's share (request built and
sent until the server read it) 11-13 ms at p99 against 4.4-5.1 ms, and the zenoh sample's arrival
after its put 9-10 ms against 3.5-3.9 ms (docs/performance.md). `None` leaves the nice as it is.

Wall-clock figures belong here and in the docs, never in tests.
"""

from __future__ import annotations

import os
import queue
import re
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

from loadtest.ports import free_ports
from service.keys import STATE, all_twins, twin_key

#: (designation, initial setpoint) of the twins, in order
TWIN_MIX: tuple[tuple[str, dict], ...] = (
    ("6208", {}),
    ("6205", {}),
    ("7208", {"radial_load_n": 3000.0}),
    ("6208", {"shaft_current_a": 5.0}),
)


#: the client's nice while it measures (the service's default io_thread_nice)
CLIENT_NICE = -5


def client_priority(nice: int | None) -> tuple[int, int]:
    """Set the calling thread's nice to `nice` (Linux: per thread; threads it starts later inherit
    it) where allowed; returns (the nice before, the nice in force)."""
    before = os.getpriority(os.PRIO_PROCESS, 0)
    if nice is None or nice == before:
        return before, before
    try:
        os.setpriority(os.PRIO_PROCESS, 0, nice)
    except OSError:  # lowering the nice needs root or CAP_SYS_NICE
        pass
    return before, os.getpriority(os.PRIO_PROCESS, 0)


def _percentile(values: list[float], q: float) -> float | None:
    if not values:
        return None
    values = sorted(values)
    k = min(len(values) - 1, max(0, round(q / 100.0 * (len(values) - 1))))
    return values[k]


def twin_plan(n: int, *, alike: bool = False) -> list[tuple[str, str, dict]]:
    """(id, designation, initial setpoint) of the n twins of the benchmark: the mix in turn, or
    (`alike`, for `--twins auto`) n twins like the first, the kind the capacity formula counts."""
    plan = []
    for i in range(n):
        designation, setpoint = TWIN_MIX[0 if alike else i % len(TWIN_MIX)]
        tag = "-5A" if setpoint.get("shaft_current_a") else ""
        plan.append((f"b{i + 1}-{designation}{tag}", designation, dict(setpoint)))
    return plan


class _Serve:
    """`bearing-twin serve` in a subprocess, its output kept."""

    def __init__(self, args: list[str], env: dict, cwd: Path):
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "service.cli", "serve", *args],
            cwd=cwd,
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        self.log: list[str] = []
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self.proc.stdout is not None  # stdout=PIPE
        for line in self.proc.stdout:
            self.log.append(line)

    def stop(self) -> None:
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(30.0)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(10.0)


def run_service_benchmark(
    twins: int | str = 1,
    seconds: float = 10.0,
    rate_hz: float = 20.0,
    *,
    record: bool = True,
    zenoh_on: bool = True,
    force: bool = False,
    settle_s: float = 3.0,
    start_timeout_s: float = 300.0,
    client_nice: int | None = CLIENT_NICE,
) -> dict:
    import httpx

    auto = twins == "auto"
    if not auto and not (isinstance(twins, int) and twins >= 1):
        raise ValueError(f"twins = {twins!r}: at least 1, or 'auto'")
    plan = twin_plan(1 if auto else int(twins))
    port, zport = free_ports(2)
    endpoint = f"tcp/127.0.0.1:{zport}"
    repo = Path(__file__).resolve().parents[1]
    env = {
        **os.environ,
        "PYTHONUNBUFFERED": "1",
        "PYTHONPATH": os.pathsep.join(filter(None, [str(repo), os.environ.get("PYTHONPATH")])),
    }
    if force:
        env["BEARING_TWIN_ADMISSION"] = "off"
    first_id, first_designation, first_setpoint = plan[0]
    with tempfile.TemporaryDirectory(prefix="bearing-twin-bench-") as tmp:
        args = ["--port", str(port), "--twin-id", first_id, "--bearing", first_designation, "--log-level", "warning"]
        args += ["--zenoh-listen", endpoint] if zenoh_on else ["--no-zenoh"]
        args += ["--record", str(Path(tmp) / "bench.rrd")] if record else ["--no-record"]
        serve = _Serve(args, env, Path(tmp))
        session = sub = None
        nice_before: int | None = None
        nice_in_force = os.getpriority(os.PRIO_PROCESS, 0)
        from service.settings import ZenohAccessSettings

        prefix = ZenohAccessSettings().zenoh.prefix  # the service it starts inherits the environment
        inbox: queue.SimpleQueue = queue.SimpleQueue()
        url = f"http://127.0.0.1:{port}"
        refused: list[dict] = []
        samples: dict[str, list[float]] = {}
        try:
            with httpx.Client(base_url=url, timeout=60.0) as http:
                deadline = time.monotonic() + start_timeout_s
                while True:
                    if serve.proc.poll() is not None:
                        raise RuntimeError("the service did not start: " + "".join(serve.log[-20:]))
                    try:
                        if http.get("/health", timeout=2.0).status_code == 200:
                            break
                    except httpx.HTTPError:
                        pass
                    if time.monotonic() > deadline:
                        raise RuntimeError("the service did not answer /health")
                    time.sleep(0.2)
                nice_before, nice_in_force = client_priority(client_nice)  # after the service's start
                if first_setpoint:
                    http.put(f"/v1/bearings/{first_id}/setpoint", json=first_setpoint).raise_for_status()
                capacity_at_start = http.get("/health").json().get("capacity") or {}
                # the service overhead per twin (one window of >= 1 s) and the first twin's engine as
                # it runs (one window of 2 s of simulated time: what a twin alike it costs)
                settle = time.monotonic() + 10.0
                while auto and (
                    capacity_at_start.get("service_overhead_per_twin_cpu_s_per_s") is None
                    or capacity_at_start.get("alike_engine_cpu_s_per_sim_s") is None
                ):
                    if time.monotonic() > settle:
                        break
                    time.sleep(0.5)
                    capacity_at_start = http.get("/health").json().get("capacity") or {}
                if auto:
                    held = capacity_at_start.get("max_twins")
                    if held is None:
                        raise RuntimeError(
                            "--twins auto: the service states no capacity (admission off, or no "
                            "twin calibrated): give a number of twins"
                        )
                    plan = twin_plan(max(1, int(held)), alike=True)
                running = [(first_id, first_designation)]
                for twin_id, designation, setpoint in plan[1:]:
                    body = {"id": twin_id, "designation": designation, **({"setpoint": setpoint} if setpoint else {})}
                    r = http.post("/v1/bearings", json=body)
                    if r.status_code == 201:
                        running.append((twin_id, designation))
                    else:
                        detail = r.json().get("detail") or [{}]
                        refused.append(
                            {
                                "id": twin_id,
                                "designation": designation,
                                "status": r.status_code,
                                "message": detail[0].get("message"),
                            }
                        )
                base_load = {
                    tid: http.get(f"/v1/bearings/{tid}").json()["setpoint"]["radial_load_n"] for tid, _ in running
                }
                if zenoh_on:
                    import zenoh

                    from service.bus.zenoh_bus import client_config

                    # a zenoh client with the credentials of the environment (BEARING_TWIN_ZENOH_USER ...)
                    session = zenoh.open(client_config([endpoint], prefix=prefix))

                    def on_state(sample):  # zenoh thread: hand off only
                        inbox.put((time.perf_counter(), str(sample.key_expr), sample.payload.to_bytes()))

                    sub = session.declare_subscriber(all_twins(prefix, STATE), on_state)
                # settle: every twin stepping, then settle_s more
                settle_end = time.monotonic() + 120.0
                while time.monotonic() < settle_end:
                    h = http.get("/health").json()
                    if all(t["frames"] > 0 for t in h["twins"]):
                        break
                    time.sleep(0.2)
                time.sleep(settle_s)
                h0 = http.get("/health").json()
                first = {t["id"]: t for t in h0["twins"]}
                totals0 = (h0.get("capacity") or {}).get("service_overhead") or {}
                wall0 = time.perf_counter()
                latencies: dict[str, list[float]] = {tid: [] for tid, _ in running}
                lost = k = 0
                put_s: list[float] = []
                next_health = time.perf_counter()
                t_end = time.perf_counter() + seconds
                while time.perf_counter() < t_end:
                    tid = running[k % len(running)][0]
                    k += 1
                    load = base_load[tid] - 0.5 * (k % 400)  # a new value every time, in range
                    pattern = re.compile(rb'"radial_load_n":' + re.escape(repr(float(load)).encode()) + rb"[,}]")
                    key = twin_key(prefix, tid, STATE)
                    t0 = time.perf_counter()
                    http.put(f"/v1/bearings/{tid}/setpoint", json={"radial_load_n": load}).raise_for_status()
                    put_s.append(time.perf_counter() - t0)
                    if zenoh_on:
                        seen, wait_until = None, t0 + 1.0
                        while seen is None and time.perf_counter() < wait_until:
                            try:
                                t_msg, k_msg, payload = inbox.get(timeout=max(0.0, wait_until - time.perf_counter()))
                            except queue.Empty:
                                break
                            if k_msg == key and t_msg >= t0 and pattern.search(payload):
                                seen = t_msg
                        if seen is None:
                            lost += 1
                        else:
                            latencies[tid].append(seen - t0)
                    now = time.perf_counter()
                    if now >= next_health:
                        next_health = now + 0.5
                        for t in http.get("/health").json()["twins"]:
                            if t.get("real_time_factor") is not None:
                                samples.setdefault(t["id"], []).append(t["real_time_factor"])
                    time.sleep(max(0.0, t0 + 1.0 / rate_hz - time.perf_counter()))
                health = http.get("/health").json()
                run_wall_s = time.perf_counter() - wall0
        finally:
            if sub is not None:
                sub.undeclare()
            if session is not None:
                session.close()
            serve.stop()
            if nice_before is not None:
                client_priority(nice_before)
    last = {t["id"]: t for t in health["twins"]}
    ms = lambda v: None if v is None else round(1e3 * v, 3)  # noqa: E731
    rows = []
    for tid, designation in running:
        a, b = first.get(tid, {}), last.get(tid, {})
        frames = b.get("frames", 0) - a.get("frames", 0)
        late = b.get("overruns", 0) - a.get("overruns", 0)
        rtf = samples.get(tid, [])
        rows.append(
            {
                "id": tid,
                "designation": designation,
                "real_time_factor_median": statistics.median(rtf) if rtf else None,
                "real_time_factor_min": min(rtf) if rtf else None,
                "late_fraction": late / frames if frames else None,
                "frames": frames,
                "late_frames": late,
                "resyncs": b.get("resyncs", 0) - a.get("resyncs", 0),
                "dropped": b.get("dropped"),
                "cost": b.get("cost"),
                "setpoints": len(latencies.get(tid, [])),
                "client_latency_ms_p99": ms(_percentile(latencies.get(tid, []), 99)),
                "service_latency_ms": b.get("setpoint_latency_ms"),
            }
        )
    every = [v for values in latencies.values() for v in values]
    return {
        "twins_requested": twins,
        "twins_planned": len(plan),
        "capacity_at_start": capacity_at_start,
        "seconds": seconds,
        "rate_hz": rate_hz,
        "zenoh": zenoh_on,
        "recording": record,
        "admission": "off" if force else health.get("capacity", {}).get("admission"),
        "frame_s": (last.get(running[0][0]) or {}).get("frame_s"),
        "lateness_s": (last.get(running[0][0]) or {}).get("lateness_s"),
        "twins": rows,
        "refused": refused,
        "setpoints": k,
        "client_latency_ms_p50": ms(_percentile(every, 50)),
        "client_latency_ms_p99": ms(_percentile(every, 99)),
        "client_latency_ms_max": ms(max(every)) if every else None,
        "client_lost": lost,
        "client_nice": nice_in_force,
        "http_put_ms_p50": ms(_percentile(put_s, 50)),
        "http_put_ms_p99": ms(_percentile(put_s, 99)),
        "capacity": health.get("capacity"),
        "recording_rows": health.get("recording_rows"),
        "overhead_over_run": overhead_over_run(
            totals0, (health.get("capacity") or {}).get("service_overhead") or {}, run_wall_s, len(running)
        ),
    }


def overhead_over_run(before: dict, after: dict, wall_s: float, twins: int) -> dict | None:
    """The service overhead by thread role over the whole measurement, from the cumulative totals
    of /health `capacity.service_overhead` (service.core.thread_cpu) at its start and end:
    `<role>_cpu_s_per_s`, `engine_cpu_s_per_s`, `twin_overhead_cpu_s_per_s`, per twin, and
    `twin_overhead_fraction` (of the engines' CPU); None when the service gives no totals."""
    if wall_s <= 0 or "twin_overhead_cpu_s_total" not in after or "twin_overhead_cpu_s_total" not in before:
        return None
    rate = {
        k.removesuffix("_cpu_s_total") + "_cpu_s_per_s": (after[k] - before.get(k, 0.0)) / wall_s
        for k in after
        if k.endswith("_cpu_s_total") and after[k] is not None and before.get(k) is not None
    }
    engine, twin = rate.get("engine_cpu_s_per_s") or 0.0, rate["twin_overhead_cpu_s_per_s"]
    return {
        "window_s": wall_s,
        **rate,
        "twin_overhead_per_twin_cpu_s_per_s": twin / twins if twins else None,
        "twin_overhead_fraction": twin / engine if engine > 0 else None,
    }
