"""`bearing-twin attack`: a bounded, loopback-only abuse run against a service, measuring whether
load steals real time ("Load cannot steal real time").

    bearing-twin attack --seconds 60 --start --json                # own service on free loopback ports
    bearing-twin attack --seconds 60 --url http://127.0.0.1:8000 --zenoh-connect tcp/127.0.0.1:7447

For `seconds` of wall time (at most 600), all at once, each in its own process (so that one
flood's client work does not show up as the service's latency in another's figures):

* a hostile HTTP flood, `concurrency` (default 32) requests in flight, as fast as the service
  answers: a mix of valid setpoints (with the token) and hostile requests - invalid setpoints
  (NaN/Infinity, out of range, wrong types, unknown fields, garbage), bodies above the size cap,
  a missing or wrong token, unknown twins, unknown paths, wrong methods, invalid twin creations,
  malformed JSON - and GET state reads. It never creates or deletes a twin or starts anything;
* an unauthenticated read flood: `readers` (default 4) connections reading GET state without a
  token, as fast as the service answers;
* optionally (`--zenoh-connect`, or `--start`) a zenoh setpoint flood at `zenoh_rate` per second
  (valid and invalid payloads), counting one result per setpoint (an unanswered one is reported)
  and checking every state message for non-finite numbers;
* each flood process measures its own CPU time (`attacker_cpu_cores`: on a shared host the
  attackers' CPU is taken from the twin too);
* on what watchers use (loadtest.attack_watchers): zenoh twin-id squatting by an anonymous
  peer (`squat`, on by default with zenoh) and, with an OPC UA endpoint (`--opcua`, or `--start`),
  password guessing, a session flood and a subscription flood (`opcua_*`);
* in this process, a /health probe every 50 ms: its latency (p50, p99, max) and the default
  twin's real-time factor; the flood's figures use the probes from 1 s after the flood started
  (the real-time factor is measured over the last second). The same probe runs for `baseline_s`
  (default 3 s) before the flood, for the idle figures.

Every 200 answer with JSON is parsed strictly (NaN/Infinity refused): `nan_checks`. `ok` means no
5xx, no non-finite number, no valid setpoint refused other than by the rate limit (429), no
hostile request accepted, no create blocked by a squatter or answered with its text, no guessed
OPC UA password accepted, every /health probe answered, and (with --start) a clean exit. The
real-time factor and /health p99 are reported beside their targets (median real-time
factor >= 0.95, /health p99 <= 100 ms) in `targets`; they are figures of the host, not part of
`ok`. Loopback only: a URL or zenoh endpoint on another host is refused.
"""

from __future__ import annotations

import asyncio
import collections
import json
import math
import multiprocessing as mp
import random
import secrets
import statistics
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from loadtest import attack_watchers
from service.tools.client import (
    TargetConfig,
    add_target_arguments,
    check_loopback,
    strict_json,
    target_arguments,
    url_is_loopback,
)

MAX_SECONDS = 600.0
MAX_CONCURRENCY = 64
TARGET_RTF = 0.95
TARGET_HEALTH_P99_MS = 100.0
_OVER_CAP = 70 * 1024  # a body just above the default 64 KiB cap


@dataclass
class AttackConfig(TargetConfig):
    """The attack's figures; the service attacked: `TargetConfig` (loopback only)."""

    seconds: float
    concurrency: int = 32
    readers: int = 4
    zenoh_rate_hz: float = 500.0
    baseline_s: float = 3.0
    probe_every_s: float = 0.05
    opcua_url: str | None = None  # OPC UA endpoint of the service (loopback), None: no OPC UA floods
    squat: bool = True  # with zenoh: the twin-id squatting
    record: bool = field(default=False, kw_only=True)  # with start: off by default (the figures are the API's)


def _percentile(values: list[float], q: float) -> float | None:
    if not values:
        return None
    ordered = sorted(values)
    k = min(len(ordered) - 1, max(0, math.ceil(q / 100.0 * len(ordered)) - 1))
    return ordered[k]


# ---- the HTTP floods (child processes) ---------------------------------------------------------
_KINDS = (
    "valid",
    "valid",
    "nan",
    "inf",
    "range",
    "type",
    "unknown-field",
    "garbage",
    "malformed",
    "big",
    "no-token",
    "wrong-token",
    "unknown-twin",
    "unknown-path",
    "bad-method",
    "create-invalid",
    "delete-unknown",
    "state",
    "state",
    "bearings",
)


class _Deck:
    """The kinds of hostile request, dealt from shuffled decks of `_KINDS`: the mix's proportions,
    and every kind in each run of len(_KINDS) requests (a short or slowed-down flood still sends
    them all)."""

    def __init__(self, rng: random.Random):
        self.rng = rng
        self.cards: list[str] = []

    def deal(self) -> str:
        if not self.cards:
            self.cards = list(_KINDS)
            self.rng.shuffle(self.cards)
        return self.cards.pop()


def _hostile_request(
    rng: random.Random, bid: str, token: str | None, valid: dict, kind: str | None = None
) -> tuple[str, str, str, bytes | None, dict, bool | None]:
    """(kind, method, path, body, headers, valid?) of one flood request (`kind`: one of `_KINDS`,
    default a random one): valid True = a valid setpoint (200 or 429 expected), False = hostile
    (4xx expected), None = a read (200 or 4xx)."""
    auth = {"Authorization": f"Bearer {token}"} if token else {}
    js = {"content-type": "application/json"}
    sp = f"/v1/bearings/{bid}/setpoint"
    kind = kind or rng.choice(_KINDS)
    if kind == "valid":
        return kind, "PUT", sp, json.dumps(valid).encode(), {**auth, **js}, True
    bodies = {
        "nan": b'{"shaft_speed_rad_s": NaN}',
        "inf": b'{"radial_load_n": Infinity}',
        "range": b'{"shaft_speed_rad_s": 1e9}',
        "type": b'{"radial_load_n": "three thousand"}',
        "unknown-field": b'{"warp_factor": 9}',
        "malformed": b'{"radial_load_n": 3000',
        "garbage": bytes(rng.randrange(256) for _ in range(40)),
    }
    if kind in bodies:
        return kind, "PUT", sp, bodies[kind], {**auth, **js}, False
    if kind == "big":
        return kind, "PUT", sp, b'{"x": "' + b"x" * _OVER_CAP + b'"}', {**auth, **js}, False
    if kind == "no-token":
        return kind, "PUT", sp, json.dumps(valid).encode(), js, not token
    if kind == "wrong-token":
        return (
            kind,
            "PUT",
            sp,
            json.dumps(valid).encode(),
            {"Authorization": "Bearer wrong-" + secrets.token_hex(4), **js},
            not token,
        )
    if kind == "unknown-twin":
        return (
            kind,
            "PUT",
            f"/v1/bearings/no-such-{rng.randrange(10**6)}/setpoint",
            json.dumps(valid).encode(),
            {**auth, **js},
            False,
        )
    if kind == "unknown-path":
        return (
            kind,
            "GET",
            rng.choice(
                ["/v1/nothing", "/admin", "/v1/bearings/%00/state", "/../../etc/passwd", "/v1/bearings/" + "a" * 300]
            ),
            None,
            {},
            False,
        )
    if kind == "bad-method":
        return kind, rng.choice(["DELETE", "PATCH", "POST"]), "/health", b"{}", js, False
    if kind == "create-invalid":
        body = rng.choice(
            [
                b'{"id": "x y", "designation": "6208"}',
                b'{"id": "ok1", "designation": "9999"}',
                b'{"designation": 6208, "id": []}',
                b"[]",
            ]
        )
        return kind, "POST", "/v1/bearings", body, {**auth, **js}, False
    if kind == "delete-unknown":
        return kind, "DELETE", f"/v1/bearings/no-such-{rng.randrange(10**6)}", None, auth, False
    if kind == "bearings":
        return kind, "GET", "/v1/bearings", None, auth, None
    return kind, "GET", f"/v1/bearings/{bid}/state", None, auth, None


def _http_flood(spec: dict, go, out) -> None:
    """Child process: the hostile flood (spec["mode"] "hostile") or the read flood ("reads")."""
    try:
        out.put(asyncio.run(_http_flood_async(spec, go)))
    except BaseException as exc:  # noqa: BLE001 - reported to the parent
        out.put({"mode": spec["mode"], "crashed": f"{type(exc).__name__}: {exc}"})


async def _http_flood_async(spec: dict, go) -> dict:
    import httpx

    mode, url, bid, token = spec["mode"], spec["url"], spec["bearing_id"], spec["token"]
    workers = spec["workers"]
    rng = random.Random(spec["seed"])
    deck = _Deck(rng)
    ranges = spec["ranges"]
    status: collections.Counter = collections.Counter()
    kinds: collections.Counter = collections.Counter()
    counts: collections.Counter = collections.Counter()
    unexpected: list[str] = []
    limits = httpx.Limits(max_connections=workers, max_keepalive_connections=workers)
    async with httpx.AsyncClient(base_url=url, timeout=30.0, limits=limits) as client:
        await asyncio.get_running_loop().run_in_executor(None, go.wait, 120.0)
        t0, cpu0 = time.monotonic(), time.process_time()
        end = t0 + spec["seconds"]

        async def worker() -> None:
            headers: dict
            while time.monotonic() < end:
                if mode == "reads":
                    kind, method, path, body, headers, valid = (
                        "read",
                        "GET",
                        f"/v1/bearings/{bid}/state",
                        None,
                        {},
                        None,
                    )
                else:
                    setpoint = {
                        n: round(rng.uniform(lo, hi), 3) for n, (lo, hi) in ranges.items() if rng.random() < 0.6
                    } or {"oil_temperature_c": 40.0}
                    kind, method, path, body, headers, valid = _hostile_request(rng, bid, token, setpoint, deck.deal())
                kinds[kind] += 1
                try:
                    r = await client.request(method, path, content=body, headers=headers)
                except httpx.HTTPError as exc:
                    counts["transport_errors"] += 1
                    if len(unexpected) < 50:
                        unexpected.append(f"{kind} {method} {path[:60]}: {type(exc).__name__}: {exc}")
                    continue
                code = r.status_code
                status[code] += 1
                if code >= 500:
                    if len(unexpected) < 50:
                        unexpected.append(f"{kind} {method} {path[:60]}: {code} {r.text[:200]}")
                elif valid is True and code not in (200, 429):
                    counts["valid_refused"] += 1
                    if len(unexpected) < 50:
                        unexpected.append(f"valid {kind}: {code} {r.text[:200]}")
                elif valid is False and code < 400:
                    counts["hostile_accepted"] += 1
                    if len(unexpected) < 50:
                        unexpected.append(f"hostile {kind} accepted: {code} {r.text[:200]}")
                if code == 200 and r.headers.get("content-type", "").startswith("application/json"):
                    counts["nan_checked"] += 1
                    try:
                        strict_json(r.content)
                    except ValueError:
                        counts["non_finite"] += 1

        await asyncio.gather(*(worker() for _ in range(workers)))
        elapsed, cpu = time.monotonic() - t0, time.process_time() - cpu0
    return {
        "mode": mode,
        "workers": workers,
        "seconds": round(elapsed, 2),
        "cpu_s": round(cpu, 2),
        "status": dict(status),
        "kinds": dict(kinds),
        "counts": dict(counts),
        "unexpected": unexpected,
    }


# ---- the zenoh flood (child process) -----------------------------------------------------------
def _zenoh_flood(spec: dict, go, out) -> None:
    try:
        out.put(_zenoh_flood_run(spec, go))
    except BaseException as exc:  # noqa: BLE001
        out.put({"mode": "zenoh", "crashed": f"{type(exc).__name__}: {exc}"})


def _zenoh_flood_run(spec: dict, go) -> dict:
    import zenoh

    from service.bus.access import ZenohAccess
    from service.bus.zenoh_bus import client_config

    access = ZenohAccess(user=spec["user"], password=spec["password"]) if spec.get("user") else ZenohAccess.from_env()
    prefix, bid = spec["prefix"], spec["bearing_id"]
    rng = random.Random(spec["seed"])
    lock = threading.Lock()
    results: collections.Counter = collections.Counter()
    state = {"messages": 0, "non_finite": 0}

    def on_result(sample) -> None:
        try:
            msg = strict_json(sample.payload.to_bytes())
            key = "accepted" if msg.get("accepted") else f"refused_{msg.get('status', 'other')}"
        except Exception:  # noqa: BLE001
            key = "unreadable"
        with lock:
            results[key] += 1

    def on_state(sample) -> None:
        try:
            strict_json(sample.payload.to_bytes())
            bad = 0
        except ValueError:
            bad = 1
        except Exception:  # noqa: BLE001
            bad = 0
        with lock:
            state["messages"] += 1
            state["non_finite"] += bad

    session = zenoh.open(client_config([spec["endpoint"]], access=access, prefix=prefix))
    sent = 0
    try:
        subs = [
            session.declare_subscriber(f"{prefix}/{bid}/setpoint/result", on_result),
            session.declare_subscriber(f"{prefix}/{bid}/state", on_state),
        ]
        pub = session.declare_publisher(f"{prefix}/{bid}/setpoint", congestion_control=zenoh.CongestionControl.BLOCK)
        time.sleep(0.5)  # routes
        go.wait(120.0)
        t0, cpu0 = time.monotonic(), time.process_time()
        end, period, next_t = t0 + spec["seconds"], 1.0 / spec["rate_hz"], t0
        payloads = [
            b'{"shaft_speed_rad_s": NaN}',
            b'{"radial_load_n": -5}',
            b'{"warp": 1}',
            b"\xff\xfe",
            b'{"shaft_speed_rad_s": 400.0, "token": "x"}',
        ]
        while time.monotonic() < end:
            if rng.random() < 0.5:
                pub.put(json.dumps({"oil_temperature_c": round(rng.uniform(30.0, 60.0), 2)}).encode())
            else:
                pub.put(rng.choice(payloads))
            sent += 1
            next_t += period
            delay = next_t - time.monotonic()
            if delay > 0:
                time.sleep(delay)
            elif delay < -1.0:
                next_t = time.monotonic()
        elapsed, cpu = time.monotonic() - t0, time.process_time() - cpu0
        deadline = time.monotonic() + 5.0  # the last results
        while time.monotonic() < deadline:
            with lock:
                if sum(results.values()) >= sent:
                    break
            time.sleep(0.05)
        for sub in subs:
            sub.undeclare()
        pub.undeclare()
    finally:
        session.close()
    with lock:
        answered = sum(results.values())
        return {
            "mode": "zenoh",
            "seconds": round(elapsed, 2),
            "cpu_s": round(cpu, 2),
            "sent": sent,
            "results": dict(results),
            "unanswered": max(0, sent - answered),
            "state_messages": state["messages"],
            "non_finite": state["non_finite"],
        }


# ---- this process: the /health probe -----------------------------------------------------------
def _probe(client, url: str, bid: str, seconds: float, every_s: float, t_ref: float) -> list[dict]:
    """GET /health every `every_s` for `seconds`: [{"t", "ms", "rtf", "late", "ok"}]."""
    out = []
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        t = time.monotonic()
        rec = {"t": t - t_ref, "ms": None, "rtf": None, "late": None, "ok": False}
        try:
            t0 = time.perf_counter()
            r = client.get(f"{url}/health")
            rec["ms"] = (time.perf_counter() - t0) * 1e3
            rec["ok"] = r.status_code == 200
            tw = next((x for x in r.json().get("twins", []) if x.get("id") == bid), None)
            if tw is not None:
                rec["rtf"], rec["late"] = tw.get("real_time_factor"), tw.get("late_fraction")
        except Exception:  # noqa: BLE001 - a failed probe is counted (ok False)
            pass
        out.append(rec)
        time.sleep(max(0.0, every_s - (time.monotonic() - t)))
    return out


def _probe_figures(probes: list[dict]) -> dict:
    ms = [p["ms"] for p in probes if p["ms"] is not None]
    rtf = [p["rtf"] for p in probes if p["rtf"] is not None]
    late = [p["late"] for p in probes if p["late"] is not None]

    def r(x, n=2):
        return round(x, n) if x is not None else None

    return {
        "probes": len(probes),
        "failed": sum(1 for p in probes if not p["ok"]),
        "health_p50_ms": r(_percentile(ms, 50)),
        "health_p99_ms": r(_percentile(ms, 99)),
        "health_max_ms": r(max(ms) if ms else None),
        "real_time_factor_median": r(statistics.median(rtf) if rtf else None, 4),
        "real_time_factor_min": r(min(rtf) if rtf else None, 4),
        "late_fraction_last": r(late[-1] if late else None, 4),
    }


def run_attack(cfg: AttackConfig) -> dict:
    """Run the attack (bounded: cfg.seconds <= MAX_SECONDS, plus start-up and shutdown)."""
    import httpx

    if not (0 < cfg.seconds <= MAX_SECONDS and math.isfinite(cfg.seconds)):
        raise ValueError(f"seconds = {cfg.seconds!r}: must be in (0, {MAX_SECONDS:g}]")
    if not (1 <= cfg.concurrency <= MAX_CONCURRENCY):
        raise ValueError(f"concurrency = {cfg.concurrency!r}: must be in [1, {MAX_CONCURRENCY}]")
    if not (0 <= cfg.readers <= MAX_CONCURRENCY):
        raise ValueError(f"readers = {cfg.readers!r}: must be in [0, {MAX_CONCURRENCY}]")
    if not (0 < cfg.zenoh_rate_hz <= 100_000):
        raise ValueError(f"zenoh_rate_hz = {cfg.zenoh_rate_hz!r}: must be in (0, 100000] [1/s]")
    if not cfg.start:
        check_loopback(cfg.url, cfg.zenoh_connect)
        if cfg.opcua_url and not url_is_loopback(cfg.opcua_url.replace("opc.tcp://", "http://", 1)):
            raise ValueError(f"opcua_url = {cfg.opcua_url!r}: the attack runs against loopback only")
    log = cfg.log or (lambda _line: None)
    rng = random.Random(cfg.seed)
    token = cfg.token
    started = None
    if cfg.start and token is None:
        token = secrets.token_urlsafe(24)
    url, zenoh_endpoint = cfg.url.rstrip("/"), cfg.zenoh_connect
    report: dict[str, Any] = {
        "seconds": cfg.seconds,
        "started_service": cfg.start,
        "bearing_id": cfg.bearing_id,
        "concurrency": cfg.concurrency,
        "readers": cfg.readers,
    }
    client = httpx.Client(timeout=30.0)
    ctx = mp.get_context("spawn")
    procs: list = []
    try:
        zuser = zpass = None
        if cfg.start:
            from loadtest.soak import _Started

            assert token is not None  # generated above when the attack starts the service
            started = _Started(
                token, None, lambda line: log(line.replace("soak: ", "attack: ", 1)), record=cfg.record, opcua=True
            )
            url, zenoh_endpoint = started.url, started.zenoh_endpoint
            zuser, zpass = started.zenoh_user, started.zenoh_password
            started.wait_ready(client)
        report.update(url=url, zenoh=zenoh_endpoint)
        headers = {"Authorization": f"Bearer {token}"} if token else {}
        info = client.get(f"{url}/v1/bearings/{cfg.bearing_id}", headers=headers)
        if info.status_code != 200:
            raise RuntimeError(f"GET /v1/bearings/{cfg.bearing_id}: {info.status_code} {info.text[:300]}")
        limits = info.json()["limits"]
        from loadtest.soak import _SAFE

        ranges = {n: (max(lo, limits[n][0]), min(hi, limits[n][1])) for n, (lo, hi) in _SAFE.items() if n in limits}
        t_ref = time.monotonic()
        log(f"attack: {cfg.baseline_s:g} s of idle /health probes")
        baseline = _probe(client, url, cfg.bearing_id, cfg.baseline_s, cfg.probe_every_s, t_ref)

        go, out = ctx.Event(), ctx.Queue()
        common = {"url": url, "bearing_id": cfg.bearing_id, "token": token, "seconds": cfg.seconds, "ranges": ranges}
        specs: list[tuple[Callable[..., Any], dict[str, Any]]] = [
            (_http_flood, {**common, "mode": "hostile", "workers": cfg.concurrency, "seed": rng.randrange(2**32)})
        ]
        if cfg.readers:
            specs.append(
                (
                    _http_flood,
                    {**common, "mode": "reads", "token": None, "workers": cfg.readers, "seed": rng.randrange(2**32)},
                )
            )
        if zenoh_endpoint:
            specs.append(
                (
                    _zenoh_flood,
                    {
                        "endpoint": zenoh_endpoint,
                        "bearing_id": cfg.bearing_id,
                        "prefix": attack_watchers.target_prefix(started),
                        "user": zuser,
                        "password": zpass,
                        "seconds": cfg.seconds,
                        "rate_hz": cfg.zenoh_rate_hz,
                        "seed": rng.randrange(2**32),
                    },
                )
            )
        specs += attack_watchers.specs(cfg, started, url, zenoh_endpoint, token)
        for _, spec in specs:
            if "connected" in spec:  # a part that connects before the floods start
                spec["connected"] = ctx.Event()
        for target, spec in specs:
            p = ctx.Process(target=target, args=(spec, go, out), daemon=True)
            p.start()
            procs.append(p)
        time.sleep(3.0)  # the children import httpx / zenoh and connect
        for _, spec in specs:
            if spec.get("connected") is not None and not spec["connected"].wait(60.0):
                log(f"attack: {spec['mode']} did not connect within 60 s")
        log(f"attack: {cfg.seconds:g} s of floods ({', '.join(s.get('mode', 'zenoh') for _, s in specs)})")
        flood_start = time.monotonic()
        go.set()
        during = _probe(client, url, cfg.bearing_id, cfg.seconds, cfg.probe_every_s, t_ref)
        parts: dict[str, Any] = {}
        deadline = time.monotonic() + 60.0
        while len(parts) < len(specs) and time.monotonic() < deadline:
            try:
                part = out.get(timeout=1.0)
            except Exception:  # noqa: BLE001 - queue.Empty
                continue
            parts[part.get("mode", "?")] = part
        settled = [p for p in during if p["t"] >= flood_start - t_ref + 1.0] or during
        report["baseline"] = _probe_figures(baseline)
        report["flood"] = _probe_figures(settled)
        report["http_flood"] = parts.get("hostile")
        report["read_flood"] = parts.get("reads")
        report["zenoh_flood"] = parts.get("zenoh") if zenoh_endpoint else None
        for name in attack_watchers.WATCHERS:
            report[name] = parts.get(name)
        report["missing_parts"] = [s.get("mode", "zenoh") for _, s in specs if s.get("mode", "zenoh") not in parts]
        health = client.get(f"{url}/health").json()
        report["service"] = {
            "status": health.get("status"),
            "http_tarpit": health.get("http_tarpit"),
            "thread_priority": health.get("thread_priority"),
            "twins": [
                {
                    k: t.get(k)
                    for k in ("id", "real_time_factor", "late_fraction", "errors", "restarts", "overruns", "frames")
                }
                for t in health.get("twins", [])
            ],
        }
        if started is not None:
            report["shutdown"] = started.stop()
    finally:
        for p in procs:
            p.join(5.0)
            if p.is_alive():
                p.kill()
                p.join(5.0)
        if started is not None:
            started.kill()
            import shutil

            shutil.rmtree(started.dir, ignore_errors=True)
        client.close()
    _totals(report)
    _verdict(report)
    return report


def _totals(report: dict) -> None:
    totals: collections.Counter[str] = collections.Counter()
    for name in ("http_flood", "read_flood"):
        part = report.get(name) or {}
        for code, n in (part.get("status") or {}).items():
            totals[f"{int(code) // 100}xx"] += n
        counts = part.get("counts") or {}
        for key in ("transport_errors", "valid_refused", "hostile_accepted", "nan_checked", "non_finite"):
            totals[key] += counts.get(key, 0)
        if part.get("seconds"):
            part["rate_hz"] = round(sum((part.get("status") or {}).values()) / part["seconds"], 1)
    z = report.get("zenoh_flood") or {}
    cpu = {}
    for name in ("http_flood", "read_flood", "zenoh_flood"):  # the attackers' own CPU [cores]: taken from the twin too
        part = report.get(name) or {}
        if part.get("seconds") and part.get("cpu_s") is not None:
            cpu[name] = round(part["cpu_s"] / part["seconds"], 3)
    report["attacker_cpu_cores"] = {**cpu, "total": round(sum(cpu.values()), 3)} if cpu else None
    totals["nan_checked"] += z.get("state_messages", 0)
    totals["non_finite"] += z.get("non_finite", 0)
    report["totals"] = {
        k: totals.get(k, 0)
        for k in (
            "2xx",
            "4xx",
            "5xx",
            "transport_errors",
            "valid_refused",
            "hostile_accepted",
            "nan_checked",
            "non_finite",
        )
    }
    if z:
        report["totals"]["zenoh_sent"] = z.get("sent", 0)
        report["totals"]["zenoh_unanswered"] = z.get("unanswered", 0)


def _verdict(report: dict) -> None:
    t, f = report["totals"], report.get("flood") or {}
    failures = []
    if t["5xx"]:
        failures.append(f"{t['5xx']} 5xx answers")
    if t["non_finite"]:
        failures.append(f"{t['non_finite']} answers or messages with non-finite numbers")
    if t["valid_refused"]:
        failures.append(f"{t['valid_refused']} valid setpoints refused other than by the rate limit")
    if t["hostile_accepted"]:
        failures.append(f"{t['hostile_accepted']} hostile requests accepted")
    if f.get("failed") or (report.get("baseline") or {}).get("failed"):
        failures.append(f"{f.get('failed', 0)} /health probes failed during the flood")
    for name in report.get("missing_parts") or ():
        failures.append(f"the {name} flood reported nothing")
    for name in ("http_flood", "read_flood", "zenoh_flood", *attack_watchers.WATCHERS):
        if (report.get(name) or {}).get("crashed"):
            failures.append(f"{name}: {report[name]['crashed']}")
    failures += attack_watchers.failures(report)
    sd = report.get("shutdown")
    if sd is not None and not sd.get("clean"):
        failures.append(f"service shutdown not clean: {sd}")
    report["failures"] = failures
    report["ok"] = not failures
    rtf, p99 = f.get("real_time_factor_median"), f.get("health_p99_ms")
    report["targets"] = {
        "real_time_factor_median_min": TARGET_RTF,
        "health_p99_ms_max": TARGET_HEALTH_P99_MS,
        "real_time_factor_median": rtf,
        "health_p99_ms": p99,
        "met": bool(rtf is not None and p99 is not None and rtf >= TARGET_RTF and p99 <= TARGET_HEALTH_P99_MS),
    }


def format_report(r: dict) -> str:
    b, f, t = r.get("baseline") or {}, r.get("flood") or {}, r["totals"]
    lines = [
        f"attack on {r.get('url')} for {r['seconds']:g} s (twin {r['bearing_id']}, HTTP concurrency "
        f"{r['concurrency']}, {r['readers']} unauthenticated readers"
        + (", zenoh flood" if r.get("zenoh_flood") else "")
        + ")"
    ]
    for name, part in (("hostile HTTP", r.get("http_flood")), ("read flood", r.get("read_flood"))):
        if part and not part.get("crashed"):
            lines.append(
                f"  {name}: {sum(part['status'].values())} answers at {part.get('rate_hz')} /s; "
                f"status {dict(sorted(part['status'].items()))}; transport errors "
                f"{part['counts'].get('transport_errors', 0)}"
            )
    z = r.get("zenoh_flood")
    if z and not z.get("crashed"):
        lines.append(f"  zenoh: {z['sent']} setpoints, results {z['results']}, unanswered {z['unanswered']}")
    lines.append(
        f"  totals: 2xx {t['2xx']}, 4xx {t['4xx']}, 5xx {t['5xx']}; NaN checks {t['nan_checked']}, "
        f"non-finite {t['non_finite']}"
    )
    if r.get("attacker_cpu_cores"):
        lines.append(f"  attackers' own CPU [cores]: {r['attacker_cpu_cores']}")
    lines += attack_watchers.summary_lines(r)
    tarpit = (r.get("service") or {}).get("http_tarpit")
    if tarpit:
        lines.append(
            f"  tarpit: {tarpit.get('held', 0)} refusals held {tarpit.get('delay_s')} s, "
            f"{tarpit.get('answered_at_once', 0)} answered at once"
        )
    lines.append(
        f"  idle:  real-time factor median {b.get('real_time_factor_median')}, /health p50 "
        f"{b.get('health_p50_ms')} ms, p99 {b.get('health_p99_ms')} ms"
    )
    lines.append(
        f"  flood: real-time factor median {f.get('real_time_factor_median')} (min "
        f"{f.get('real_time_factor_min')}), /health p50 {f.get('health_p50_ms')} ms, p99 "
        f"{f.get('health_p99_ms')} ms, max {f.get('health_max_ms')} ms"
    )
    tg = r["targets"]
    lines.append(
        f"  targets (median RTF >= {tg['real_time_factor_median_min']}, /health p99 <= "
        f"{tg['health_p99_ms_max']:g} ms): {'met' if tg['met'] else 'NOT met'}"
    )
    lines.append("  OK" if r["ok"] else "  FAILED: " + "; ".join(r["failures"]))
    return "\n".join(lines)


def add_attack_command(sub) -> None:
    p = sub.add_parser(
        "attack",
        help="bounded loopback abuse run: hostile HTTP flood, read flood, optional "
        "zenoh flood; real-time factor and /health latency under load",
        description=__doc__.split("\n\n")[0],
    )
    p.add_argument("--seconds", type=float, required=True, help=f"length of the floods [s] (<= {MAX_SECONDS:g})")
    add_target_arguments(
        p,
        url_help="service URL, loopback only (ignored with --start)",
        zenoh_help="zenoh endpoint of the service for the zenoh flood, loopback only (credentials: "
        "BEARING_TWIN_ZENOH_USER / _PASSWORD)",
        start_help="launch an own `bearing-twin serve` on free loopback ports (token, zenoh access control, no "
        "recording unless --record) and flood zenoh too",
        twin_help="twin to attack and measure (default `default`)",
    )
    p.add_argument("--record", action="store_true", help="with --start: the service records as `serve` does")
    p.add_argument(
        "--opcua",
        metavar="opc.tcp://127.0.0.1:PORT",
        help="OPC UA endpoint of the service for the login, session and subscription floods (loopback "
        "only; with --start: its own)",
    )
    p.add_argument("--no-squat", action="store_true", help="no zenoh twin-id squatting")
    p.add_argument("--concurrency", type=int, default=32, help="hostile HTTP requests in flight (default 32)")
    p.add_argument("--readers", type=int, default=4, help="unauthenticated GET state readers (default 4; 0: none)")
    p.add_argument("--zenoh-rate", type=float, default=500.0, help="zenoh setpoints per second (default 500)")
    p.add_argument("--baseline", type=float, default=3.0, help="idle /health probing before the flood [s] (default 3)")
    p.add_argument("--seed", type=int, help="random seed")
    p.add_argument("--json", action="store_true", help="print the report as JSON")
    p.set_defaults(func=_cmd_attack)


def _cmd_attack(args) -> int:
    cfg = AttackConfig(
        seconds=args.seconds,
        **target_arguments(args),
        concurrency=args.concurrency,
        readers=args.readers,
        zenoh_rate_hz=args.zenoh_rate,
        baseline_s=args.baseline,
        record=args.record,
        opcua_url=args.opcua,
        squat=not args.no_squat,
        log=lambda line: print(line, file=sys.stderr, flush=True),
    )
    try:
        report = run_attack(cfg)
    except (RuntimeError, ValueError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    print(json.dumps(report, indent=2) if args.json else format_report(report), flush=True)
    return 0 if report["ok"] else 1
