"""Bad input, fuzzed: hypothesis throws wrong types, NaN/Infinity (as raw JSON text),
huge numbers, missing and extra fields, oversized bodies and non-JSON bytes at every HTTP
endpoint of a real server (uvicorn on 127.0.0.1) and at the zenoh setpoint handler: never a 5xx,
never a crash, and no non-finite number in any state read or snapshot published afterwards.
Example counts are bounded (the whole module takes well under a minute)."""

from __future__ import annotations

import json
import math
import threading
import time
import urllib.parse

import httpx
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from service.core.admission import AdmissionGate
from service.core.intake import SetpointIntake
from service.core.runner import TwinRunner
from service.settings import ServiceSettings

CAP = 4096
FIELDS = [
    "shaft_speed_rad_s",
    "radial_load_n",
    "axial_load_n",
    "oil_temperature_c",
    "shaft_current_a",
    "shaft_voltage_v",
]
FUZZ = settings(
    max_examples=120,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)

# ---- strategies ---------------------------------------------------------------------------------
nasty_numbers = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-(10**40), max_value=10**40),
    st.sampled_from([0, -0.0, 1e308, -1e308, 5e-324, 2**63, -(2**63), 10**400, 72596.0, 2073.0, 1e7]),
)
scalars = st.one_of(st.none(), st.booleans(), nasty_numbers, st.text(max_size=40))
json_values = st.recursive(
    scalars,
    lambda children: st.one_of(
        st.lists(children, max_size=4), st.dictionaries(st.text(max_size=12), children, max_size=4)
    ),
    max_leaves=12,
)
setpoint_like = st.dictionaries(
    st.one_of(st.sampled_from(FIELDS + ["token", "seq", ""]), st.text(max_size=12)), json_values, max_size=7
)


def _dumps(value) -> bytes:
    """JSON text that may carry NaN / Infinity literals and huge integers (as a client could send)."""
    try:
        return json.dumps(value, allow_nan=True).encode()
    except (ValueError, OverflowError):
        return b"{}"


raw_text = st.sampled_from(
    [
        b"",
        b"{",
        b"}",
        b"null",
        b"[]",
        b"NaN",
        b"Infinity",
        b'{"radial_load_n": NaN}',
        b'{"radial_load_n": Infinity}',
        b'{"radial_load_n": -Infinity}',
        b'{"radial_load_n": 1e999}',
        b'{"shaft_speed_rad_s": 1' + b"0" * 400 + b"}",
        b'{"radial_load_n": "3000"}',
        b'{"radial_load_n": 3000, "radial_load_n": NaN}',
        b"\xff\xfe\x00garbage",
        b'{"a":' * 200,
        b"[" * 5000,
        b'{"action": "start", "path": "a\\u0000.rrd"}',
        b'{"action": "start", "path": "../../x.rrd"}',
        b'{"id": "x\\ny"}',
        b'{"designation": "6208", "setpoint": {"radial_load_n": NaN}}',
        b'{"scenario": {"name": "x", "duration_s": 1e308, "steps": []}}',
        b'{"scenario": {"name": "x", "duration_s": NaN}}',
        b'{"scenario": []}',
    ]
)


def bodies(shaped):
    return st.one_of(
        shaped.map(_dumps),
        json_values.map(_dumps),
        raw_text,
        st.binary(max_size=300),
        st.integers(min_value=CAP + 1, max_value=3 * CAP).map(lambda n: b'{"name": "' + b"a" * n + b'"}'),
    )


scenario_like = st.fixed_dictionaries(
    {},
    optional={
        "name": st.one_of(st.text(max_size=20), st.sampled_from(["seed000_load_sweep", "nope", "../etc"]), json_values),
        "scenario": st.one_of(
            json_values,
            st.fixed_dictionaries(
                {
                    "name": st.text(max_size=10),
                    "duration_s": nasty_numbers,
                    "steps": st.lists(
                        st.dictionaries(
                            st.sampled_from(["at_s", "set", "ramp", "over_s", "phase"]), json_values, max_size=4
                        ),
                        max_size=3,
                    ),
                }
            ),
        ),
        "run": json_values,
        "restart": json_values,
        "extra": json_values,
    },
)
bearing_like = st.fixed_dictionaries(
    {},
    optional={
        "id": st.one_of(st.text(max_size=70), st.sampled_from(["default", "a/b", "*", "x" * 64])),
        "designation": st.one_of(st.sampled_from(["6208", "7208", "6205", "9999", ""]), json_values),
        "diametral_clearance_m": nasty_numbers,
        "lubricant": st.one_of(st.text(max_size=20), json_values),
        "setpoint": setpoint_like,
        "extra": json_values,
    },
)
recording_like = st.fixed_dictionaries(
    {},
    optional={
        "action": st.one_of(st.sampled_from(["start", "stop", "pause"]), json_values),
        "path": st.one_of(
            st.text(max_size=40),
            st.sampled_from(["ok.rrd", "d/ok.rrd", "../x.rrd", "/tmp/x.rrd", "x.txt", "a\x00.rrd", ".hidden.rrd"]),
            json_values,
        ),
        "extra": json_values,
    },
)
ids = st.one_of(st.sampled_from(["default", "nobody", "x" * 200, "%", "..", "a.b"]), st.text(min_size=1, max_size=30))


# ---- the server -----------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def fuzz_server(hostile, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("fuzz")
    settings_ = ServiceSettings(
        enable_zenoh=False,
        enable_recording=True,
        record=tmp / "rec" / "service.rrd",
        scenario_dir=hostile.SCENARIOS,
        max_twins=3,
        setpoint_rate_hz=0.0,
        max_body_bytes=CAP,
    )
    with hostile.ThreadServer(settings_) as srv, httpx.Client(base_url=srv.url, timeout=60.0) as client:
        yield srv, client


def _send(client, method, path, body: bytes):
    r = client.request(method, path, content=body, headers={"content-type": "application/json"})
    assert r.status_code < 500, (method, path, body[:200], r.status_code, r.text[:500])
    if r.status_code >= 400:
        detail = r.json()["detail"]  # the service's error body, JSON without NaN
        assert isinstance(detail, list) and detail, r.text
    json.loads(r.content or b"null", parse_constant=lambda c: pytest.fail(f"response carries {c}"))
    return r


def _quote(bearing_id: str) -> str:
    return urllib.parse.quote(bearing_id, safe="")


@FUZZ
@given(bearing_id=ids, body=bodies(setpoint_like))
def test_fuzz_put_setpoint(fuzz_server, bearing_id, body):
    _srv, client = fuzz_server
    _send(client, "PUT", f"/v1/bearings/{_quote(bearing_id)}/setpoint", body)


@FUZZ
@given(body=bodies(bearing_like))
def test_fuzz_post_bearings(fuzz_server, body):
    _srv, client = fuzz_server
    r = _send(client, "POST", "/v1/bearings", body)
    if r.status_code == 201:  # keep room for the next ones
        assert client.delete(f"/v1/bearings/{_quote(r.json()['id'])}").status_code == 200


@FUZZ
@given(bearing_id=ids, body=bodies(scenario_like))
def test_fuzz_post_scenario(fuzz_server, bearing_id, body):
    _srv, client = fuzz_server
    _send(client, "POST", f"/v1/bearings/{_quote(bearing_id)}/scenario", body)


@FUZZ
@given(bearing_id=ids, body=bodies(recording_like))
def test_fuzz_post_recording(fuzz_server, bearing_id, body):
    _srv, client = fuzz_server
    _send(client, "POST", f"/v1/bearings/{_quote(bearing_id)}/recording", body)


@FUZZ
@given(
    bearing_id=ids.filter(lambda i: i != "default"),
    body=st.one_of(st.just(b""), bodies(json_values)),
    what=st.sampled_from(["", "/scenario"]),
)
def test_fuzz_delete(fuzz_server, bearing_id, body, what):
    _srv, client = fuzz_server
    _send(client, "DELETE", f"/v1/bearings/{_quote(bearing_id)}{what}", body)


@pytest.mark.parametrize(
    "path",
    [
        "a\x00.rrd",
        "x" * 300 + ".rrd",
        "service.rrd/x.rrd",
        "sub.rrd",
        "a b.rrd",
        ".hidden.rrd",
        "d/../x.rrd",
        "C:\\x.rrd",
    ],
)
def test_recording_paths_that_reached_the_file_system_are_422(fuzz_server, path):
    """A NUL byte, a name longer than the file system allows, a folder that is a file and a
    target that is a folder gave 500s before the paths were restricted."""
    srv, client = fuzz_server
    (srv.service.recordings_dir() / "sub.rrd").mkdir(parents=True, exist_ok=True)
    r = client.post("/v1/bearings/default/recording", json={"action": "start", "path": path})
    assert r.status_code == 422, r.text
    assert r.json()["detail"][0]["field"] == "path"


def test_after_the_fuzzing_the_service_is_alive_and_finite(fuzz_server):
    """Runs after the fuzz tests of this module (pytest keeps file order)."""
    srv, client = fuzz_server
    client.post("/v1/bearings/default/recording", json={"action": "stop"})
    client.delete("/v1/bearings/default/scenario")
    health = client.get("/health")
    assert health.status_code == 200
    twins = health.json()["twins"]
    assert any(t["id"] == "default" for t in twins)
    for t in twins:
        assert t["running"], t
        assert t["errors"] == 0, t
        state = client.get(f"/v1/bearings/{_quote(t['id'])}/state")
        assert state.status_code == 200
        s = json.loads(state.content, parse_constant=lambda c: pytest.fail(f"state carries {c}"))
        for key in ("time_s", "friction_torque_n_m", "shaft_speed_rad_s"):
            assert math.isfinite(s[key])
        for value in s["setpoint"].values():
            assert math.isfinite(value)
    # and it still follows a good setpoint
    r = client.put(
        "/v1/bearings/default/setpoint",
        json={
            "radial_load_n": 3000.0,
            "shaft_speed_rad_s": 500.0,
            "axial_load_n": 0.0,
            "oil_temperature_c": 40.0,
            "shaft_current_a": 0.0,
            "shaft_voltage_v": 0.0,
        },
    )
    assert r.status_code in (200, 422), r.text  # 422 only if a value was learned as not held
    seq = client.get("/v1/bearings/default/state").json()["seq"]
    client_state = lambda: client.get("/v1/bearings/default/state").json()  # noqa: E731
    deadline = time.monotonic() + 30
    while client_state()["seq"] <= seq:
        assert time.monotonic() < deadline, "the twin stopped publishing"
        time.sleep(0.05)


# ---- zenoh payloads ---------------------------------------------------------------------------------
class ListSink:
    def __init__(self):
        self.texts: list[str] = []
        self.lock = threading.Lock()
        self.dropped = 0

    def publish(self, snapshot):
        with self.lock:
            self.texts.append(snapshot.to_json())

    def close(self):
        pass


@pytest.fixture(scope="module")
def running_runner():
    from twin.engine import Twin

    twin = Twin("6208")
    twin.advance(0.001)
    sink = ListSink()
    runner = TwinRunner(twin, sinks=[sink], publish_rate_hz=50.0).start()
    runner.intake = SetpointIntake("default", AdmissionGate(max_payload_bytes=CAP), runner)
    yield runner, sink
    assert runner.stop(10.0)


zenoh_payloads = st.one_of(
    bodies(setpoint_like), setpoint_like.map(lambda d: json.dumps(d, allow_nan=True) if _dumpable(d) else "{}")
)


def _dumpable(value) -> bool:
    try:
        json.dumps(value, allow_nan=True)
        return True
    except (ValueError, OverflowError):
        return False


@settings(
    max_examples=300, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(payload=zenoh_payloads)
def test_fuzz_zenoh_setpoint_handler(running_runner, payload):
    runner, _sink = running_runner
    result = runner.intake(payload)
    assert isinstance(result, dict) and isinstance(result["accepted"], bool)
    json.dumps(result, allow_nan=False)  # what the bus publishes: never NaN
    if not result["accepted"]:
        assert result["status"] in (401, 413, 422, 429) and result["error"]


def test_zenoh_fuzzing_published_only_finite_snapshots(running_runner):
    runner, sink = running_runner
    n = len(sink.texts)
    deadline = time.monotonic() + 30
    while len(sink.texts) < n + 5:
        assert time.monotonic() < deadline and runner.running, "the runner stopped publishing"
        time.sleep(0.02)
    with sink.lock:
        texts = list(sink.texts)
    for text in texts:
        json.loads(text, parse_constant=lambda c: pytest.fail(f"snapshot carries {c}"))
    assert runner.errors == 0 and runner.running


def test_nasty_payloads_through_a_real_zenoh_session(hostile):
    """A few of the worst payloads over a real zenoh link: each gets a refusal on the result key,
    the state stream stays finite and the twin keeps running."""
    pytest.importorskip("zenoh")
    endpoint = f"tcp/127.0.0.1:{hostile.free_port()}"
    settings_ = ServiceSettings(
        enable_zenoh=True,
        zenoh_listen=[endpoint],
        enable_recording=False,
        scenario_dir=hostile.SCENARIOS,
        max_body_bytes=CAP,
    )
    payloads = [
        b'{"radial_load_n": NaN}',
        b'{"shaft_speed_rad_s": Infinity}',
        b'{"radial_load_n": 1e999}',
        b'{"axial_load_n": 1' + b"0" * 300 + b"}",
        b"\xff\x00garbage",
        b"[" * 3000,
        b"null",
        b'{"radial_load_n": "lots"}',
        b'{"unknown": 1}',
        b'{"radial_load_n": 1}' + b" " * (CAP + 1),
    ]
    with hostile.ThreadServer(settings_):
        peer = hostile.Peer(endpoint)
        try:
            peer.subscribe("bearing/default/setpoint/result")
            peer.subscribe("bearing/default/state")
            first = hostile.wait_for(lambda: _try(peer, payloads[0]), lambda r: r is not None)
            results = [first] + [peer.result_after("bearing/default/setpoint", p) for p in payloads[1:]]
            for payload, result in zip(payloads, results, strict=True):
                assert result["accepted"] is False, (payload[:50], result)
            assert results[-1]["status"] == 413
            states = []
            deadline = time.monotonic() + 30
            while len(states) < 5 and time.monotonic() < deadline:
                key, _, data = peer.wait_for(lambda item: True)
                if key == "bearing/default/state":
                    states.append(hostile.strict_loads(data))
            assert len(states) >= 5 and states[-1]["seq"] > states[0]["seq"]
        finally:
            peer.close()


def _try(peer, payload):
    try:
        return peer.result_after("bearing/default/setpoint", payload, timeout_s=2.0)
    except AssertionError:
        return None
