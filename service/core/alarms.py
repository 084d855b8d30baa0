"""Alarms with state: pure functions and state machines, no I/O, no threads, no transport.

`AlarmEvaluator(bearing_id, settings).update(inputs) -> [AlarmEvent]` follows one twin. Its
inputs are typed (`AlarmInputs`), made from a snapshot by `inputs_from_snapshot`; the blocks a
snapshot may not carry yet (`life`, `vibration`) are optional, and their alarms stay quiet while
they are absent. The alarm ids, the zone table and the `Rule` / `Level` types live in
service.core.alarm_rules; the inputs and their reading from a snapshot in service.core.alarm_inputs.

The alarms (ids are stable; docs/service.md "Alarms"):

* `vibration_zone` - ISO 20816-3:2022 evaluation zones from the broadband velocity RMS
  [mm/s] (10-1000 Hz, snapshot `vibration.velocity_rms_mm_s`, twin.vibration.indicators). Zone boundaries of Annex A,
  Table A.1 (group 1: large machines, 300 kW to 50 MW) and Table A.2 (group 2: medium machines,
  15 kW to 300 kW), rigid / flexible support (clause 4.4). Zone C ("unsatisfactory for long-term
  continuous operation") raises a warning, zone D ("severe enough to cause damage") a critical
  alarm (ISO 20816-1:2016 clause 6.2.2 zone descriptions); zones A and B raise nothing.
* `lubrication_kappa` - kappa = nu / nu1 (ISO 281:2007 clause 9.3, snapshot `life.kappa`) below
  `kappa_threshold` (1: the oil is thinner than the rated viscosity).
* `lubrication_boundary` - a loaded contact in the boundary regime: the smallest film parameter
  Lambda over the loaded contacts at or below `boundary_lambda` (seed 000 Table 2: boundary for
  Lambda <= 1). A contact is loaded when it carries at least `loaded_contact_fraction` of the
  largest contact load (the light contacts at the edge of the load zone do not count).
  Both lubrication alarms rise only after the condition lasts `lubrication_delay_s`.
* `electrical_discharge` - snapshot `electrical.discharge_risk`: 'possible' warning, 'likely'
  critical (the value is 0 / 1 / 2 for none / possible / likely; the message quotes the
  engine's reason).
* `defect_ftf`, `defect_bpfo`, `defect_bpfi`, `defect_bsf`, `defect_two_bsf` - envelope-spectrum
  amplitude at the fundamental of a defect frequency [m/s^2] (snapshot
  `vibration.envelope_lines[name].harmonics[0]`; 2 x BSF is the rate at which a ball defect
  strikes the races) above `defect_amplitude_m_s2` and above `defect_significance` x the
  envelope noise floor (`vibration.envelope_noise_floor_m_s2`) when the floor is known (Randall
  & Antoni 2011 sec. 3.3; twin.vibration.indicators.SIGNIFICANCE).
* `life_used` - Palmgren-Miner damage fraction (snapshot `life.damage_fraction`) above
  `life_used_warning` (warning) and `life_used_critical` (critical).
* `temperature_zone` - outer-ring temperature (snapshot `thermal.temperatures_c.outer_ring`, the
  measured one when a measurement is assimilated) above `temperature_warning_c` (82 degC: the oil
  sump limit of ISO 13709 / API 610) and `temperature_critical_c`.
* `temperature_rate` - rate of rise of the outer ring over a minute of thermal time (snapshot
  `thermal.outer_ring_rate_k_per_min`) above `temperature_rate_warning_k_per_min` and
  `temperature_rate_critical_k_per_min`.
* `temperature_unexplained` - the dissipation estimator gated the last measured temperature
  (snapshot `thermal.unexplained_heating`): heat the friction and the dissipation cannot
  explain (lubricant loss, overload, a failing bearing; twin.thermal.estimator); critical.
* `measured_line` - a measured accelerometer window (service.core.measured, posted over HTTP or
  zenoh) shows a defect line (BPFO, BPFI, 2 x BSF) at least `LINE_ALARM_DB` over its background
  for a defect the twin does not hold; value: the highest such line [dB]; warning.
* `measured_kurtosis` - the measured window's kurtosis above the twin's own by more than
  `KURTOSIS_MARGIN`; value: measured - predicted [-]; warning.
  Both follow the windows (`update_measured`), not the snapshots: a later window without the
  finding clears them after `clear_hold_s` of twin time.

State (`AlarmTracker`): every alarm has ordered levels (warning, critical), each with a raise
threshold and a clear threshold on the safe side of it (a deadband; `clear_ratio`). A level is
entered once the value has stayed beyond its raise threshold for the alarm's raise delay (an
on-delay), and left once the value has stayed on the safe side of its clear threshold for
`clear_hold_s` (an off-delay): the deadband and on/off-delays of alarm rationalisation in
ANSI/ISA-18.2-2016 (IEC 62682:2014) clause 11.5. Each transition is an `AlarmEvent`: raised,
escalated, deescalated, cleared. Times are the twin's simulated time [s] (a fast-mode twin
judges durations on its own clock); events also carry the wall-clock time they were made.
A value that is undefined (null: kappa at rest, no vibration block) changes nothing and resets
the pending on/off-delays.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterable, Mapping
from typing import Any

from pydantic import BaseModel, ConfigDict, Field

from service.core.alarm_inputs import AlarmInputs, VibrationInputs
from service.core.alarm_rules import (
    DEFECT_LINES,
    DISCHARGE_LEVELS,
    EVENT_SCHEMA,
    OPCUA_SEVERITY,
    TIME_EPS_S,
    Level,
    Rule,
    Severity,
    Transition,
    line_name,
    vibration_zone,
    zone_boundaries,
)
from service.core.json_numbers import finite_number
from service.core.measured import KURTOSIS_MARGIN, LINE_ALARM_DB
from service.settings import AlarmSettings

__all__ = ["Alarm", "AlarmEvaluator", "AlarmEvent", "AlarmTracker"]


# ---- state machine -----------------------------------------------------------------------------


class AlarmEvent(BaseModel):
    """A transition of one alarm: JSON on zenoh `bearing/{id}/alarm`, rows in the recording,
    OPC UA events (docs/service.md "Alarms")."""

    model_config = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False)
    schema_: str = Field(
        default=EVENT_SCHEMA,
        alias="schema",
        serialization_alias="schema",
        description="Message schema identifier [text].",
    )
    seq: int = Field(description="Per-twin counter of alarm events [-].")
    bearing_id: str = Field(description="Twin name [text].")
    alarm_id: str = Field(description="Alarm id, e.g. 'lubrication_boundary' [text].")
    category: str = Field(description="vibration | lubrication | electrical | defect | life [text].")
    transition: Transition = Field(description="raised | escalated | deescalated | cleared [text].")
    active: bool = Field(description="Whether the alarm is active after this event [bool].")
    severity: Severity | None = Field(description="Level after the event; null when cleared [text].")
    opcua_severity: int = Field(
        description="OPC UA event severity 1..1000 (warning 500, critical 800, cleared 100) [-]."
    )
    since_s: float | None = Field(description="Simulated time the alarm was raised; null when cleared [s].")
    time_s: float = Field(description="Simulated time of this event [s].")
    snapshot_seq: int | None = Field(
        default=None,
        description="seq of the snapshot that caused the event; null when the inputs came from elsewhere [-].",
    )
    wall_time_s: float = Field(description="Wall-clock time of this event, seconds since the Unix epoch [s].")
    value: float = Field(description="The watched value at the event [unit].")
    threshold: float = Field(description="Raise threshold of the level concerned [unit].")
    clear_threshold: float = Field(description="Clear threshold of that level (hysteresis) [unit].")
    unit: str = Field(description="Unit of value and thresholds [text].")
    message: str = Field(description="What happened, in words [text].")

    def to_dict(self) -> dict:
        return self.model_dump(by_alias=True, mode="json")

    def to_json(self) -> str:
        return self.model_dump_json(by_alias=True)


class Alarm(BaseModel):
    """The state of one alarm of one twin (GET /v1/bearings/{id}/alarms)."""

    model_config = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False)
    alarm_id: str = Field(description="Alarm id [text].")
    category: str = Field(description="vibration | lubrication | electrical | defect | life [text].")
    description: str = Field(description="What it watches [text].")
    active: bool = Field(description="Whether it is active [bool].")
    severity: Severity | None = Field(description="warning | critical; null when inactive [text].")
    since_s: float | None = Field(description="Simulated time it was raised; null when inactive [s].")
    since_wall_time_s: float | None = Field(
        description="Wall-clock time it was raised (Unix epoch); null when inactive [s]."
    )
    value: float | None = Field(description="Latest value; null when undefined (e.g. no vibration block) [unit].")
    threshold: float | None = Field(description="Raise threshold of the active level, else of the first level [unit].")
    clear_threshold: float | None = Field(description="Clear threshold of that level [unit].")
    unit: str = Field(description="Unit of value and thresholds [text].")
    message: str = Field(description="Latest word on it [text].")


class AlarmTracker:
    """One alarm's state machine (module docstring: deadband and on/off-delays)."""

    def __init__(self, rule: Rule):
        self.rule = rule
        self.level = -1  # index into the levels, -1 inactive
        self.since_s: float | None = None  # simulated time raised
        self.since_wall_s: float | None = None
        self.value: float | None = None
        self.levels: tuple[Level, ...] = ()
        self.message = ""
        self._pending_level = -1  # level waiting for its on-delay
        self._pending_since: float | None = None
        self._clear_since: float | None = None
        self._last_t: float | None = None

    @property
    def active(self) -> bool:
        return self.level >= 0

    def _reset_timers(self) -> None:
        self._pending_level, self._pending_since, self._clear_since = -1, None, None

    def update(
        self, t: float, value: float | None, levels: Iterable[Level], message: str = "", wall_s: float = 0.0
    ) -> Transition | None:
        """Feed the value at simulated time `t`; the transition it causes, if any."""
        levels = tuple(levels)
        self.levels = levels
        if self._last_t is not None and t < self._last_t:
            self._reset_timers()  # the clock went back (a restarted twin)
        self._last_t = t
        if value is None or not math.isfinite(value) or not levels:
            self.value = None if value is None or not math.isfinite(value) else value
            self._reset_timers()
            return None
        self.value, self.message = value, message
        rule = self.rule
        raised = max((i for i, lv in enumerate(levels) if rule.beyond(value, lv.threshold)), default=-1)
        held = max((i for i, lv in enumerate(levels) if rule.beyond(value, lv.clear)), default=-1)
        held = max(held, raised)
        if raised > self.level:  # towards a worse level: on-delay
            self._clear_since = None
            if self._pending_since is None:
                self._pending_since = t
            self._pending_level = raised
            if t - self._pending_since >= rule.raise_delay_s - TIME_EPS_S:
                was = self.level
                self.level = raised
                self._reset_timers()
                if was < 0:
                    self.since_s, self.since_wall_s = t, wall_s
                    return "raised"
                return "escalated"
            return None
        self._pending_level, self._pending_since = -1, None
        if held < self.level:  # back past the clear threshold: off-delay
            if self._clear_since is None:
                self._clear_since = t
            if t - self._clear_since >= rule.clear_hold_s - TIME_EPS_S:
                self.level = held
                self._clear_since = None
                if held < 0:
                    self.since_s = self.since_wall_s = None
                    return "cleared"
                return "deescalated"
            return None
        self._clear_since = None
        return None

    def state(self) -> Alarm:
        lv = self.levels[self.level] if self.active else (self.levels[0] if self.levels else None)
        return Alarm(
            alarm_id=self.rule.id,
            category=self.rule.category,
            description=self.rule.description,
            active=self.active,
            severity=lv.severity if self.active and lv is not None else None,
            since_s=self.since_s,
            since_wall_time_s=self.since_wall_s,
            value=self.value,
            threshold=lv.threshold if lv else None,
            clear_threshold=lv.clear if lv else None,
            unit=self.rule.unit,
            message=self.message,
        )


# ---- the alarms of one twin --------------------------------------------------------------------
def _above(severity: Severity, threshold: float, ratio: float) -> Level:
    return Level(severity, threshold, threshold * ratio)


def _below(severity: Severity, threshold: float, ratio: float) -> Level:
    return Level(severity, threshold, threshold / ratio)


class AlarmEvaluator:
    """Every alarm of one twin (module docstring); `update(inputs)` returns the events."""

    def __init__(
        self, bearing_id: str, settings: AlarmSettings | None = None, wall_clock: Callable[[], float] = time.time
    ):
        s = self.settings = settings or AlarmSettings()
        self.bearing_id = bearing_id
        self._wall_clock = wall_clock
        self.seq = 0
        zones = zone_boundaries(s.machine_group, s.support)
        self.zones = zones
        hold = s.clear_hold_s
        table = (
            f"ISO 20816-3:2022 Table A.{s.machine_group}, group {s.machine_group}, {s.support} "
            f"support: A/B {zones[0]:g}, B/C {zones[1]:g}, C/D {zones[2]:g} mm/s"
        )
        rules = [
            Rule(
                "vibration_zone",
                "vibration",
                "mm/s",
                "above",
                s.vibration_delay_s,
                hold,
                f"Velocity RMS 10-1000 Hz in zone C (warning) or D (critical) of {table}",
            ),
            Rule(
                "lubrication_kappa",
                "lubrication",
                "-",
                "below",
                s.lubrication_delay_s,
                hold,
                f"kappa = nu / nu1 (ISO 281:2007 clause 9.3) below {s.kappa_threshold:g} for "
                f"{s.lubrication_delay_s:g} s",
            ),
            Rule(
                "lubrication_boundary",
                "lubrication",
                "-",
                "below",
                s.lubrication_delay_s,
                hold,
                f"a loaded contact in the boundary regime (Lambda <= {s.boundary_lambda:g}, seed 000 "
                f"Table 2) for {s.lubrication_delay_s:g} s; value: the smallest Lambda of the "
                f"contacts carrying >= {s.loaded_contact_fraction:g} x the largest load",
            ),
            Rule(
                "electrical_discharge",
                "electrical",
                "-",
                "above",
                s.discharge_delay_s,
                hold,
                "electrical discharge risk: possible (warning), likely (critical); value 0/1/2 = none/possible/likely",
            ),
            *(
                Rule(
                    f"defect_{n}",
                    "defect",
                    "m/s^2",
                    "above",
                    s.defect_delay_s,
                    hold,
                    f"envelope amplitude at {line_name(n)} above {s.defect_amplitude_m_s2:g} m/s^2 and "
                    f"{s.defect_significance:g} x the envelope noise floor",
                )
                for n in DEFECT_LINES
            ),
            Rule(
                "life_used",
                "life",
                "-",
                "above",
                0.0,
                hold,
                f"Palmgren-Miner damage fraction above {s.life_used_warning:g} (warning), "
                f"{s.life_used_critical:g} (critical)",
            ),
            Rule(
                "temperature_zone",
                "thermal",
                "degC",
                "above",
                s.temperature_delay_s,
                hold,
                f"outer ring above {s.temperature_warning_c:g} degC (warning; ISO 13709 / API 610 oil sump "
                f"limit 82 degC) or {s.temperature_critical_c:g} degC (critical)",
            ),
            Rule(
                "temperature_rate",
                "thermal",
                "K/min",
                "above",
                s.temperature_delay_s,
                hold,
                f"outer ring rising faster than {s.temperature_rate_warning_k_per_min:g} K/min (warning) or "
                f"{s.temperature_rate_critical_k_per_min:g} K/min (critical) over a minute of thermal time",
            ),
            Rule(
                "temperature_unexplained",
                "thermal",
                "-",
                "above",
                0.0,
                hold,
                "measured temperature beyond what the friction and the dissipation explain (the estimator's "
                "innovation gate); value 1 = unexplained",
            ),
            Rule(
                "measured_line",
                "vibration",
                "dB",
                "above",
                0.0,
                hold,
                f"a measured window shows a defect line at least {LINE_ALARM_DB:g} dB over its background for "
                "a defect the twin does not hold; value: the highest such line",
            ),
            Rule(
                "measured_kurtosis",
                "vibration",
                "-",
                "above",
                0.0,
                hold,
                f"measured kurtosis above the twin's by more than {KURTOSIS_MARGIN:g}; value: measured - predicted",
            ),
        ]
        self.trackers: dict[str, AlarmTracker] = {r.id: AlarmTracker(r) for r in rules}
        r = s.clear_ratio
        self._static_levels = {
            "vibration_zone": (_above("warning", zones[1], r), _above("critical", zones[2], r)),
            "lubrication_kappa": (_below("warning", s.kappa_threshold, r),),
            "lubrication_boundary": (_below("warning", s.boundary_lambda, r),),
            # ordinal value: warning at 1 (possible), critical at 2 (likely); clear = one step down
            "electrical_discharge": (Level("warning", 1.0, 0.5), Level("critical", 2.0, 1.5)),
            "life_used": (_above("warning", s.life_used_warning, r), _above("critical", s.life_used_critical, r)),
            "temperature_zone": (
                _above("warning", s.temperature_warning_c, r),
                _above("critical", s.temperature_critical_c, r),
            ),
            "temperature_rate": (
                _above("warning", s.temperature_rate_warning_k_per_min, r),
                _above("critical", s.temperature_rate_critical_k_per_min, r),
            ),
            "temperature_unexplained": (Level("critical", 1.0, 0.5),),
            "measured_line": (_above("warning", LINE_ALARM_DB, r),),
            "measured_kurtosis": (_above("warning", KURTOSIS_MARGIN, r),),
        }
        for tracker in self.trackers.values():
            tracker.levels = self._levels(tracker.rule.id, None)

    def _levels(self, alarm_id: str, vib: VibrationInputs | None) -> tuple[Level, ...]:
        if alarm_id.startswith("defect_"):
            s = self.settings
            floor = vib.noise_floor_m_s2 if vib is not None else None
            threshold = max(s.defect_amplitude_m_s2, s.defect_significance * floor if floor else 0.0)
            return (_above("warning", threshold, s.clear_ratio),)
        return self._static_levels[alarm_id]

    def _values(self, x: AlarmInputs) -> dict[str, tuple[float | None, str]]:
        s = self.settings
        vib = x.vibration
        out: dict[str, tuple[float | None, str]] = {}
        v = vib.velocity_rms_mm_s if vib is not None else None
        out["vibration_zone"] = (
            v,
            ""
            if v is None
            else f"velocity RMS {v:.3g} mm/s: ISO 20816-3 zone {vibration_zone(v, s.machine_group, s.support)}",
        )
        out["lubrication_kappa"] = (x.kappa, "" if x.kappa is None else f"kappa = {x.kappa:.3g}")
        lam = x.min_loaded_lambda
        out["lubrication_boundary"] = (
            lam,
            ""
            if lam is None
            else f"smallest Lambda of the loaded contacts {lam:.3g}; "
            f"{x.boundary_contacts} loaded contact(s) in the boundary regime",
        )
        risk = x.discharge_risk
        out["electrical_discharge"] = (
            DISCHARGE_LEVELS.get(risk) if risk is not None else None,
            f"discharge risk {risk}: {x.discharge_reason}" if risk else "",
        )
        lines = vib.line_amplitudes_m_s2 if vib is not None else {}
        for n in DEFECT_LINES:
            a = lines.get(n)
            out[f"defect_{n}"] = (a, "" if a is None else f"envelope amplitude at {line_name(n)} {a:.3g} m/s^2")
        d = x.damage_fraction
        out["life_used"] = (d, "" if d is None else f"damage fraction {d:.3g}")
        t = x.outer_ring_c
        out["temperature_zone"] = (t, "" if t is None else f"outer ring {t:.1f} degC")
        rate = x.outer_ring_rate_k_per_min
        out["temperature_rate"] = (rate, "" if rate is None else f"outer ring rising {rate:.2f} K/min")
        u = x.unexplained_heating
        res = "" if x.residual_k is None else f" (measured - predicted {x.residual_k:+.1f} K)"
        out["temperature_unexplained"] = (
            None if u is None else float(u),
            "" if u is None else ("unexplained heating" if u else "explained") + res,
        )
        return out

    def update(self, inputs: AlarmInputs) -> list[AlarmEvent]:
        """Feed one instant; the events it causes (in alarm order)."""
        events = []
        wall = self._wall_clock()
        for alarm_id, (value, message) in self._values(inputs).items():
            tracker = self.trackers[alarm_id]
            levels = self._levels(alarm_id, inputs.vibration)
            transition = tracker.update(inputs.time_s, value, levels, message, wall)
            if transition is not None:
                events.append(self._event(tracker, transition, inputs.time_s, wall, inputs.seq))
        return events

    def update_measured(self, comparison: Mapping[str, Any]) -> list[AlarmEvent]:
        """Feed one measured-window comparison (service.core.measured.MeasuredComparator.compare);
        the events of the `measured_*` alarms, at the twin time the comparison was made."""
        t = finite_number(comparison.get("twin_time_s"))
        if t is None:
            return []
        alarms = comparison.get("alarms") or []
        lines = [a for a in alarms if a.get("code") == "unexplained_line"]
        line_db = max((finite_number(a.get("height_db")) or 0.0 for a in lines), default=0.0)
        line_text = "; ".join(str(a.get("message", "")) for a in lines) or "no unexplained defect line"
        measured = finite_number((comparison.get("measured") or {}).get("kurtosis"))
        predicted = finite_number((comparison.get("predicted") or {}).get("kurtosis"))
        excess = None if measured is None or predicted is None else measured - predicted
        values = {
            "measured_line": (line_db, f"window {comparison.get('window')}: {line_text}"),
            "measured_kurtosis": (
                excess,
                ""
                if excess is None
                else f"window {comparison.get('window')}: kurtosis {measured:.2f} measured, {predicted:.2f} predicted",
            ),
        }
        events = []
        wall = self._wall_clock()
        seq = comparison.get("twin_seq")
        for alarm_id, (value, message) in values.items():
            tracker = self.trackers[alarm_id]
            transition = tracker.update(t, value, self._levels(alarm_id, None), message, wall)
            if transition is not None:
                events.append(self._event(tracker, transition, t, wall, seq if isinstance(seq, int) else None))
        return events

    def _event(
        self, tracker: AlarmTracker, transition: Transition, t: float, wall: float, snapshot_seq: int | None = None
    ) -> AlarmEvent:
        self.seq += 1
        rule, level = tracker.rule, tracker.level
        assert tracker.value is not None  # a transition is fed a finite value (AlarmTracker.update)
        lv = tracker.levels[level] if level >= 0 else tracker.levels[0]  # cleared: the first level
        severity = lv.severity if level >= 0 else None
        word = {
            "raised": "raised",
            "escalated": "escalated to",
            "deescalated": "stepped down to",
            "cleared": "cleared",
        }[transition]
        text = f"{rule.id} {word}{'' if severity is None else ' ' + severity}: {tracker.message}"
        return AlarmEvent(
            seq=self.seq,
            bearing_id=self.bearing_id,
            alarm_id=rule.id,
            category=rule.category,
            transition=transition,
            active=level >= 0,
            severity=severity,
            opcua_severity=OPCUA_SEVERITY[severity],
            since_s=tracker.since_s,
            time_s=t,
            snapshot_seq=snapshot_seq,
            wall_time_s=wall,
            value=float(tracker.value),
            threshold=lv.threshold,
            clear_threshold=lv.clear,
            unit=rule.unit,
            message=text,
        )

    def states(self) -> list[Alarm]:
        """Every alarm's state (active or not), in the order of ALARM_IDS."""
        return [t.state() for t in self.trackers.values()]

    def active(self) -> list[Alarm]:
        return [t.state() for t in self.trackers.values() if t.active]
