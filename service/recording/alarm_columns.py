"""Alarm events and measured-vibration comparisons to rerun columns: the alarm log and state
entities, the states in force at the start of a segment, and the measured indicators beside the
twin's (`vibration/measured/...`)."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import rerun as rr

from service.recording.columns import format_number
from service.recording.layout import ALARM_LOG_LEVEL, ALARM_STATES, SEQ, SIM_TIME, TwinLayout


# ---- alarms ---------------------------------------------------------------------------------------
@dataclass(slots=True)
class AlarmRow:
    """One alarm event (service.core.alarms.AlarmEvent) as the recorder keeps it."""

    bearing_id: str
    alarm_id: str
    transition: str  # raised | escalated | deescalated | cleared
    severity: str | None  # warning | critical | None (cleared)
    time_s: float  # simulated time of the event [s]
    seq: int | None  # seq of the snapshot that caused it
    value: float
    threshold: float
    clear_threshold: float
    unit: str
    message: str

    @classmethod
    def of(cls, event) -> AlarmRow:
        """From an `AlarmEvent` (or its dict)."""
        get: Callable[..., Any] = event.get if isinstance(event, Mapping) else (lambda k, d=None: getattr(event, k, d))
        seq = get("snapshot_seq")
        return cls(
            bearing_id=str(get("bearing_id")),
            alarm_id=str(get("alarm_id")),
            transition=str(get("transition")),
            severity=get("severity"),
            time_s=float(get("time_s")),
            seq=int(seq) if isinstance(seq, int) else None,
            value=float(get("value")),
            threshold=float(get("threshold")),
            clear_threshold=float(get("clear_threshold")),
            unit=str(get("unit") or "-"),
            message=str(get("message") or ""),
        )

    @property
    def state(self) -> str:
        return self.severity if self.severity in ALARM_STATES else "inactive"

    @property
    def text(self) -> str:
        unit = "" if self.unit == "-" else f" {self.unit}"
        return (
            f"{self.message} [value {format_number(self.value)}{unit}, raise at {format_number(self.threshold)}{unit}, "
            f"clear at {format_number(self.clear_threshold)}{unit}]"
        )


def _alarm_index(times_ns: np.ndarray, seqs: list[int | None]) -> list:
    """sim_time, and seq when every row has one."""
    index = [rr.TimeColumn(SIM_TIME, duration=times_ns.astype("timedelta64[ns]"))]
    if all(s is not None for s in seqs):
        index.append(rr.TimeColumn(SEQ, sequence=np.array(seqs, dtype=np.int64)))
    return index


def alarm_columns(tw: TwinLayout, rows: list[AlarmRow], offset_s: float) -> list:
    """(entity path, index columns, component columns) triples of a twin's alarm events: a
    TextLog row at `alarms/{alarm_id}` and a StateChange row at `alarm_states/{alarm_id}` per
    event, at the event's simulated time (shifted by the twin's offset) and snapshot seq."""
    out: list = []
    by_alarm: dict[str, list[AlarmRow]] = {}
    for r in rows:
        by_alarm.setdefault(r.alarm_id, []).append(r)
    for alarm_id, group in by_alarm.items():
        # rows with and without a snapshot seq go in separate calls (index columns of one length)
        for part in ([r for r in group if r.seq is not None], [r for r in group if r.seq is None]):
            if not part:
                continue
            t = np.round((np.array([r.time_s for r in part]) + offset_s) * 1e9).astype(np.int64)
            seqs = [r.seq for r in part]
            out.append(
                (
                    f"{tw.root}/alarms/{alarm_id}",
                    _alarm_index(t, seqs),
                    rr.TextLog.columns(
                        text=[r.text for r in part], level=[ALARM_LOG_LEVEL.get(r.severity, "INFO") for r in part]
                    ),
                )
            )
            out.append(
                (
                    f"{tw.root}/alarm_states/{alarm_id}",
                    _alarm_index(t, seqs),
                    rr.StateChange.columns(state=[r.state for r in part]),
                )
            )
    return out


MEASURED_LINES = ("BPFO", "BPFI", "2xBSF")


def measured_columns(tw: TwinLayout, comparisons: list[Mapping], offset_s: float) -> list:
    """(entity path, index columns, component columns) triples of the measured-window comparisons
    of a twin (service.core.measured), at the twin's simulated time when each window arrived
    (shifted by the twin's offset) and its snapshot seq: Scalars `vibration/measured/{kurtosis,rms_m_s2,crest_factor}/
    {measured,predicted}` (no row where the twin predicts none), `vibration/measured/line_height_db/
    {BPFO,BPFI,2xBSF}` [dB over the median of +-20 Hz], and a TextLog `vibration/measured/alarms`
    (level WARN per alarm, INFO when the window raises none)."""
    rows = [c for c in comparisons if c.get("twin_time_s") is not None]
    if not rows:
        return []
    t = np.round((np.array([c["twin_time_s"] for c in rows]) + offset_s) * 1e9).astype(np.int64)
    seqs = [c.get("twin_seq") for c in rows]
    base = f"{tw.root}/vibration/measured"
    out: list = []

    def scalars(path: str, values: list) -> None:
        keep = [k for k, v in enumerate(values) if v is not None]
        if keep:
            idx = _alarm_index(t[keep], [seqs[k] for k in keep])
            out.append((path, idx, rr.Scalars.columns(scalars=np.array([values[k] for k in keep], dtype=float))))

    for key in ("kurtosis", "rms_m_s2", "crest_factor"):
        scalars(f"{base}/{key}/measured", [c["measured"][key] for c in rows])
        scalars(f"{base}/{key}/predicted", [c["predicted"].get(key) for c in rows])
    for name in MEASURED_LINES:
        scalars(
            f"{base}/line_height_db/{name}",
            [next((d["height_db"] for d in c["measured"]["defect_lines"] if d["name"] == name), None) for c in rows],
        )
    texts = [
        (
            "; ".join(a["message"] for a in c["alarms"]) or f"window {c['window']}: explained by the twin",
            "WARN" if c["alarms"] else "INFO",
        )
        for c in rows
    ]
    out.append(
        (
            f"{base}/alarms",
            _alarm_index(t, seqs),
            rr.TextLog.columns(text=[x for x, _ in texts], level=[lv for _, lv in texts]),
        )
    )
    return out


def alarm_states_in_force(
    tw: TwinLayout, states: Mapping[str, str], time_s: float, seq: int | None, offset_s: float
) -> list:
    """StateChange rows of every alarm's state when a new output (a segment) started, at
    `time_s` (its first row), so that its state timeline does not begin empty."""
    active = list(states.items())
    t = np.array([round((time_s + offset_s) * 1e9)], dtype=np.int64)
    return [
        (f"{tw.root}/alarm_states/{alarm_id}", _alarm_index(t, [seq]), rr.StateChange.columns(state=[state]))
        for alarm_id, state in active
    ]
