"""Twin-id squatting on zenoh against a REAL service (uvicorn + zenoh on 127.0.0.1): with only the
HTTP token set (no zenoh access control), an anonymous zenoh peer declares `bearing/pump-9/alive`
and answers `bearing/pump-9/owner` with forged text. A create of `pump-9` with the valid token is
not blocked (201), and no answer repeats the forged text. Every wait is bounded."""

from __future__ import annotations

import json

import httpx
import pytest

zenoh = pytest.importorskip("zenoh")

from service.bus.zenoh_bus import make_config  # noqa: E402
from service.settings import ServiceSettings  # noqa: E402

TOKEN = "squat-test-token-321"
FORGED = {"key": "bearing/pump-9", "bearing_id": "pump-9", "pid": 1, "host": "evil", "http": "http://evil", "zid": "0"}


def test_an_anonymous_squatter_blocks_no_create(support):
    endpoint = support.free_endpoint()
    settings = ServiceSettings(
        enable_recording=False, token=TOKEN, max_twins=2, zenoh_listen=[endpoint], admission="off"
    )
    assert not settings.zenoh.access_control
    with support.ThreadServer(settings, start_timeout_s=120.0, stop_timeout_s=30.0) as srv:
        evil = zenoh.open(make_config([], [endpoint], "peer"))
        try:
            token = evil.liveliness().declare_token("bearing/pump-9/alive")
            owner = evil.declare_queryable(
                "bearing/pump-9/owner", lambda q: q.reply("bearing/pump-9/owner", json.dumps(FORGED))
            )
            bus = srv.service.bus
            assert support.wait_until(lambda: bus._alive_elsewhere("bearing/pump-9"), 10.0)
            with httpx.Client(base_url=srv.url, timeout=60.0, headers={"Authorization": f"Bearer {TOKEN}"}) as http:
                r = http.post("/v1/bearings", json={"id": "pump-9", "designation": "6208"})
                assert r.status_code == 201, r.text
                assert "evil" not in r.text
                listed = http.get("/v1/bearings")
                assert "pump-9" in [t["id"] for t in listed.json()] and "evil" not in listed.text
            owner.undeclare()
            token.undeclare()
        finally:
            evil.close()
