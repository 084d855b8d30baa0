"""A measured temperature reaches the twin's thermal network the same way over HTTP and zenoh,
against a REAL service (uvicorn + zenoh on 127.0.0.1 free ports, multicast scouting off).

`PUT /v1/bearings/{id}/temperature` and zenoh `bearing/{id}/temperature` take one vocabulary
(service.core.measured_temperature.MeasuredTemperature: node outer_ring / housing / oil,
temperature_c in [-60, 400] degC, strict JSON types). Over zenoh each payload is answered on
`bearing/{id}/temperature/result`: accepted with the node and the value, or refused naming the
field and its allowed range. An accepted measurement appears in the snapshot's thermal block
(`measured_node`, `measured_c`). Every wait is bounded; no wall-clock threshold."""

from __future__ import annotations

import json

import httpx
import pytest

pytest.importorskip("zenoh")

from service.settings import ServiceSettings


@pytest.fixture(scope="module")
def service(support):
    endpoint = support.free_endpoint()
    settings = ServiceSettings(enable_recording=False, zenoh_listen=[endpoint], publish_rate_hz=25.0)
    with (
        support.ThreadServer(settings, start_timeout_s=120.0) as srv,
        httpx.Client(base_url=srv.url, timeout=60.0) as http,
    ):
        yield srv, http, endpoint


def _result(peer, support, payload) -> dict:
    peer.drain()
    key = "bearing/default/temperature/result"
    sample = peer.wait_for(
        lambda s: s.key == key,
        poke=lambda: peer.session.put("bearing/default/temperature", payload),
        poke_every_s=5.0,
    )
    return support.strict_loads(sample.payload)


def test_zenoh_temperature_is_taken_and_shown_in_the_thermal_block(service, support):
    _srv, http, endpoint = service
    peer = support.Peer(endpoint)
    try:
        peer.subscribe("bearing/*/temperature/result")
        result = _result(peer, support, json.dumps({"node": "outer_ring", "temperature_c": 47.5}))
        assert result == {"accepted": True, "node": "outer_ring", "temperature_c": 47.5, "bearing_id": "default"}
        thermal = support.wait_for(
            lambda: http.get("/v1/bearings/default/state").json()["thermal"],
            lambda t: t["measured_c"] == 47.5,
            60.0,
        )
        assert thermal["measured_node"] == "outer_ring"
        # the node defaults to the outer ring, as over HTTP
        assert _result(peer, support, json.dumps({"temperature_c": 48.0}))["node"] == "outer_ring"
    finally:
        peer.close()


@pytest.mark.parametrize(
    "payload, field, allowed",
    [
        ({"node": "outer_ring", "temperature_c": 900.0}, "temperature_c", [-60.0, 400.0]),
        ({"node": "oil", "temperature_c": -300.0}, "temperature_c", [-60.0, 400.0]),
        ({"node": "outer_ring", "temperature_c": "62"}, "temperature_c", None),  # strict: no coercion
        ({"node": "cage", "temperature_c": 40.0}, "node", None),
        ({"temperature_c": 40.0, "unit": "F"}, "unit", None),
        ({"temperature_c": 40.0, "token": "x"}, "token", None),
        ([40.0], None, ["node", "temperature_c"]),
    ],
)
def test_zenoh_temperature_refusals_name_the_field(service, support, payload, field, allowed):
    _srv, _http, endpoint = service
    peer = support.Peer(endpoint)
    try:
        peer.subscribe("bearing/*/temperature/result")
        result = _result(peer, support, json.dumps(payload))
        assert result["accepted"] is False and result["status"] == 422, result
        (err,) = result["detail"]
        assert err["field"] == field, err
        if allowed is not None:
            assert err["allowed"] == allowed, err
    finally:
        peer.close()


def test_zenoh_temperature_that_is_not_json_is_refused(service, support):
    _srv, _http, endpoint = service
    peer = support.Peer(endpoint)
    try:
        peer.subscribe("bearing/*/temperature/result")
        result = _result(peer, support, b"\xff not json")
        assert result["accepted"] is False and result["status"] == 422
        assert "not valid JSON" in result["error"]
    finally:
        peer.close()


def test_the_vocabulary_names_the_nodes_of_the_thermal_network():
    """The nodes a measurement may name are the thermal network's measurable ones
    (twin.thermal.coupling.MEASURABLE_NODES), in one list for HTTP, zenoh, OPC UA and scenarios."""
    from service.core.measured_temperature import MEASURABLE_NODES
    from twin.thermal.coupling import MEASURABLE_NODES as NETWORK_NODES

    assert MEASURABLE_NODES == NETWORK_NODES
