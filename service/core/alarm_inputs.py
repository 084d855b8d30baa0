"""The alarms' inputs: `AlarmInputs`, one twin at one instant as the alarms see it, built from a
snapshot (a `twin.snapshot.Snapshot` or its dict) by `inputs_from_snapshot`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from service.core.alarm_rules import DEFECT_LINES
from service.core.json_numbers import finite_number
from service.settings import AlarmSettings
from twin.snapshot import LAMBDA_KEY
from twin.snapshot_blocks import K_LAMBDA, K_LOAD
from twin.snapshot_frame import SnapshotFrame


# ---- inputs ------------------------------------------------------------------------------------
@dataclass(frozen=True)
class VibrationInputs:
    """What the vibration indicators give the alarms (twin.vibration.indicators)."""

    velocity_rms_mm_s: float | None = None  # ISO 20816 band 10-1000 Hz [mm/s]
    line_amplitudes_m_s2: Mapping[str, float] = field(default_factory=dict)  # envelope, fundamental [m/s^2]
    noise_floor_m_s2: float | None = None  # median envelope amplitude [m/s^2]


@dataclass(frozen=True)
class AlarmInputs:
    """One twin at one instant, as the alarms see it (SI unless the name says otherwise)."""

    time_s: float  # simulated time [s]
    seq: int | None = None  # the snapshot's seq (None: not from a snapshot)
    min_loaded_lambda: float | None = None  # smallest Lambda over the loaded contacts [-]
    boundary_contacts: int = 0  # loaded contacts with Lambda <= boundary_lambda
    kappa: float | None = None  # ISO 281 viscosity ratio [-]
    discharge_risk: str | None = None  # 'none' | 'possible' | 'likely'
    discharge_reason: str = ""
    damage_fraction: float | None = None  # Palmgren-Miner damage [-]
    vibration: VibrationInputs | None = None
    outer_ring_c: float | None = None  # outer-ring temperature [degC]
    outer_ring_rate_k_per_min: float | None = None  # its rate of rise [K/min]
    unexplained_heating: bool | None = None  # the estimator gated the last measurement
    residual_k: float | None = None  # measured - predicted temperature [K]


def _get(obj: Any, name: str) -> Any:
    """Field `name` of `obj`: a snapshot model's attribute, or its wire key in the snapshot's dict
    (`lambda_` is `lambda` on the wire); None when absent."""
    if obj is None:
        return None
    if isinstance(obj, Mapping):
        return obj.get(LAMBDA_KEY if name == "lambda_" else name)
    return getattr(obj, name, None)


def _line_amplitude(entry: Any) -> float | None:
    """A defect line's fundamental amplitude [m/s^2]: `harmonics[0]` of a
    twin.snapshot.DefectLine (or its dict)."""
    harmonics = _get(entry, "harmonics")
    if isinstance(harmonics, (list, tuple)) and harmonics:
        return finite_number(harmonics[0])
    return None


def vibration_inputs(block: Any) -> VibrationInputs | None:
    """`VibrationInputs` from a snapshot's `vibration` block (twin.snapshot.VibrationState, or
    its dict): `velocity_rms_mm_s`, the fundamentals of `envelope_lines` {ftf, bpfo, bpfi, bsf,
    two_bsf: DefectLine}, `envelope_noise_floor_m_s2`. None without a block."""
    if block is None:
        return None
    lines: dict[str, float] = {}
    table = _get(block, "envelope_lines")
    if isinstance(table, Mapping):
        for name, entry in table.items():
            a = _line_amplitude(entry)
            if a is not None and name in DEFECT_LINES:
                lines[str(name)] = a
    return VibrationInputs(
        velocity_rms_mm_s=finite_number(_get(block, "velocity_rms_mm_s")),
        line_amplitudes_m_s2=lines,
        noise_floor_m_s2=finite_number(_get(block, "envelope_noise_floor_m_s2")),
    )


def _seq(value: Any) -> int | None:
    return int(value) if isinstance(value, int) and not isinstance(value, bool) else None


def loaded_lambda(loads_n: np.ndarray, lambdas: np.ndarray, settings: AlarmSettings) -> tuple[float | None, int]:
    """(smallest Lambda, contacts at or below `boundary_lambda`) over the loaded contacts: those
    carrying at least `loaded_contact_fraction` of the largest load, with a finite Lambda."""
    loads = np.where(np.isfinite(loads_n), loads_n, 0.0)
    peak = float(loads.max(initial=0.0))
    if peak <= 0.0:
        return None, 0
    lam = lambdas[(loads > 0.0) & (loads >= settings.loaded_contact_fraction * peak) & np.isfinite(lambdas)]
    if lam.size == 0:
        return None, 0
    return float(lam.min()), int(np.count_nonzero(lam <= settings.boundary_lambda))


def inputs_from_snapshot(snapshot: Any, settings: AlarmSettings | None = None) -> AlarmInputs:
    """The alarms' inputs from a `twin.snapshot.Snapshot` (or its dict, or a
    twin.snapshot_frame.SnapshotFrame: its contact arrays, without building its tree): contacts,
    electrical, and the optional `life` and `vibration` blocks."""
    s = settings or AlarmSettings()
    if isinstance(snapshot, SnapshotFrame):
        contacts = snapshot.ball_arrays.contacts
        min_lambda, boundary = loaded_lambda(contacts[:, K_LOAD], contacts[:, K_LAMBDA], s)
        snapshot = snapshot.head
    else:
        rows = []
        for ball in _get(snapshot, "balls") or ():
            for side in ("inner", "outer"):
                c = _get(ball, side)
                if c is not None:
                    load, lam = finite_number(_get(c, "load_n")), finite_number(_get(c, "lambda_"))
                    rows.append((math.nan if load is None else load, math.nan if lam is None else lam))
        table = np.array(rows, dtype=float).reshape(-1, 2)
        min_lambda, boundary = loaded_lambda(table[:, 0], table[:, 1], s)
    electrical = _get(snapshot, "electrical")
    life = _get(snapshot, "life")
    thermal = _get(snapshot, "thermal")
    temps = _get(thermal, "temperatures_c") or {}
    unexplained = _get(thermal, "unexplained_heating")
    return AlarmInputs(
        time_s=float(_get(snapshot, "time_s") or 0.0),
        seq=_seq(_get(snapshot, "seq")),
        min_loaded_lambda=min_lambda,
        boundary_contacts=boundary,
        kappa=finite_number(_get(life, "kappa")),
        discharge_risk=_get(electrical, "discharge_risk"),
        discharge_reason=str(_get(electrical, "reason") or ""),
        damage_fraction=finite_number(_get(life, "damage_fraction")),
        vibration=vibration_inputs(_get(snapshot, "vibration")),
        outer_ring_c=finite_number(temps.get("outer_ring")) if thermal is not None else None,
        outer_ring_rate_k_per_min=finite_number(_get(thermal, "outer_ring_rate_k_per_min")),
        unexplained_heating=bool(unexplained) if unexplained is not None else None,
        residual_k=finite_number(_get(thermal, "residual_k")),
    )
