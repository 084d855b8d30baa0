"""Alarm events are logged in the rerun recording: a real twin's
snapshots and the events of the real `AlarmEvaluator` go through `RerunRecorder.log_alarm`; the
.rrd is read back. Entities (service.recording.layout): `bearing/{id}/alarms/{alarm_id}`
(TextLog with level) and `bearing/{id}/alarm_states/{alarm_id}` (StateChange), at the simulated
time and seq of the snapshot that caused the event."""

from __future__ import annotations

import pytest

pytest.importorskip("rerun")

from service.core.alarm_inputs import AlarmInputs
from service.core.alarm_rules import ALARM_IDS
from service.core.alarms import AlarmEvaluator
from service.recording import RerunRecorder, describe_recording, read_column, recording_segments
from service.settings import AlarmSettings
from twin.engine import Twin

FRAME_S = 0.02


@pytest.fixture(scope="module")
def run():
    """40 snapshots of a real twin, and the electrical alarm events of the real evaluator fed
    with a discharge risk that is 'possible' from snapshot 10, 'likely' from 20, 'none' from 30
    (no delays; a clear hold of one frame, so the clear comes one snapshot after the risk falls)."""
    twin = Twin("6208", bearing_id="a")
    ev = AlarmEvaluator("a", AlarmSettings(clear_hold_s=FRAME_S))
    snaps, events = [], []
    for k in range(40):
        twin.advance(FRAME_S)
        s = twin.snapshot()
        snaps.append(s)
        risk = "none" if k < 10 else "possible" if k < 20 else "likely" if k < 30 else "none"
        events += ev.update(AlarmInputs(time_s=s.time_s, seq=s.seq, discharge_risk=risk, discharge_reason="test"))
    assert [e.transition for e in events] == ["raised", "escalated", "cleared"]
    assert [e.snapshot_seq for e in events] == [snaps[k].seq for k in (10, 20, 31)]
    return twin, snaps, events


def _alarm_rows(path, alarm_id: str, bearing_id: str = "a"):
    base = f"bearing/{bearing_id}"
    return list(
        zip(
            read_column(path, f"{base}/alarms/{alarm_id}", "seq"),
            read_column(path, f"{base}/alarms/{alarm_id}", "sim_time"),
            [t[0] for t in read_column(path, f"{base}/alarms/{alarm_id}", "TextLog:text")],
            [lv[0] for lv in read_column(path, f"{base}/alarms/{alarm_id}", "TextLog:level")],
            strict=True,
        )
    )


def test_every_alarm_event_is_a_log_row_and_a_state_at_its_snapshot(tmp_path, run):
    twin, snaps, events = run
    path = tmp_path / "alarms.rrd"
    rec = RerunRecorder(path)
    rec.add_twin_from(twin)
    for s in snaps:
        rec.publish(s)
    for e in events:
        rec.log_alarm(e)
    rec.close()
    assert rec.alarms_logged == 3 and rec.alarms_dropped == 0

    rows = _alarm_rows(path, "electrical_discharge")
    assert [(seq, lv) for seq, _t, _text, lv in rows] == [
        (snaps[10].seq, "WARN"),
        (snaps[20].seq, "CRITICAL"),
        (snaps[31].seq, "INFO"),
    ]
    assert [t for _seq, t, _text, _lv in rows] == [round(snaps[k].time_s * 1e9) for k in (10, 20, 31)]
    raised, escalated, cleared = (text for _s, _t, text, _l in rows)
    assert raised.startswith("electrical_discharge raised warning: discharge risk possible: test")
    assert "[value 1, raise at 1, clear at 0.5]" in raised
    assert (
        escalated.startswith("electrical_discharge escalated to critical") and "raise at 2, clear at 1.5" in escalated
    )
    assert cleared.startswith("electrical_discharge cleared") and "[value 0," in cleared
    states = read_column(path, "bearing/a/alarm_states/electrical_discharge", "StateChange:state")
    # the state from the first row on ("inactive"), then one row per event
    assert [s[0] for s in states] == ["inactive", "warning", "critical", "inactive"]
    assert read_column(path, "bearing/a/alarm_states/electrical_discharge", "seq") == [
        snaps[k].seq for k in (0, 10, 20, 31)
    ]

    info = describe_recording(path)["entities"]
    # every alarm has its state configuration (values and colours) and its state from the start
    for alarm_id in ALARM_IDS:
        e = info[f"bearing/a/alarm_states/{alarm_id}"]
        assert "StateConfiguration:values" in e["components"]
        assert e["rows"] == 1 + (3 if alarm_id == "electrical_discharge" else 0)  # the first row's state too
    assert not any(k.startswith("bearing/a/alarms/") and k != "bearing/a/alarms/electrical_discharge" for k in info)


def test_events_of_a_twin_not_recorded_are_left_out_and_dicts_are_taken(tmp_path, run):
    twin, snaps, events = run
    path = tmp_path / "other.rrd"
    rec = RerunRecorder(path)
    rec.add_twin_from(twin)
    for s in snaps:
        rec.publish(s)
    rec.log_alarm(events[0].model_copy(update={"bearing_id": "somebody-else"}))
    rec.log_alarm(events[0].to_dict())  # the zenoh JSON form
    rec.log_alarm({"bearing_id": "a"})  # not an event: skipped, counted, never raised
    rec.close()
    assert rec.alarms_logged == 1 and rec.errors == 1
    assert [seq for seq, *_ in _alarm_rows(path, "electrical_discharge")] == [snaps[10].seq]
    assert not any("somebody-else" in k for k in describe_recording(path)["entities"])


def test_a_new_segment_starts_with_the_alarms_in_force(tmp_path, run):
    """Rotation: the second segment, complete on its own, shows the alarm raised in the first as
    its state from its first row on (no event in it)."""
    twin, snaps, events = run
    path = tmp_path / "seg.rrd"
    rec = RerunRecorder(path, flush_interval_s=1e6, slow_interval_s=1e6)
    rec.add_twin_from(twin)
    for s in snaps[:15]:
        rec.publish(s)
    rec.log_alarm(events[0])  # raised at snapshot 10
    rec.flush()
    second = rec.rotate()
    assert second is not None
    for s in snaps[15:20]:
        rec.publish(s)
    rec.close()
    states = read_column(second, "bearing/a/alarm_states/electrical_discharge", "StateChange:state")
    seqs = read_column(second, "bearing/a/alarm_states/electrical_discharge", "seq")
    assert [s[0] for s in states] == ["warning"] and seqs == [snaps[15].seq]
    assert read_column(second, "bearing/a/alarms/electrical_discharge", "seq") == []  # the event is in the first
    both = recording_segments(path)
    assert [s[0] for s in read_column(both, "bearing/a/alarm_states/electrical_discharge", "StateChange:state")] == [
        "inactive",
        "warning",
        "warning",
    ]  # from the first row on


def test_the_blueprint_has_the_alarm_views():
    import rerun.blueprint as rrb

    from service.recording.blueprint import twin_blueprint
    from service.recording.layout import TwinLayout

    views = []

    def walk(node):
        for child in node.contents or []:
            if isinstance(child, rrb.View):
                views.append(child)
            else:
                walk(child)

    walk(twin_blueprint(TwinLayout("a", "6208", 9), 10.0))
    by_name = {v.name: v for v in views}
    assert isinstance(by_name["a: alarm states"], rrb.StateTimelineView)
    assert isinstance(by_name["a: alarm events"], rrb.TextLogView)
    assert by_name["a: alarm states"].contents == ["+ /bearing/a/alarm_states/**"]
    assert by_name["a: alarm events"].contents == ["+ /bearing/a/alarms/**"]
