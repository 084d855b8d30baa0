"""Bearings that are not in the catalog, over HTTP: `POST /v1/bearings` with a whole bearing spec
(`spec`, twin.spec.BearingSpec) and scenarios whose `bearing:` is a spec, against a REAL uvicorn
server on 127.0.0.1 (zenoh and recordings off, admission off; every wait bounded)."""

from __future__ import annotations

import copy

import httpx
import pytest

from service.settings import ServiceSettings
from twin import catalog


@pytest.fixture(scope="module")
def client(support):
    settings = ServiceSettings(
        enable_zenoh=False, enable_recording=False, start_twin=False, admission="off", max_twins=3
    )
    with (
        support.ThreadServer(settings, start_timeout_s=60.0, stop_timeout_s=15.0) as srv,
        httpx.Client(base_url=srv.url, timeout=120.0) as c,
    ):
        yield c


@pytest.fixture(scope="module")
def own_spec() -> dict:
    """A 6205 with 8 balls instead of 9, under a designation of its own: a bearing the catalog
    does not have."""
    spec = catalog.bearing("6205").model_dump(mode="json")
    spec["designation"] = "MY 6205/8"
    spec["geometry"]["ball_count"] = 8
    return spec


def only_error(response) -> dict:
    assert response.status_code == 422, response.text
    (err,) = response.json()["detail"]
    return err


def test_a_twin_from_a_spec_runs_with_its_geometry(client, own_spec, support):
    r = client.post("/v1/bearings", json={"spec": own_spec, "setpoint": {"shaft_speed_rad_s": 200.0}})
    assert r.status_code == 201, r.text
    info = r.json()
    # the default id is the spec's designation, made a valid twin name
    assert info["id"] == "MY-6205-8-1"
    assert info["designation"] == "MY 6205/8" and info["ball_count"] == 8
    state = support.wait_for(
        lambda: client.get(f"/v1/bearings/{info['id']}/state"), lambda s: s.status_code == 200, timeout=30.0
    ).json()
    assert state["designation"] == "MY 6205/8" and len(state["balls"]) == 8
    # an inline scenario naming the same spec runs on it; another spec or a file path does not
    scenario = {
        "name": "own",
        "duration_s": 0.02,
        "bearing": own_spec,
        "steps": [{"at_s": 0.0, "set": {"radial_load_n": 800.0}}],
    }
    r = client.post(f"/v1/bearings/{info['id']}/scenario", json={"scenario": scenario})
    assert r.status_code == 202, r.text
    other = copy.deepcopy(own_spec)
    other["geometry"]["ball_count"] = 7
    err = only_error(
        client.post(f"/v1/bearings/{info['id']}/scenario", json={"scenario": {**scenario, "bearing": other}})
    )
    assert err["field"] == "bearing" and "POST /v1/bearings with 'spec'" in err["message"]
    err = only_error(
        client.post(f"/v1/bearings/{info['id']}/scenario", json={"scenario": {**scenario, "bearing": "own.yaml"}})
    )
    assert err["field"] == "scenario.bearing"
    assert "spec file" in err["message"] and "mapping of BearingSpec fields" in err["message"]
    assert client.delete(f"/v1/bearings/{info['id']}").status_code == 200


def test_an_invalid_spec_is_refused_naming_the_field_and_range(client, own_spec):
    bad = copy.deepcopy(own_spec)
    bad["geometry"]["ball_count"] = 20
    err = only_error(client.post("/v1/bearings", json={"spec": bad}))
    assert err["field"] == "spec.geometry.ball_count"
    assert err["allowed"] == [3, 16] and "allowed range [3, 16]" in err["message"]
    bad = copy.deepcopy(own_spec)
    bad["geometry"]["outer_groove_radius_m"] = 2 * bad["geometry"]["ball_radius_m"]
    err = only_error(client.post("/v1/bearings", json={"spec": bad}))
    assert err["field"] == "spec.geometry" and "outer_groove_radius_m" in err["message"]
    bad = {k: v for k, v in own_spec.items() if k != "geometry"}
    err = only_error(client.post("/v1/bearings", json={"spec": bad}))
    assert err["field"] == "spec.geometry" and "required" in err["message"].lower()


@pytest.mark.parametrize(
    "part, name, value",
    [
        ("mounting", "rotor_mass_kg", True),  # a JSON true is not 1 kg
        ("mounting", "rotor_mass_kg", "2.0"),  # nor is text a number
        ("mounting", "diametral_clearance_m", "1e-5"),
        ("geometry", "ball_count", "8"),
        ("geometry", "ball_count", True),
    ],
)
def test_a_spec_takes_numbers_only_as_json_numbers(client, own_spec, part, name, value):
    """The spec models are strict (twin.spec): a JSON string or true/false where a number goes is
    refused naming the field, never converted."""
    bad = copy.deepcopy(own_spec)
    bad[part][name] = value
    err = only_error(client.post("/v1/bearings", json={"spec": bad}))
    assert err["field"] == f"spec.{part}.{name}", err


@pytest.mark.parametrize(
    "extra, field, inside",
    [
        ({"designation": "6208"}, "designation", "not both"),
        ({"lubricant": "ISO VG 68"}, "lubricant", "spec.lubricant"),
        ({"diametral_clearance_m": 1e-5}, "diametral_clearance_m", "spec.mounting.diametral_clearance_m"),
        ({"thermal": {"shear_heating": True}}, "thermal", "spec.thermal"),
        ({"housing": {"enabled": True}}, "housing", "spec.housing"),
    ],
)
def test_a_spec_beside_a_designation_or_an_override_is_refused(client, own_spec, extra, field, inside):
    err = only_error(client.post("/v1/bearings", json={"spec": own_spec, **extra}))
    assert err["field"] == field and inside in err["message"]


def test_openapi_shows_the_spec_fields_with_units(client):
    schemas = client.get("/openapi.json").json()["components"]["schemas"]
    spec_ref = str(schemas["BearingCreate"]["properties"]["spec"])
    assert "BearingSpec" in spec_ref
    assert set(schemas["BearingSpec"]["properties"]) >= {
        "designation",
        "geometry",
        "material",
        "lubricant",
        "mounting",
        "housing",
        "surface_profile",
    }
    geometry = schemas["Geometry"]["properties"]
    assert "[m]" in geometry["ball_radius_m"]["description"]
    assert "[-]" in geometry["ball_count"]["description"]
    assert (geometry["ball_count"]["minimum"], geometry["ball_count"]["maximum"]) == (3, 16)
    assert "[Pa]" in schemas["Material"]["properties"]["youngs_modulus_pa"]["description"]


def test_the_documented_create_body_creates_its_twin(client):
    """docs/service.md "Bearings not in the catalog": its JSON body is a valid request."""
    import json
    import re
    from pathlib import Path

    text = (Path(__file__).resolve().parents[3] / "docs" / "service.md").read_text()
    body = json.loads(re.search(r'```json\n(\{"id": "test-rig".*?)```', text, re.S).group(1))
    r = client.post("/v1/bearings", json=body)
    assert r.status_code == 201, r.text
    assert (r.json()["designation"], r.json()["ball_count"], r.json()["diametral_clearance_m"]) == ("MY-6205", 8, 1e-5)
    assert client.delete("/v1/bearings/test-rig").status_code == 200


def test_a_nested_housing_error_gives_both_sides_of_its_range(client, own_spec):
    bad = copy.deepcopy(own_spec)
    bad["housing"]["accelerometer"]["sample_rate_hz"] = -1.0
    err = only_error(client.post("/v1/bearings", json={"spec": bad}))
    assert err["field"] == "spec.housing.accelerometer.sample_rate_hz"
    assert None not in err["allowed"] and "allowed range" in err["message"]


def test_every_spec_field_in_the_openapi_carries_its_unit(client):
    schemas = client.get("/openapi.json").json()["components"]["schemas"]
    missing = [
        f"{name}.{prop}"
        for name in (
            "BearingSpec",
            "Geometry",
            "Material",
            "Surface",
            "Lubricant",
            "Mounting",
            "Lubrication",
            "Electrical",
            "Thermal",
        )
        for prop, p in schemas[name]["properties"].items()
        if "[" not in p.get("description", "")
    ]
    assert not missing, f"fields without a [unit] in their description: {missing}"


def test_an_unknown_field_lists_the_setpoint_fields_only_for_a_setpoint(client):
    """An unknown field in a twin's setpoint body is answered with the setpoint's fields as the
    allowed names; in its other bodies (defects, measured temperature, scenario, recording) with
    none of them (they were offered the setpoint's fields, the wrong list)."""
    r = client.post("/v1/bearings", json={"id": "fields-1", "designation": "6208"})
    assert r.status_code == 201, r.text
    try:
        err = only_error(client.put("/v1/bearings/fields-1/setpoint", json={"radial_load": 1.0}))
        assert err["field"] == "radial_load" and "radial_load_n" in err["allowed"]
        for method, path, body in (
            ("PUT", "defects", {"defects": [], "x": 1}),
            ("PUT", "temperature", {"node": "outer_ring", "temperature_c": 50.0, "x": 1}),
            ("POST", "recording", {"x": 1}),
        ):
            r = client.request(method, f"/v1/bearings/fields-1/{path}", json=body)
            assert r.status_code == 422, (path, r.text)
            (err,) = [e for e in r.json()["detail"] if e["field"] == "x"]
            assert "unknown field" in err["message"], (path, err)
            assert err["allowed"] is None or "radial_load_n" not in err["allowed"], (path, err)
    finally:
        assert client.delete("/v1/bearings/fields-1").status_code == 200


def test_every_answer_says_nosniff(client):
    """An error that quotes the request (here an unknown twin id that looks like HTML) is JSON, and
    every answer, a success or a refusal, carries `X-Content-Type-Options: nosniff`
    (service.api.middleware.NoSniff) so that a browser never renders it as HTML."""
    r = client.get("/v1/bearings/%3Cimg%20src%3Dx%3E")
    assert r.status_code in (404, 422) and r.headers["content-type"].startswith("application/json")
    assert r.headers["x-content-type-options"] == "nosniff"
    assert client.get("/health").headers["x-content-type-options"] == "nosniff"
