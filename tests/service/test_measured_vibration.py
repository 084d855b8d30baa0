"""Measured vibration beside the twin, against a REAL service (uvicorn + zenoh on 127.0.0.1, free
ports, fast mode, multicast scouting off as in the other service tests).

The measured windows are 1 s of the CWRU drive-end records (tests/data/cwru; Case Western Reserve
University Bearing Data Center): record 105, inner-race fault 0.007 in (its BPFI line stands
24-29 dB over its +-20 Hz background in each 1 s window, kurtosis 5.1-5.6), and the healthy record
97 (12 kHz). The twins are 6205s at the record's speed (1797 rpm); one is healthy, the other
carries an inner-race spall of the record's size (0.178 mm wide, 0.279 mm deep) set through the
defect API. The comparison (service.core.measured) must raise its residual alarm on the first
window for the healthy twin (a BPFI line it has no defect for, a kurtosis above its Gaussian 3)
and raise none for the twin with the matching defect, nor for the healthy window on the healthy
twin. Bad windows get a 422 naming the field. Every wait is bounded; no wall-clock threshold."""

from __future__ import annotations

import json
import math
import time
from pathlib import Path

import httpx
import numpy as np
import pytest

pytest.importorskip("zenoh")

from service.core.measured import encode_frame
from service.settings import ServiceSettings
from twin import catalog

DATA = Path(__file__).resolve().parents[1] / "data" / "cwru"
FS = 12000.0
RPM = 1797.0
SPEED_RAD_S = RPM * 2.0 * math.pi / 60.0
RB = catalog.bearing("6205").geometry.ball_radius_m
INNER = {"kind": "inner", "width_m": 0.178e-3, "length_m": 0.178e-3, "depth_m": 0.279e-3}
INNER_WINDOW = np.load(DATA / "105_DE_5s.npy")[:12000]  # [g]
HEALTHY_WINDOW = np.load(DATA / "97_DE_12k_5s.npy")[:12000]  # [g]


@pytest.fixture(scope="module")
def service(support):
    endpoint = support.free_endpoint()
    settings = ServiceSettings(
        enable_recording=False,
        zenoh_listen=[endpoint],
        fast=True,
        publish_rate_hz=50.0,
        opcua=f"opc.tcp://127.0.0.1:{support.free_port()}",
        opcua_security="none",
    )
    with (
        support.ThreadServer(settings, start_timeout_s=120.0, stop_timeout_s=60.0) as srv,
        httpx.Client(base_url=srv.url, timeout=60.0) as http,
    ):
        for name in ("healthy", "inner"):
            created = http.post(
                "/v1/bearings",
                json={
                    "id": name,
                    "designation": "6205",
                    "setpoint": {"shaft_speed_rad_s": SPEED_RAD_S, "radial_load_n": 1000.0},
                },
            )
            assert created.status_code == 201, created.text
        put = http.put("/v1/bearings/inner/defects", json={"defects": [INNER]})
        assert put.status_code == 200, put.text
        for name in ("healthy", "inner"):  # both twins at the record's speed
            support.wait_for(
                lambda n=name: http.get(f"/v1/bearings/{n}/state").json()["shaft_speed_rad_s"],
                lambda w: abs(w - SPEED_RAD_S) < 1e-6 * SPEED_RAD_S,
                120.0,
            )
        yield srv, http, endpoint


def _post(http, name, samples_g):
    return http.post(
        f"/v1/bearings/{name}/vibration/measured",
        params={"sample_rate_hz": FS, "units": "g"},
        content=np.asarray(samples_g, dtype="<f4").tobytes(),
        headers={"content-type": "application/octet-stream"},
    )


def test_inner_race_window_alarms_on_the_healthy_twin_only(service, support):
    """An inner-race window: the healthy twin raises `unexplained_line` BPFI (and `kurtosis_above_twin`);
    the twin with the inner-race defect raises nothing; the GET returns the same comparison."""
    _srv, http, _ep = service
    last = http.get("/v1/bearings/healthy/vibration/comparison")  # other tests of the module may have posted
    windows = last.json()["window"] if last.status_code == 200 else 0
    r = _post(http, "healthy", INNER_WINDOW)
    assert r.status_code == 200, r.text
    healthy = support.strict_loads(r.text)
    assert healthy["window"] == windows + 1 and healthy["alarm"] is True
    codes = {(a["code"], a.get("line")) for a in healthy["alarms"]}
    assert ("unexplained_line", "BPFI") in codes and ("kurtosis_above_twin", None) in codes
    bpfi = next(d for d in healthy["measured"]["defect_lines"] if d["name"] == "BPFI")
    assert abs(bpfi["relative_error"]) < 0.015 and bpfi["height_db"] > 16.0
    assert healthy["predicted"]["defect_kinds"] == [] and healthy["predicted"]["kurtosis"] == 3.0
    assert healthy["residual"]["kurtosis"] == pytest.approx(healthy["measured"]["kurtosis"] - 3.0)
    assert http.get("/v1/bearings/healthy/vibration/comparison").json()["window"] == windows + 1

    r = _post(http, "inner", INNER_WINDOW)
    assert r.status_code == 200, r.text
    inner = support.strict_loads(r.text)
    assert inner["predicted"]["defect_kinds"] == ["inner"]
    assert inner["alarm"] is False and inner["alarms"] == []


def _line_of_bpfi(body) -> bool:
    """The active `measured_line` alarm carries a BPFI line (a window with the line evaluated)."""
    return any(a["alarm_id"] == "measured_line" and a["value"] > 0.0 for a in body["active"])


def _active_alarm_ids(http, name, timeout_s=10.0, until=_line_of_bpfi):
    """The ids of the twin's active alarms once the alarm thread has seen the latest window: an
    alarm left active by an earlier window of another test in this module (the service is shared)
    is not taken for the new window's."""
    deadline = time.monotonic() + timeout_s
    while True:
        r = http.get(f"/v1/bearings/{name}/alarms")
        assert r.status_code == 200, r.text
        body = r.json()
        ids = {a["alarm_id"] for a in body["active"]}
        if until(body) or time.monotonic() > deadline:
            return ids, body
        time.sleep(0.25)  # a few reads a second: within the service's read rate


def test_measured_window_raises_the_stateful_alarm_on_the_healthy_twin_only(service):
    """The comparison's findings enter the twin's alarms (service.core.alarms `measured_line`,
    `measured_kurtosis`; ISA-18.2 states, the same events as every alarm: HTTP, zenoh, OPC UA,
    the recording): after one inner-race window the healthy twin has `measured_line` active with the
    BPFI height as its value, the twin with the inner-race defect has neither."""
    _srv, http, _ep = service
    assert _post(http, "healthy", INNER_WINDOW).status_code == 200
    ids, body = _active_alarm_ids(http, "healthy")
    assert {"measured_line", "measured_kurtosis"} <= ids, body["active"]
    line = next(a for a in body["active"] if a["alarm_id"] == "measured_line")
    assert line["severity"] == "warning" and line["value"] > 16.0 and "BPFI" in line["message"]
    assert any(e["alarm_id"] == "measured_line" and e["transition"] == "raised" for e in body["events"])
    assert _post(http, "inner", INNER_WINDOW).status_code == 200
    ids, _ = _active_alarm_ids(http, "inner", timeout_s=2.0)
    assert not ids & {"measured_line", "measured_kurtosis"}


def test_healthy_window_on_the_healthy_twin_is_quiet(service):
    """0.4 s of the healthy record as JSON (5 significant digits: the body stays under the
    service's 64 KiB limit): no alarm on the healthy twin."""
    _srv, http, _ep = service
    samples = [float(f"{v:.5g}") for v in HEALTHY_WINDOW[:4800]]
    r = http.post(
        "/v1/bearings/healthy/vibration/measured", json={"sample_rate_hz": FS, "units": "g", "samples": samples}
    )
    assert r.status_code == 200, r.text
    assert r.json()["alarm"] is False


@pytest.mark.parametrize(
    "params, body, field",
    [
        ({"sample_rate_hz": FS, "units": "g"}, np.zeros(100, "<f4").tobytes(), "samples"),
        ({"sample_rate_hz": FS, "units": "g"}, np.r_[np.zeros(5000), np.nan].astype("<f4").tobytes(), "samples"),
        ({"sample_rate_hz": 1e9, "units": "g"}, np.zeros(4096, "<f4").tobytes(), "sample_rate_hz"),
        ({"sample_rate_hz": FS, "units": "furlongs"}, np.zeros(4096, "<f4").tobytes(), "units"),
        ({"units": "g"}, np.zeros(4096, "<f4").tobytes(), "sample_rate_hz"),
        ({"sample_rate_hz": FS, "shaft_hz": 5000.0}, np.zeros(4096, "<f4").tobytes(), "shaft_hz"),
    ],
)
def test_bad_windows_get_422_naming_the_field(service, params, body, field):
    _srv, http, _ep = service
    r = http.post(
        "/v1/bearings/healthy/vibration/measured",
        params=params,
        content=body,
        headers={"content-type": "application/octet-stream"},
    )
    assert r.status_code == 422, r.text
    detail = r.json()["detail"]
    assert detail[0]["field"] == field and detail[0]["message"]


def test_bad_json_window_names_the_field(service):
    _srv, http, _ep = service
    r = http.post("/v1/bearings/healthy/vibration/measured", json={"sample_rate_hz": FS, "samples": [1.0] * 10})
    assert r.status_code == 422 and r.json()["detail"][0]["field"] == "samples"
    r = http.post("/v1/bearings/healthy/vibration/measured", json={"sample_rate_hz": -1, "samples": [0.0] * 2000})
    assert r.status_code == 422 and r.json()["detail"][0]["field"] == "sample_rate_hz"
    assert http.get("/v1/bearings/nobody/vibration/comparison").status_code == 404


def test_zenoh_frame_gives_the_comparison(service, support):
    """The binary frame on `bearing/{id}/vibration/measured` (service.core.measured layout) is
    answered on `bearing/{id}/vibration/comparison`: the residual alarm for the healthy twin, none
    for the twin with the matching defect; a truncated frame is refused naming `n`."""
    _srv, _http, endpoint = service
    peer = support.Peer(endpoint)
    try:
        peer.subscribe("bearing/*/vibration/comparison")
        time.sleep(0.5)
        frame = encode_frame(INNER_WINDOW, FS, "g")
        for name, alarmed in (("healthy", True), ("inner", False)):
            key = f"bearing/{name}/vibration/comparison"
            sample = peer.wait_for(
                lambda s, k=key: s.key == k,
                poke=lambda n=name: peer.session.put(f"bearing/{n}/vibration/measured", frame),
                poke_every_s=5.0,
            )
            result = support.strict_loads(sample.payload)
            assert result["accepted"] is True and result["alarm"] is alarmed, json.dumps(result)[:400]
            peer.drain()
        sample = peer.wait_for(
            lambda s: s.key == "bearing/healthy/vibration/comparison",
            poke=lambda: peer.session.put("bearing/healthy/vibration/measured", frame[:-8]),
            poke_every_s=5.0,
        )
        result = support.strict_loads(sample.payload)
        assert result["accepted"] is False and result["status"] == 422 and result["detail"][0]["field"] == "n"
    finally:
        peer.close()


def test_opcua_shows_the_comparison(service, support):
    """OPC UA `<twin>/MeasuredVibration/...`: after an inner-race window on the healthy twin, its
    `alarm` is true, `alarm_codes` names the BPFI line, `bpfi_height_db` and `kurtosis` are the
    HTTP comparison's (read within a bounded wait: the facade refreshes with the snapshots)."""
    import asyncio

    from asyncua import Client

    from service.opcua.layout import NAMESPACE_URI, ROOT_FOLDER

    srv, http, _ep = service
    posted = _post(http, "healthy", INNER_WINDOW).json()
    bpfi = next(d["height_db"] for d in posted["measured"]["defect_lines"] if d["name"] == "BPFI")

    async def read_all():
        c = Client(srv.service.opcua.url, timeout=20, watchdog_intervall=10.0)
        async with c:
            idx = await c.get_namespace_index(NAMESPACE_URI)
            folder = await c.nodes.objects.get_child(
                [f"{idx}:{ROOT_FOLDER}", f"{idx}:healthy", f"{idx}:MeasuredVibration"]
            )
            out = {}
            for name in ("window", "alarm", "alarm_codes", "bpfi_height_db", "kurtosis"):
                out[name] = await (await folder.get_child(f"{idx}:{name}")).read_value()
            return out

    def fetch():
        try:
            return asyncio.run(asyncio.wait_for(read_all(), 60.0))
        except Exception as exc:  # noqa: BLE001 - not there yet (facade syncing, busy machine): retry
            return {"window": None, "error": repr(exc)}

    values = support.wait_for(fetch, lambda v: v["window"] == posted["window"], 180.0, interval=0.5)
    assert values["alarm"] is True and "unexplained_line:BPFI" in values["alarm_codes"]
    assert values["bpfi_height_db"] == pytest.approx(bpfi, rel=1e-12)
    assert values["kurtosis"] == pytest.approx(posted["measured"]["kurtosis"], rel=1e-12)


def test_rerun_recording_holds_measured_beside_predicted(tmp_path):
    """The rerun recorder (service.recording) logs each comparison at the twin's simulated time:
    `vibration/measured/kurtosis/{measured,predicted}` side by side, the BPFI line height and the
    alarm text, read back from the .rrd file."""
    from service.core.measured import MeasuredComparator, window_from_float32
    from service.recording import RerunRecorder, read_column
    from twin.engine import Twin
    from twin.setpoint import Setpoint

    twin = Twin(
        catalog.bearing("6205"), bearing_id="m", setpoint=Setpoint(shaft_speed_rad_s=SPEED_RAD_S, radial_load_n=1000.0)
    )
    twin.advance(0.01)
    path = tmp_path / "m.rrd"
    rec = RerunRecorder(path)
    rec.add_twin_from(twin)
    comparator = MeasuredComparator("m", twin.model.spec.geometry)
    comparator.listeners.append(rec.log_measured)
    snap = twin.snapshot()
    rec.publish(snap)
    out = comparator.compare(window_from_float32(INNER_WINDOW.astype("<f4").tobytes(), FS, "g"), snap, ())
    rec.close()
    assert rec.errors == 0 and comparator.listener_errors == 0
    base = "bearing/m/vibration/measured"
    assert [v[0] for v in read_column(path, f"{base}/kurtosis/measured", "Scalars:scalars")] == pytest.approx(
        [out["measured"]["kurtosis"]]
    )
    assert [v[0] for v in read_column(path, f"{base}/kurtosis/predicted", "Scalars:scalars")] == [3.0]
    bpfi = next(d["height_db"] for d in out["measured"]["defect_lines"] if d["name"] == "BPFI")
    assert [v[0] for v in read_column(path, f"{base}/line_height_db/BPFI", "Scalars:scalars")] == pytest.approx([bpfi])
    assert "BPFI" in read_column(path, f"{base}/alarms", "TextLog:text")[0][0]
