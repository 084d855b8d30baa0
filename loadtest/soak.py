"""`bearing-twin soak`: a bounded long run against a service, driving random valid and invalid
setpoints over HTTP and zenoh and measuring what a user leaving it running for weeks cares about.

    bearing-twin soak --minutes 10 --start --json          # own service on free loopback ports
    bearing-twin soak --minutes 60 --url http://127.0.0.1:8000 --zenoh-connect tcp/127.0.0.1:7447

What it does, for `minutes` of wall time:

* sends `rate` setpoints per second (half over HTTP PUT, half over zenoh when connected), a
  `invalid` share of them invalid on purpose (negative or out-of-range values, NaN/Infinity
  literals, wrong types, unknown fields, non-JSON bytes, bodies above 64 KiB, a missing or wrong
  HTTP token when the service has one, a zenoh payload carrying a "token" field) and the rest
  valid (random values well inside the bearing's limits; HTTP with the token, zenoh without:
  zenoh has its own access control); every 4th tick also reads GET state (strict JSON);
* zenoh: a client of the endpoint with the credentials of BEARING_TWIN_ZENOH_USER / _PASSWORD
  (with --start: a generated users file for the service and a generated writer `soak`), key
  prefix BEARING_TWIN_ZENOH_PREFIX (default bearing);
* subscribes to `{prefix}/*/state` and counts gaps in each twin's `seq` (dropped messages),
  out-of-order messages and non-finite numbers, and to the setpoint result key, pairing each
  zenoh setpoint with its result in order (zenoh keeps the order of one link) after a first
  round trip (a valid setpoint put until its result arrives: then both routes exist);
* every `sample_s` reads /health (real-time factor, frames, overruns, runner errors, restarts,
  fallbacks, rows recorded) and the service's resident memory (psutil, else /proc/<pid>/status
  VmRSS; the pid comes from /health, or the subprocess; /health's own `rss_bytes` when the
  process is not on this machine);
* memory growth = (median of the last 3 samples - first sample after the warm-up) / that first
  sample; the warm-up is a quarter of the run, at least 10 s and at most 60 s (JIT, buffers,
  caches); growth is judged (`ok` needs it under the limit) only when at least 60 s were
  measured after the warm-up: a shorter run reports it, but one-off settling steps of tens of MB
  cannot be told from a leak there (`MIN_JUDGED_WINDOW_S`);
* an unexpected answer is an error: a 5xx, a transport failure, a refusal of a valid setpoint
  other than 429, an acceptance of an invalid one;
* with `--start` it launches `bearing-twin serve` on free loopback ports with a token, zenoh
  access control (a generated users file: the writer `soak`) and a recording in a temp dir, and at the end stops it
  with SIGTERM (bounded wait) and reads the
  recording back, every segment of it (`service.recording.recording_segments`; `--record-segment-s`
  sets the service's rotation period): complete = every segment readable on its own (one
  recording id, the static geometry, a blueprint), together at least the rows the service
  reported, no gap in the recorded `seq`, nothing recorded twice.

`ok` (exit status 0) = no error, no seq gap, memory growth under `max_memory_growth_pct`, and
with --start a clean exit and a complete recording. `--no-record` (with --start) runs the service
without its rerun recording, to tell the service's own memory from the rerun SDK's. (rerun-sdk
0.41's file sink holds the RRD footer's chunk manifest in memory until the file closes, about
1 MB/s at 50 snapshots/s here: the service writes its recording without a footer by default,
`BEARING_TWIN_RECORD_FOOTER`; docs/operations.md.)
"""

from __future__ import annotations

import collections
import json
import math
import os
import random
import secrets
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import service
from loadtest.ports import free_ports
from service.keys import DEFAULT_PREFIX, SETPOINT, SETPOINT_RESULT, STATE, all_twins, twin_key
from service.recording.reader import snapshots_per_trend_window, window_seq_gaps
from service.recording.recorder import RerunRecorder
from service.settings import ServiceSettings
from service.tools.client import TargetConfig, add_target_arguments, strict_json, target_arguments, url_is_loopback

_FIELDS = ("shaft_speed_rad_s", "radial_load_n", "axial_load_n", "oil_temperature_c")
# valid values stay well inside what the DEM holds (the limits allow loads it cannot hold)
_SAFE = {
    "shaft_speed_rad_s": (50.0, 1500.0),
    "radial_load_n": (500.0, 9000.0),
    "axial_load_n": (-1500.0, 1500.0),
    "oil_temperature_c": (20.0, 90.0),
}
_INVALID_EXPECTED = {400, 401, 413, 422}
_BIG = 128 * 1024


@dataclass
class SoakConfig(TargetConfig):
    """The soak's own settings; the service driven: `TargetConfig` (with start: `record` also
    checks the recording)."""

    minutes: float
    rate_hz: float = 10.0
    invalid_fraction: float = 0.3
    sample_s: float = 2.0
    max_memory_growth_pct: float = 5.0
    publish_rate_hz: float | None = None
    keep_dir: bool = False
    record_segment_s: float | None = None  # with start: the service's BEARING_TWIN_RECORD_SEGMENT_S [s]


def _rss_bytes(pid: int) -> tuple[int | None, str]:
    try:
        import psutil

        return int(psutil.Process(pid).memory_info().rss), "psutil"
    except ImportError:
        pass
    except Exception:  # noqa: BLE001
        return None, "psutil"
    try:
        with open(f"/proc/{pid}/status", encoding="ascii") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) * 1024, "proc"
    except (OSError, ValueError, IndexError):
        pass
    return None, "proc"


class _Started:
    """`bearing-twin serve` as a subprocess on free loopback ports, token and zenoh access control
    (a users file with the writer `soak`, its password in `zenoh_password`) in its environment."""

    def __init__(
        self,
        token: str,
        publish_rate_hz: float | None,
        log,
        record: bool = True,
        record_segment_s: float | None = None,
        opcua: bool = False,
    ):
        """`opcua`: serve OPC UA too, on a free loopback port (`opcua_url`; security `auto`)."""
        self.dir = Path(tempfile.mkdtemp(prefix="bearing-twin-soak-"))
        self.zenoh_user, self.zenoh_password = "soak", secrets.token_urlsafe(18)
        users = self.dir / "zenoh-users.txt"
        fd = os.open(users, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        with os.fdopen(fd, "w") as f:
            f.write(f"{self.zenoh_user}:{self.zenoh_password}\n")
        self.port, zenoh_port, opcua_port = free_ports(3)
        self.zenoh_endpoint = f"tcp/127.0.0.1:{zenoh_port}"
        self.rrd = self.dir / "soak.rrd" if record else None
        self.log_path = self.dir / "serve.log"
        cmd = [
            sys.executable,
            "-m",
            "service.cli",
            "serve",
            "--host",
            "127.0.0.1",
            "--port",
            str(self.port),
            "--zenoh-listen",
            self.zenoh_endpoint,
            "--log-level",
            "warning",
        ]
        cmd += ["--record", str(self.rrd)] if self.rrd is not None else ["--no-record"]
        self.opcua_url = f"opc.tcp://127.0.0.1:{opcua_port}" if opcua else None
        if self.opcua_url:
            cmd += ["--opcua", self.opcua_url]
        if publish_rate_hz:
            cmd += ["--publish-rate", str(publish_rate_hz)]
        env = {k: v for k, v in os.environ.items() if not k.startswith("BEARING_TWIN_")}
        # the service of this source tree, not whichever one the temporary folder would import
        source = str(Path(service.__file__).resolve().parents[1])
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [source, os.environ.get("PYTHONPATH")]))
        env.update(
            {
                "BEARING_TWIN_TOKEN": token,
                "PYTHONUNBUFFERED": "1",
                "BEARING_TWIN_ZENOH_USERSFILE": str(users),
                "BEARING_TWIN_ZENOH_WRITERS": self.zenoh_user,
            }
        )
        if record_segment_s is not None:
            env["BEARING_TWIN_RECORD_SEGMENT_S"] = repr(float(record_segment_s))
        self._log_file = open(self.log_path, "wb")
        self.proc = subprocess.Popen(cmd, cwd=self.dir, env=env, stdout=self._log_file, stderr=subprocess.STDOUT)
        self.url = f"http://127.0.0.1:{self.port}"
        if log:
            log(
                f"soak: started `bearing-twin serve` (pid {self.proc.pid}) on {self.url}, zenoh "
                f"{self.zenoh_endpoint}, recording {self.rrd or 'off'}"
            )

    def wait_ready(self, client, timeout_s: float = 180.0) -> None:
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                raise RuntimeError(
                    f"the service exited at start (status {self.proc.returncode}):\n"
                    + self.log_path.read_text(errors="replace")[-3000:]
                )
            try:
                if client.get(f"{self.url}/health", timeout=2.0).status_code == 200:
                    return
            except Exception:  # noqa: BLE001
                pass
            time.sleep(0.2)
        raise RuntimeError("the service did not answer /health in time")

    def stop(self, timeout_s: float = 30.0) -> dict:
        t0 = time.monotonic()
        out: dict[str, Any] = {"signal": "SIGTERM", "exit_code": None, "seconds": None, "killed": False}
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(timeout_s)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(15)
                out["killed"] = True
        out["exit_code"] = self.proc.returncode
        out["seconds"] = round(time.monotonic() - t0, 2)
        out["clean"] = _clean_shutdown(out)
        self._log_file.close()
        return out

    def kill(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait(15)
        if not self._log_file.closed:
            self._log_file.close()


class _Stream:
    """zenoh client: seq gaps of {prefix}/*/state and the setpoint results of one twin."""

    def __init__(self, endpoint: str, bearing_id: str, prefix: str = DEFAULT_PREFIX, access: Any = None):
        import zenoh

        from service.bus.zenoh_bus import client_config

        self.session = zenoh.open(client_config([endpoint], access=access, prefix=prefix))
        self.bearing_id = bearing_id
        self.lock = threading.Lock()
        self.last_seq: dict[str, int] = {}
        self.messages = 0
        self.gaps = 0
        self.dropped = 0
        self.out_of_order = 0
        self.non_finite = 0
        self.first_at: float | None = None
        self.results: collections.deque = collections.deque()
        self._subs = [
            self.session.declare_subscriber(all_twins(prefix, STATE), self._on_state),
            self.session.declare_subscriber(twin_key(prefix, bearing_id, SETPOINT_RESULT), self._on_result),
        ]
        self.publisher_key = twin_key(prefix, bearing_id, SETPOINT)

    def _on_state(self, sample) -> None:
        try:
            msg = strict_json(sample.payload.to_bytes())
            bid, seq = str(msg["bearing_id"]), int(msg["seq"])
        except ValueError:
            with self.lock:
                self.non_finite += 1
            return
        except Exception:  # noqa: BLE001
            return
        with self.lock:
            self.messages += 1
            if self.first_at is None:
                self.first_at = time.monotonic()
            last = self.last_seq.get(bid)
            if last is not None:
                if seq > last + 1:
                    self.gaps += 1
                    self.dropped += seq - last - 1
                elif seq <= last:
                    self.out_of_order += 1
            if last is None or seq > last:
                self.last_seq[bid] = seq

    def _on_result(self, sample) -> None:
        try:
            msg = strict_json(sample.payload.to_bytes())
        except Exception:  # noqa: BLE001
            msg = {"accepted": None}
        with self.lock:
            self.results.append(msg)

    def put(self, payload: bytes | str) -> None:
        self.session.put(self.publisher_key, payload)

    def take_results(self) -> list[dict]:
        with self.lock:
            out = list(self.results)
            self.results.clear()
        return out

    def handshake(self, payload: bytes, timeout_s: float = 30.0) -> int:
        """Put the valid setpoint `payload` until a result comes back, then drop every result so
        far; returns the number of puts. zenoh routes declarations asynchronously: a setpoint put
        before the service's subscriber is known here, or answered before this session's result
        subscriber is known there, is lost without an answer, and pairing in order would then
        shift every later pair by one. After one round trip both routes exist."""
        deadline = time.monotonic() + timeout_s  # a liveness bound, not a performance figure
        puts = 0
        while time.monotonic() < deadline:
            self.put(payload)
            puts += 1
            wait_until = time.monotonic() + 0.5
            while time.monotonic() < wait_until:
                with self.lock:
                    answered = bool(self.results)
                if answered:
                    time.sleep(0.5)  # the answers of earlier puts still on their way
                    self.take_results()
                    return puts
                time.sleep(0.01)
        raise RuntimeError(f"no zenoh setpoint result within {timeout_s} s: is the twin on this bus?")

    def close(self) -> None:
        for sub in self._subs:
            try:
                sub.undeclare()
            except Exception:  # noqa: BLE001
                pass
        try:
            self.session.close()
        except Exception:  # noqa: BLE001
            pass


class _Driver:
    """Random valid and invalid setpoints (see the module docstring)."""

    def __init__(self, rng: random.Random, limits: dict, token: str | None):
        self.rng = rng
        self.token = token
        self.ranges = {}
        for name, (lo, hi) in _SAFE.items():
            llo, lhi = limits.get(name, (lo, hi))
            self.ranges[name] = (max(lo, llo), min(hi, lhi))
        self.limits = limits

    def valid(self) -> dict:
        names = self.rng.sample(_FIELDS, self.rng.randint(1, len(_FIELDS)))
        return {n: round(self.rng.uniform(*self.ranges[n]), 3) for n in names}

    def invalid_http(self) -> tuple[bytes, dict]:
        """(body, extra headers) of a request the service must refuse with a 4xx."""
        r = self.rng.random()
        kinds = ["negative", "nan", "inf", "range", "type", "unknown", "garbage", "big"]
        if self.token is not None:
            kinds += ["no-token", "wrong-token"]
        kind = self.rng.choice(kinds)
        hdr: dict = {}
        good = json.dumps(self.valid()).encode()
        if kind == "negative":
            body = b'{"radial_load_n": -%d}' % (1 + int(r * 1000))
        elif kind == "nan":
            body = b'{"shaft_speed_rad_s": NaN}'
        elif kind == "inf":
            body = b'{"radial_load_n": Infinity}'
        elif kind == "range":
            hi = self.limits.get("shaft_speed_rad_s", (0.0, 2000.0))[1]
            body = json.dumps({"shaft_speed_rad_s": hi * (2.0 + r)}).encode()
        elif kind == "type":
            body = b'{"radial_load_n": "three thousand"}'
        elif kind == "unknown":
            body = b'{"radial_load": 3000}'
        elif kind == "garbage":
            body = bytes(self.rng.randrange(256) for _ in range(40))
        elif kind == "big":
            body = b'{"unknown": "' + b"x" * _BIG + b'"}'
        elif kind == "no-token":
            body, hdr = good, {"Authorization": None}
        else:
            body, hdr = good, {"Authorization": "Bearer wrong-" + secrets.token_hex(4)}
        return body, hdr

    def zenoh_payload(self, valid: bool) -> bytes:
        """A zenoh setpoint: never the HTTP token (zenoh has its own access control); a payload
        with a "token" field is one of the invalid kinds (refused with 422)."""
        if valid:
            return json.dumps(self.valid()).encode()
        kind = self.rng.choice(["negative", "nan", "unknown", "garbage", "big", "token-field"])
        if kind == "negative":
            return b'{"radial_load_n": -5}'
        if kind == "nan":
            return b'{"shaft_speed_rad_s": NaN}'
        if kind == "unknown":
            return b'{"radial_load": 3000}'
        if kind == "garbage":
            return b"\xff\xfenot json"
        if kind == "big":
            return ('{"unknown": "' + "x" * _BIG + '"}').encode()
        return json.dumps({**self.valid(), "token": "not-a-zenoh-field"}).encode()


def run_soak(cfg: SoakConfig) -> dict:
    """Run the soak (bounded by cfg.minutes plus start-up and shutdown); returns the report."""
    import httpx

    if not (cfg.minutes > 0 and math.isfinite(cfg.minutes)):
        raise ValueError(f"minutes = {cfg.minutes!r}: must be > 0")
    if not (cfg.rate_hz > 0 and math.isfinite(cfg.rate_hz)):
        raise ValueError(f"rate = {cfg.rate_hz!r}: must be > 0 [1/s]")
    log = cfg.log or (lambda _line: None)
    rng = random.Random(cfg.seed)
    token = cfg.token
    token_source = "given" if token else None
    started = None
    if cfg.start and token is None:
        token, token_source = secrets.token_urlsafe(24), "generated"
    url, zenoh_endpoint = cfg.url.rstrip("/"), cfg.zenoh_connect
    report: dict[str, Any] = {
        "minutes": cfg.minutes,
        "rate_hz": cfg.rate_hz,
        "started_service": cfg.start,
        "token": token_source,
        "bearing_id": cfg.bearing_id,
    }
    headers = {"Authorization": f"Bearer {token}"} if token else {}
    client = httpx.Client(timeout=30.0)
    stream = None
    try:
        if cfg.start:
            assert token is not None  # generated above when not given
            started = _Started(
                token, cfg.publish_rate_hz, log, record=cfg.record, record_segment_s=cfg.record_segment_s
            )
            url, zenoh_endpoint = started.url, started.zenoh_endpoint
            started.wait_ready(client)
        report.update(url=url, zenoh=zenoh_endpoint)
        info = client.get(f"{url}/v1/bearings/{cfg.bearing_id}", headers=headers)
        if info.status_code != 200:
            raise RuntimeError(f"GET /v1/bearings/{cfg.bearing_id}: {info.status_code} {info.text[:300]}")
        limits = {k: tuple(v) for k, v in info.json()["limits"].items()}
        driver = _Driver(rng, limits, token)
        if zenoh_endpoint:
            from service.bus.access import ZenohAccess
            from service.settings import ZenohAccessSettings

            env = ZenohAccessSettings()
            access = (
                ZenohAccess(user=started.zenoh_user, password=started.zenoh_password)
                if started is not None
                else ZenohAccess.from_settings(env.zenoh)
            )
            prefix = DEFAULT_PREFIX if started is not None else env.zenoh.prefix  # the started one: default
            stream = _Stream(zenoh_endpoint, cfg.bearing_id, prefix, access)
            report["zenoh_handshake_puts"] = stream.handshake(driver.zenoh_payload(True))
            report["zenoh_access"] = access.describe(listening=False) if access.enabled else "none"
        health0 = client.get(f"{url}/health", headers=headers).json()
        pid = started.proc.pid if started is not None else health0.get("pid")
        local = started is not None or url_is_loopback(url)
        body = _drive(cfg, client, url, headers, driver, stream, pid if local else None, log, report)
        report.update(body)
        if stream is not None:
            time.sleep(1.0)  # the last results and states
            _pair_results(report, stream)
            with stream.lock:
                report["stream"] = {
                    "messages": stream.messages,
                    "twins": len(stream.last_seq),
                    "seq_gaps": stream.gaps,
                    "dropped_messages": stream.dropped,
                    "out_of_order": stream.out_of_order,
                    "non_finite": stream.non_finite,
                    "rate_hz": round(stream.messages / max(report["duration_s"], 1e-9), 2),
                }
            last_stream_seq = stream.last_seq.get(cfg.bearing_id)
        else:
            report["stream"] = None
            last_stream_seq = None
        if started is not None:
            if stream is not None:
                stream.close()
                stream = None
            report["shutdown"] = started.stop()
            report["recording"] = (
                _check_recording(started.rrd, cfg.bearing_id, report.get("recording_rows_reported", 0), last_stream_seq)
                if started.rrd is not None
                else None
            )
            report["service_log"] = str(started.log_path)
    finally:
        if stream is not None:
            stream.close()
        if started is not None:
            started.kill()
            if not cfg.keep_dir:
                shutil.rmtree(started.dir, ignore_errors=True)
                report["service_dir_removed"] = True
        client.close()
    _verdict(report, cfg)
    return report


def _drive(cfg, client, url, headers, driver, stream, pid, log, report) -> dict:
    import httpx

    duration = cfg.minutes * 60.0
    warmup = warmup_s(duration)
    put_url = f"{url}/v1/bearings/{cfg.bearing_id}/setpoint"
    counts: collections.Counter = collections.Counter()
    status_counts: collections.Counter = collections.Counter()
    unexpected: list[str] = []
    expectations: collections.deque = collections.deque()
    report["_expect"] = expectations
    samples: list[dict] = []
    rss: list[tuple[float, int]] = []
    rss_source = None
    stop = threading.Event()
    t0 = time.monotonic()

    def sample() -> None:
        nonlocal rss_source
        while not stop.is_set():
            now = time.monotonic() - t0
            try:
                h = client.get(f"{url}/health", headers=headers, timeout=10.0).json()
                tw = next((t for t in h["twins"] if t["id"] == cfg.bearing_id), None)
                samples.append(
                    {
                        "t": now,
                        "twin": tw,
                        "recording_rows": h.get("recording_rows", 0),
                        "rss_bytes": h.get("rss_bytes"),
                    }
                )
            except Exception as exc:  # noqa: BLE001
                counts["health_errors"] += 1
                unexpected.append(f"/health: {type(exc).__name__}: {exc}")
                h = {}
            value, source = _rss_bytes(pid) if pid is not None else (h.get("rss_bytes"), "health")
            if value is not None:
                rss.append((now, value))
                rss_source = source
            stop.wait(cfg.sample_s)

    sampler = threading.Thread(target=sample, name="soak-sampler", daemon=True)
    sampler.start()
    period = 1.0 / cfg.rate_hz
    tick = 0
    next_t = time.monotonic()
    last_progress = time.monotonic()
    try:
        while time.monotonic() - t0 < duration:
            tick += 1
            valid = driver.rng.random() >= cfg.invalid_fraction
            over_zenoh = stream is not None and tick % 2 == 0
            if over_zenoh:
                stream.put(driver.zenoh_payload(valid))
                expectations.append(valid)
                counts["zenoh_valid" if valid else "zenoh_invalid"] += 1
            else:
                if valid:
                    body, extra = json.dumps(driver.valid()).encode(), {}
                else:
                    body, extra = driver.invalid_http()
                hdrs = {**headers, "content-type": "application/json"}
                for k, v in extra.items():
                    if v is None:
                        hdrs.pop(k, None)
                    else:
                        hdrs[k] = v
                counts["http_valid" if valid else "http_invalid"] += 1
                try:
                    r = client.put(put_url, content=body, headers=hdrs)
                    status_counts[r.status_code] += 1
                    if r.status_code >= 500:
                        counts["server_errors"] += 1
                        unexpected.append(f"PUT: {r.status_code} {r.text[:200]}")
                    elif r.status_code == 429:
                        counts["rate_limited"] += 1
                    elif valid and r.status_code != 200:
                        unexpected.append(f"valid PUT {body[:100]!r}: {r.status_code} {r.text[:200]}")
                    elif not valid and r.status_code not in _INVALID_EXPECTED:
                        unexpected.append(f"invalid PUT {body[:100]!r}: {r.status_code} {r.text[:200]}")
                except httpx.HTTPError as exc:
                    counts["transport_errors"] += 1
                    unexpected.append(f"PUT: {type(exc).__name__}: {exc}")
            if tick % 4 == 0:
                try:
                    r = client.get(f"{url}/v1/bearings/{cfg.bearing_id}/state", headers=headers)
                    counts["state_reads"] += 1
                    status_counts[r.status_code] += 1
                    if r.status_code != 200:
                        unexpected.append(f"GET state: {r.status_code} {r.text[:200]}")
                    else:
                        try:
                            strict_json(r.content)
                        except ValueError as exc:
                            counts["non_finite_states"] += 1
                            unexpected.append(f"GET state: {exc}")
                except httpx.HTTPError as exc:
                    counts["transport_errors"] += 1
                    unexpected.append(f"GET state: {type(exc).__name__}: {exc}")
            if stream is not None and len(expectations) > 200:
                _pair_results(report, stream)
            if time.monotonic() - last_progress >= 30.0:
                last_progress = time.monotonic()
                log(
                    f"soak: {time.monotonic() - t0:.0f} / {duration:.0f} s, {sum(status_counts.values())} "
                    f"HTTP answers, {len(unexpected)} unexpected"
                )
            next_t += period
            delay = next_t - time.monotonic()
            if delay > 0:
                time.sleep(delay)
            else:
                next_t = time.monotonic()
    finally:
        elapsed = time.monotonic() - t0
        stop.set()
        sampler.join(30.0)

    out: dict[str, Any] = {"duration_s": round(elapsed, 2), "warmup_s": warmup}
    out["setpoints"] = {
        k: counts[k] for k in ("http_valid", "http_invalid", "zenoh_valid", "zenoh_invalid", "rate_limited")
    }
    out["http"] = {
        "status_counts": {str(k): v for k, v in sorted(status_counts.items())},
        "server_errors": counts["server_errors"],
        "transport_errors": counts["transport_errors"],
        "state_reads": counts["state_reads"],
        "non_finite_states": counts["non_finite_states"],
        "health_errors": counts["health_errors"],
    }
    out["unexpected"] = unexpected[:50]
    out["unexpected_count"] = len(unexpected)
    out["memory"] = _memory(rss, warmup, rss_source)
    twins = [s for s in samples if s["twin"] is not None]
    after = [s for s in twins if s["t"] >= warmup] or twins
    rtf = [s["twin"]["real_time_factor"] for s in after if s["twin"].get("real_time_factor") is not None]
    out["real_time_factor"] = {
        "median": round(statistics.median(rtf), 4) if rtf else None,
        "min": round(min(rtf), 4) if rtf else None,
        "samples": len(rtf),
    }
    if twins:
        first, last = twins[0]["twin"], twins[-1]["twin"]
        frames = last["frames"] - first["frames"]
        overruns = last["overruns"] - first["overruns"]
        out["runner"] = {
            "frames": frames,
            "overruns": overruns,
            "overrun_fraction": round(overruns / frames, 4) if frames else None,
            "resyncs": last["resyncs"] - first["resyncs"],
            "errors": last["errors"] - first["errors"],
            "restarts": last["restarts"] - first["restarts"],
            "fallbacks": last.get("fallbacks", 0) - first.get("fallbacks", 0),
            "sink_dropped": last["dropped"] - first["dropped"],
            "setpoints_accepted": last["setpoints_accepted"] - first["setpoints_accepted"],
            "status": last["status"],
        }
        out["recording_rows_reported"] = twins[-1]["recording_rows"]
    else:
        out["runner"] = None
    return out


def _pair_results(report: dict, stream: _Stream) -> None:
    """Pair zenoh results with what was sent, in order."""
    expectations: collections.deque = report["_expect"]
    z = report.setdefault(
        "zenoh_results", {"received": 0, "accepted": 0, "refused": {}, "unexpected": 0, "missing": 0, "examples": []}
    )
    for msg in stream.take_results():
        z["received"] += 1
        valid = expectations.popleft() if expectations else None
        accepted = msg.get("accepted")
        if accepted is True:
            z["accepted"] += 1
        else:
            key = str(msg.get("status", "?"))
            z["refused"][key] = z["refused"].get(key, 0) + 1
        # 429: rate limit; 403: the service has an HTTP token and no zenoh access control
        bad = (
            valid is None
            or accepted is None
            or (valid and accepted is not True and msg.get("status") not in (429, 403))
            or (not valid and accepted is True)
        )
        if bad:
            z["unexpected"] += 1
            if len(z["examples"]) < 10:
                z["examples"].append({"sent_valid": valid, "result": {k: v for k, v in msg.items() if k != "detail"}})
    z["missing"] = len(expectations)


#: memory growth is judged only over at least this much wall time after the warm-up [s]: in a
#: shorter window one-off steps of settling (a code path compiled or loaded on first use, rerun
#: and zenoh buffers reaching their size: +18 and +28 MB steps were seen 8 and 28 s into a run,
#: flat afterwards) cannot be told from a leak
MIN_JUDGED_WINDOW_S = 60.0


def warmup_s(duration_s: float) -> float:
    """The warm-up before the memory baseline: a quarter of the run, 10-60 s."""
    return min(60.0, max(10.0, 0.25 * duration_s))


def _memory(rss: list[tuple[float, int]], warmup: float, source: str | None) -> dict:
    if not rss:
        return {
            "source": source,
            "samples": 0,
            "baseline_mb": None,
            "final_mb": None,
            "max_mb": None,
            "growth_pct": None,
            "judged": False,
        }
    base = next((v for t, v in rss if t >= warmup), rss[0][1])
    window = rss[-1][0] - warmup
    tail = [v for _, v in rss[-3:]]
    final = statistics.median(tail)
    return {
        "source": source,
        "samples": len(rss),
        "baseline_mb": round(base / 2**20, 2),
        "final_mb": round(final / 2**20, 2),
        "max_mb": round(max(v for _, v in rss) / 2**20, 2),
        "series_mb": [[round(t, 1), round(v / 2**20, 2)] for t, v in rss],
        "window_s": round(max(window, 0.0), 1),
        "judged": window >= MIN_JUDGED_WINDOW_S,
        "growth_pct": round((final - base) / base * 100.0, 3) if base else None,
    }


def _check_recording(
    path: Path, bearing_id: str, rows_reported: int, last_stream_seq: int | None, snapshots_per_row: int | None = None
) -> dict:
    """Read every segment of the recording `path` once (see the module doc). `snapshots_per_row`:
    snapshots a trend row stands for (None: the service's, `RerunRecorder.SERVICE_OPTIONS`)."""
    out: dict[str, Any] = {
        "path": str(path),
        "rows_reported": rows_reported,
        "rows_read": None,
        "seq_gaps": None,
        "duplicates": None,
        "segments": 0,
        "segment_files": [],
        "complete": False,
        "error": None,
    }
    try:
        import numpy as np

        from service.recording import recording_segments
        from service.recording.reader import open_reader as _reader

        entity = f"/bearing/{bearing_id}/friction_torque_n_m"
        static = f"/bearing/{bearing_id}/geometry/inner_raceway"
        segments = recording_segments(path)
        if not segments:
            raise FileNotFoundError(f"{path}: no recording")
        seqs: list = []
        recording_ids = set()
        segments_ok = True
        for seg in segments:
            reader = _reader(seg)
            recordings = reader.recordings()
            info = {
                "file": seg.name,
                "bytes": seg.stat().st_size,
                "rows": 0,
                "blueprints": len(reader.blueprints()),
                "static_geometry": False,
                "recording_id": recordings[0].recording_id if recordings else None,
            }
            if recordings:
                recording_ids.add(info["recording_id"])
                for chunk in reader.stream(store=recordings[0]):
                    if chunk.entity_path == static and chunk.is_static:
                        info["static_geometry"] = True
                    elif chunk.entity_path == entity and not chunk.is_static:
                        info["rows"] += chunk.num_rows
                        batch = chunk.to_record_batch()
                        seqs.extend(batch.column(batch.schema.get_field_index("seq")).to_pylist())
            segments_ok &= bool(recordings and info["blueprints"] and info["static_geometry"])
            out["segment_files"].append(info)
        out["segments"] = len(segments)
        out["recording_ids"] = len(recording_ids)
        s = np.sort(np.array(seqs, dtype=np.int64))
        out["rows_read"] = len(s)
        d = s[1:] - s[:-1] if len(s) > 1 else np.zeros(0, dtype=np.int64)
        # the trends are window means: a row per window of `per_window` snapshots, carrying the
        # seq of the window's last snapshot (RerunRecorder.SERVICE_OPTIONS)
        per_window = snapshots_per_row or snapshots_per_trend_window(
            ServiceSettings().runner.publish_rate_hz, float(RerunRecorder.SERVICE_OPTIONS["trend_window_s"])
        )
        gaps = window_seq_gaps(s, per_window)
        out["snapshots_per_row"] = per_window
        out["seq_gaps"] = gaps
        out["duplicates"] = int((d == 0).sum())
        out["first_seq"] = int(s[0]) if len(s) else None
        out["last_seq"] = int(s[-1]) if len(s) else None
        out["complete"] = bool(
            segments_ok
            and len(recording_ids) == 1
            and len(s) * per_window >= max(rows_reported - per_window, 1)
            and gaps == 0
            and out["duplicates"] == 0
            and (last_stream_seq is None or (len(s) and int(s[-1]) >= last_stream_seq))
        )
    except Exception as exc:  # noqa: BLE001
        out["error"] = f"{type(exc).__name__}: {exc}"
    return out


def _verdict(report: dict, cfg: SoakConfig) -> None:
    report.pop("_expect", None)
    failures = []
    if report.get("unexpected_count"):
        failures.append(f"{report['unexpected_count']} unexpected HTTP answers")
    z = report.get("zenoh_results")
    if z and (z["unexpected"] or z["missing"]):
        failures.append(f"zenoh results: {z['unexpected']} unexpected, {z['missing']} missing")
    s = report.get("stream")
    if s is not None:
        if s["seq_gaps"] or s["out_of_order"] or s["non_finite"]:
            failures.append(
                f"state stream: {s['seq_gaps']} seq gaps ({s['dropped_messages']} messages), "
                f"{s['out_of_order']} out of order, {s['non_finite']} non-finite"
            )
        if not s["messages"]:
            failures.append("no state message received over zenoh")
    runner = report.get("runner") or {}
    if runner.get("errors"):
        failures.append(f"{runner['errors']} runner errors")
    memory = report.get("memory") or {}
    growth = memory.get("growth_pct")
    if growth is not None and memory.get("judged") and growth >= cfg.max_memory_growth_pct:
        failures.append(f"memory grew {growth:.2f} % (limit {cfg.max_memory_growth_pct:g} %)")
    if cfg.start:
        sd = report.get("shutdown") or {}
        if not _clean_shutdown(sd):
            failures.append(f"service did not stop cleanly on SIGTERM: {_shutdown_text(sd)}")
        rec = report.get("recording") or {}
        if cfg.record and not rec.get("complete"):
            failures.append(f"recording incomplete: {rec}")
    report["failures"] = failures
    report["ok"] = not failures


def _clean_shutdown(sd: dict) -> bool:
    """A clean stop on SIGTERM: not killed, and the exit status is 0 or the re-raised SIGTERM
    (uvicorn re-raises the signal once its graceful shutdown - runners stopped, zenoh closed,
    recording flushed - is complete, so the process ends as "terminated by SIGTERM", -15)."""
    return not sd.get("killed") and sd.get("exit_code") in (0, -signal.SIGTERM)


def _shutdown_text(sd: dict) -> str:
    if sd.get("killed"):
        return f"did not stop within the bound: killed after {sd['seconds']} s"
    if _clean_shutdown(sd):
        return f"clean shutdown in {sd['seconds']} s"
    return f"stopped with exit status {sd['exit_code']} after {sd['seconds']} s (not a clean shutdown)"


def format_report(r: dict) -> str:
    """Human-readable summary."""
    f = lambda v, spec="{:.3f}": "-" if v is None else spec.format(v)  # noqa: E731
    lines = [
        f"soak: {r['duration_s']:.0f} s against {r.get('url')} (zenoh {r.get('zenoh') or 'off'}), "
        f"{'own service' if r['started_service'] else 'external service'}, token {r.get('token') or 'none'}"
    ]
    sp = r["setpoints"]
    lines.append(
        f"  setpoints: HTTP {sp['http_valid']} valid + {sp['http_invalid']} invalid, zenoh "
        f"{sp['zenoh_valid']} valid + {sp['zenoh_invalid']} invalid; rate-limited {sp['rate_limited']}"
    )
    h = r["http"]
    lines.append(
        f"  HTTP answers {h['status_counts']}; 5xx {h['server_errors']}, transport errors "
        f"{h['transport_errors']}, state reads {h['state_reads']} (non-finite {h['non_finite_states']})"
    )
    z = r.get("zenoh_results")
    if z:
        lines.append(
            f"  zenoh results: {z['received']} ({z['accepted']} accepted, refused {z['refused']}), "
            f"unexpected {z['unexpected']}, missing {z['missing']}; access {r.get('zenoh_access')}"
        )
        if z["refused"].get("403"):
            lines.append(
                "  note: zenoh setpoints refused with 403: the service needs an HTTP token and has "
                'no zenoh access control (docs/operations.md "zenoh access control")'
            )
    s = r.get("stream")
    if s:
        lines.append(
            f"  state stream: {s['messages']} messages ({s['rate_hz']:.1f}/s), seq gaps {s['seq_gaps']} "
            f"({s['dropped_messages']} dropped), out of order {s['out_of_order']}, non-finite {s['non_finite']}"
        )
    m = r["memory"]
    lines.append(
        f"  memory ({m['source']}): {f(m['baseline_mb'], '{:.1f}')} -> {f(m['final_mb'], '{:.1f}')} MB "
        f"(max {f(m['max_mb'], '{:.1f}')}), growth {f(m['growth_pct'], '{:.2f}')} % after {r['warmup_s']:.0f} s warm-up"
        + (
            ""
            if m.get("judged")
            else f" (not judged: {m.get('window_s', 0):.0f} s measured, a leak needs "
            f"{MIN_JUDGED_WINDOW_S:.0f} s to tell from settling)"
        )
    )
    rtf = r["real_time_factor"]
    lines.append(f"  real-time factor: median {f(rtf['median'])}, min {f(rtf['min'])}")
    ru = r.get("runner")
    if ru:
        lines.append(
            f"  runner: {ru['frames']} frames, overruns {ru['overruns']} ({f(ru['overrun_fraction'], '{:.1%}')}), "
            f"resyncs {ru['resyncs']}, errors {ru['errors']}, restarts {ru['restarts']}, fallbacks "
            f"{ru['fallbacks']}, sink drops {ru['sink_dropped']}"
        )
    if r.get("shutdown"):
        sd = r["shutdown"]
        lines.append(f"  SIGTERM: {_shutdown_text(sd)}")
    if r.get("recording"):
        rec = r["recording"]
        mb = sum(f["bytes"] for f in rec.get("segment_files", [])) / 1e6
        lines.append(
            f"  recording {rec['path']}: {rec.get('segments', 1)} segment(s), {mb:.1f} MB, "
            f"{rec['rows_read']} rows read back, {rec['rows_reported']} "
            f"reported, seq gaps {rec['seq_gaps']}, duplicates {rec.get('duplicates')}, complete {rec['complete']}"
            + (f", error {rec['error']}" if rec.get("error") else "")
        )
    for u in r.get("unexpected", [])[:10]:
        lines.append(f"  unexpected: {u}")
    lines.append("  OK" if r["ok"] else "  FAILED: " + "; ".join(r["failures"]))
    return "\n".join(lines)


def add_soak_command(sub) -> None:
    p = sub.add_parser(
        "soak",
        help="long run: random valid and invalid setpoints over HTTP and zenoh; "
        "memory growth, seq gaps, real-time factor, overruns, errors, recording check",
        description=__doc__.split("\n\n")[0],
    )
    p.add_argument(
        "--minutes", type=float, required=True, help="wall-clock length of the run [min] (bounded: <= 10080)"
    )
    add_target_arguments(
        p,
        url_help="service URL (ignored with --start)",
        zenoh_help="zenoh endpoint of the service, e.g. tcp/127.0.0.1:7447 (default: no zenoh unless --start)",
        start_help="launch an own `bearing-twin serve` on free loopback ports, recording into a temp dir; stop "
        "it with SIGTERM at the end and read the recording back",
        twin_help="twin to drive (default `default`)",
    )
    p.add_argument(
        "--rate", type=float, default=10.0, help="setpoints per second, HTTP and zenoh together (default 10)"
    )
    p.add_argument("--invalid", type=float, default=0.3, help="share of invalid setpoints (default 0.3)")
    p.add_argument("--sample", type=float, default=2.0, help="health / memory sampling period [s] (default 2)")
    p.add_argument("--max-memory-growth", type=float, default=5.0, help="memory growth limit for `ok` [%%] (default 5)")
    p.add_argument("--seed", type=int, help="random seed")
    p.add_argument("--keep", action="store_true", help="with --start: keep the temp dir (recording, service log)")
    p.add_argument(
        "--no-record",
        action="store_true",
        help="with --start: run the service without its recording "
        "(to tell the service's own memory from the rerun SDK's)",
    )
    p.add_argument(
        "--record-segment-s",
        type=float,
        metavar="SECONDS",
        help="with --start: the service's recording rotation period [s] (BEARING_TWIN_RECORD_SEGMENT_S; "
        "default: the service's, 600 s)",
    )
    p.add_argument("--json", action="store_true", help="print the report as JSON")
    p.set_defaults(func=_cmd_soak)


def _cmd_soak(args) -> int:
    if not (0 < args.minutes <= 7 * 24 * 60):
        print("error: --minutes must be in (0, 10080]", file=sys.stderr)
        return 2
    if args.record_segment_s is not None and not (0.0 <= args.record_segment_s < float("inf")):
        print("error: --record-segment-s is a period in seconds >= 0 (0 = no rotation by age)", file=sys.stderr)
        return 2
    if not (0.0 <= args.invalid <= 1.0):
        print("error: --invalid is a share in [0, 1]", file=sys.stderr)
        return 2
    cfg = SoakConfig(
        minutes=args.minutes,
        **target_arguments(args),
        rate_hz=args.rate,
        invalid_fraction=args.invalid,
        sample_s=args.sample,
        max_memory_growth_pct=args.max_memory_growth,
        keep_dir=args.keep,
        record=not args.no_record,
        record_segment_s=args.record_segment_s,
        log=lambda line: print(line, file=sys.stderr, flush=True),
    )
    try:
        report = run_soak(cfg)
    except (RuntimeError, ValueError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    print(json.dumps(report, indent=2) if args.json else format_report(report), flush=True)
    return 0 if report["ok"] else 1
