"""Alarm events on zenoh `bearing/{id}/alarm` (TwinChannel.publish_alarm) and in the `monitor`
table: a real zenoh bus and a monitor session on 127.0.0.1; every wait is bounded."""

from __future__ import annotations

import io
import json
import threading

import pytest

pytest.importorskip("zenoh")

from service.bus.zenoh_bus import ZenohBus
from service.core.alarm_inputs import AlarmInputs
from service.core.alarms import AlarmEvaluator
from service.tools.monitor import TwinTable, run_monitor


def _events() -> list[dict]:
    """A raised then cleared electrical alarm, made by the real evaluator."""
    ev = AlarmEvaluator("a1")
    out = []
    for t, risk in ((0.0, "likely"), (1.0, "none"), (2.5, "none")):
        out += [e.to_dict() for e in ev.update(AlarmInputs(time_s=t, discharge_risk=risk, discharge_reason="test"))]
    assert [e["transition"] for e in out] == ["raised", "cleared"]
    return out


def test_table_keeps_the_active_alarms_and_renders_them():
    raised, cleared = _events()
    table = TwinTable()
    table.on_alarm("bearing/a1/alarm", json.dumps(raised).encode())
    assert table.snapshot()["a1"]["alarms"] == {"electrical_discharge": "critical"}
    text = io.StringIO()
    from rich.console import Console

    Console(file=text, width=250).print(table.render())
    assert "electrical_discharge:critical" in text.getvalue()
    table.on_alarm("bearing/a1/alarm", json.dumps(cleared).encode())
    assert table.snapshot()["a1"]["alarms"] == {}
    table.on_alarm("bearing/a1/alarm", b"not json")
    assert table.invalid == 1


def test_alarm_events_reach_zenoh_and_the_monitor(support):
    endpoint = support.free_endpoint()
    raised, _cleared = _events()
    bus = ZenohBus(listen=[endpoint], connect=[])
    peer = support.Peer(endpoint)
    stop = threading.Event()
    try:
        channel = bus.attach_twin("a1", lambda: None, lambda p: {})
        peer.subscribe("bearing/a1/alarm")
        got = peer.wait_for(
            lambda s: s.key == "bearing/a1/alarm", poke=lambda: channel.publish_alarm(raised), poke_every_s=0.1
        )
        body = support.strict_loads(got.payload)
        assert body == {**raised, "bearing_id": "a1"} and body["schema"] == "bearing-twin/alarm/1"

        def keep_publishing():
            while not stop.wait(0.05):
                channel.publish_alarm(raised)

        thread = threading.Thread(target=keep_publishing, daemon=True)
        thread.start()
        rows = run_monitor([endpoint], [], duration_s=4.0, out=io.StringIO())
        stop.set()
        thread.join(5.0)
        channel.detach()
        channel.publish_alarm(raised)  # after detach: a no-op
    finally:
        stop.set()
        peer.close()
        bus.close()
    assert rows["a1"]["alarms"] == {"electrical_discharge": "critical"}
