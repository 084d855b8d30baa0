"""The lubrication alarm of a REAL twin through the whole service: uvicorn + zenoh + OPC UA on
127.0.0.1 (free ports), the default 6208 twin in fast mode. Load up and hot oil (8 kN, 110 degC:
the oil's viscosity drops from 0.040 to 0.0045 Pa s, Lambda of the loaded contacts from 1.75 to
0.37, below seed 000 Table 2's boundary limit of 1) raise `lubrication_boundary`; back to 3 kN and
40 degC clear it. The events arrive on zenoh `bearing/default/alarm`, as OPC UA events from the
twin object, and in GET /v1/bearings/default/alarms. Every wait is bounded."""

from __future__ import annotations

import asyncio
import json

import httpx
import pytest

pytest.importorskip("asyncua")
pytest.importorskip("zenoh")
from asyncua import Client

from service.opcua.layout import EVENT_TYPE, NAMESPACE_URI, ROOT_FOLDER
from service.settings import AlarmSettings, ServiceSettings

WAIT_S = 120.0
DELAY_S = 0.05  # lubrication on-delay [s of simulated time]
HOLD_S = 0.05  # off-delay


class Events:
    """asyncua subscription handler: collects the alarm events."""

    def __init__(self):
        self.got: list = []

    def event_notification(self, event):
        self.got.append(event)


def test_load_up_and_hot_oil_raise_then_clear_the_lubrication_alarm(support):
    endpoint = support.free_endpoint()
    settings = ServiceSettings(
        enable_recording=False,
        zenoh_listen=[endpoint],
        fast=True,
        publish_rate_hz=200.0,
        opcua=f"opc.tcp://127.0.0.1:{support.free_port()}",
        alarms=AlarmSettings(
            lubrication_delay_s=DELAY_S,
            clear_hold_s=HOLD_S,
            # this test follows the boundary-regime alarm; the ISO 281 kappa alarm
            # (kappa ~ 0.3 at 110 degC, also raised) has its own tests in test_alarms.py
            kappa_threshold=0.01,
            # and the thermal alarms (the 110 degC oil puts the outer ring above
            # the 82 degC zone; the step raises its rate): test_thermal_alarms.py
            temperature_warning_c=250.0,
            temperature_critical_c=290.0,
            temperature_rate_warning_k_per_min=999.0,
            temperature_rate_critical_k_per_min=1000.0,
        ),
    )
    with (
        support.ThreadServer(settings, start_timeout_s=120.0, stop_timeout_s=30.0) as srv,
        httpx.Client(base_url=srv.url, timeout=30.0) as http,
    ):
        peer = support.Peer(endpoint)
        try:
            peer.subscribe("bearing/default/alarm")
            result = asyncio.run(asyncio.wait_for(_scenario(srv, http, peer, support), 4 * WAIT_S))
        finally:
            peer.close()
    zenoh_events, opc_events, listing, t_hot, t_cool = result

    raised, cleared = zenoh_events
    assert (raised["alarm_id"], raised["transition"], raised["severity"]) == (
        "lubrication_boundary",
        "raised",
        "warning",
    )
    assert raised["schema"] == "bearing-twin/alarm/1" and raised["bearing_id"] == "default"
    assert raised["value"] <= 1.0 and raised["threshold"] == 1.0
    assert raised["clear_threshold"] == pytest.approx(1.0 / 0.9)
    assert raised["since_s"] >= t_hot + DELAY_S - 1e-9  # the on-delay, in simulated time
    assert (cleared["alarm_id"], cleared["transition"], cleared["active"]) == ("lubrication_boundary", "cleared", False)
    assert cleared["value"] > 1.0 / 0.9
    assert cleared["time_s"] >= t_cool + HOLD_S - 1e-9  # the off-delay

    assert [(e.alarm_id, e.transition, e.Severity) for e in opc_events] == [
        ("lubrication_boundary", "raised", 500),
        ("lubrication_boundary", "cleared", 100),
    ]
    assert opc_events[0].value == pytest.approx(raised["value"]) and opc_events[0].SourceName == "default"

    assert listing["active"] == []
    assert [(e["alarm_id"], e["transition"]) for e in listing["events"]] == [
        ("lubrication_boundary", "raised"),
        ("lubrication_boundary", "cleared"),
    ]
    (state,) = [a for a in listing["alarms"] if a["alarm_id"] == "lubrication_boundary"]
    assert state["active"] is False and state["value"] > 1.0 / 0.9


async def _scenario(srv, http, peer, support):
    def get(path):
        r = http.get(path)
        r.raise_for_status()
        return r.json()

    def zenoh_alarm(transition):
        sample = peer.wait_for(lambda s: json.loads(s.payload)["transition"] == transition, timeout_s=WAIT_S)
        return support.strict_loads(sample.payload)

    async with Client(srv.service.opcua.url, timeout=20, watchdog_intervall=10.0) as c:
        idx = await c.get_namespace_index(NAMESPACE_URI)
        twin = await c.nodes.objects.get_child([f"{idx}:{ROOT_FOLDER}", f"{idx}:default"])
        evtype = await c.nodes.base_event_type.get_child(f"{idx}:{EVENT_TYPE}")
        handler, at_server = Events(), Events()
        sub = await c.create_subscription(20, handler)
        await sub.subscribe_events(twin, evtype)
        sub_server = await c.create_subscription(20, at_server)
        await sub_server.subscribe_events(c.nodes.server, evtype)  # where most clients look
        await asyncio.to_thread(
            support.wait_for, lambda: get("/v1/bearings/default/state")["time_s"], lambda t: t > 0.02, 2 * WAIT_S
        )
        before = await asyncio.to_thread(get, "/v1/bearings/default/alarms")
        assert before["active"] == [] and before["events"] == []

        t_hot = (await asyncio.to_thread(get, "/v1/bearings/default/state"))["time_s"]
        put = await asyncio.to_thread(
            http.put, "/v1/bearings/default/setpoint", json={"radial_load_n": 8000.0, "oil_temperature_c": 110.0}
        )
        assert put.status_code == 200, put.text
        raised = await asyncio.to_thread(zenoh_alarm, "raised")
        during = await asyncio.to_thread(get, "/v1/bearings/default/alarms")
        assert [a["alarm_id"] for a in during["active"]] == ["lubrication_boundary"]
        level_node = await twin.get_child([f"{idx}:Alarms", f"{idx}:lubrication_boundary"])
        for _ in range(400):  # the facade's next update, bounded
            level = await level_node.read_value()
            if level != "inactive":
                break
            await asyncio.sleep(0.05)

        t_cool = (await asyncio.to_thread(get, "/v1/bearings/default/state"))["time_s"]
        put = await asyncio.to_thread(
            http.put, "/v1/bearings/default/setpoint", json={"radial_load_n": 3000.0, "oil_temperature_c": 40.0}
        )
        assert put.status_code == 200, put.text
        cleared = await asyncio.to_thread(zenoh_alarm, "cleared")
        for _ in range(400):  # the OPC UA events, bounded
            if len(handler.got) >= 2 and len(at_server.got) >= 2:
                break
            await asyncio.sleep(0.05)
        listing = await asyncio.to_thread(get, "/v1/bearings/default/alarms")
        await sub.delete()
        await sub_server.delete()
    assert [(e.alarm_id, e.transition, e.SourceName) for e in at_server.got] == [
        ("lubrication_boundary", "raised", "default"),
        ("lubrication_boundary", "cleared", "default"),
    ]
    assert level == "warning"  # Alarms/<id> while the alarm is active
    return [raised, cleared], handler.got, listing, t_hot, t_cool
