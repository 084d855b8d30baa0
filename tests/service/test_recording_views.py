"""The recording for people: few large chunks, the blueprint once, a log row for every
setpoint / scenario state / restart / fallback, line breaks where rows are missing or a twin's
id starts a new run, and the resources of a removed twin freed. Real twins, files read back."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

pytest.importorskip("rerun")

from service.recording import RerunRecorder, describe_recording, read_column, read_index
from twin.engine import Twin

FRAME_S = 0.02  # one snapshot per 20 ms of simulated time (50 Hz)


@pytest.fixture(scope="module")
def run():
    """60 snapshots; a radial-load step after 20, a shaft-speed step after 40."""
    twin = Twin("6208", bearing_id="a")
    snaps = []
    for k in range(60):
        if k == 20:
            twin.set_setpoint(radial_load_n=4000.0)
        if k == 40:
            twin.set_setpoint(shaft_speed_rad_s=300.0)
        twin.advance(FRAME_S)
        snaps.append(twin.snapshot())
    return twin, snaps


def _events(path, bearing_id="a") -> list[tuple[int, str, str]]:
    seqs = read_column(path, f"bearing/{bearing_id}/events", "seq")
    texts = read_column(path, f"bearing/{bearing_id}/events", "TextLog:text")
    levels = read_column(path, f"bearing/{bearing_id}/events", "TextLog:level")
    return [(s, t[0], lv[0]) for s, t, lv in zip(seqs, texts, levels, strict=True)]


def test_one_chunk_per_entity_and_send_and_one_blueprint(tmp_path, run):
    """All rows of a send interval in one chunk per entity: 60 rows sent in 3 flushes give 3
    chunks per per-snapshot entity (not 60 x balls x fields); the blueprint is sent once."""
    twin, snaps = run
    path = tmp_path / "c.rrd"
    rec = RerunRecorder(path, flush_interval_s=1e6, slow_interval_s=1e6)
    rec.add_twin_from(twin)
    for part in (snaps[:20], snaps[20:40], snaps[40:]):
        for s in part:
            rec.publish(s)
        rec.flush()
    rec.close()
    info = describe_recording(path)
    assert info["blueprints"] == 1
    per_snapshot = {k: v for k, v in info["entities"].items() if v["rows"] == len(snaps)}
    assert len(per_snapshot) >= 20
    for entity, e in per_snapshot.items():
        assert e["chunks"] == 3, entity
    # 9 balls, 2 contacts, many fields: still about two dozen entities, not hundreds (besides one
    # alarm_states entity per alarm, whose state is logged from the first row on, and the
    # setpoint-change markers beside each trend)
    temporal = [
        k
        for k, v in info["entities"].items()
        if v["chunks"] and "/alarm_states/" not in k and not k.endswith("/changes")
    ]
    assert len(temporal) <= 30, temporal


def test_a_log_row_for_every_setpoint_scenario_restart_and_fallback(tmp_path, run):
    twin, snaps = run
    # without a scenario every setpoint change is a row at the snapshot that shows it
    plain = tmp_path / "plain.rrd"
    rec = RerunRecorder(plain)
    rec.add_twin_from(twin)
    for s in snaps:
        rec.publish(s)
    rec.close()
    at = {t: s for s, t, _ in _events(plain)}
    assert at["setpoint: radial_load_n 3000 -> 4000"] == snaps[20].seq
    assert at["setpoint: shaft_speed_rad_s 500 -> 300"] == snaps[40].seq

    path = tmp_path / "ev.rrd"
    scenario = SimpleNamespace(name="ramp", state="running", phase="up", error=None)
    rec = RerunRecorder(path)
    rec.add_twin_from(twin, context=lambda: scenario)
    for s in snaps[:30]:
        rec.publish(s)
    scenario.phase = "hold"
    for s in snaps[30:45]:
        rec.publish(s)
    scenario.state, scenario.phase = "done", None
    restarted = snaps[45].model_copy(update={"restarts": 1, "status": "restarted: penetration at t = 1 s"})
    rec.publish(restarted)
    fallback = snaps[46].model_copy(
        update={
            "restarts": 2,
            "status": "setpoint not held (penetration): radial_load_n = 9e4 N; restarted from the warm "
            "start at the last safe setpoint (radial_load_n = 4000 N); fallbacks: 1",
        }
    )
    rec.publish(fallback)
    for s in snaps[47:]:
        rec.publish(s.model_copy(update={"restarts": 2}))
    rec.close()
    ev = _events(path)
    texts = [t for _, t, _ in ev]
    assert texts[0] == "scenario ramp: running, phase up"
    assert texts[1].startswith("setpoint in force: shaft_speed_rad_s = ")
    assert texts[2] == "status: ok"
    at = {t: s for s, t, _ in ev}
    # while a scenario phase runs its setpoint changes (a ramp: every frame) are not logged one
    # by one; the change shows with the next phase, or when the scenario ends
    assert at["setpoint: radial_load_n 3000 -> 4000"] == snaps[30].seq
    assert at["setpoint: shaft_speed_rad_s 500 -> 300"] == snaps[45].seq
    assert sum(t.startswith("setpoint") for t in texts) == 3
    assert at["scenario ramp: running, phase hold"] == snaps[30].seq
    assert at["scenario ramp: done"] == snaps[45].seq
    restart = [(s, t, lv) for s, t, lv in ev if t.startswith("restart")]
    assert restart == [(snaps[45].seq, "restart (restarts: 1): restarted: penetration at t = 1 s", "WARN")]
    fb = [(s, lv) for s, t, lv in ev if t.startswith("fallback (restarts: 2): setpoint not held")]
    assert fb == [(snaps[46].seq, "ERROR")]
    assert at["status: ok"] in (snaps[0].seq, snaps[47].seq)


def test_line_breaks_where_rows_are_missing(tmp_path, run):
    """Snapshots lost before the recorder (a seq gap): an empty row half-way (the line breaks)
    on sim_time only, so the seq index still holds exactly the snapshots recorded."""
    twin, snaps = run
    path = tmp_path / "gap.rrd"
    kept = snaps[:10] + snaps[15:]
    rec = RerunRecorder(path)
    rec.add_twin_from(twin)
    for s in kept:
        rec.publish(s)
    rec.close()
    e = describe_recording(path)["entities"]["bearing/a/friction_torque_n_m"]
    assert e["rows"] == len(kept) and e["breaks"] == 1
    assert list(read_index(path, "bearing/a/friction_torque_n_m")) == [s.seq for s in kept]
    assert describe_recording(path)["entities"]["bearing/a/contacts/lambda"]["breaks"] == 1
    assert (snaps[15].seq, f"5 snapshots not recorded (seq {snaps[10].seq}..{snaps[14].seq})", "INFO") in _events(path)


def test_a_recreated_twin_continues_after_the_previous_run(tmp_path, run):
    """Delete a twin and create one with the same id: its simulated time starts at 0 again; the
    recording shows it after the previous run (1 s later, with a line break), not on top of it."""
    twin, snaps = run
    path = tmp_path / "again.rrd"
    rec = RerunRecorder(path)
    rec.add_twin_from(twin)
    for s in snaps[:20]:
        rec.publish(s)
    assert rec.remove_twin("a") and rec.bearing_ids == []
    rec.add_twin_from(twin)
    for s in snaps[:20]:  # time and seq start over
        rec.publish(s)
    rec.close()
    t = read_column(path, "bearing/a/friction_torque_n_m", "sim_time")
    first, second = t[:20], t[20:]
    assert second[0] == round((snaps[19].time_s + 1.0) * 1e9)
    assert np.all(np.diff(t) > 0)
    assert describe_recording(path)["entities"]["bearing/a/friction_torque_n_m"]["breaks"] == 1
    assert first == [round(s.time_s * 1e9) for s in snaps[:20]]
    assert any("new run of twin a" in text for _, text, _ in _events(path))


def test_removed_twins_leave_nothing_behind(tmp_path, run):
    """The recorder forgets a removed twin: entry, context, buffers (resources follow
    the twins); what it published before is in the file."""
    twin, snaps = run
    rec = RerunRecorder(tmp_path / "rm.rrd")
    for k in range(30):
        rec.add_twin_from(twin, bearing_id=f"t{k}", context=lambda: None)
        rec.publish(snaps[k].model_copy(update={"bearing_id": f"t{k}"}))
        rec.remove_twin(f"t{k}")
    assert rec.bearing_ids == [] and rec._context == {} and rec.queued == 0
    rec.close()
    rows = {k: v["rows"] for k, v in describe_recording(tmp_path / "rm.rrd")["entities"].items()}
    assert all(rows[f"bearing/t{k}/friction_torque_n_m"] == 1 for k in range(30))
