"""The tarpit and the cheapest refusals (load cannot steal real time), with a real
uvicorn on 127.0.0.1 (service.api.middleware `Tarpit`, `TokenGate`):

* a client over its error budget (client_error_burst refusals, then client_error_rate_hz) gets
  each further refusal at least tarpit_delay_s after it was decided, with Retry-After;
* /health is never held nor counted, even from that client's address while its refusals are
  held; another client address within its own budget is never held (the tarpit's counters);
* at most tarpit_max_held refusals are held at once, the rest are answered at once (counted);
* a write without the token is refused 401 before routing, the body cap or validation;
* the settings are validated (field named, allowed range).

Clients come from different loopback addresses (127.0.0.x: the whole of 127/8 is the loopback
interface on Linux), each with its own budget. Only lower bounds of the hold are asserted
(they are the configured delay), never an upper wall-clock bound: whether a request was held
is read from the tarpit's counters in /health."""

from __future__ import annotations

import json
import math
import threading
import time

import httpx
import pytest
from pydantic import ValidationError

from service.settings import HttpSettings, SecuritySettings, ServiceSettings

TOKEN = "tarpit-test-token-0123456789"
DELAY_S = 1.0  # tarpit_delay_s
BURST = 3  # client_error_burst
RATE_HZ = 0.05  # client_error_rate_hz: one refusal refilled every 20 s (none within a test)
MAX_HELD = 2  # tarpit_max_held


@pytest.fixture(scope="module")
def served(hostile):
    settings = ServiceSettings(
        enable_zenoh=False,
        enable_recording=False,
        scenario_dir=hostile.SCENARIOS,
        token=TOKEN,
        tarpit_delay_s=DELAY_S,
        client_error_rate_hz=RATE_HZ,
        client_error_burst=BURST,
        tarpit_max_held=MAX_HELD,
    )
    with hostile.ThreadServer(settings) as srv:
        yield srv


def _client(srv, source: str, timeout: float = 60.0) -> httpx.Client:
    """A client whose connections come from the loopback address `source`."""
    return httpx.Client(base_url=srv.url, timeout=timeout, transport=httpx.HTTPTransport(local_address=source))


def _tarpit(client: httpx.Client) -> dict:
    r = client.get("/health")
    assert r.status_code == 200
    return r.json()["http_tarpit"]


def _unauthorized_put(client: httpx.Client) -> httpx.Response:
    return client.put("/v1/bearings/default/setpoint", json={"oil_temperature_c": 40.0})


def test_a_client_over_its_error_budget_gets_its_refusals_after_the_delay(served):
    with _client(served, "127.0.0.11") as bad:
        before = _tarpit(bad)
        assert before["active"] and before["delay_s"] == DELAY_S and before["max_held"] == MAX_HELD
        for _ in range(BURST):  # within the budget: not held
            assert _unauthorized_put(bad).status_code == 401
        assert _tarpit(bad)["held"] == before["held"]
        for _ in range(2):  # over it: each refusal held
            t0 = time.monotonic()
            r = _unauthorized_put(bad)
            waited = time.monotonic() - t0
            assert r.status_code == 401 and r.headers["www-authenticate"].startswith("Bearer")
            assert waited >= DELAY_S
            assert int(r.headers["retry-after"]) >= math.ceil(DELAY_S)
            assert r.json()["detail"][0]["field"] == "Authorization"
        after = _tarpit(bad)
        assert after["held"] == before["held"] + 2 and after["held_now"] == 0
        assert after["errors_over_budget"] >= before["errors_over_budget"] + 2
        # any refusal counts, not only 401: an invalid setpoint with the token is held too
        t0 = time.monotonic()
        r = bad.put(
            "/v1/bearings/default/setpoint",
            json={"oil_temperature_c": "hot"},
            headers={"Authorization": f"Bearer {TOKEN}"},
        )
        assert r.status_code == 422 and time.monotonic() - t0 >= DELAY_S
        # what succeeds is never held: a valid setpoint and a read, from the same address
        held = _tarpit(bad)["held"]
        assert (
            bad.put(
                "/v1/bearings/default/setpoint",
                json={"oil_temperature_c": 41.0},
                headers={"Authorization": f"Bearer {TOKEN}"},
            ).status_code
            == 200
        )
        assert bad.get("/v1/bearings/default/state").status_code == 200
        assert _tarpit(bad)["held"] == held


def test_health_and_a_client_within_its_budget_are_never_held(served):
    with _client(served, "127.0.0.12") as bad, _client(served, "127.0.0.13") as good:
        for _ in range(BURST):
            _unauthorized_put(bad)
        start = _tarpit(good)["held"]
        holding = threading.Thread(target=_unauthorized_put, args=(bad,), daemon=True)
        holding.start()
        deadline = time.monotonic() + 30.0
        while _tarpit(good)["held_now"] < 1:  # the bad client's refusal is being held
            assert time.monotonic() < deadline, "the over-budget refusal was never held"
            time.sleep(0.02)
        # meanwhile /health answers, from the bad client's own address too, and is never counted
        for _ in range(5):
            r = bad.get("/health")
            assert r.status_code == 200 and r.json()["http_tarpit"]["held_now"] >= 0
        for _ in range(BURST + 3):  # 405 on /health: not counted, not held
            assert bad.delete("/health").status_code == 405
        # another address, within its own budget: a refusal and a success, neither held
        assert _unauthorized_put(good).status_code == 401
        assert (
            good.put(
                "/v1/bearings/default/setpoint",
                json={"oil_temperature_c": 42.0},
                headers={"Authorization": f"Bearer {TOKEN}"},
            ).status_code
            == 200
        )
        holding.join(30.0)
        assert not holding.is_alive()
        assert _tarpit(good)["held"] == start + 1  # the bad client's one refusal only


def test_held_refusals_are_bounded(served):
    with _client(served, "127.0.0.14") as bad, _client(served, "127.0.0.15") as probe:
        for _ in range(BURST):
            _unauthorized_put(bad)
        before = _tarpit(probe)
        n = MAX_HELD + 3
        codes: list[int] = []
        peak = [0]
        stop = threading.Event()

        def watch() -> None:
            while not stop.is_set():
                peak[0] = max(peak[0], _tarpit(probe)["held_now"])
                time.sleep(0.01)

        def one() -> None:
            with _client(served, "127.0.0.14") as c:  # a connection each: concurrent
                codes.append(_unauthorized_put(c).status_code)

        watcher = threading.Thread(target=watch, daemon=True)
        watcher.start()
        threads = [threading.Thread(target=one, daemon=True) for _ in range(n)]
        for t in threads:
            t.start()
        for t in threads:
            t.join(60.0)
        stop.set()
        watcher.join(10.0)
        after = _tarpit(probe)
        assert codes == [401] * n  # every refusal answered
        assert peak[0] <= MAX_HELD and after["held_now"] == 0
        held = after["held"] - before["held"]
        at_once = after["answered_at_once"] - before["answered_at_once"]
        assert held + at_once == n and held >= 1


def test_the_tarpit_holds_at_most_max_held_and_answers_the_rest_at_once():
    """The middleware alone, n refusals arriving in one event-loop turn: exactly max_held are held
    (the others answered at once), each held one answered after the delay with Retry-After."""
    import asyncio

    from service.api.middleware import Tarpit
    from service.core.admission import AdmissionGate

    gate = AdmissionGate(error_rate_hz=0.001, error_burst=1)

    async def refuse(scope, receive, send):
        await send({"type": "http.response.start", "status": 429, "headers": [(b"retry-after", b"1")]})
        await send({"type": "http.response.body", "body": b"{}"})

    tarpit = Tarpit(refuse, gate=gate, delay_s=0.2, max_held=3)

    async def main():
        out = []

        async def one(i):
            sent = []

            async def send(message):
                sent.append((asyncio.get_running_loop().time(), message))

            t0 = asyncio.get_running_loop().time()
            await tarpit(
                {"type": "http", "path": "/v1/bearings", "method": "GET", "client": ("10.1.2.3", 5)}, None, send
            )
            out.append((sent[0][0] - t0, dict(sent[0][1]["headers"])))

        await asyncio.gather(*(one(i) for i in range(8)))
        return out

    out = asyncio.run(main())
    s = tarpit.stats
    assert s.held == 3 and s.answered_at_once == 4 and s.held_now == 0  # the first was within the burst
    held = [h for dt, h in out if dt >= 0.2]
    assert len(held) == 3 and all(h[b"retry-after"] == b"1" for h in held)  # ceil(0.2 s) = 1
    assert gate.errors_over_budget == 7


def test_a_write_without_the_token_is_refused_before_routing_and_validation(served):
    with _client(served, "127.0.0.16") as c:
        # an unknown twin, an unknown path, a body above the cap, garbage: 401 all, never 404/413/422
        cases = [
            ("PUT", "/v1/bearings/no-such-twin/setpoint", b'{"oil_temperature_c": 40}'),
            ("POST", "/v1/nothing-here", b"{}"),
            ("PUT", "/v1/bearings/default/setpoint", b'{"x": "' + b"x" * (70 * 1024) + b'"}'),
            ("DELETE", "/v1/bearings/default", None),
            ("PUT", "/v1/bearings/default/setpoint", b"\xff\xfe garbage"),
        ]
        for method, path, body in cases:
            r = c.request(method, path, content=body, headers={"content-type": "application/json"})
            assert r.status_code == 401, (method, path, r.status_code)
            assert json.loads(r.content)["detail"][0]["field"] == "Authorization"
        r = c.put(
            "/v1/bearings/default/setpoint", json={"oil_temperature_c": 40.0}, headers={"Authorization": "Bearer wrong"}
        )
        assert r.status_code == 401 and "invalid token" in r.text
        # with the token, the same unknown twin is a 404 again (routing reached)
        r = c.put(
            "/v1/bearings/no-such-twin/setpoint",
            json={"oil_temperature_c": 40.0},
            headers={"Authorization": f"Bearer {TOKEN}"},
        )
        assert r.status_code == 404


@pytest.mark.parametrize(
    "field, value",
    [
        ("tarpit_delay_s", -0.1),
        ("tarpit_delay_s", 61.0),
        ("client_error_rate_hz", -1.0),
        ("client_error_burst", 0),
        ("tarpit_max_held", 0),
        ("tarpit_max_held", 256),
    ],
)
def test_tarpit_settings_are_validated(field, value):
    with pytest.raises(ValidationError, match=field):
        ServiceSettings(enable_zenoh=False, enable_recording=False, **{field: value})


def test_tarpit_defaults():
    security, http = SecuritySettings(), HttpSettings()  # the groups' defaults, no environment
    assert security.tarpit_delay_s == 2.0 and security.client_error_rate_hz == 5.0
    assert security.client_error_burst == 20 and security.tarpit_max_held == 64
    assert security.tarpit_max_held < http.max_connections


def test_no_error_budget_or_no_delay_means_no_tarpit():
    """client_error_rate_hz 0 (no budget) or tarpit_delay_s 0: nothing is held, /health says inactive."""
    import asyncio

    from service.api.middleware import Tarpit
    from service.core.admission import AdmissionGate

    async def refuse(scope, receive, send):
        await send({"type": "http.response.start", "status": 401, "headers": []})
        await send({"type": "http.response.body", "body": b"{}"})

    for gate, delay in (
        (AdmissionGate(error_rate_hz=None), 5.0),
        (AdmissionGate(error_rate_hz=0.001, error_burst=1), 0.0),
    ):
        tarpit = Tarpit(refuse, gate=gate, delay_s=delay, max_held=3)
        sent = []

        async def send(message, sent=sent):
            sent.append(message)

        async def main(tarpit=tarpit, send=send):
            for _ in range(5):
                await tarpit({"type": "http", "path": "/v1/x", "method": "PUT", "client": ("10.9.9.9", 1)}, None, send)

        asyncio.run(main())
        assert not tarpit.active and tarpit.stats.record()["active"] is False
        assert tarpit.stats.held == 0 and len(sent) == 10
        assert all(
            b"retry-after" not in dict(m.get("headers") or ()) for m in sent if m["type"] == "http.response.start"
        )
