"""Bearing-level trends as window statistics, markers of setpoint and defect changes, robust scales.

Why windows. A snapshot samples the twin at one instant, 50 times a second; the ball-pass ripple
of the loads, the friction torque and the capacitance runs at hundreds of hertz, so 50 Hz samples
fold it into slow false oscillations (the balls per regime become a 4-5 square wave). Each trend
row here is a window of `window_s` of simulated time instead: the mean of the snapshots in it
(the ripple averages out: the samples fall at effectively random phases of it), and for the
measured series (`layout.TREND_BANDS`) also their smallest and largest value, drawn as thin
lines on either side (the band the ripple spans). A window closes at its end, at a gap (`Row.
gap_before`: a line break) and at a forced send (flush, close: the last window may be short).

Markers. A setpoint or defect change puts a point (`layout.CHANGE_MARKER`) on every trend at the
snapshot where it took effect (`{trend}/changes`); the text of the change is in `events`.

Robust scale. The bearing capacitance spans decades when a contact's film nearly closes: one
value 10^7 times the others flattens the line to zero. A value more than `OFF_SCALE_DECADES`
decades from the running median is left out of the line and drawn as a marker at the edge of the
line's range (`electrical/capacitance_pf/off_scale`), with its value in `events`; where the
capacitance goes missing (the film broke: metal contact, the capacitance is undefined) a marker
at `electrical/capacitance_pf/film_broken` starts each such run, and `events` says why the line
is empty there (at most once a minute: a film in mixed lubrication breaks and heals often).
"""

from __future__ import annotations

import math

import numpy as np
import rerun as rr

from service.recording.columns import F_LAMBDA, F_LOAD, THERMAL_NODES, THERMAL_SOURCES, ball_regime, log10_kohm
from service.recording.layout import (
    CAPACITANCE_LEAF,
    FILM_BROKEN_LEAF,
    OFF_SCALE_LEAF,
    REGIME_ORDER,
    SEQ,
    SIM_TIME,
    TREND_BANDS,
    TwinLayout,
)

OFF_SCALE_DECADES = 1.0  # a capacitance more than this many decades from the running median is off scale
NOTE_EVERY_NS = 60_000_000_000  # [ns of simulated time] at most one film-broken / -healed event per minute
_MEDIAN_MEMORY = 0.9  # running median of the capacitance: weight of the old value per window


def trend_values(tw: TwinLayout, rows: list) -> dict[str, np.ndarray]:
    """{trend leaf: (n, k) values per snapshot} in the units of `layout.SERIES` (setpoints beside
    the measured values; NaN where a snapshot has no value)."""
    n = len(rows)
    c = np.stack([r.contacts for r in rows])  # (n, z, 2, K)
    reg = np.stack([r.regimes for r in rows])
    load, lam = c[..., F_LOAD], c[..., F_LAMBDA]
    sp = np.array([r.setpoint if r.setpoint is not None else (math.nan,) * 6 for r in rows]).reshape(n, 6)
    with np.errstate(invalid="ignore"):
        qmax = np.nanmax(np.where(np.isfinite(load), load, -math.inf).reshape(n, -1), axis=1)
        loaded = np.isfinite(lam) & (load > 0)
    qmax[~np.isfinite(qmax)] = math.nan
    min_lam = np.where(loaded, lam, math.inf).min(axis=1)  # (n, 2)
    min_lam[~np.isfinite(min_lam)] = math.nan
    ball_reg = ball_regime(reg)
    counts = np.stack([(ball_reg == code).sum(axis=1) for code in REGIME_ORDER], axis=1).astype(np.float64)
    rise = np.array([r.electrical.get("contact_temperature_rise_k", math.nan) for r in rows])
    out = {
        "friction_torque_n_m": np.array([[r.friction_torque_n_m] for r in rows], dtype=np.float64),
        "loads_n": np.column_stack([qmax, sp[:, 1], sp[:, 2]]),
        "speeds_rad_s": np.column_stack(
            [sp[:, 0], [r.shaft_speed_rad_s for r in rows], [r.cage_speed_rad_s for r in rows]]
        ),
        "min_lambda": min_lam,
        "regime_counts": counts,
        "temperatures_c": np.column_stack([sp[:, 3], sp[:, 3] + np.nan_to_num(rise)]),
    }
    if any(r.thermal is not None for r in rows):
        nt = len(THERMAL_NODES)
        th = np.array(
            [r.thermal if r.thermal is not None else (math.nan,) * (nt + len(THERMAL_SOURCES)) for r in rows],
            dtype=np.float64,
        )
        out["thermal/nodes_c"] = th[:, :nt]
        out["thermal/heat_w"] = th[:, nt:]
    if any(r.electrical for r in rows):

        def el(key: str, scale: float = 1.0) -> np.ndarray:
            return np.array([r.electrical.get(key, math.nan) for r in rows], dtype=np.float64) * scale

        out[CAPACITANCE_LEAF] = el("capacitance_f", 1e12)[:, None]
        out["electrical/resistance_log10_kohm"] = np.column_stack(
            [log10_kohm(el("resistance_ohm")), log10_kohm(el("impedance_ohm"))]
        )
        out["electrical/shaft_voltage_v"] = np.column_stack([el("shaft_voltage_v"), sp[:, 5]])
        out["electrical/shaft_current_ma"] = np.column_stack([el("shaft_current_a", 1e3), sp[:, 4] * 1e3])
        out["electrical/film_field_v_per_um"] = el("max_film_field_v_m", 1e-6)[:, None]
        out["electrical/current_density_a_per_mm2"] = el("current_density_a_m2", 1e-6)[:, None]
    return out


def split_windows(rows: list, window_s: float, final: bool) -> tuple[list[list], list]:
    """(complete windows, rows of the window still open): rows grouped by floor(time / window_s),
    a new window at every row with `gap_before`; with `final` the open window closes too."""
    windows: list[list] = []
    current: list = []
    key = None
    for r in rows:
        k = math.floor(r.time_s / window_s)
        if current and (k != key or r.gap_before is not None):
            windows.append(current)
            current = []
        current.append(r)
        key = k
    if final and current:
        windows.append(current)
        current = []
    return windows, current


def _index(t_ns: np.ndarray, seq: np.ndarray) -> list:
    return [rr.TimeColumn(SIM_TIME, duration=t_ns.astype("timedelta64[ns]")), rr.TimeColumn(SEQ, sequence=seq)]


def _scalars(v: np.ndarray) -> rr.ComponentColumnList:
    n, k = v.shape
    return rr.Scalars.columns(scalars=v.reshape(-1)).partition(np.full(n, k))


def _stats(values: np.ndarray, starts: np.ndarray, band: tuple[int, ...]) -> np.ndarray:
    """Per window (the contiguous, non-empty row ranges beginning at `starts`): the mean of every
    series, then the min and max of the series in `band`; NaN values are left out, and a window of
    NaN only stays NaN (fmin / fmax ignore NaN, and no warning is raised: this runs on the
    recorder's thread, where warnings filters are not safe)."""
    finite = ~np.isnan(values)
    zeroed = np.where(finite, values, 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.add.reduceat(zeroed, starts, axis=0) / np.add.reduceat(finite, starts, axis=0)
    if not band:
        return mean
    sel = values[:, list(band)]
    lo = np.fmin.reduceat(sel, starts, axis=0)
    hi = np.fmax.reduceat(sel, starts, axis=0)
    return np.hstack([mean, lo, hi])


def trend_columns(tw: TwinLayout, windows: list[list], offset_s: float, bands: bool = True) -> list:
    """The (entity path, index columns, component columns) triples of the trend entities for
    complete `windows` of rows: a row per window at the mean time of its snapshots (seq of its
    last), the change markers and the capacitance's off-scale and film-broken markers at their
    snapshots (with `events` rows saying why). `bands`: False leaves the min / max out (windows
    of one snapshot)."""
    rows = [r for w in windows for r in w]
    if not rows:
        return []
    values = trend_values(tw, rows)
    n = len(rows)
    t_ns = np.round((np.fromiter((r.time_s for r in rows), np.float64, n) + offset_s) * 1e9).astype(np.int64)
    seq = np.fromiter((r.seq for r in rows), np.int64, n)
    sizes = np.fromiter((len(w) for w in windows), np.intp, len(windows))  # none empty (split_windows)
    ends = np.cumsum(sizes)
    starts = ends - sizes
    w_t = np.round(np.add.reduceat(t_ns, starts) / sizes).astype(np.int64)
    w_seq = seq[ends - 1]
    out: list = []
    notes: list[tuple[int, str]] = []
    if CAPACITANCE_LEAF in values:
        has_el = np.array([bool(r.electrical) for r in rows])
        notes += _capacitance_scale(tw, values[CAPACITANCE_LEAF][:, 0], has_el, t_ns, seq, out)
    root = tw.root
    for leaf, v in values.items():
        band = TREND_BANDS.get(leaf, ()) if bands else ()
        out.append((f"{root}/{leaf}", _index(w_t, w_seq), _scalars(_stats(v, starts, band))))
    changed = _changes(tw, rows)
    if changed:
        sel = np.array(changed)
        for leaf, v in values.items():
            first = v[sel, 0]
            ok = np.isfinite(first)
            if ok.any():
                out.append(
                    (
                        f"{root}/{leaf}/changes",
                        _index(t_ns[sel][ok], seq[sel][ok]),
                        rr.Scalars.columns(scalars=first[ok]),
                    )
                )
    if notes:
        sel = np.array([j for j, _ in notes])
        out.append(
            (
                f"{root}/events",
                _index(t_ns[sel], seq[sel]),
                rr.TextLog.columns(text=[t for _, t in notes], level=["WARN"] * len(notes)),
            )
        )
    return out


def _changes(tw: TwinLayout, rows: list) -> list[int]:
    """Indexes of the rows where the setpoint or the defects differ from the row before."""
    last = tw.last
    changed = []
    for j, r in enumerate(rows):
        key = (r.setpoint, tuple(r.defects or ()))
        prev = last.get("trend_change_key")
        if prev is not None and key != prev:
            changed.append(j)
        last["trend_change_key"] = key
    return changed


def _capacitance_scale(
    tw: TwinLayout, c_pf: np.ndarray, has_el: np.ndarray, t_ns: np.ndarray, seq: np.ndarray, out: list
) -> list[tuple[int, str]]:
    """Leaves off-scale and undefined capacitances out of `c_pf` (set NaN, in place), marks them,
    and returns the event texts (at a change of state only). `has_el`: the rows with electrical
    fields (only there is a missing capacitance a broken film)."""
    last = tw.last
    root = tw.root
    ref = last.get("c_median_pf")
    finite = np.isfinite(c_pf) & (c_pf > 0)
    if ref is None and finite.any():
        ref = float(np.median(c_pf[finite]))
    notes: list[tuple[int, str]] = []
    off = np.zeros(c_pf.size, dtype=bool)
    if ref is not None and ref > 0:
        with np.errstate(divide="ignore", invalid="ignore"):
            off = finite & (np.abs(np.log10(c_pf / ref)) > OFF_SCALE_DECADES)
        good = finite & ~off
        if good.any():
            ref = _MEDIAN_MEMORY * ref + (1.0 - _MEDIAN_MEMORY) * float(np.median(c_pf[good]))
        last["c_median_pf"] = ref
    broken = ~np.isfinite(c_pf) & has_el
    state = last.get("c_state", "ok")
    starts = np.zeros(c_pf.size, dtype=bool)  # the first snapshot of each run of broken ones
    for j in range(c_pf.size):
        now = "broken" if broken[j] else "off" if off[j] else "ok"
        if now != state:
            starts[j] = now == "broken"
            quiet = t_ns[j] < last.get("c_note_ns", -NOTE_EVERY_NS) + NOTE_EVERY_NS
            if quiet and now != "off":
                state = now  # the film breaks and heals often: one note a minute
                continue
            last["c_note_ns"] = int(t_ns[j])
            if now == "broken":
                notes.append(
                    (
                        j,
                        "film broken (metal contact): the bearing capacitance is undefined, its plot is "
                        "empty and marked x until the film carries the load again",
                    )
                )
            elif now == "off":
                notes.append(
                    (
                        j,
                        f"bearing capacitance {c_pf[j]:.3g} pF is off scale (more than "
                        f"{OFF_SCALE_DECADES:g} decade from the running median {ref:.3g} pF): marked ^",
                    )
                )
            elif state == "broken":
                notes.append((j, "film carries the load again: bearing capacitance defined"))
            state = now
    last["c_state"] = state
    good = finite & ~off
    edge = float(np.max(c_pf[good])) if good.any() else (ref if ref is not None else 0.0)
    if off.any():
        out.append(
            (
                f"{root}/{OFF_SCALE_LEAF}",
                _index(t_ns[off], seq[off]),
                rr.Scalars.columns(scalars=np.full(int(off.sum()), edge)),
            )
        )
    if starts.any():
        base = float(np.min(c_pf[good])) if good.any() else edge
        out.append(
            (
                f"{root}/{FILM_BROKEN_LEAF}",
                _index(t_ns[starts], seq[starts]),
                rr.Scalars.columns(scalars=np.full(int(starts.sum()), base)),
            )
        )
    c_pf[off | broken] = math.nan
    return notes
