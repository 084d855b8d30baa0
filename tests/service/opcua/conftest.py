"""Fixtures shared by the OPC UA tests that run a real service (test_opcua.py, test_opcua_security.py).

Each of those modules defines its own module-scoped `server` fixture (a `support.ThreadServer` whose
settings carry the module's bearer token `TOKEN`); the fixtures here build on it: an HTTP client
with that token and the facade once the default twin is stepping. Every wait is bounded."""

from __future__ import annotations

import httpx
import pytest

WAIT_S = 60.0


@pytest.fixture(scope="module")
def http(server, request):
    """An httpx client of the module's server, authorised with the module's `TOKEN`."""
    headers = {"Authorization": f"Bearer {request.module.TOKEN}"}
    with httpx.Client(base_url=server.url, timeout=30.0, headers=headers) as c:
        yield c


@pytest.fixture(scope="module")
def facade(server, http, support):
    """The running OPC UA facade, once the default twin publishes (its snapshots count up)."""
    facade = server.service.opcua
    assert facade is not None and facade.running
    support.wait_for(lambda: http.get("/v1/bearings/default/state").json()["seq"], lambda s: s >= 3, timeout=WAIT_S)
    return facade
