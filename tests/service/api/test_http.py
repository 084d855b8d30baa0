"""The HTTP API against a REAL uvicorn server on 127.0.0.1 (free port, background thread), zenoh
and the service-wide recording disabled; every wait is bounded."""

from __future__ import annotations

import functools
import importlib.util
import json
import math
import time
from pathlib import Path

import httpx
import numpy as np
import pytest

from service.recording.layout import SIM_TIME
from service.recording.reader import read_index
from service.settings import ServiceSettings

SCENARIOS = Path(__file__).resolve().parents[3] / "scenarios"
HAVE_RERUN = importlib.util.find_spec("rerun") is not None
WAIT_S = 20.0


@pytest.fixture(scope="module")
def recordings(tmp_path_factory):
    return tmp_path_factory.mktemp("recordings")


@pytest.fixture(scope="module")
def client(recordings, support):
    settings = ServiceSettings(
        enable_zenoh=False,
        enable_recording=False,
        scenario_dir=SCENARIOS,
        record=recordings / "service.rrd",
        max_twins=4,
    )
    with (
        support.ThreadServer(settings, start_timeout_s=60.0, stop_timeout_s=15.0) as srv,
        httpx.Client(base_url=srv.url, timeout=120.0) as c,
    ):
        yield c


@pytest.fixture(scope="module")
def wait_for(support):
    """support.wait_for(fetch, predicate, timeout=WAIT_S): poll until predicate(fetch()), bounded."""
    return functools.partial(support.wait_for, timeout=WAIT_S)


def detail(response) -> list[dict]:
    body = response.json()
    assert set(body) == {"detail"}, body
    assert isinstance(body["detail"], list) and body["detail"], body
    for item in body["detail"]:
        assert set(item) == {"field", "message", "allowed"}, item
    return body["detail"]


def test_health(client):
    h = client.get("/health").json()
    assert h["status"] == "ok"
    assert h["uptime_s"] >= 0.0
    assert h["zenoh"] is False and h["recording"] is None
    (tw,) = [t for t in h["twins"] if t["id"] == "default"]
    for key in (
        "real_time_factor",
        "late_fraction",
        "lateness_s",
        "frame_s",
        "overruns",
        "dropped",
        "frames",
        "published",
        "errors",
        "mode",
        "cost",
    ):
        assert key in tw
    cap = h["capacity"]
    assert cap["admission"] in ("measured", "off") and cap["stepping_threads"] >= 1
    assert cap["budget_cpu_s_per_s"] > 0.0
    assert tw["running"] and tw["mode"] == "real_time"


def test_state_is_the_contract(client, wait_for):
    state = wait_for(lambda: client.get("/v1/bearings/default/state"), lambda r: r.status_code == 200)
    text = state.text
    json.loads(text, parse_constant=lambda c: pytest.fail(f"JSON carries {c}"))
    s = state.json()
    assert s["schema"] == "bearing-twin/state/1" and s["bearing_id"] == "default"
    assert s["designation"] == "6208"
    assert len(s["balls"]) == 9
    ball = s["balls"][0]
    for side in ("inner", "outer"):
        for key in ("load_n", "h_min_m", "lambda", "regime", "mu", "entrainment_speed_m_s"):
            assert key in ball[side]
    later = wait_for(lambda: client.get("/v1/bearings/default/state").json(), lambda x: x["seq"] > s["seq"])
    assert later["time_s"] > s["time_s"]


def test_put_setpoint_shows_up_in_state(client, wait_for):
    r = client.put("/v1/bearings/default/setpoint", json={"radial_load_n": 4200.0})
    assert r.status_code == 200, r.text
    body = r.json()
    assert body["setpoint"]["radial_load_n"] == 4200.0
    assert body["setpoint"]["shaft_speed_rad_s"] == 500.0  # partial: the rest is kept
    wait_for(
        lambda: client.get("/v1/bearings/default/state").json(),
        lambda s: s["setpoint"]["radial_load_n"] == 4200.0,
        timeout=10.0,
    )
    info = client.get("/v1/bearings/default").json()
    assert info["setpoint"]["radial_load_n"] == 4200.0
    assert client.put("/v1/bearings/default/setpoint", json={}).status_code == 200  # empty = no change


def test_setpoint_latency_counts_from_the_requests_arrival(client, wait_for):
    """A setpoint's latency by stage (/health `setpoint_latency_ms`) starts where the server read
    its request: `http` (arrival -> submit) and `admission` (submit -> accepted) come before the
    stages inside the runner, and the `http` stage lies within the client's own round trip (the
    server runs in this process: one clock)."""
    r = client.post("/v1/bearings", json={"id": "latency-6205", "designation": "6205"})
    assert r.status_code == 201, r.text
    try:
        t0 = time.perf_counter()
        assert client.put("/v1/bearings/latency-6205/setpoint", json={"radial_load_n": 1500.0}).status_code == 200
        round_trip_ms = 1e3 * (time.perf_counter() - t0)
        health = wait_for(
            lambda: client.get("/health").json(),
            lambda h: any(t["id"] == "latency-6205" and t["setpoint_latency_ms"] for t in h["twins"]),
        )
        latency = next(t for t in health["twins"] if t["id"] == "latency-6205")["setpoint_latency_ms"]
        assert latency["count"] == 1
        assert set(latency) == {"http", "admission", "apply", "step", "build", "publish", "total", "count"}
        stages = {name: latency[name]["max"] for name in ("http", "admission", "apply", "step", "build", "publish")}
        assert all(v >= 0.0 for v in stages.values()), stages
        assert stages["http"] + stages["admission"] <= round_trip_ms
        assert sum(stages.values()) == pytest.approx(latency["total"]["max"], abs=0.01)  # rounded to 1 us each
    finally:
        client.delete("/v1/bearings/latency-6205")


@pytest.mark.parametrize(
    "body, field, low, high",
    [
        ({"radial_load_n": -1}, "radial_load_n", 0.0, None),
        ({"shaft_speed_rad_s": 1e9}, "shaft_speed_rad_s", 0.0, None),
        ({"shaft_speed_rad_s": 3000.0}, "shaft_speed_rad_s", 0.0, None),  # within the schema, above the 6208's limit
        ({"oil_temperature_c": 200.0}, "oil_temperature_c", -30.0, 150.0),
        ({"axial_load_n": "lots"}, "axial_load_n", None, None),
        ({"radial_load_n": True}, "radial_load_n", 0.0, None),  # a bool is not a load
        ({"radial_load_n": "3000"}, "radial_load_n", 0.0, None),  # nor is a string
    ],
)
def test_invalid_setpoint_names_field_and_range(client, body, field, low, high):
    r = client.put("/v1/bearings/default/setpoint", json=body)
    assert r.status_code == 422, r.text
    (err,) = detail(r)
    assert err["field"] == field
    assert field in err["message"] or "Input should" in err["message"]
    lo, hi = err["allowed"]
    assert math.isfinite(lo) and math.isfinite(hi) and lo < hi
    if low is not None:
        assert lo == low
    if high is not None:
        assert hi == high
    assert f"[{lo:g}, {hi:g}]" in err["message"]


def test_strict_types_and_the_bearings_own_range(client):
    """{"radial_load_n": true} is not 1 N and "3000" is not 3000 N: 422 naming the field; an
    out-of-range value is answered with the 6208's own range, not the vocabulary's static bound."""
    before = client.get("/v1/bearings/default").json()["setpoint"]
    for body in ({"radial_load_n": True}, {"radial_load_n": "3000"}, {"shaft_speed_rad_s": False}):
        r = client.put("/v1/bearings/default/setpoint", json=body)
        assert r.status_code == 422, (body, r.text)
        (err,) = detail(r)
        assert err["field"] == next(iter(body)) and "number" in err["message"]
    assert client.get("/v1/bearings/default").json()["setpoint"] == before  # nothing applied
    r = client.put("/v1/bearings/default/setpoint", json={"shaft_speed_rad_s": 3000.0})
    (err,) = detail(r)
    assert err["allowed"][0] == 0.0 and err["allowed"][1] == pytest.approx(2073.66, abs=0.005)
    assert "outside the allowed range [0, 2073.66] rad/s for bearing 6208" in err["message"]
    # POST /v1/bearings: the initial setpoint of a new twin, with that bearing's range
    r = client.post("/v1/bearings", json={"designation": "6200", "setpoint": {"radial_load_n": True}})
    assert r.status_code == 422 and detail(r)[0]["field"] == "setpoint.radial_load_n"


def test_docs_are_served_without_a_cdn(client):
    page = client.get("/docs")
    assert page.status_code == 200
    assert "cdn." not in page.text and "http://" not in page.text and "https://" not in page.text
    for asset in ("swagger-ui-bundle.js", "swagger-ui.css"):
        assert f"/docs/assets/{asset}" in page.text
        r = client.get(f"/docs/assets/{asset}")
        assert r.status_code == 200 and len(r.content) > 10_000
    spec = client.get("/openapi.json").json()
    assert spec["openapi"].startswith("3.1")
    # POST /v1/bearings documents what it answers (README, HTTP API): 409 duplicate, 503 no capacity
    assert {"201", "409", "422", "503"} <= set(spec["paths"]["/v1/bearings"]["post"]["responses"])


@pytest.mark.parametrize(
    "raw", [b'{"shaft_speed_rad_s": NaN}', b'{"shaft_speed_rad_s": Infinity}', b'{"radial_load_n": -Infinity}']
)
def test_non_finite_values_are_refused_by_field(client, raw):
    r = client.put("/v1/bearings/default/setpoint", content=raw, headers={"content-type": "application/json"})
    assert r.status_code == 422, r.text
    (err,) = detail(r)
    field = raw.split(b'"')[1].decode()
    assert err["field"] == field and "finite" in err["message"]


@pytest.mark.parametrize(
    "raw", [b"{", b"[1, 2]", b'"text"', b"", b'{"radial_load_n": 1, "nonsense": 2}', b"\xff\xfe\x00"]
)
def test_garbage_is_a_clean_4xx_never_a_500(client, raw):
    r = client.put("/v1/bearings/default/setpoint", content=raw, headers={"content-type": "application/json"})
    assert r.status_code in (400, 422), r.text  # 400: bytes that are not even text
    errs = detail(r)
    assert "Traceback" not in r.text
    if b"nonsense" in raw:
        assert errs[0]["field"] == "nonsense"
        assert "radial_load_n" in errs[0]["allowed"]


@pytest.mark.parametrize(
    "body, field, allowed",
    [
        ({"node": "oil", "temperature_c": -300.0}, "temperature_c", [-60.0, 400.0]),
        ({"node": "outer_ring", "temperature_c": 900.0}, "temperature_c", [-60.0, 400.0]),
        ({"node": "cage", "temperature_c": 40.0}, "node", None),
    ],
)
def test_a_measured_temperature_out_of_range_names_both_sides(client, body, field, allowed):
    # MeasuredTemperature declares [-60, 400] degC: the error states the whole range whichever
    # side is crossed (pydantic names only that side), and a node the network has not is named
    r = client.put("/v1/bearings/default/temperature", json=body)
    assert r.status_code == 422, r.text
    (err,) = detail(r)
    assert err["field"] == field and err["allowed"] == allowed, err
    if allowed is not None:
        assert "allowed range [-60, 400] degC" in err["message"], err


def test_a_measured_temperature_in_range_is_taken(client):
    r = client.put("/v1/bearings/default/temperature", json={"node": "outer_ring", "temperature_c": 45.0})
    assert r.status_code == 200, r.text
    assert r.json() == {"bearing_id": "default", "node": "outer_ring", "temperature_c": 45.0}


def test_unknown_twin_is_404(client):
    for method, url, body in (
        ("GET", "/v1/bearings/nope/state", None),
        ("GET", "/v1/bearings/nope", None),
        ("PUT", "/v1/bearings/nope/setpoint", {"radial_load_n": 1.0}),
        ("DELETE", "/v1/bearings/nope", None),
        ("POST", "/v1/bearings/nope/scenario", {"name": "seed000_load_sweep"}),
        ("POST", "/v1/bearings/nope/recording", {"action": "stop"}),
    ):
        r = client.request(method, url, json=body)
        assert r.status_code == 404, (method, url, r.text)
        (err,) = detail(r)
        assert err["field"] == "bearing_id" and "default" in err["allowed"]


def test_create_two_twins_duplicate_and_delete(client, wait_for):
    r = client.post(
        "/v1/bearings",
        json={
            "id": "pump-7208",
            "designation": "7208",
            "diametral_clearance_m": 5e-6,
            "lubricant": "ISO VG 68",
            "setpoint": {"shaft_speed_rad_s": 300.0, "axial_load_n": 1000.0},
        },
    )
    assert r.status_code == 201, r.text
    info = r.json()
    assert info["designation"] == "7208" and info["ball_count"] == 13 and info["lubricant"] == "ISO VG 68"
    assert info["diametral_clearance_m"] == 5e-6 and info["kind"] == "angular_contact"
    assert info["setpoint"]["shaft_speed_rad_s"] == 300.0
    assert info["limits"]["axial_load_n"][0] == 0.0
    try:
        dup = client.post("/v1/bearings", json={"id": "pump-7208"})
        assert dup.status_code == 409
        assert detail(dup)[0]["field"] == "id"
        ids = [b["id"] for b in client.get("/v1/bearings").json()]
        assert "default" in ids and "pump-7208" in ids
        # independent twins
        client.put("/v1/bearings/pump-7208/setpoint", json={"radial_load_n": 1234.0})
        s = wait_for(
            lambda: client.get("/v1/bearings/pump-7208/state").json(),
            lambda s: s["setpoint"]["radial_load_n"] == 1234.0,
        )
        assert s["designation"] == "7208" and len(s["balls"]) == 13
        assert client.get("/v1/bearings/default/state").json()["setpoint"]["radial_load_n"] != 1234.0
        assert {t["id"] for t in client.get("/health").json()["twins"]} >= {"default", "pump-7208"}
        # an auto-named twin
        auto = client.post("/v1/bearings", json={"designation": "6205"})
        assert auto.status_code == 201 and auto.json()["id"] == "6205-1"
        assert client.delete("/v1/bearings/6205-1").status_code == 200
    finally:
        assert client.delete("/v1/bearings/pump-7208").status_code == 200
    assert client.get("/v1/bearings/pump-7208/state").status_code == 404
    assert "pump-7208" not in [b["id"] for b in client.get("/v1/bearings").json()]


@pytest.mark.parametrize(
    "body, field",
    [
        ({"designation": "9999"}, "designation"),
        ({"lubricant": "olive oil"}, "lubricant"),
        ({"diametral_clearance_m": 1.0}, "diametral_clearance_m"),
        ({"id": "a/b"}, "id"),
        ({"setpoint": {"shaft_speed_rad_s": 5000.0}}, "setpoint.shaft_speed_rad_s"),
        ({"setpoint": {"radial_load_n": float("-1")}}, "setpoint.radial_load_n"),
        ({"colour": "red"}, "colour"),
        ({"thermal": {"equivalent_resistance_ohm": -1.0}}, "thermal.equivalent_resistance_ohm"),
        ({"thermal": {"crater_depth_m": 0.0}}, "thermal.crater_depth_m"),
        ({"thermal": {"shear_heating": "maybe"}}, "thermal.shear_heating"),
    ],
)
def test_invalid_creation_is_422(client, body, field):
    r = client.post("/v1/bearings", json=body)
    assert r.status_code == 422, r.text
    assert detail(r)[0]["field"] == field


def test_ev_twin_with_shear_and_current_heating(client, wait_for):
    # seed 003: a 6200 created with shear heating on, driven at 20 000 rpm and 10 A, publishes the
    # inlet heating and a thinner film than the isothermal film (factor < 1)
    r = client.post(
        "/v1/bearings",
        json={
            "id": "ev",
            "designation": "6200",
            "lubricant": "ISO VG 32",
            "thermal": {"shear_heating": True},
            "setpoint": {"shaft_speed_rad_s": 2094.4, "radial_load_n": 300.0, "shaft_current_a": 10.0},
        },
    )
    assert r.status_code == 201, r.text
    try:
        state = wait_for(
            lambda: client.get("/v1/bearings/ev/state").json(),
            lambda s: s["electrical"]["shear_temperature_rise_k"] > 0.0,
        )
        e = state["electrical"]
        assert e["current_temperature_rise_k"] > 0.0 and 0.0 < e["film_thermal_factor"] < 1.0
        # the EV scenario's thermal options match this twin: accepted
        ok = client.post("/v1/bearings/ev/scenario", json={"name": "ev_motor_current_ramp"})
        assert ok.status_code == 202, ok.text
        # a scenario for an isothermal twin of the same bearing is refused by 'thermal'
        inline = {
            "name": "cold",
            "bearing": "6200",
            "lubricant": "ISO VG 32",
            "duration_s": 0.01,
            "thermal": {"shear_heating": False},
        }
        bad = client.post("/v1/bearings/ev/scenario", json={"scenario": inline})
        assert bad.status_code == 422 and detail(bad)[0]["field"] == "thermal", bad.text
    finally:
        client.delete("/v1/bearings/ev")


def test_scenarios(client, wait_for):
    names = client.get("/v1/scenarios").json()["scenarios"]
    assert "seed000_startup_steady_slowdown" in names and "seed000_clearance_sweep" in names
    r = client.post("/v1/bearings", json={"id": "scn"})
    assert r.status_code == 201
    try:
        r = client.post("/v1/bearings/scn/scenario", json={"name": "seed000_load_sweep"})
        assert r.status_code == 202, r.text
        body = r.json()
        assert body["accepted"] and body["expected_duration_s"] == pytest.approx(0.36)
        wait_for(lambda: client.get("/v1/bearings/scn/scenario").json(), lambda s: s["state"] == "running")
        # an inline scenario replaces it and runs to its end
        inline = {
            "name": "inline",
            "duration_s": 0.05,
            "steps": [{"at_s": 0.0, "ramp": {"radial_load_n": 1500.0}, "over_s": 0.02}],
        }
        r = client.post("/v1/bearings/scn/scenario", json={"scenario": inline})
        assert r.status_code == 202, r.text
        assert r.json()["replaced"] == "seed000_load_sweep"
        done = wait_for(lambda: client.get("/v1/bearings/scn/scenario").json(), lambda s: s["state"] == "done")
        assert done["name"] == "inline" and done["progress"] == 1.0
        state = client.get("/v1/bearings/scn/state").json()
        assert state["setpoint"]["radial_load_n"] == 1500.0
        # a matching run of a multi-run scenario is accepted, another mounting is not
        ok = client.post("/v1/bearings/scn/scenario", json={"name": "seed000_clearance_sweep", "run": "pd_0"})
        assert ok.status_code == 202, ok.text
        assert client.delete("/v1/bearings/scn/scenario").json()["state"] == "cancelled"
        bad = client.post("/v1/bearings/scn/scenario", json={"name": "seed000_clearance_sweep"})
        assert bad.status_code == 422 and detail(bad)[0]["field"] == "diametral_clearance_m"
        bad = client.post("/v1/bearings/scn/scenario", json={"name": "seed000_clearance_sweep", "run": "x"})
        assert bad.status_code == 422 and "pd_0" in detail(bad)[0]["allowed"]
        bad = client.post("/v1/bearings/scn/scenario", json={"name": "nope"})
        assert bad.status_code == 422 and detail(bad)[0]["field"] == "name"
        assert "seed000_load_sweep" in detail(bad)[0]["allowed"]
        bad = client.post("/v1/bearings/scn/scenario", json={})
        assert bad.status_code == 422
        bad = client.post(
            "/v1/bearings/scn/scenario",
            json={"scenario": {**inline, "steps": [{"at_s": 0.0, "set": {"shaft_speed_rad_s": 9000.0}}]}},
        )
        assert bad.status_code == 422
        err = detail(bad)[0]
        assert err["field"] == "scenario.steps[0].set.shaft_speed_rad_s" and err["allowed"][1] < 9000.0
        bad = client.post("/v1/bearings/scn/scenario", json={"scenario": {**inline, "duration_s": -1}})
        assert bad.status_code == 422 and detail(bad)[0]["field"] == "scenario.duration_s"
        ev = client.post("/v1/bearings/scn/scenario", json={"name": "ev_motor_current_ramp"})
        assert ev.status_code == 422 and detail(ev)[0]["field"] == "bearing"  # needs a 6200 twin
    finally:
        client.delete("/v1/bearings/scn")


@pytest.mark.skipif(not HAVE_RERUN, reason="rerun-sdk not installed")
def test_recording_start_stop(client, recordings):
    from rerun.chunk import RrdReader

    r = client.post("/v1/bearings/default/recording", json={"action": "start", "path": "default-test.rrd"})
    assert r.status_code == 200, r.text
    assert r.json()["recording"] is True
    time.sleep(0.5)
    r = client.post("/v1/bearings/default/recording", json={"action": "stop"})
    assert r.status_code == 200
    body = r.json()
    assert body["recording"] is False and body["rows_logged"] > 0
    path = recordings / "default-test.rrd"
    assert Path(body["path"]).resolve() == path.resolve()
    rows = 0
    for chunk in RrdReader(str(path)).stream():
        if chunk.entity_path == "/bearing/default/friction_torque_n_m" and not chunk.is_static:
            rows += chunk.num_rows
    # one trend row per 0.2 s window of simulated time (RerunRecorder.SERVICE_OPTIONS), never more rows
    # than snapshots, and no window missing: consecutive rows at most 1.5 windows apart in simulated time
    # (a loaded host paces the twin below real time, so the snapshots per window vary)
    assert 1 <= rows <= body["rows_logged"]
    times_s = np.sort(read_index(path, "/bearing/default/friction_torque_n_m", SIM_TIME)) / 1e9
    assert times_s.size == rows and (times_s.size < 2 or np.diff(times_s).max() <= 1.5 * 0.2)
    # stopping again is harmless
    assert client.post("/v1/bearings/default/recording", json={"action": "stop"}).json()["recording"] is False


@pytest.mark.parametrize(
    "body, field",
    [
        ({"action": "start", "path": "../escape.rrd"}, "path"),
        ({"action": "start", "path": "/etc/x.rrd"}, "path"),
        ({"action": "start", "path": "x.txt"}, "path"),
        ({"action": "pause"}, "action"),
    ],
)
def test_recording_bad_input(client, body, field):
    r = client.post("/v1/bearings/default/recording", json=body)
    assert r.status_code == 422, r.text
    assert detail(r)[0]["field"] == field


def _schemas(openapi: dict) -> dict:
    return openapi["components"]["schemas"]


def test_openapi_fields_carry_units(client):
    spec = client.get("/openapi.json").json()
    schemas = _schemas(spec)
    ours = [
        "BearingCreate",
        "BearingInfo",
        "Health",
        "TwinHealth",
        "SetpointResponse",
        "ScenarioRequest",
        "ScenarioAccepted",
        "ScenarioStatus",
        "RecordingRequest",
        "RecordingStatus",
        "FieldError",
        "SetpointUpdate",
    ]
    missing = []
    for name in ours:
        assert name in schemas, name
        for prop, sch in schemas[name]["properties"].items():
            desc = sch.get("description", "")
            if "[" not in desc:
                missing.append(f"{name}.{prop}")
    assert not missing, f"fields without a [unit] in their description: {missing}"
    # every number anywhere (the snapshot contract included) has a unit
    numbers = []
    for name, sch in schemas.items():
        for prop, p in sch.get("properties", {}).items():
            types = {p.get("type")} | {a.get("type") for a in p.get("anyOf", [])}
            if "number" in types and "[" not in p.get("description", ""):
                numbers.append(f"{name}.{prop}")
    assert not numbers, f"numeric fields without a [unit]: {numbers}"
    paths = spec["paths"]
    for path in (
        "/health",
        "/v1/bearings",
        "/v1/bearings/{bearing_id}",
        "/v1/bearings/{bearing_id}/setpoint",
        "/v1/bearings/{bearing_id}/state",
        "/v1/bearings/{bearing_id}/scenario",
        "/v1/bearings/{bearing_id}/recording",
    ):
        assert path in paths, path


def test_max_twins_is_a_409(client):
    created = []
    try:
        while True:
            r = client.post("/v1/bearings", json={"designation": "6200"})
            if r.status_code != 201:
                break
            created.append(r.json()["id"])
            assert len(created) <= 4
        assert r.status_code == 409 and "max_twins" in detail(r)[0]["message"]
    finally:
        for bearing_id in created:
            client.delete(f"/v1/bearings/{bearing_id}")
