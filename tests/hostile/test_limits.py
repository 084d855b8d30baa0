"""Rate and size limits: setpoint bursts per twin are rate-limited (429 + Retry-After)
without starving reads; request bodies are capped (413), by Content-Length and while streaming a
chunked body; the zenoh handler applies the same limits."""

from __future__ import annotations

import json
import threading
import time

import httpx
import pytest

from service.core.admission import AdmissionGate, TokenBucket
from service.core.intake import SetpointIntake
from service.core.runner import TwinRunner
from service.settings import ServiceSettings

RATE, BURST, CAP = 5.0, 10, 2048


@pytest.fixture(scope="module")
def limited(hostile, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("limits")
    settings = ServiceSettings(
        enable_zenoh=False,
        enable_recording=False,
        scenario_dir=hostile.SCENARIOS,
        record=tmp / "service.rrd",
        max_twins=3,
        setpoint_rate_hz=RATE,
        setpoint_burst=BURST,
        max_body_bytes=CAP,
    )
    with hostile.ThreadServer(settings) as srv, httpx.Client(base_url=srv.url, timeout=30.0) as client:
        yield client


def _exhaust(client, bearing_id="default"):
    """PUT until a 429 (bounded); returns the 429 response and how many were accepted."""
    accepted = 0
    for _ in range(BURST * 20):
        r = client.put(f"/v1/bearings/{bearing_id}/setpoint", json={"oil_temperature_c": 41.0})
        if r.status_code == 429:
            return r, accepted
        assert r.status_code == 200, r.text
        accepted += 1
    raise AssertionError("no 429 after many setpoints")


def test_setpoint_burst_gets_429_with_retry_after(limited):
    time.sleep(BURST / RATE + 0.2)  # a full bucket, whatever this module's other tests spent
    t0 = time.monotonic()
    r, accepted = _exhaust(limited)
    elapsed = time.monotonic() - t0
    # the bucket lets `burst` through at once plus what refilled meanwhile, never more
    assert BURST <= accepted <= BURST + RATE * elapsed + 1
    retry = int(r.headers["retry-after"])
    assert retry >= 1
    (err,) = r.json()["detail"]
    assert "too many setpoints" in err["message"] and "retry after" in err["message"]
    # invalid setpoints count against the budget as well (a fuzzer cannot flood with them)
    bad = limited.put("/v1/bearings/default/setpoint", json={"radial_load_n": "x"})
    assert bad.status_code == 429
    # the budget refills at the configured rate
    time.sleep(1.5 / RATE)
    assert limited.put("/v1/bearings/default/setpoint", json={"oil_temperature_c": 42.0}).status_code == 200
    health = limited.get("/health").json()
    (tw,) = [t for t in health["twins"] if t["id"] == "default"]
    assert tw["setpoints_rate_limited"] >= 2


def test_reads_keep_answering_during_a_setpoint_burst(limited):
    stop = threading.Event()
    statuses: list[int] = []

    def burst():
        with httpx.Client(base_url=str(limited.base_url), timeout=30.0) as c:
            while not stop.is_set():
                statuses.append(c.put("/v1/bearings/default/setpoint", json={"oil_temperature_c": 43.0}).status_code)

    threads = [threading.Thread(target=burst) for _ in range(4)]
    for t in threads:
        t.start()
    try:
        seqs = []
        for _ in range(40):
            r = limited.get("/v1/bearings/default/state")
            assert r.status_code == 200
            seqs.append(r.json()["seq"])
            assert limited.get("/health").status_code == 200
    finally:
        stop.set()
        for t in threads:
            t.join(30)
    assert statuses.count(429) > 0 and set(statuses) <= {200, 429}
    assert seqs[-1] >= seqs[0]


def test_rate_limit_is_per_twin(limited):
    r = limited.post("/v1/bearings", json={"id": "other", "designation": "6205"})
    assert r.status_code == 201, r.text
    try:
        _exhaust(limited)
        assert limited.put("/v1/bearings/other/setpoint", json={"oil_temperature_c": 45.0}).status_code == 200
    finally:
        assert limited.delete("/v1/bearings/other").status_code == 200
    # an unknown twin is a 404, not a rate-limit answer
    assert limited.put("/v1/bearings/nobody/setpoint", json={}).status_code == 404


@pytest.mark.parametrize(
    "method, path",
    [
        ("PUT", "/v1/bearings/default/setpoint"),
        ("POST", "/v1/bearings"),
        ("POST", "/v1/bearings/default/scenario"),
        ("POST", "/v1/bearings/default/recording"),
    ],
)
def test_body_over_the_cap_is_413(limited, method, path):
    body = b'{"name": "' + b"x" * (CAP + 10) + b'"}'
    r = limited.request(method, path, content=body, headers={"content-type": "application/json"})
    assert r.status_code == 413, r.text
    (err,) = r.json()["detail"]
    assert err["allowed"] == [0, CAP]
    assert limited.get("/health").status_code == 200


def test_chunked_body_is_counted_while_streaming(limited):
    def big():
        for _ in range(10):
            yield b" " * (CAP // 4)

    r = limited.post("/v1/bearings/default/recording", content=big(), headers={"content-type": "application/json"})
    assert r.status_code == 413, r.text

    def small():
        yield b'{"action": '
        yield b'"stop"}'

    r = limited.post("/v1/bearings/default/recording", content=small(), headers={"content-type": "application/json"})
    assert r.status_code == 200, r.text


def test_body_at_the_cap_passes(limited):
    body = json.dumps({"name": "nope"}).encode()
    body = body[:-1] + b" " * (CAP - len(body)) + b"}"
    assert len(body) == CAP
    r = limited.post("/v1/bearings/default/scenario", content=body, headers={"content-type": "application/json"})
    assert r.status_code == 422  # read and validated: an unknown scenario name


@pytest.fixture(scope="module")
def twin():
    from twin.engine import Twin

    tw = Twin("6208")
    tw.advance(0.001)
    return tw


def test_zenoh_handler_rate_and_size(twin):
    gate = AdmissionGate(setpoint_rate_hz=RATE, setpoint_burst=BURST, max_payload_bytes=CAP)
    intake = SetpointIntake(twin.bearing_id, gate, TwinRunner(twin))  # the same gate as HTTP's
    results = [intake(b'{"oil_temperature_c": 44}') for _ in range(BURST + 5)]
    accepted = [r for r in results if r["accepted"]]
    limited = [r for r in results if not r["accepted"]]
    assert BURST <= len(accepted) < BURST + 5
    assert limited and all(r["status"] == 429 and r["retry_after_s"] > 0 for r in limited)
    big = intake(b'{"oil_temperature_c": 44' + b" " * CAP + b"}")
    assert big["accepted"] is False and big["status"] == 413
    assert gate.rate_limited(twin.bearing_id) == len(limited)
    assert intake.refused == len(limited) + 1


def test_token_bucket_refills_on_its_clock():
    now = [0.0]
    bucket = TokenBucket(2.0, 3, clock=lambda: now[0])
    assert [bucket.take()[0] for _ in range(4)] == [True, True, True, False]
    ok, retry = bucket.take()
    assert not ok and retry == pytest.approx(0.5)
    now[0] += 0.5
    assert bucket.take() == (True, 0.0)
    now[0] += 100.0  # never more than the burst
    assert [bucket.take()[0] for _ in range(4)] == [True, True, True, False]
    with pytest.raises(ValueError):
        TokenBucket(0.0, 1)
