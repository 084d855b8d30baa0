"""Snapshots to rows, rows to rerun columns (one `send_columns` call per entity and send).

`extract` turns a snapshot (the pydantic `twin.snapshot.Snapshot`, or any object of the same
shape: fields a snapshot does not carry are simply not recorded) into a `Row` of plain numbers;
`now_columns` / `slow_columns` turn the rows buffered for one twin into
(entity path, index columns, component columns) triples for the entities of
`service.recording.layout`; `events` derives the log rows (setpoints, scenario, restarts,
fallbacks, status) from consecutive rows.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import rerun as rr

from service.recording.arrow import bar_columns
from service.recording.layout import (
    CONTACT_SERIES,
    LOAD_ZONE,
    REGIME_CODE,
    RISK_VALUES,
    SEQ,
    SIDES,
    SIM_TIME,
    TwinLayout,
)
from twin.physics.friction import REGIME_NAMES
from twin.snapshot import LAMBDA_KEY
from twin.snapshot_blocks import B_AZIMUTH
from twin.snapshot_blocks import CONTACT_FIELDS as FRAME_CONTACT_FIELDS
from twin.snapshot_frame import SnapshotFrame

# contact fields per ball and side, in this order (getattr with a None default)
CONTACT_FIELDS = ("load_n", "lambda_", "mu", "contact_angle_rad", "resistance_ohm", "capacitance_f")
F_LOAD, F_LAMBDA, F_MU, F_ANGLE, F_R, F_C = range(len(CONTACT_FIELDS))
# the same fields' columns in a frame's contact arrays (twin.snapshot_blocks.BallArrays)
_FRAME_COLUMNS = [FRAME_CONTACT_FIELDS.index(LAMBDA_KEY if n == "lambda_" else n) for n in CONTACT_FIELDS]
_FRAME_REGIME_CODES = np.array([REGIME_CODE[name] for name in REGIME_NAMES], dtype=np.int8)  # frame code -> ours
SETPOINT_FIELDS = (
    "shaft_speed_rad_s",
    "radial_load_n",
    "axial_load_n",
    "oil_temperature_c",
    "shaft_current_a",
    "shaft_voltage_v",
)
THERMAL_NODES = ("shaft", "inner_ring", "balls", "outer_ring", "housing", "oil")
THERMAL_SOURCES = ("rolling", "sliding", "spin", "drag", "seal")
_ELECTRICAL_FIELDS = (
    "resistance_ohm",
    "capacitance_f",
    "impedance_ohm",
    "shaft_voltage_v",
    "shaft_current_a",
    "max_film_field_v_m",
    "current_density_a_m2",
    "contact_temperature_rise_k",
)


@dataclass(slots=True)
class Row:
    """One snapshot as plain numbers (NaN where the snapshot has no value)."""

    time_s: float
    seq: int
    status: str
    restarts: int
    setpoint: tuple | None  # SETPOINT_FIELDS, or None
    shaft_speed_rad_s: float
    cage_speed_rad_s: float
    friction_torque_n_m: float
    contacts: np.ndarray  # (Z, 2, len(CONTACT_FIELDS)) float64
    regimes: np.ndarray  # (Z, 2) int8, REGIME_CODE
    azimuth_rad: np.ndarray  # (Z,)
    electrical: dict  # numeric bearing-level fields of _ELECTRICAL_FIELDS
    risk: str | None  # "none" | "possible" | "likely" | None
    risk_reason: str | None
    context: str | None  # scenario state given with the snapshot (recorder.publish)
    positions_m: np.ndarray | None
    gap_before: str | None = None  # why the line breaks before this row (lost rows, new run)
    defects: tuple | None = None  # the active local defects as text (None: not in the snapshot)
    vibration: Any = None  # the snapshot's vibration block (twin.snapshot.VibrationState) or None
    thermal: tuple | None = None  # THERMAL_NODES temperatures [degC] then THERMAL_SOURCES heat [W]


_FIELD_CACHE: dict = {}


def _present(obj, names: tuple[str, ...]) -> tuple[str | None, ...]:
    """`names` with None for those `obj` does not have; cached per pydantic model class (a
    getattr that misses on a pydantic model raises inside __getattr__: microseconds)."""
    cls = type(obj)
    key = (cls, names)
    found = _FIELD_CACHE.get(key)
    if found is None:
        declared = getattr(cls, "model_fields", None)
        if not isinstance(declared, dict):  # duck-typed object: look at this instance
            return tuple(n if hasattr(obj, n) else None for n in names)
        found = tuple(n if n in declared else None for n in names)
        _FIELD_CACHE[key] = found
    return found


def _num(v) -> float:
    if v is None or isinstance(v, bool):
        return math.nan
    try:
        return float(v)
    except (TypeError, ValueError):
        return math.nan


def ball_count(snapshot) -> int:
    """Balls of a snapshot or a frame (twin.snapshot_frame.SnapshotFrame: without building its tree)."""
    if isinstance(snapshot, SnapshotFrame):
        return snapshot.ball_arrays.ball_count
    return len(snapshot.balls)


def extract(snapshot, positions_m: np.ndarray | None = None, context: str | None = None) -> Row:
    """A snapshot (or a frame: its arrays, without building its tree) as a `Row`."""
    if isinstance(snapshot, SnapshotFrame):
        arrays = snapshot.ball_arrays
        z = arrays.ball_count
        contacts = arrays.contacts[:, _FRAME_COLUMNS].reshape(z, 2, len(CONTACT_FIELDS))
        regimes = _FRAME_REGIME_CODES[arrays.regimes].reshape(z, 2)
        azimuth = arrays.balls[:, B_AZIMUTH]
        return _row(snapshot.head, contacts, regimes, azimuth, positions_m, context)
    balls = snapshot.balls
    z = len(balls)
    contacts = np.full((z, 2, len(CONTACT_FIELDS)), math.nan)
    regimes = np.zeros((z, 2), dtype=np.int8)
    azimuth = np.empty(z)
    if z:
        cf = _present(balls[0].inner, CONTACT_FIELDS)
        for i, b in enumerate(balls):
            azimuth[i] = b.azimuth_rad
            for side, c in enumerate((b.inner, b.outer)):
                row = contacts[i, side]
                for k, name in enumerate(cf):
                    if name is not None:
                        row[k] = _num(getattr(c, name))
                regimes[i, side] = REGIME_CODE.get(str(getattr(c, "regime", "")), 0)
    return _row(snapshot, contacts, regimes, azimuth, positions_m, context)


def _row(snapshot, contacts, regimes, azimuth, positions_m, context) -> Row:
    """The row of a snapshot's bearing-level fields around its per-contact arrays."""
    electrical: dict = {}
    risk = reason = None
    el = getattr(snapshot, "electrical", None) if _present(snapshot, ("electrical",))[0] else None
    if el is not None:
        items = (
            el
            if isinstance(el, Mapping)
            else {k: getattr(el, k, None) for k in (*_ELECTRICAL_FIELDS, "discharge_risk", "reason")}
        )
        for key in _ELECTRICAL_FIELDS:
            v = _num(items.get(key))
            if math.isfinite(v):
                electrical[key] = v
        r = items.get("discharge_risk")
        if isinstance(r, str):
            risk = r
            reason = items.get("reason") if isinstance(items.get("reason"), str) else None
    has_defects, has_vibration = _present(snapshot, ("defects", "vibration"))
    defects = tuple(_defect_text(d) for d in snapshot.defects or ()) if has_defects else None
    vibration = snapshot.vibration if has_vibration else None
    block = getattr(snapshot, "thermal", None) if _present(snapshot, ("thermal",))[0] else None
    thermal = None
    if block is not None:
        thermal = (
            *(_num(block.temperatures_c.get(n)) for n in THERMAL_NODES),
            *(_num(block.heat_w.get(n)) for n in THERMAL_SOURCES),
        )
    sp = getattr(snapshot, "setpoint", None) if _present(snapshot, ("setpoint",))[0] else None
    setpoint = tuple(_num(getattr(sp, f, None)) for f in SETPOINT_FIELDS) if sp is not None else None
    return Row(
        time_s=float(snapshot.time_s),
        seq=int(snapshot.seq),
        status=str(snapshot.status),
        restarts=int(getattr(snapshot, "restarts", 0) or 0),
        setpoint=setpoint,
        shaft_speed_rad_s=_num(getattr(snapshot, "shaft_speed_rad_s", None)),
        cage_speed_rad_s=_num(snapshot.cage_speed_rad_s),
        friction_torque_n_m=_num(snapshot.friction_torque_n_m),
        contacts=contacts,
        regimes=regimes,
        azimuth_rad=azimuth,
        electrical=electrical,
        risk=risk,
        risk_reason=reason,
        context=context,
        positions_m=positions_m,
        defects=defects,
        vibration=vibration,
        thermal=thermal,
    )


def _defect_text(d) -> str:
    """'outer spall 0.5 x 0.6 mm, 50 um deep at 0 deg' of a twin.vibration.defects model."""
    get = d.get if isinstance(d, Mapping) else (lambda k, default=None: getattr(d, k, default))
    kind = get("kind")
    width_mm, length_mm = format_number(get("width_m", 0.0) * 1e3), format_number(get("length_m", 0.0) * 1e3)
    size = f"{width_mm} x {length_mm} mm, {format_number(get('depth_m', 0.0) * 1e6)} um deep"
    where = {
        "outer": f"outer spall {size} at azimuth {format_number(get('azimuth_deg', 0.0))} deg",
        "inner": f"inner spall {size} at ring angle {format_number(get('ring_angle_deg', 0.0))} deg",
        "ball": f"ball {get('ball_index', 0)} defect {size}",
    }
    return where.get(str(kind), f"{kind} defect {size}")


# ---- columns ------------------------------------------------------------------------------------
@dataclass
class Batch:
    """Rows of one twin with their index columns (sim_time shifted by the twin's offset)."""

    rows: list[Row]
    t_ns: np.ndarray
    seq: np.ndarray
    out: list = field(default_factory=list)

    @classmethod
    def of(cls, rows: list[Row], offset_s: float) -> Batch:
        n = len(rows)
        # integer nanoseconds, rounded (rerun truncates float seconds: 0.002 s would become 1999999 ns)
        t = np.round((np.fromiter((r.time_s for r in rows), np.float64, n) + offset_s) * 1e9).astype(np.int64)
        return cls(rows=rows, t_ns=t, seq=np.fromiter((r.seq for r in rows), np.int64, n))

    def index(self, sel=None) -> list:
        t, s = (self.t_ns, self.seq) if sel is None else (self.t_ns[sel], self.seq[sel])
        return [rr.TimeColumn(SIM_TIME, duration=t.astype("timedelta64[ns]")), rr.TimeColumn(SEQ, sequence=s)]

    def scalars(self, path: str, values: np.ndarray) -> None:
        """values (n,) or (n, k): one row per snapshot; a single value that is not finite gives
        an empty row (the line breaks there), several keep their NaN."""
        v = np.asarray(values, dtype=np.float64)
        if v.ndim == 1:
            ok = np.isfinite(v)
            lengths = ok.astype(np.int32)
            col = rr.Scalars.columns(scalars=v[ok])
            self.out.append((path, self.index(), col.partition(lengths) if not ok.all() else col))
        else:
            n, k = v.shape
            self.out.append((path, self.index(), rr.Scalars.columns(scalars=v.reshape(-1)).partition(np.full(n, k))))

    def breaks(self, paths: list[str], offset_s: float, previous_time_s: float | None) -> None:
        """An empty row (a line break) before every row marked `gap_before`, half-way to the
        previous row, on the sim_time timeline only (it is no snapshot: no seq)."""
        at = []
        prev = previous_time_s
        for r in self.rows:
            if r.gap_before is not None:
                t0 = (prev if prev is not None else r.time_s) + offset_s
                t1 = r.time_s + offset_s
                at.append(round((t0 + t1) / 2 * 1e9) if t1 > t0 else round(t1 * 1e9) - 1)
            prev = r.time_s
        if not at:
            return
        idx = [rr.TimeColumn(SIM_TIME, duration=np.array(at, dtype=np.int64).astype("timedelta64[ns]"))]
        for path in paths:
            self.out.append((path, idx, rr.Scalars.columns(scalars=np.zeros(0)).partition(np.zeros(len(at), np.int32))))


def log10_kohm(ohm: np.ndarray) -> np.ndarray:
    with np.errstate(divide="ignore", invalid="ignore"):
        v = np.log10(ohm / 1e3)
    v[~np.isfinite(v)] = math.nan
    return v


def ball_regime(regimes: np.ndarray) -> np.ndarray:
    """(..., Z, 2) contact regimes -> (..., Z) ball regime: the worst loaded contact (boundary <
    mixed < full film), no contact when neither contact is loaded."""
    r = regimes.astype(np.int16)
    loaded = np.where(r > 0, r, 99)
    worst = loaded.min(axis=-1)
    return np.where(worst == 99, 0, worst).astype(np.uint16)


def now_columns(tw: TwinLayout, batch: Batch) -> None:
    """The views of the bearing now (at the time cursor): the balls by regime and the contact
    loads in 3D, the load zone bars. The trends are `service.recording.trends`."""
    rows = batch.rows
    n, z = len(rows), tw.ball_count
    root = tw.root
    c = np.stack([r.contacts for r in rows])  # (n, z, 2, K)
    reg = np.stack([r.regimes for r in rows])  # (n, z, 2)
    az = np.stack([r.azimuth_rad for r in rows])  # (n, z)
    ball_reg = ball_regime(reg)  # (n, z)
    load = c[..., F_LOAD]

    # 3D: balls by regime, contact loads as arrows
    if tw.has_geometry:
        cos_az, sin_az = np.cos(az), np.sin(az)
        rp = tw.pitch_radius_m
        pos = np.stack([rp * cos_az, rp * sin_az, np.zeros_like(az)], axis=-1)  # (n, z, 3)
        for j, r in enumerate(rows):
            if r.positions_m is not None:
                pos[j] = r.positions_m
        batch.out.append(
            (
                f"{root}/balls",
                batch.index(),
                rr.Points3D.columns(
                    positions=pos.reshape(-1, 3).astype(np.float32), class_ids=ball_reg.reshape(-1)
                ).partition(np.full(n, z)),
            )
        )
        if tw.load_scale_m_per_n is None:
            peak = float(np.nanmax(load)) if load.size and np.isfinite(load).any() else 0.0
            if peak > 0.0:
                tw.load_scale_m_per_n = 2.0 * (tw.ball_radius_m or 0.0) / peak
        scale = tw.load_scale_m_per_n or 0.0
        a = np.nan_to_num(c[:, :, 0, F_ANGLE])  # inner contacts: from the ball centre inwards
        length = np.nan_to_num(load[:, :, 0]) * scale
        vectors = np.stack([-np.cos(a) * cos_az, -np.cos(a) * sin_az, np.sin(a)], axis=-1) * length[..., None]
        batch.out.append(
            (
                f"{root}/loads",
                batch.index(),
                rr.Arrows3D.columns(
                    origins=pos.reshape(-1, 3).astype(np.float32), vectors=vectors.reshape(-1, 3).astype(np.float32)
                ).partition(np.full(n, z)),
            )
        )

    # the load zone now: bars against azimuth [deg] in (-180, 180], inner left of outer
    deg = np.degrees(np.angle(np.exp(1j * az)))
    w = tw.bar_width_deg
    for f, (leaf, _title) in zip((F_LOAD, F_LAMBDA, F_MU), LOAD_ZONE, strict=True):
        for side, name in enumerate(SIDES):
            values = c[:, :, side, f]
            if f == F_LAMBDA:
                values = np.where(np.isfinite(values), values, 0.0)  # no contact: no bar
            batch.out.append(
                (
                    f"{root}/load_zone/{leaf}/{name}",
                    batch.index(),
                    bar_columns(values, deg + (w / 2 if side else -w / 2)),
                )
            )


def slow_columns(tw: TwinLayout, batch: Batch) -> None:
    """The per-contact series (2 Z instances per row)."""
    rows = batch.rows
    n = len(rows)
    root = tw.root
    c = np.stack([r.contacts for r in rows]).reshape(n, -1, len(CONTACT_FIELDS))  # (n, 2z, K)
    fields = {
        "load_n": c[..., F_LOAD],
        LAMBDA_KEY: c[..., F_LAMBDA],
        "mu": c[..., F_MU],
        "resistance_log10_kohm": log10_kohm(c[..., F_R]),
        "capacitance_pf": c[..., F_C] * 1e12,
    }
    has_el = bool(np.isfinite(c[..., F_C]).any())
    for leaf, _title in CONTACT_SERIES:
        if leaf in ("resistance_log10_kohm", "capacitance_pf") and not has_el:
            continue
        batch.scalars(f"{root}/contacts/{leaf}", fields[leaf])


def scalar_paths(tw: TwinLayout, slow: bool) -> list[str]:
    from service.recording.layout import FAST_SERIES

    if slow:
        return [f"{tw.root}/contacts/{leaf}" for leaf, _ in CONTACT_SERIES]
    return [f"{tw.root}/{leaf}" for leaf in FAST_SERIES]


# ---- events ---------------------------------------------------------------------------------------
def format_number(v: float) -> str:
    return f"{v:.6g}"


def events(tw: TwinLayout, batch: Batch) -> None:
    """Log rows for what changed from one row to the next (state kept in `tw.last`, which a new
    segment or file resets so that it starts with the state in force): the scenario state, the
    setpoint, restarts, fallbacks and the status; and the discharge risk as a state."""
    last = tw.last
    texts: list[tuple[int, str, str]] = []
    risks: list[tuple[int, str]] = []
    for j, r in enumerate(batch.rows):
        if r.gap_before is not None:
            texts.append((j, r.gap_before, "INFO"))
        if r.context != last.get("context", "-") and (r.context is not None or "context" in last):
            texts.append((j, r.context or "no scenario", "INFO"))
        last["context"] = r.context
        # a running scenario changes the setpoint at every frame of a ramp: its phase rows stand
        # for those, and the setpoint is logged (as the change since the last row) when the
        # phase changes or the scenario ends
        in_phase = r.context is not None and ": running" in r.context and r.context == last.get("logged_context")
        if r.setpoint is not None and r.setpoint != last.get("setpoint") and not in_phase:
            old = last.get("setpoint")
            if old is None:
                what = ", ".join(f"{n} = {format_number(v)}" for n, v in zip(SETPOINT_FIELDS, r.setpoint, strict=True))
                texts.append((j, f"setpoint in force: {what}", "INFO"))
            else:
                what = ", ".join(
                    f"{n} {format_number(a)} -> {format_number(b)}"
                    for n, a, b in zip(SETPOINT_FIELDS, old, r.setpoint, strict=True)
                    if a != b
                )
                texts.append((j, f"setpoint: {what}", "INFO"))
            last["setpoint"] = r.setpoint
        last["logged_context"] = r.context
        restarted = "restarts" in last and r.restarts > last["restarts"]
        last["restarts"] = r.restarts
        status_changed = r.status != last.get("status")
        last["status"] = r.status
        if "fallbacks" in r.status and "setpoint not held" in r.status and (restarted or status_changed):
            texts.append((j, f"fallback (restarts: {r.restarts}): {r.status}", "ERROR"))
        elif restarted:
            texts.append((j, f"restart (restarts: {r.restarts}): {r.status}", "WARN"))
        elif status_changed:
            texts.append((j, f"status: {r.status}", "INFO" if r.status == "ok" else "WARN"))
        if r.defects is not None and r.defects != last.get("defects", ()):
            texts.append(
                (
                    j,
                    "defects: " + "; ".join(r.defects) if r.defects else "defects cleared",
                    "WARN" if r.defects else "INFO",
                )
            )
        if r.defects is not None:
            last["defects"] = r.defects
        if r.risk is not None and r.risk != last.get("risk"):
            risks.append((j, r.risk if r.risk in RISK_VALUES else "none"))
            if last.get("risk") is not None:
                texts.append(
                    (
                        j,
                        f"discharge risk {r.risk}: {r.risk_reason or ''}".rstrip(": "),
                        "ERROR" if r.risk == "likely" else "WARN" if r.risk == "possible" else "INFO",
                    )
                )
            last["risk"] = r.risk
    if texts:
        sel = np.array([j for j, _, _ in texts])
        batch.out.append(
            (
                f"{tw.root}/events",
                batch.index(sel),
                rr.TextLog.columns(text=[t for _, t, _ in texts], level=[lv for _, _, lv in texts]),
            )
        )
    if risks:
        sel = np.array([j for j, _ in risks])
        batch.out.append(
            (
                f"{tw.root}/electrical/discharge_risk",
                batch.index(sel),
                rr.StateChange.columns(state=[s for _, s in risks]),
            )
        )
