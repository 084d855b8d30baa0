"""Access: with BEARING_TWIN_TOKEN set, mutating HTTP requests need the bearer token
(401 without it or with a wrong one), reads stay open unless `read_requires_token`; the service
says what it binds and whether a token is needed. The token is HTTP only: zenoh has its own
authentication and access control (tests/hostile/test_zenoh_access.py)."""

from __future__ import annotations

import hmac

import httpx
import pytest

from service.core.admission import bearer_token, token_matches
from service.settings import ServiceSettings

TOKEN = "s3cret-Token_for.tests"
AUTH = {"Authorization": f"Bearer {TOKEN}"}


def _settings(hostile, tmp_path, **kw):
    return ServiceSettings(
        enable_zenoh=False,
        enable_recording=False,
        scenario_dir=hostile.SCENARIOS,
        record=tmp_path / "service.rrd",
        max_twins=3,
        **kw,
    )


@pytest.fixture(scope="module")
def guarded(hostile, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("access")
    with (
        hostile.ThreadServer(_settings(hostile, tmp, token=TOKEN)) as srv,
        httpx.Client(base_url=srv.url, timeout=30.0) as client,
    ):
        yield client


MUTATIONS = [
    ("PUT", "/v1/bearings/default/setpoint", {"radial_load_n": 3100.0}),
    ("POST", "/v1/bearings", {"id": "acc-1", "designation": "6205"}),
    ("POST", "/v1/bearings/default/scenario", {"name": "seed000_load_sweep"}),
    ("POST", "/v1/bearings/default/recording", {"action": "stop"}),
    ("DELETE", "/v1/bearings/default/scenario", None),
    ("DELETE", "/v1/bearings/acc-1", None),
]


@pytest.mark.parametrize(
    "headers",
    [
        {},
        {"Authorization": "Bearer wrong"},
        {"Authorization": f"Basic {TOKEN}"},
        {"Authorization": f"Bearer {TOKEN}x"},
        {"Authorization": "Bearer"},
    ],
    ids=["none", "wrong", "other-scheme", "longer", "empty"],
)
def test_mutations_without_the_token_are_401(guarded, headers):
    before = guarded.get("/v1/bearings/default").json()["setpoint"]
    twins = [b["id"] for b in guarded.get("/v1/bearings").json()]
    for method, path, body in MUTATIONS:
        r = guarded.request(method, path, json=body, headers=headers)
        assert r.status_code == 401, (method, path, r.text)
        assert r.headers["www-authenticate"].startswith("Bearer")
        (err,) = r.json()["detail"]
        assert err["field"] == "Authorization" and "token" in err["message"]
        assert TOKEN not in r.text
    # nothing happened
    assert guarded.get("/v1/bearings/default").json()["setpoint"] == before
    assert [b["id"] for b in guarded.get("/v1/bearings").json()] == twins


def test_mutations_with_the_token_succeed(guarded):
    expected = [200, 201, 202, 200, 200, 200]
    for (method, path, body), status in zip(MUTATIONS, expected, strict=True):
        r = guarded.request(method, path, json=body, headers=AUTH)
        assert r.status_code == status, (method, path, r.text)
        if method == "PUT":
            assert r.json()["setpoint"]["radial_load_n"] == 3100.0
    # the scheme name is case-insensitive (RFC 7235)
    r = guarded.put("/v1/bearings/default/setpoint", json={}, headers={"Authorization": f"bearer {TOKEN}"})
    assert r.status_code == 200


def test_reads_stay_open(guarded):
    for path in (
        "/health",
        "/v1/bearings",
        "/v1/bearings/default",
        "/v1/bearings/default/state",
        "/v1/scenarios",
        "/openapi.json",
    ):
        assert guarded.get(path).status_code == 200, path


def test_openapi_declares_the_bearer_scheme(guarded):
    spec = guarded.get("/openapi.json").json()
    assert spec["components"]["securitySchemes"]["bearerToken"]["scheme"] == "bearer"
    put = spec["paths"]["/v1/bearings/{bearing_id}/setpoint"]["put"]
    assert put["security"] == [{"bearerToken": []}]
    assert {"401", "413", "429"} <= set(put["responses"])
    assert "security" not in spec["paths"]["/v1/bearings/{bearing_id}/state"]["get"]


def test_reads_need_the_token_when_configured(hostile, tmp_path):
    settings = _settings(hostile, tmp_path, token=TOKEN, read_requires_token=True)
    with hostile.ThreadServer(settings) as srv, httpx.Client(base_url=srv.url, timeout=30.0) as c:
        for path in ("/v1/bearings", "/v1/bearings/default/state", "/v1/scenarios", "/openapi.json"):
            assert c.get(path).status_code == 401, path
            assert c.get(path, headers={"Authorization": "Bearer nope"}).status_code == 401, path
            assert c.get(path, headers=AUTH).status_code == 200, path
        assert c.get("/health").status_code == 200  # the liveness probe stays open
        assert c.put("/v1/bearings/default/setpoint", json={}).status_code == 401


def test_no_token_configured_means_open(hostile, tmp_path):
    with hostile.ThreadServer(_settings(hostile, tmp_path)) as srv, httpx.Client(base_url=srv.url, timeout=30.0) as c:
        assert c.put("/v1/bearings/default/setpoint", json={"radial_load_n": 3200.0}).status_code == 200
        assert c.get("/v1/bearings/default/state").status_code == 200


def test_token_comparison_is_constant_time(monkeypatch):
    calls = []
    real = hmac.compare_digest

    def spy(a, b):
        calls.append((a, b))
        return real(a, b)

    monkeypatch.setattr(hmac, "compare_digest", spy)
    assert token_matches(TOKEN, TOKEN) and not token_matches("x", TOKEN) and not token_matches(None, TOKEN)
    assert len(calls) == 2 and all(isinstance(a, bytes) and isinstance(b, bytes) for a, b in calls)
    assert token_matches("anything", None)  # no token configured
    assert bearer_token(b"Bearer  abc ") == b"abc" and bearer_token(b"Basic abc") is None
    assert bearer_token(None) is None and bearer_token(b"Bearer") is None


def test_settings_token_from_environment(monkeypatch):
    monkeypatch.setenv("BEARING_TWIN_TOKEN", TOKEN)
    s = ServiceSettings()
    assert s.security.token_value == TOKEN and TOKEN not in repr(s) and not s.security.read_requires_token
    monkeypatch.setenv("BEARING_TWIN_TOKEN", "")
    assert ServiceSettings().security.token is None
    monkeypatch.setenv("BEARING_TWIN_TOKEN", "has space")
    with pytest.raises(ValueError) as err:
        ServiceSettings()
    assert "has space" not in str(err.value)  # never echoed


# zenoh setpoints carry no token; zenoh's own access control is tested in tests/hostile/test_zenoh_access.py
