"""Snapshots to rows, rows to rerun columns (one `send_columns` call per entity and send).

`extract` turns a snapshot (the pydantic `twin.snapshot.Snapshot`, or any object of the same
shape: fields a snapshot does not carry are simply not recorded) into a `Row` of plain numbers;
`fast_columns` / `slow_columns` turn the rows buffered for one twin into
(entity path, index columns, component columns) triples for the entities of
`service.recording.layout`; `events` derives the log rows (setpoints, scenario, restarts,
fallbacks, status) from consecutive rows.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
import pyarrow as pa
import rerun as rr

from service.recording.layout import (
    ALARM_LOG_LEVEL,
    ALARM_STATES,
    CONTACT_SERIES,
    CURSOR_HARMONICS,
    CURSOR_NAMES,
    CURSOR_WIDTH_FRACTION,
    LOAD_ZONE,
    REGIME_CODE,
    REGIME_ORDER,
    RISK_VALUES,
    SEQ,
    SIDES,
    SIM_TIME,
    SPECTRUM_PIXELS,
    VIB_LINES,
    TwinLayout,
)

# contact fields per ball and side, in this order (getattr with a None default)
CONTACT_FIELDS = ("load_n", "lambda_", "mu", "contact_angle_rad", "resistance_ohm", "capacitance_f")
F_LOAD, F_LAMBDA, F_MU, F_ANGLE, F_R, F_C = range(len(CONTACT_FIELDS))
SETPOINT_FIELDS = ("shaft_speed_rad_s", "radial_load_n", "axial_load_n", "oil_temperature_c",
                   "shaft_current_a", "shaft_voltage_v")
_ELECTRICAL_FIELDS = ("resistance_ohm", "capacitance_f", "impedance_ohm", "shaft_voltage_v", "shaft_current_a",
                      "max_film_field_v_m", "current_density_a_m2", "contact_temperature_rise_k")


@dataclass(slots=True)
class Row:
    """One snapshot as plain numbers (NaN where the snapshot has no value)."""

    time_s: float
    seq: int
    status: str
    restarts: int
    setpoint: tuple | None            # SETPOINT_FIELDS, or None
    shaft_speed_rad_s: float
    cage_speed_rad_s: float
    friction_torque_n_m: float
    contacts: np.ndarray              # (Z, 2, len(CONTACT_FIELDS)) float64
    regimes: np.ndarray               # (Z, 2) int8, REGIME_CODE
    azimuth_rad: np.ndarray           # (Z,)
    electrical: dict                  # numeric bearing-level fields of _ELECTRICAL_FIELDS
    risk: str | None                  # "none" | "possible" | "likely" | None
    risk_reason: str | None
    context: str | None               # scenario state given with the snapshot (recorder.publish)
    positions_m: np.ndarray | None
    gap_before: str | None = None     # why the line breaks before this row (lost rows, new run)
    defects: tuple | None = None      # the active local defects as text (None: not in the snapshot)
    vibration: object | None = None   # the snapshot's vibration block (twin.snapshot.VibrationState)


_FIELD_CACHE: dict = {}


def _present(obj, names: tuple[str, ...]) -> tuple[str | None, ...]:
    """`names` with None for those `obj` does not have; cached per pydantic model class (a
    getattr that misses on a pydantic model raises inside __getattr__: microseconds)."""
    cls = type(obj)
    key = (cls, names)
    found = _FIELD_CACHE.get(key)
    if found is None:
        declared = getattr(cls, "model_fields", None)
        if not isinstance(declared, dict):   # duck-typed object: look at this instance
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


def extract(snapshot, positions_m: np.ndarray | None = None, context: str | None = None) -> Row:
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
                regimes[i, side] = REGIME_CODE.get(getattr(c, "regime", None), 0)
    electrical: dict = {}
    risk = reason = None
    el = getattr(snapshot, "electrical", None) if _present(snapshot, ("electrical",))[0] else None
    if el is not None:
        items = el if isinstance(el, Mapping) else {k: getattr(el, k, None) for k in
                                                    (*_ELECTRICAL_FIELDS, "discharge_risk", "reason")}
        for k in _ELECTRICAL_FIELDS:
            v = _num(items.get(k))
            if math.isfinite(v):
                electrical[k] = v
        r = items.get("discharge_risk")
        if isinstance(r, str):
            risk = r
            reason = items.get("reason") if isinstance(items.get("reason"), str) else None
    has_defects, has_vibration = _present(snapshot, ("defects", "vibration"))
    defects = tuple(_defect_text(d) for d in snapshot.defects or ()) if has_defects else None
    vibration = snapshot.vibration if has_vibration else None
    sp = getattr(snapshot, "setpoint", None) if _present(snapshot, ("setpoint",))[0] else None
    setpoint = tuple(_num(getattr(sp, f, None)) for f in SETPOINT_FIELDS) if sp is not None else None
    return Row(time_s=float(snapshot.time_s), seq=int(snapshot.seq), status=str(snapshot.status),
               restarts=int(getattr(snapshot, "restarts", 0) or 0), setpoint=setpoint,
               shaft_speed_rad_s=_num(getattr(snapshot, "shaft_speed_rad_s", None)),
               cage_speed_rad_s=_num(snapshot.cage_speed_rad_s),
               friction_torque_n_m=_num(snapshot.friction_torque_n_m),
               contacts=contacts, regimes=regimes, azimuth_rad=azimuth,
               electrical=electrical, risk=risk, risk_reason=reason, context=context,
               positions_m=positions_m, defects=defects, vibration=vibration)


def _defect_text(d) -> str:
    """'outer spall 0.5 x 0.6 mm, 50 um deep at 0 deg' of a twin.vibration.defects model."""
    get = d.get if isinstance(d, Mapping) else (lambda k, default=None: getattr(d, k, default))
    kind = get("kind")
    size = f"{_fmt(get('width_m', 0.0) * 1e3)} x {_fmt(get('length_m', 0.0) * 1e3)} mm, {_fmt(get('depth_m', 0.0) * 1e6)} um deep"
    where = {"outer": f"outer spall {size} at azimuth {_fmt(get('azimuth_deg', 0.0))} deg",
             "inner": f"inner spall {size} at ring angle {_fmt(get('ring_angle_deg', 0.0))} deg",
             "ball": f"ball {get('ball_index', 0)} defect {size}"}
    return where.get(kind, f"{kind} defect {size}")


# ---- arrow helpers ------------------------------------------------------------------------------
class _Arrow:
    """A ready arrow array as a `ComponentBatchLike`."""

    def __init__(self, array: pa.Array) -> None:
        self.array = array

    def as_arrow_array(self) -> pa.Array:
        return self.array


_TENSOR_TYPE = None


def _tensor_rows(values) -> pa.Array:
    """One rerun TensorData (1-D, float32) per row of `values` (n, k), or per array of a list of
    1-D arrays (rows of different lengths), built as one arrow array (rerun's own
    `BarChart.columns` takes one tensor for all rows)."""
    global _TENSOR_TYPE
    if _TENSOR_TYPE is None:
        _TENSOR_TYPE = rr.components.TensorDataBatch(
            rr.encodings.TensorData(array=np.zeros(1, np.float32))).as_arrow_array().type
    if isinstance(values, np.ndarray):
        values = np.ascontiguousarray(values, dtype=np.float32)
        n, k = values.shape
        sizes = np.full(n, k, dtype=np.int64)
    else:
        sizes = np.array([len(v) for v in values], dtype=np.int64)
        n = sizes.size
        values = np.concatenate([np.asarray(v, dtype=np.float32) for v in values]) if n else np.zeros(0, np.float32)
    offsets = np.zeros(n + 1, dtype=np.int32)
    np.cumsum(sizes, out=offsets[1:])
    f_shape, f_names, f_buffer = _TENSOR_TYPE[0], _TENSOR_TYPE[1], _TENSOR_TYPE[2]
    shape = pa.ListArray.from_arrays(pa.array(np.arange(n + 1, dtype=np.int32)),
                                     pa.array(sizes.astype(np.uint64)), type=f_shape.type)
    utype = f_buffer.type
    children = []
    code = None
    for i in range(utype.num_fields):
        ft = utype.field(i)
        if ft.name == "F32":
            code = utype.type_codes[i]
            children.append(pa.ListArray.from_arrays(pa.array(offsets), pa.array(values.reshape(-1)), type=ft.type))
        else:
            children.append(pa.array([], type=ft.type))
    buffer = pa.Array.from_buffers(utype, n, [None, pa.py_buffer(np.full(n, code, dtype=np.int8).tobytes()),
                                              pa.py_buffer(np.arange(n, dtype=np.int32).tobytes())],
                                   children=children)
    return pa.StructArray.from_arrays([shape, pa.nulls(n, type=f_names.type), buffer],
                                      fields=[f_shape, f_names, f_buffer])


def _bar_columns(values, abscissa, widths=None) -> list:
    """BarChart columns, a row per row of values / abscissa (arrays (n, k) or lists of 1-D
    arrays); widths: the bar widths of each row (a list of 1-D arrays), else the static ones."""
    out = [rr.ComponentColumn(rr.BarChart.descriptor_values(), _Arrow(_tensor_rows(values))),
           rr.ComponentColumn(rr.BarChart.descriptor_abscissa(), _Arrow(_tensor_rows(abscissa)))]
    if widths is not None:
        out.append(rr.ComponentColumn(rr.BarChart.descriptor_widths(),
                                      rr.components.LengthBatch(np.concatenate(widths).astype(np.float32)),
                                      lengths=np.array([len(w) for w in widths])))
    return out


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


def _log10_kohm(ohm: np.ndarray) -> np.ndarray:
    with np.errstate(divide="ignore", invalid="ignore"):
        v = np.log10(ohm / 1e3)
    v[~np.isfinite(v)] = math.nan
    return v


def _ball_regime(regimes: np.ndarray) -> np.ndarray:
    """(..., Z, 2) contact regimes -> (..., Z) ball regime: the worst loaded contact (boundary <
    mixed < full film), no contact when neither contact is loaded."""
    r = regimes.astype(np.int16)
    loaded = np.where(r > 0, r, 99)
    worst = loaded.min(axis=-1)
    return np.where(worst == 99, 0, worst).astype(np.uint16)


def fast_columns(tw: TwinLayout, batch: Batch) -> None:
    rows = batch.rows
    n, z = len(rows), tw.ball_count
    root = tw.root
    c = np.stack([r.contacts for r in rows])                    # (n, z, 2, K)
    reg = np.stack([r.regimes for r in rows])                   # (n, z, 2)
    az = np.stack([r.azimuth_rad for r in rows])                # (n, z)
    ball_reg = _ball_regime(reg)                                # (n, z)
    load = c[..., F_LOAD]
    lam = c[..., F_LAMBDA]

    # 3D: balls by regime, contact loads as arrows
    if tw.has_geometry:
        cos_az, sin_az = np.cos(az), np.sin(az)
        rp = tw.pitch_radius_m
        pos = np.stack([rp * cos_az, rp * sin_az, np.zeros_like(az)], axis=-1)   # (n, z, 3)
        for j, r in enumerate(rows):
            if r.positions_m is not None:
                pos[j] = r.positions_m
        batch.out.append((f"{root}/balls", batch.index(), rr.Points3D.columns(
            positions=pos.reshape(-1, 3).astype(np.float32), class_ids=ball_reg.reshape(-1)).partition(np.full(n, z))))
        if tw.load_scale_m_per_n is None:
            peak = float(np.nanmax(load)) if load.size and np.isfinite(load).any() else 0.0
            if peak > 0.0:
                tw.load_scale_m_per_n = 2.0 * tw.ball_radius_m / peak
        scale = tw.load_scale_m_per_n or 0.0
        a = np.nan_to_num(c[:, :, 0, F_ANGLE])          # inner contacts: from the ball centre inwards
        length = np.nan_to_num(load[:, :, 0]) * scale
        vectors = np.stack([-np.cos(a) * cos_az, -np.cos(a) * sin_az, np.sin(a)], axis=-1) * length[..., None]
        batch.out.append((f"{root}/loads", batch.index(), rr.Arrows3D.columns(
            origins=pos.reshape(-1, 3).astype(np.float32),
            vectors=vectors.reshape(-1, 3).astype(np.float32)).partition(np.full(n, z))))

    # the load zone now: bars against azimuth [deg] in (-180, 180], inner left of outer
    deg = np.degrees(np.angle(np.exp(1j * az)))
    w = tw.bar_width_deg
    for f, (leaf, _title) in zip((F_LOAD, F_LAMBDA, F_MU), LOAD_ZONE, strict=True):
        for side, name in enumerate(SIDES):
            values = c[:, :, side, f]
            if f == F_LAMBDA:
                values = np.where(np.isfinite(values), values, 0.0)   # no contact: no bar
            batch.out.append((f"{root}/load_zone/{leaf}/{name}", batch.index(),
                              _bar_columns(values, deg + (w / 2 if side else -w / 2))))

    # bearing-level trends and the setpoint beside them
    batch.scalars(f"{root}/friction_torque_n_m", [r.friction_torque_n_m for r in rows])
    sp = np.array([r.setpoint if r.setpoint is not None else (math.nan,) * 6 for r in rows])
    qmax = np.nanmax(np.where(np.isfinite(load), load, -math.inf).reshape(n, -1), axis=1)
    qmax[~np.isfinite(qmax)] = math.nan
    batch.scalars(f"{root}/loads_n", np.column_stack([qmax, sp[:, 1], sp[:, 2]]))
    batch.scalars(f"{root}/speeds_rad_s", np.column_stack(
        [sp[:, 0], [r.shaft_speed_rad_s for r in rows], [r.cage_speed_rad_s for r in rows]]))
    with np.errstate(invalid="ignore"):
        loaded = np.isfinite(lam) & (load > 0)
    min_lam = np.where(loaded, lam, math.inf).min(axis=1)                          # (n, 2)
    min_lam[~np.isfinite(min_lam)] = math.nan
    batch.scalars(f"{root}/min_lambda", min_lam)
    counts = np.stack([(ball_reg == code).sum(axis=1) for code in REGIME_ORDER], axis=1)
    batch.scalars(f"{root}/regime_counts", counts.astype(np.float64))
    rise = np.array([r.electrical.get("contact_temperature_rise_k", math.nan) for r in rows])
    batch.scalars(f"{root}/temperatures_c", np.column_stack([sp[:, 3], sp[:, 3] + np.nan_to_num(rise)]))

    # electrical panel, engineering units
    if any(r.electrical for r in rows):
        def el(key: str, scale: float = 1.0) -> np.ndarray:
            return np.array([r.electrical.get(key, math.nan) for r in rows]) * scale

        batch.scalars(f"{root}/electrical/capacitance_pf", el("capacitance_f", 1e12))
        batch.scalars(f"{root}/electrical/resistance_log10_kohm",
                      np.column_stack([_log10_kohm(el("resistance_ohm")), _log10_kohm(el("impedance_ohm"))]))
        batch.scalars(f"{root}/electrical/shaft_voltage_v", el("shaft_voltage_v"))
        batch.scalars(f"{root}/electrical/shaft_current_ma", el("shaft_current_a", 1e3))
        batch.scalars(f"{root}/electrical/film_field_v_per_um", el("max_film_field_v_m", 1e-6))
        batch.scalars(f"{root}/electrical/current_density_a_per_mm2", el("current_density_a_m2", 1e-6))


def slow_columns(tw: TwinLayout, batch: Batch) -> None:
    """The per-contact series (2 Z instances per row)."""
    rows = batch.rows
    n = len(rows)
    root = tw.root
    c = np.stack([r.contacts for r in rows]).reshape(n, -1, len(CONTACT_FIELDS))   # (n, 2z, K)
    fields = {"load_n": c[..., F_LOAD], "lambda": c[..., F_LAMBDA], "mu": c[..., F_MU],
              "resistance_log10_kohm": _log10_kohm(c[..., F_R]), "capacitance_pf": c[..., F_C] * 1e12}
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
def _fmt(v: float) -> str:
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
        in_phase = (r.context is not None and ": running" in r.context and r.context == last.get("logged_context"))
        if r.setpoint is not None and r.setpoint != last.get("setpoint") and not in_phase:
            old = last.get("setpoint")
            if old is None:
                what = ", ".join(f"{n} = {_fmt(v)}" for n, v in zip(SETPOINT_FIELDS, r.setpoint, strict=True))
                texts.append((j, f"setpoint in force: {what}", "INFO"))
            else:
                what = ", ".join(f"{n} {_fmt(a)} -> {_fmt(b)}"
                                 for n, a, b in zip(SETPOINT_FIELDS, old, r.setpoint, strict=True) if a != b)
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
            texts.append((j, "defects: " + "; ".join(r.defects) if r.defects else "defects cleared",
                          "WARN" if r.defects else "INFO"))
        if r.defects is not None:
            last["defects"] = r.defects
        if r.risk is not None and r.risk != last.get("risk"):
            risks.append((j, r.risk if r.risk in RISK_VALUES else "none"))
            if last.get("risk") is not None:
                texts.append((j, f"discharge risk {r.risk}: {r.risk_reason or ''}".rstrip(": "),
                              "ERROR" if r.risk == "likely" else "WARN" if r.risk == "possible" else "INFO"))
            last["risk"] = r.risk
    if texts:
        sel = np.array([j for j, _, _ in texts])
        batch.out.append((f"{tw.root}/events", batch.index(sel),
                          rr.TextLog.columns(text=[t for _, t, _ in texts], level=[lv for _, _, lv in texts])))
    if risks:
        sel = np.array([j for j, _ in risks])
        batch.out.append((f"{tw.root}/electrical/discharge_risk", batch.index(sel),
                          rr.StateChange.columns(state=[s for _, s in risks])))


# ---- alarms ---------------------------------------------------------------------------------------
@dataclass(slots=True)
class AlarmRow:
    """One alarm event (service.core.alarms.AlarmEvent) as the recorder keeps it."""

    bearing_id: str
    alarm_id: str
    transition: str                   # raised | escalated | deescalated | cleared
    severity: str | None              # warning | critical | None (cleared)
    time_s: float                     # simulated time of the event [s]
    seq: int | None                   # seq of the snapshot that caused it
    value: float
    threshold: float
    clear_threshold: float
    unit: str
    message: str

    @classmethod
    def of(cls, event) -> AlarmRow:
        """From an `AlarmEvent` (or its dict)."""
        get = event.get if isinstance(event, Mapping) else (lambda k, d=None: getattr(event, k, d))
        seq = get("snapshot_seq")
        return cls(bearing_id=str(get("bearing_id")), alarm_id=str(get("alarm_id")),
                   transition=str(get("transition")), severity=get("severity"),
                   time_s=float(get("time_s")), seq=int(seq) if isinstance(seq, int) else None,
                   value=float(get("value")), threshold=float(get("threshold")),
                   clear_threshold=float(get("clear_threshold")), unit=str(get("unit") or "-"),
                   message=str(get("message") or ""))

    @property
    def state(self) -> str:
        return self.severity if self.severity in ALARM_STATES else "inactive"

    @property
    def text(self) -> str:
        unit = "" if self.unit == "-" else f" {self.unit}"
        return (f"{self.message} [value {_fmt(self.value)}{unit}, raise at {_fmt(self.threshold)}{unit}, "
                f"clear at {_fmt(self.clear_threshold)}{unit}]")


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
            out.append((f"{tw.root}/alarms/{alarm_id}", _alarm_index(t, seqs),
                        rr.TextLog.columns(text=[r.text for r in part],
                                           level=[ALARM_LOG_LEVEL.get(r.severity, "INFO") for r in part])))
            out.append((f"{tw.root}/alarm_states/{alarm_id}", _alarm_index(t, seqs),
                        rr.StateChange.columns(state=[r.state for r in part])))
    return out


def alarm_states_in_force(tw: TwinLayout, states: Mapping[str, str], time_s: float, seq: int | None,
                          offset_s: float) -> list:
    """StateChange rows of the alarms active when a new output (a segment) started, at `time_s`
    (its first row), so that its state timeline does not begin empty."""
    active = [(k, v) for k, v in states.items() if v != "inactive"]
    t = np.array([round((time_s + offset_s) * 1e9)], dtype=np.int64)
    return [(f"{tw.root}/alarm_states/{alarm_id}", _alarm_index(t, [seq]), rr.StateChange.columns(state=[state]))
            for alarm_id, state in active]


# ---- vibration ------------------------------------------------------------------------------------
def vibration_columns(tw: TwinLayout, batch: Batch) -> None:
    """The indicators of every new accelerometer window (a row at the snapshot that first
    carries it): `vibration/...` Scalars and the envelope bar charts (layout.VIBRATION_SERIES)."""
    last = tw.last
    sel, blocks = [], []
    for j, r in enumerate(batch.rows):
        v = r.vibration
        if v is None or v.window_end_s == last.get("window_end_s"):
            continue
        last["window_end_s"] = v.window_end_s
        sel.append(j)
        blocks.append(v)
    if not sel:
        return
    idx = np.array(sel)
    root = tw.root
    n = len(blocks)

    def scalars(leaf: str, values) -> None:
        v = np.asarray(values, dtype=np.float64).reshape(n, -1)
        batch.out.append((f"{root}/vibration/{leaf}", batch.index(idx),
                          rr.Scalars.columns(scalars=v.reshape(-1)).partition(np.full(n, v.shape[1]))))

    scalars("acceleration_rms_peak_m_s2", [[b.rms_m_s2, b.peak_m_s2] for b in blocks])
    scalars("velocity_rms_mm_s", [[b.velocity_rms_mm_s] for b in blocks])
    scalars("kurtosis", [[b.kurtosis, b.band_kurtosis, b.crest_factor] for b in blocks])
    freqs = np.array([[getattr(b.defect_frequencies_hz, k) for k in VIB_LINES] for b in blocks])
    amps = np.array([[_line_fundamental(b, k) for k in VIB_LINES] for b in blocks])
    floor = np.array([[b.envelope_noise_floor_m_s2] for b in blocks])
    scalars("defect_frequencies_hz", freqs)
    scalars("envelope_lines_m_s2", np.hstack([amps, floor]))
    # the envelope spectrum as the snapshot has it: its largest peaks, and the defect lines (markers)
    k = max(1, max(len(b.envelope_peaks_hz) for b in blocks))
    peak_f = np.zeros((n, k))
    peak_a = np.zeros((n, k))
    for i, b in enumerate(blocks):
        for m, p in enumerate(b.envelope_peaks_hz):
            peak_f[i, m], peak_a[i, m] = p.frequency_hz, p.amplitude
    batch.out.append((f"{root}/vibration/envelope/peaks", batch.index(idx), _bar_columns(peak_a, peak_f)))
    batch.out.append((f"{root}/vibration/envelope/defect_lines", batch.index(idx),
                      _bar_columns(np.nan_to_num(amps), freqs)))
    _spectrum_columns(tw, batch, idx, blocks)


def _spectrum_columns(tw: TwinLayout, batch: Batch, idx: np.ndarray, blocks: list) -> None:
    """The windows' full spectra (VibrationState.envelope_spectrum / amplitude_spectrum; windows
    without them are skipped) as bar charts against frequency [Hz], bars a bin wide or (range /
    SPECTRUM_PIXELS), whichever is wider:
    `vibration/envelope/spectrum` with the defect-frequency cursors
    `vibration/envelope/cursor/{FTF,BPFO,BPFI,BSF,2xBSF}` (1x, 2x, 3x each, as tall as the spectrum), and
    `vibration/spectrum` with the envelope band `vibration/spectrum_envelope_band`."""
    root = tw.root
    env = [(j, b.envelope_spectrum) for j, b in enumerate(blocks) if getattr(b, "envelope_spectrum", None) is not None]
    if env:
        sel = idx[[j for j, _ in env]]
        amps = [np.asarray(e.amplitude_m_s2) for _, e in env]
        tops = [float(a.max()) if a.size else 0.0 for a in amps]
        batch.out.append((f"{root}/vibration/envelope/spectrum", batch.index(sel),
                          _bar_columns(amps, [e.frequencies_hz for _, e in env],
                                       [np.full(a.size, _bar_width(e)) for a, (_, e) in zip(amps, env, strict=True)])))
        for name, label in zip(VIB_LINES, CURSOR_NAMES, strict=True):
            fs, hs, ws = [], [], []
            for (j, e), top in zip(env, tops, strict=True):
                f0 = getattr(blocks[j].defect_frequencies_hz, name)
                f = np.array([k * f0 for k in range(1, CURSOR_HARMONICS + 1) if k * f0 <= e.max_hz])
                fs.append(f)
                hs.append(np.full(f.size, top))
                ws.append(np.full(f.size, max(2.0 * e.step_hz, e.max_hz / CURSOR_WIDTH_FRACTION)))
            batch.out.append((f"{root}/vibration/envelope/cursor/{label}", batch.index(sel), _bar_columns(hs, fs, ws)))
    acc = [(j, b.amplitude_spectrum) for j, b in enumerate(blocks) if getattr(b, "amplitude_spectrum", None) is not None]
    if acc:
        sel = idx[[j for j, _ in acc]]
        amps = [np.asarray(a.amplitude_m_s2) for _, a in acc]
        batch.out.append((f"{root}/vibration/spectrum", batch.index(sel),
                          _bar_columns(amps, [a.frequencies_hz for _, a in acc],
                                       [np.full(x.size, _bar_width(a)) for x, (_, a) in zip(amps, acc, strict=True)])))
        band = [blocks[j].envelope_band_hz for j, _ in acc]
        batch.out.append((f"{root}/vibration/spectrum_envelope_band", batch.index(sel),
                          _bar_columns([np.array([float(a.max()) if a.size else 0.0]) for a in amps],
                                       [np.array([0.5 * (lo + hi)]) for lo, hi in band],
                                       [np.array([hi - lo]) for lo, hi in band])))


def _bar_width(spectrum) -> float:
    """Bar width [Hz] of a spectrum's bins: a bin, or (its range / SPECTRUM_PIXELS) when wider."""
    return max(spectrum.step_hz, (spectrum.max_hz + 0.5 * spectrum.step_hz) / SPECTRUM_PIXELS)


def _line_fundamental(block, name: str) -> float:
    line = (block.envelope_lines or {}).get(name)
    return float(line.harmonics[0]) if line is not None and line.harmonics else math.nan


@dataclass(slots=True)
class WaveRow:
    """Accelerometer samples that came with one snapshot (twin.vibration.sensor.WaveformBlock)."""

    seq: int
    t0_s: float
    sample_rate_hz: float
    samples: np.ndarray              # float32 [m/s^2]


def waveform_columns(tw: TwinLayout, rows: list[WaveRow], offset_s: float) -> list:
    """`vibration/acceleration_m_s2`: one Scalars row per sample at its own simulated time (the
    `seq` of the snapshot it came with), all of a send in one call."""
    rows = [r for r in rows if r.samples.size]
    if not rows:
        return []
    t = np.concatenate([np.round((r.t0_s + offset_s + np.arange(r.samples.size) / r.sample_rate_hz) * 1e9)
                        for r in rows]).astype(np.int64)
    seq = np.concatenate([np.full(r.samples.size, r.seq, dtype=np.int64) for r in rows])
    x = np.concatenate([r.samples for r in rows]).astype(np.float64)
    index = [rr.TimeColumn(SIM_TIME, duration=t.astype("timedelta64[ns]")), rr.TimeColumn(SEQ, sequence=seq)]
    return [(f"{tw.root}/vibration/acceleration_m_s2", index, rr.Scalars.columns(scalars=x))]
