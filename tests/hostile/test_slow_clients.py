"""Reads and slow clients cannot take the service (load cannot steal real time), with
real servers on 127.0.0.1:

* GET state is served from the JSON serialised once per published snapshot (the same bytes for
  every read until the next publication);
* reads are rate-limited per client (429 with Retry-After naming read_rate_hz; /health is not
  counted);
* 50 slowloris connections (headers or a body dripped a byte at a time, or nothing sent) are
  each answered 408 naming `headers` or `body` and closed, while /health keeps answering, and
  the server's connections return to the baseline;
* a token sent in the query string, or in the path, never reaches the access log.
Every wait is a bounded liveness wait; no wall-clock figure is asserted."""

from __future__ import annotations

import json
import select
import signal
import socket
import threading
import time

import httpx
import pytest

from service.core.publishing import Publisher
from service.settings import ServiceSettings
from twin.engine import Twin

HEADER_S, BODY_S = 2.0, 2.0
SLOW = 50


def test_state_json_is_serialised_once_per_snapshot():
    tw = Twin("6208", bearing_id="j1")
    pub = Publisher("j1")
    assert pub.latest_json() is None
    pub.capture(tw, 1.0)  # no worker: built and delivered at once
    first = pub.latest_json()
    got: list[bytes] = []
    threads = [threading.Thread(target=lambda: got.append(pub.latest_json())) for _ in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(10)
    assert all(b is first for b in got)  # one serialisation, shared by every reader
    assert json.loads(first) == pub.latest.to_dict()
    tw.advance(0.001)
    pub.capture(tw, 1.0)
    second = pub.latest_json()
    assert second is not first and json.loads(second)["seq"] == json.loads(first)["seq"] + 1


@pytest.fixture(scope="module")
def guarded(hostile, tmp_path_factory):
    settings = ServiceSettings(
        enable_zenoh=False,
        enable_recording=False,
        scenario_dir=hostile.SCENARIOS,
        http_header_timeout_s=HEADER_S,
        http_body_timeout_s=BODY_S,
        read_rate_hz=5.0,
        read_burst=10,
    )
    with hostile.ThreadServer(settings) as srv, httpx.Client(base_url=srv.url, timeout=30.0) as client:
        yield srv, client


def test_reads_are_rate_limited_per_client(guarded):
    _, client = guarded
    time.sleep(2.5)  # a full bucket (10 reads at 5/s refill)
    t0 = time.monotonic()
    codes, refused = [], None
    bodies = set()
    for i in range(40):  # every API read shares the client's budget
        r = client.get("/v1/bearings/default/state" if i % 2 else "/v1/bearings")
        codes.append(r.status_code)
        if r.status_code == 200 and i % 2:
            bodies.add(json.loads(r.content)["schema"])
        elif r.status_code == 429 and refused is None:
            refused = r
    elapsed = time.monotonic() - t0
    ok = codes.count(200)
    assert set(codes) <= {200, 429} and refused is not None
    assert 10 <= ok <= 10 + 5.0 * elapsed + 1  # the burst, plus what refilled meanwhile
    assert bodies == {"bearing-twin/state/1"}
    assert int(refused.headers["retry-after"]) >= 1
    (err,) = refused.json()["detail"]
    assert "read_rate_hz" in err["message"] and "5 per second per client" in err["message"]
    assert err["allowed"] == [0, 5.0]
    # /health is not counted: the liveness probe answers while the reads are refused
    assert all(client.get("/health").status_code == 200 for _ in range(20))
    assert client.get("/health").json()["reads_rate_limited"] >= codes.count(429)


def _slow_sockets(port: int) -> list[tuple[socket.socket, str, bytes]]:
    """SLOW connections: a third drip their headers, a third drip a declared body, the rest send
    nothing. Each with what it drips and the field its 408 must name."""
    out = []
    for i in range(SLOW):
        s = socket.create_connection(("127.0.0.1", port), timeout=10)
        s.setblocking(False)
        kind = i % 3
        if kind == 0:
            s.sendall(b"GET /health HTTP/1.1\r\nHost: x\r\n")
            out.append((s, "headers", b"X"))
        elif kind == 1:
            s.sendall(
                b"PUT /v1/bearings/default/setpoint HTTP/1.1\r\nHost: x\r\n"
                b"Content-Type: application/json\r\nContent-Length: 4096\r\n\r\n{"
            )
            out.append((s, "body", b" "))
        else:
            out.append((s, "headers", b""))
    return out


def test_slowloris_connections_are_closed_and_health_answers(guarded):
    srv, client = guarded
    state = srv.server.server_state
    baseline = len(state.connections)
    socks = _slow_sockets(int(srv.url.rsplit(":", 1)[1]))
    t0 = time.monotonic()
    # the service answers while the slow connections are open
    peak = len(state.connections)
    for _ in range(5):
        peak = max(peak, len(state.connections))
        assert client.get("/health").status_code == 200
    data = {s: b"" for s, _, _ in socks}
    closed: dict[socket.socket, float] = {}
    deadline = t0 + 60.0  # liveness bound only
    while len(closed) < SLOW and time.monotonic() < deadline:
        open_ = [s for s in data if s not in closed]
        readable, _, _ = select.select(open_, [], [], 0.2)
        for s in readable:
            try:
                chunk = s.recv(65536)
            except ConnectionResetError:
                chunk = b""
            if chunk:
                data[s] += chunk
            else:
                closed[s] = time.monotonic() - t0
        for s, _, drip in socks:  # one more byte to each open one: no deadline moves
            if s not in closed and drip:
                try:
                    s.send(drip)
                except (BlockingIOError, OSError):
                    pass
    assert len(closed) == SLOW, f"{SLOW - len(closed)} slow connections still open after 60 s"
    print(
        f"\n{peak - baseline} slow connections open at once; {SLOW} closed after "
        f"{min(closed.values()):.2f}-{max(closed.values()):.2f} s "
        f"(deadlines: headers {HEADER_S:g} s, body {BODY_S:g} s)"
    )
    for s, field, _ in socks:
        head, _, body = data[s].partition(b"\r\n\r\n")
        assert head.startswith(b"HTTP/1.1 408"), data[s][:200]
        (err,) = json.loads(body)["detail"]
        assert err["field"] == field and err["allowed"] == [0, HEADER_S if field == "headers" else BODY_S]
        s.close()
    deadline = time.monotonic() + 30.0
    while len(state.connections) > baseline + 1 and time.monotonic() < deadline:
        time.sleep(0.05)
    assert len(state.connections) <= baseline + 1  # + the test's own kept-alive client
    h = client.get("/health").json()
    assert h["status"] == "ok" and h["http_slow_closed"] >= SLOW


def test_query_string_tokens_never_reach_the_access_log(hostile, tmp_path):
    token = "s3cr3t-Tok_en"
    srv = hostile.ServeProcess(tmp_path, env={"BEARING_TWIN_TOKEN": token})
    try:
        with httpx.Client(base_url=srv.url, timeout=30.0) as c:
            assert c.get(f"/health?token={token}").status_code == 200
            assert c.get("/v1/bearings/default/state?access_token=abc123xyz&view=full").status_code == 200
            assert c.get(f"/v1/bearings/{token}/state").status_code == 404
            assert c.delete(f"/v1/bearings/x?api_key={token}").status_code == 401
            assert c.get("/health?password=hunter2&Signature=zz9").status_code == 200
        time.sleep(0.5)
    finally:
        srv.signal(signal.SIGINT, 30.0)
    text = srv.text
    assert "GET /health?token=[redacted]" in text, text[-2000:]
    assert "access_token=[redacted]&view=full" in text and "password=[redacted]" in text
    assert "/v1/bearings/[redacted]/state" in text
    for secret in (token, "abc123xyz", "hunter2", "zz9"):
        assert secret not in text
