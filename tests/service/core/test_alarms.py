"""Alarms with state (service.core.alarms, service.core.alarm_hub) on synthetic inputs: ISO
20816-3:2022 zone boundaries (Annex A, Tables A.1 and A.2), the deadband and on/off-delays of
ANSI/ISA-18.2-2016 clause 11.5, the lubrication alarm on a sequence of snapshots (seed 000 Table 2:
boundary for Lambda <= 1), defect lines against the envelope noise floor, electrical risk, life."""

from __future__ import annotations

import json
import math
from types import SimpleNamespace

import pytest

from service.core.alarm_hub import AlarmHub
from service.core.alarm_inputs import AlarmInputs, VibrationInputs, inputs_from_snapshot, vibration_inputs
from service.core.alarm_rules import ALARM_IDS, Level, Rule, vibration_zone, zone_boundaries
from service.core.alarms import AlarmEvaluator, AlarmTracker
from service.settings import AlarmSettings


# ---- ISO 20816-3 zones -----------------------------------------------------------------------
@pytest.mark.parametrize(
    ("group", "support", "expected"),
    [
        (1, "rigid", (2.3, 4.5, 7.1)),  # ISO 20816-3:2022 Table A.1, group 1, rigid
        (1, "flexible", (3.5, 7.1, 11.0)),  # Table A.1, flexible
        (2, "rigid", (1.4, 2.8, 4.5)),  # Table A.2, group 2, rigid
        (2, "flexible", (2.3, 4.5, 7.1)),  # Table A.2, flexible
    ],
)
def test_zone_boundaries_are_those_of_iso_20816_3_annex_a(group, support, expected):
    assert zone_boundaries(group, support) == expected


def test_zones_a_to_d_with_boundaries_in_the_worse_zone():
    assert [vibration_zone(v, 2, "rigid") for v in (0.5, 1.39, 1.4, 2.79, 2.8, 4.49, 4.5, 20.0)] == [
        "A",
        "A",
        "B",
        "B",
        "C",
        "C",
        "D",
        "D",
    ]
    assert vibration_zone(5.0, 1, "flexible") == "B"  # the same 5 mm/s is D for group 2 rigid
    with pytest.raises(ValueError, match="machine group 3"):
        zone_boundaries(3, "rigid")


def _vib(v: float, t: float, **kw) -> AlarmInputs:
    return AlarmInputs(time_s=t, vibration=VibrationInputs(velocity_rms_mm_s=v, **kw))


def test_vibration_zone_alarm_raises_escalates_and_clears_with_hysteresis():
    ev = AlarmEvaluator("p1", AlarmSettings(machine_group=2, support="rigid", clear_hold_s=1.0))
    log = []

    def feed(v, t):
        out = [e for e in ev.update(_vib(v, t)) if e.alarm_id == "vibration_zone"]
        log.extend(out)
        return out

    assert feed(2.0, 0.0) == []  # zone B: nothing
    (e,) = feed(3.0, 0.1)  # zone C: warning at the B/C boundary
    assert (e.transition, e.severity, e.threshold, e.value) == ("raised", "warning", 2.8, 3.0)
    assert e.clear_threshold == pytest.approx(0.9 * 2.8)
    (e,) = feed(5.0, 0.2)  # zone D: critical
    assert (e.transition, e.severity, e.threshold, e.since_s) == ("escalated", "critical", 4.5, 0.1)
    assert feed(4.2, 0.3) == []  # below C/D 4.5 but above its clear 4.05
    assert feed(3.9, 0.4) == []  # below 4.05: off-delay starts
    assert feed(4.1, 0.9) == []  # back above 4.05: off-delay reset
    assert feed(3.9, 1.0) == [] and feed(3.9, 1.99) == []
    (e,) = feed(3.9, 2.0)  # 1.0 s below the clear threshold
    assert (e.transition, e.severity, e.active) == ("deescalated", "warning", True)
    assert feed(2.6, 2.5) == [] and feed(2.6, 4.0) == []  # 2.6 > 0.9 x 2.8 = 2.52: held
    assert feed(2.4, 4.1) == []
    (e,) = feed(2.4, 5.1)
    assert (e.transition, e.severity, e.active, e.since_s) == ("cleared", None, False, None)
    assert [x.seq for x in log] == sorted(x.seq for x in log)


def test_vibration_alarm_follows_the_machine_group_and_support():
    quiet = AlarmEvaluator("p", AlarmSettings(machine_group=1, support="flexible"))
    assert [e for e in quiet.update(_vib(5.0, 0.0)) if e.alarm_id == "vibration_zone"] == []  # zone B
    loud = AlarmEvaluator("p", AlarmSettings(machine_group=2, support="rigid"))
    (e,) = [e for e in loud.update(_vib(5.0, 0.0)) if e.alarm_id == "vibration_zone"]
    assert e.severity == "critical" and "zone D" in e.message


# ---- the generic state machine ---------------------------------------------------------------
def test_on_delay_needs_a_continuous_excursion_and_undefined_values_change_nothing():
    rule = Rule("x", "test", "-", "above", raise_delay_s=1.0, clear_hold_s=0.5, description="")
    tr = AlarmTracker(rule)
    lv = (Level("warning", 10.0, 9.0),)
    assert tr.update(0.0, 11.0, lv) is None
    assert tr.update(0.9, 9.5, lv) is None  # dipped below the threshold: on-delay reset
    assert tr.update(1.0, 11.0, lv) is None
    assert tr.update(1.5, None, lv) is None  # undefined: no change, timers reset
    assert tr.update(2.0, 11.0, lv) is None
    assert tr.update(2.99, 11.0, lv) is None
    assert tr.update(3.0, 11.0, lv) == "raised" and tr.since_s == 3.0
    assert tr.update(3.1, math.nan, lv) is None and tr.active and tr.value is None
    assert tr.update(10.0, 8.0, lv) is None and tr.update(10.49, 8.0, lv) is None
    assert tr.update(10.5, 8.0, lv) == "cleared" and not tr.active


def test_clock_going_back_resets_the_delays():
    tr = AlarmTracker(Rule("x", "t", "-", "above", 1.0, 0.0, ""))
    lv = (Level("warning", 1.0, 0.9),)
    assert tr.update(5.0, 2.0, lv) is None
    assert tr.update(0.5, 2.0, lv) is None  # a restarted twin: t went back, start again
    assert tr.update(1.4, 2.0, lv) is None
    assert tr.update(1.5, 2.0, lv) == "raised"


# ---- lubrication on a sequence of snapshots --------------------------------------------------
def _snapshot(
    t: float,
    lam_loaded: float,
    *,
    load_n: float = 2000.0,
    light=(10.0, 0.5),
    kappa=None,
    risk: str = "none",
    damage=None,
    bearing_id: str = "b1",
) -> dict:
    """A snapshot dict: 4 balls, two loaded inner/outer contacts with Lambda `lam_loaded`, one
    lightly loaded contact (load, Lambda) = `light`, the rest unloaded."""

    def contact(load, lam):
        return {"load_n": load, "lambda": lam, "regime": "boundary" if lam is not None and lam <= 1 else "mixed"}

    balls = [
        {"inner": contact(load_n, lam_loaded), "outer": contact(0.8 * load_n, lam_loaded * 1.1)},
        {"inner": contact(0.5 * load_n, lam_loaded * 1.05), "outer": contact(*light)},
        {"inner": contact(0.0, None), "outer": contact(0.0, None)},
        {"inner": contact(0.0, None), "outer": contact(0.0, None)},
    ]
    snap = {
        "bearing_id": bearing_id,
        "time_s": t,
        "balls": balls,
        "electrical": {"discharge_risk": risk, "reason": f"because {risk}"},
    }
    if kappa is not None or damage is not None:
        snap["life"] = {"kappa": kappa, "damage_fraction": damage}
    return snap


def test_inputs_count_only_loaded_contacts():
    x = inputs_from_snapshot(_snapshot(0.0, 1.75, light=(10.0, 0.5)))
    assert x.min_loaded_lambda == pytest.approx(1.75)  # the 10 N contact at Lambda 0.5 is ignored
    assert x.boundary_contacts == 0
    assert x.kappa is None and x.damage_fraction is None and x.vibration is None
    x = inputs_from_snapshot(_snapshot(0.0, 0.4))
    assert x.min_loaded_lambda == pytest.approx(0.4) and x.boundary_contacts == 3
    every = inputs_from_snapshot(_snapshot(0.0, 1.75), AlarmSettings(loaded_contact_fraction=0.0))
    assert every.min_loaded_lambda == pytest.approx(0.5)  # with every loaded contact counted


def test_lubrication_alarm_raises_after_the_delay_and_clears_with_hysteresis():
    """Load up and oil hot (Lambda 1.75 -> 0.37, the 6208 at 8 kN and 110 degC), then back: the
    boundary alarm rises lubrication_delay_s after the drop and clears clear_hold_s after Lambda
    is back above 1 / clear_ratio."""
    s = AlarmSettings(lubrication_delay_s=1.0, clear_hold_s=0.5, clear_ratio=0.9)
    ev = AlarmEvaluator("b1", s)
    seq = [(t / 10, 1.75) for t in range(10)]  # 0 .. 0.9 s: mixed regime
    seq += [(1.0 + t / 10, 0.37) for t in range(15)]  # 1.0 .. 2.4 s: boundary
    seq += [(2.5 + t / 10, 1.05) for t in range(5)]  # 2.5 .. 2.9: above 1, below 1/0.9
    seq += [(3.0 + t / 10, 1.75) for t in range(10)]  # 3.0 .. 3.9: back to mixed
    events = []
    for t, lam in seq:
        events += [
            (t, e)
            for e in ev.update(inputs_from_snapshot(_snapshot(t, lam), s))
            if e.alarm_id.startswith("lubrication")
        ]
    assert [(round(t, 6), e.alarm_id, e.transition) for t, e in events] == [
        (2.0, "lubrication_boundary", "raised"),
        (3.5, "lubrication_boundary", "cleared"),
    ]
    raised, cleared = events[0][1], events[1][1]
    assert raised.value == pytest.approx(0.37) and raised.threshold == 1.0
    assert raised.clear_threshold == pytest.approx(1.0 / 0.9) and raised.since_s == pytest.approx(2.0)
    assert raised.severity == "warning" and "3 loaded contact(s) in the boundary regime" in raised.message
    assert cleared.value == pytest.approx(1.75) and not cleared.active
    body = json.loads(raised.to_json())
    assert body["schema"] == "bearing-twin/alarm/1" and body["bearing_id"] == "b1"


def test_kappa_alarm_from_the_life_block():
    s = AlarmSettings(lubrication_delay_s=0.2, clear_hold_s=0.0)
    ev = AlarmEvaluator("b1", s)
    out = []
    for t, kappa in ((0.0, 2.0), (0.1, 0.8), (0.2, 0.8), (0.3, 0.8), (0.4, None), (0.5, 1.2)):
        out += [
            (t, e.transition)
            for e in ev.update(inputs_from_snapshot(_snapshot(t, 1.75, kappa=kappa), s))
            if e.alarm_id == "lubrication_kappa"
        ]
    assert out == [(0.3, "raised"), (0.5, "cleared")]  # 1.2 > 1 / 0.9: clears at once


def test_electrical_discharge_levels():
    ev = AlarmEvaluator("b1", AlarmSettings(clear_hold_s=0.0))
    got = []
    for t, risk in ((0.0, "none"), (0.1, "possible"), (0.2, "likely"), (0.3, "possible"), (0.4, "none")):
        got += [
            (e.transition, e.severity, e.value)
            for e in ev.update(inputs_from_snapshot(_snapshot(t, 2.0, risk=risk)))
            if e.alarm_id == "electrical_discharge"
        ]
    assert got == [
        ("raised", "warning", 1.0),
        ("escalated", "critical", 2.0),
        ("deescalated", "warning", 1.0),
        ("cleared", None, 0.0),
    ]


def test_life_used_alarm():
    ev = AlarmEvaluator("b1", AlarmSettings(life_used_warning=0.5, life_used_critical=0.9))
    got = []
    for t, d in ((0.0, 0.1), (1.0, 0.6), (2.0, 0.95)):
        got += [
            (e.transition, e.severity)
            for e in ev.update(inputs_from_snapshot(_snapshot(t, 2.0, damage=d)))
            if e.alarm_id == "life_used"
        ]
    assert got == [("raised", "warning"), ("escalated", "critical")]
    with pytest.raises(ValueError, match="life_used_critical"):
        AlarmSettings(life_used_warning=0.9, life_used_critical=0.5)


# ---- defect lines and vibration from synthetic indicator inputs --------------------------------
def _indicator_lines(bpfo: float, others: float = 0.05) -> dict:
    """The snapshot's `vibration.envelope_lines` (twin.snapshot.DefectLine as dicts, fundamental first)."""
    return {
        name: {"frequency_hz": f, "harmonics": [a, 0.5 * a, 0.25 * a]}
        for name, f, a in (
            ("ftf", 15.0, others),
            ("bpfo", 107.0, bpfo),
            ("bpfi", 162.0, others),
            ("bsf", 70.0, others),
            ("two_bsf", 140.0, others),
        )
    }


def test_vibration_inputs_read_the_snapshot_fields():
    v = vibration_inputs(
        {"velocity_rms_mm_s": 3.2, "envelope_lines": _indicator_lines(2.0), "envelope_noise_floor_m_s2": 0.1}
    )
    assert v.velocity_rms_mm_s == 3.2 and v.noise_floor_m_s2 == 0.1
    assert v.line_amplitudes_m_s2 == {"ftf": 0.05, "bpfo": 2.0, "bpfi": 0.05, "bsf": 0.05, "two_bsf": 0.05}
    assert vibration_inputs(None) is None
    # the pydantic block itself (twin.snapshot.VibrationState) reads the same
    from twin.snapshot import VibrationState

    block = VibrationState.model_validate(
        {
            "window_end_s": 1.0,
            "window_s": 1.0,
            "sample_rate_hz": 51200.0,
            "shaft_speed_rad_s": 500.0,
            "contact_angle_rad": 0.0,
            "rms_m_s2": 1.0,
            "peak_m_s2": 4.0,
            "crest_factor": 4.0,
            "kurtosis": 3.0,
            "band_kurtosis": 3.0,
            "velocity_rms_mm_s": 3.2,
            "defect_frequencies_hz": {"ftf": 15.0, "bpfo": 107.0, "bpfi": 162.0, "bsf": 70.0, "two_bsf": 140.0},
            "envelope_band_hz": [10000.0, 20000.0],
            "envelope_peaks_hz": [],
            "envelope_noise_floor_m_s2": 0.1,
            "envelope_lines": _indicator_lines(2.0),
        }
    )
    assert vibration_inputs(block) == v


def test_outer_race_defect_raises_the_vibration_and_bpfo_alarms_only():
    """An outer-race spall: broadband velocity up to zone D and the BPFO envelope line 20x the
    floor; the other lines at the floor stay quiet."""
    ev = AlarmEvaluator("b1", AlarmSettings(defect_amplitude_m_s2=0.5, defect_significance=4.0))
    healthy = {"velocity_rms_mm_s": 1.0, "envelope_lines": _indicator_lines(0.1, 0.1), "envelope_noise_floor_m_s2": 0.1}
    assert ev.update(inputs_from_snapshot({**_snapshot(0.0, 2.0), "vibration": healthy})) == []
    faulty = {"velocity_rms_mm_s": 5.0, "envelope_lines": _indicator_lines(2.0, 0.1), "envelope_noise_floor_m_s2": 0.1}
    events = {e.alarm_id: e for e in ev.update(inputs_from_snapshot({**_snapshot(0.1, 2.0), "vibration": faulty}))}
    assert set(events) == {"vibration_zone", "defect_bpfo"}
    assert events["vibration_zone"].severity == "critical"
    assert events["defect_bpfo"].value == 2.0 and events["defect_bpfo"].threshold == 0.5
    assert {a.alarm_id for a in ev.active()} == {"vibration_zone", "defect_bpfo"}


def test_defect_threshold_rises_with_the_noise_floor():
    ev = AlarmEvaluator("b1", AlarmSettings(defect_amplitude_m_s2=0.5, defect_significance=4.0))
    noisy = {"envelope_lines": _indicator_lines(2.0), "envelope_noise_floor_m_s2": 0.6}  # 4 x 0.6 = 2.4 > 2.0
    assert [
        e
        for e in ev.update(inputs_from_snapshot({**_snapshot(0.0, 2.0), "vibration": noisy}))
        if e.alarm_id == "defect_bpfo"
    ] == []
    (state,) = [a for a in ev.states() if a.alarm_id == "defect_bpfo"]
    assert state.threshold == pytest.approx(2.4) and not state.active


def test_every_alarm_has_a_state_and_ids_are_stable():
    ev = AlarmEvaluator("b1")
    assert [a.alarm_id for a in ev.states()] == list(ALARM_IDS)
    assert all(not a.active and a.threshold is not None for a in ev.states())


# ---- the hub -----------------------------------------------------------------------------------
def _ns(snap: dict) -> SimpleNamespace:
    return SimpleNamespace(**snap)


def test_hub_evaluates_off_thread_and_hands_events_to_every_subscriber():
    hub = AlarmHub(AlarmSettings(lubrication_delay_s=0.0, clear_hold_s=0.0))
    got, calls = [], []

    def broken(event):
        calls.append(event)
        raise RuntimeError("subscriber down")

    hub.subscribe(broken)
    hub.subscribe(got.append)
    hub.add_twin("b1")
    try:
        hub.publish(_ns(_snapshot(0.0, 0.4)))
        hub.publish(_ns(_snapshot(0.1, 0.4, bearing_id="unknown")))  # not added: ignored
        hub.publish(_ns(_snapshot(0.2, 1.8)))
        assert hub.wait_idle(10.0)
        assert [(e.alarm_id, e.transition) for e in got] == [
            ("lubrication_boundary", "raised"),
            ("lubrication_boundary", "cleared"),
        ]
        assert len(calls) == 2 and hub.subscriber_errors == 2
        assert [e.transition for e in hub.events("b1")] == ["raised", "cleared"]
        assert hub.events("b1", 1)[0].transition == "cleared" and hub.events("unknown") == []
        assert hub.active("b1") == [] and len(hub.states("b1")) == len(ALARM_IDS)
        hub.forget("b1")
        assert hub.states("b1") == [] and hub.events("b1") == []
    finally:
        hub.close()
    hub.publish(_ns(_snapshot(0.3, 0.4)))  # after close: ignored, never raises
