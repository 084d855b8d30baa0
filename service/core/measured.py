"""Measured vibration beside the twin: a monitoring system's accelerometer window, analysed with
the twin's own analysis (twin.vibration.analysis.analyse_signal), compared with the twin's
prediction at the same operating point.

Inputs (every transport goes through `window_from_*`, then `MeasuredComparator.compare`):

- JSON {"sample_rate_hz": ..., "units": "m/s2" | "g", "samples": [...], "shaft_hz": optional}
  (HTTP `POST /v1/bearings/{id}/vibration/measured`, application/json);
- raw little-endian float32 samples with the same fields as query parameters (HTTP, body
  application/octet-stream);
- a binary frame (zenoh `{prefix}/{id}/vibration/measured`), little-endian:

      offset  type     field
      0       4 bytes  magic b"BTVM"
      4       uint8    layout version (1)
      5       uint8    units: 0 = m/s2, 1 = g (9.80665 m/s2)
      6       uint16   reserved, 0
      8       float64  sample_rate_hz [Hz]
      16      float64  shaft_hz [Hz]; 0 = the twin's current shaft speed
      24      uint32   n, the number of samples
      28      uint32   reserved, 0
      32      float32  n samples, in the units above

Bounds: 1024 to 2^21 samples, all finite; sample rate 500 Hz to 1 MHz; shaft_hz 0 (the twin's) or
(0, fs / 20]. A bad window is refused with InputError 422 naming the field and the allowed range.

The comparison (JSON-ready dict): `measured` (the analysis, `VibrationAnalysis.to_dict`), `predicted`
(the twin at the same moment: its defects, and, when it simulates its housing, the RMS, kurtosis,
crest factor and defect-line heights of its last vibration window [the twin's line height is over
the median of its envelope spectrum]; a healthy twin without housing predicts a Gaussian kurtosis
of 3: the broadband vibration of a healthy bearing, Randall & Antoni 2011, MSSP 25, sec. 3.1),
`residual` (measured - predicted where both exist) and `alarms`, what the measurement shows that
the twin's state does not explain:

- `unexplained_line`: a defect line (BPFO, BPFI, 2xBSF) at least `line_alarm_db` over its local
  background (median of +-20 Hz) while the twin has no defect of that kind (outer, inner, ball).
  The default, 16 dB, lies between the highest defect-line height of the healthy CWRU excerpt's
  1 s windows (13.5 dB) and the lowest height of the expected line in the inner and outer-race
  ones (17.8 dB) (tests/data/cwru; Case Western Reserve University Bearing Data Center);
- `kurtosis_above_twin`: measured kurtosis above the twin's prediction by more than
  `kurtosis_margin` (default 1.5: the healthy CWRU record reads 2.7-2.8, its faults 4.2-8.1).
"""

from __future__ import annotations

import math
import struct
import threading
import time
from dataclasses import dataclass

import numpy as np

from service.core.admission import AdmissionGate, Refusal
from service.core.errors import InputError
from twin.vibration.analysis import (
    AnalysisInputError,
    analyse_signal,
    defect_multiples_of,
)

STANDARD_GRAVITY_M_S2 = 9.80665
UNITS = {"m/s2": 1.0, "g": STANDARD_GRAVITY_M_S2}
UNIT_CODES = {0: "m/s2", 1: "g"}
MIN_SAMPLES = 1024
MAX_SAMPLES = 2**21
MIN_RATE_HZ = 500.0
MAX_RATE_HZ = 1.0e6
MAGIC = b"BTVM"
LAYOUT_VERSION = 1
HEADER = struct.Struct("<4sBBHddII")  # 32 bytes, module docstring
LINE_OF_DEFECT = {"outer": "BPFO", "inner": "BPFI", "ball": "2xBSF"}
TWIN_LINE_KEY = {"BPFO": "bpfo", "BPFI": "bpfi", "2xBSF": "two_bsf"}
LINE_ALARM_DB = 16.0
KURTOSIS_MARGIN = 1.5
GAUSSIAN_KURTOSIS = 3.0


@dataclass(frozen=True)
class MeasuredWindow:
    """One validated window: samples [m/s^2], sample_rate_hz [Hz], the units it came in, shaft_hz
    [Hz] or None (the twin's current shaft speed)."""

    samples_m_s2: np.ndarray
    sample_rate_hz: float
    units: str
    shaft_hz: float | None


def _rate(value) -> float:
    if isinstance(value, bool):
        value = float("nan")  # refused below
    try:
        fs = float(value)
    except (TypeError, ValueError):
        fs = float("nan")
    if not (math.isfinite(fs) and MIN_RATE_HZ <= fs <= MAX_RATE_HZ):
        raise InputError.one(
            "sample_rate_hz", f"must be a number in [{MIN_RATE_HZ:g}, {MAX_RATE_HZ:g}] Hz", [MIN_RATE_HZ, MAX_RATE_HZ]
        )
    return fs


def _units(value) -> str:
    if not isinstance(value, str) or value not in UNITS:
        raise InputError.one("units", f"must be one of {', '.join(UNITS)}", list(UNITS))
    return value


def _shaft(value, fs: float) -> float | None:
    if value is None:
        return None
    if isinstance(value, bool):
        value = float("nan")  # refused below
    try:
        f = float(value)
    except (TypeError, ValueError):
        f = float("nan")
    if f == 0.0:
        return None
    if not (math.isfinite(f) and 0.0 < f <= fs / 20.0):
        raise InputError.one(
            "shaft_hz", f"must be 0 (the twin's shaft speed) or in (0, {fs / 20.0:g}] Hz (fs / 20)", [0.0, fs / 20.0]
        )
    return f


def _samples(values: np.ndarray, units: str) -> np.ndarray:
    if values.ndim != 1 or not MIN_SAMPLES <= values.size <= MAX_SAMPLES:
        raise InputError.one(
            "samples", f"{values.size} samples: need {MIN_SAMPLES} to {MAX_SAMPLES}", [MIN_SAMPLES, MAX_SAMPLES]
        )
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        raise InputError.one(
            "samples",
            f"{bad.size} non-finite samples (first at index {int(bad[0])}); every sample must be a finite number",
        )
    return values.astype(float) * UNITS[units]


def window_from_json(data) -> MeasuredWindow:
    """A window from the JSON body (module docstring); InputError 422 naming the field."""
    if not isinstance(data, dict):
        raise InputError.one(None, "a JSON object {sample_rate_hz, units, samples[, shaft_hz]}")
    extra = sorted(set(data) - {"sample_rate_hz", "units", "samples", "shaft_hz"})
    if extra:
        raise InputError.one(extra[0], "unknown field; allowed: sample_rate_hz, units, samples, shaft_hz")
    for name in ("sample_rate_hz", "samples"):
        if name not in data:
            raise InputError.one(name, "required")
    for name in ("sample_rate_hz", "shaft_hz"):  # JSON numbers, not text or true/false
        value = data.get(name)
        if value is not None and (isinstance(value, bool) or not isinstance(value, (int, float))):
            raise InputError.one(name, f"must be a JSON number, got {type(value).__name__}")
    fs = _rate(data["sample_rate_hz"])
    units = _units(data.get("units", "m/s2"))
    raw = data["samples"]
    if not isinstance(raw, list) or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in raw):
        raise InputError.one("samples", "must be a list of numbers")
    return MeasuredWindow(_samples(np.asarray(raw, dtype=float), units), fs, units, _shaft(data.get("shaft_hz"), fs))


def window_from_float32(body: bytes, sample_rate_hz, units: str = "m/s2", shaft_hz=None) -> MeasuredWindow:
    """A window from raw little-endian float32 samples and its parameters (module docstring)."""
    fs = _rate(sample_rate_hz)
    units = _units(units)
    if len(body) % 4:
        raise InputError.one("samples", f"{len(body)} bytes: a float32 body is a multiple of 4 bytes")
    values = np.frombuffer(body, dtype="<f4")
    return MeasuredWindow(_samples(values, units), fs, units, _shaft(shaft_hz, fs))


def encode_frame(samples, sample_rate_hz: float, units: str = "m/s2", shaft_hz: float = 0.0) -> bytes:
    """The binary frame of a window (module docstring): for monitoring clients and tests."""
    x = np.asarray(samples, dtype="<f4").ravel()
    code = {v: k for k, v in UNIT_CODES.items()}[units]
    return HEADER.pack(MAGIC, LAYOUT_VERSION, code, 0, float(sample_rate_hz), float(shaft_hz), x.size, 0) + x.tobytes()


def window_from_frame(payload: bytes) -> MeasuredWindow:
    """A window from the binary frame (module docstring); InputError 422 naming the field."""
    if len(payload) < HEADER.size:
        raise InputError.one("header", f"{len(payload)} bytes: the frame starts with a {HEADER.size}-byte header")
    magic, version, code, _r1, fs, shaft, n, _r2 = HEADER.unpack_from(payload)
    if magic != MAGIC or version != LAYOUT_VERSION:
        raise InputError.one("header", f"magic {MAGIC!r} and layout version {LAYOUT_VERSION} expected")
    if code not in UNIT_CODES:
        raise InputError.one("units", "unit code must be 0 (m/s2) or 1 (g)", [0, 1])
    body = payload[HEADER.size :]
    if len(body) != 4 * n:
        raise InputError.one("n", f"header says {n} samples, the frame carries {len(body)} bytes ({4 * n} expected)")
    return window_from_float32(body, fs, UNIT_CODES[code], shaft)


_FIELD_OF_ANALYSIS = {"signal_m_s2": "samples", "sample_rate_hz": "sample_rate_hz", "shaft_hz": "shaft_hz"}


class MeasuredComparator:
    """One twin's measured-against-predicted comparison (module docstring); thread-safe."""

    def __init__(
        self,
        bearing_id: str,
        geometry,
        runner=None,
        *,
        line_alarm_db: float = LINE_ALARM_DB,
        kurtosis_margin: float = KURTOSIS_MARGIN,
    ):
        self.bearing_id = bearing_id
        self.runner = runner
        self.multiples = defect_multiples_of(geometry)
        self.line_alarm_db, self.kurtosis_margin = line_alarm_db, kurtosis_margin
        self._lock = threading.Lock()
        self._latest: dict | None = None
        self.windows = 0
        self.listeners: list = []  # callables taking each comparison (the rerun recorder); must not block
        self.listener_errors = 0

    @property
    def latest(self) -> dict | None:
        with self._lock:
            return self._latest

    def receive(self, window: MeasuredWindow) -> dict:
        """`compare` against the runner's latest snapshot and the defects it holds."""
        return self.compare(window, self.runner.latest_snapshot(), self.runner.defect_box.target)

    def compare(self, window: MeasuredWindow, snapshot, defects: tuple) -> dict:
        """Analyse `window` and set it beside the twin (`snapshot`: its latest, `defects`: the ones
        in force). Returns the comparison and keeps it as `latest`."""
        shaft_hz = window.shaft_hz
        if shaft_hz is None:
            speed = abs(float(getattr(snapshot, "shaft_speed_rad_s", 0.0) or 0.0))
            shaft_hz = speed / (2.0 * math.pi)
            if not shaft_hz > 0.0:
                raise InputError.one(
                    "shaft_hz",
                    "the twin's shaft stands still: give the window's shaft_hz",
                    [0.0, window.sample_rate_hz / 20.0],
                )
            if shaft_hz > window.sample_rate_hz / 20.0:  # the window's rate, not a shaft_hz it did not give
                raise InputError.one(
                    "sample_rate_hz",
                    f"{window.sample_rate_hz:g} Hz is too low for the twin's shaft at {shaft_hz:.4g} Hz: at least "
                    f"{20.0 * shaft_hz:.4g} Hz (20 x the shaft), or give the window's own shaft_hz",
                    [20.0 * shaft_hz, MAX_RATE_HZ],
                )
        try:
            analysis = analyse_signal(window.samples_m_s2, window.sample_rate_hz, shaft_hz, self.multiples)
        except AnalysisInputError as exc:
            raise InputError.one(_FIELD_OF_ANALYSIS.get(exc.field, exc.field), str(exc).split(": ", 1)[1]) from None
        predicted = self._predicted(snapshot, defects)
        measured = analysis.to_dict()
        residual = {
            key: (measured[key] - predicted[key] if predicted.get(key) is not None else None)
            for key in ("rms_m_s2", "kurtosis", "crest_factor")
        }
        heights = {d.name: d.height_db for d in analysis.defect_lines}
        residual["line_height_db"] = {
            name: (
                heights[name] - predicted["line_height_db"][name]
                if predicted["line_height_db"].get(name) is not None
                else None
            )
            for name in TWIN_LINE_KEY
        }
        alarms = self._alarms(analysis, heights, predicted)
        with self._lock:
            self.windows += 1
            out = {
                "bearing_id": self.bearing_id,
                "window": self.windows,
                "received_wall_s": time.time(),
                "twin_time_s": float(snapshot.time_s) if snapshot is not None else None,
                "twin_seq": int(snapshot.seq) if snapshot is not None else None,
                "shaft_hz": shaft_hz,
                "units_received": window.units,
                "measured": measured,
                "predicted": predicted,
                "residual": residual,
                "alarm": bool(alarms),
                "alarms": alarms,
            }
            self._latest = out
        for listener in list(self.listeners):
            try:
                listener(out)
            except Exception:  # noqa: BLE001 - a listener never fails the comparison
                self.listener_errors += 1
        return out

    def _predicted(self, snapshot, defects: tuple) -> dict:
        kinds = sorted({getattr(d, "kind", None) or d.get("kind") for d in defects})
        vib = getattr(snapshot, "vibration", None) if snapshot is not None else None
        heights = dict.fromkeys(TWIN_LINE_KEY)
        if vib is not None:
            floor = vib.envelope_noise_floor_m_s2
            for name, key in TWIN_LINE_KEY.items():
                line = vib.envelope_lines.get(key)
                if line is not None and floor > 0.0 and line.harmonics and line.harmonics[0] > 0.0:
                    heights[name] = 20.0 * math.log10(line.harmonics[0] / floor)
            return {
                "source": "twin_vibration_window",
                "defect_kinds": kinds,
                "rms_m_s2": vib.rms_m_s2,
                "kurtosis": vib.kurtosis,
                "crest_factor": vib.crest_factor,
                "line_height_db": heights,
            }
        return {
            "source": "healthy_gaussian" if not kinds else "defects_only",
            "defect_kinds": kinds,
            "rms_m_s2": None,
            "kurtosis": GAUSSIAN_KURTOSIS if not kinds else None,
            "crest_factor": None,
            "line_height_db": heights,
        }

    def _alarms(self, analysis, heights: dict, predicted: dict) -> list[dict]:
        alarms = []
        kinds = set(predicted["defect_kinds"])
        for kind, name in LINE_OF_DEFECT.items():
            if name in heights and heights[name] >= self.line_alarm_db and kind not in kinds:
                line = analysis.line(name)
                alarms.append(
                    {
                        "code": "unexplained_line",
                        "line": name,
                        "height_db": heights[name],
                        "frequency_hz": line.peak_hz,
                        "message": f"measured {name} line at {line.peak_hz:.1f} Hz stands "
                        f"{heights[name]:.1f} dB over its +-20 Hz background "
                        f"(alarm at {self.line_alarm_db:g} dB); the twin has no {kind} defect",
                    }
                )
        k_pred = predicted.get("kurtosis")
        if k_pred is not None and analysis.kurtosis - k_pred > self.kurtosis_margin:
            alarms.append(
                {
                    "code": "kurtosis_above_twin",
                    "measured": analysis.kurtosis,
                    "predicted": k_pred,
                    "message": f"measured kurtosis {analysis.kurtosis:.2f} exceeds the twin's {k_pred:.2f} "
                    f"by more than {self.kurtosis_margin:g}",
                }
            )
        return alarms


class MeasuredIntake:
    """Binary frames from the bus (zenoh `{prefix}/{id}/vibration/measured`): the admission gate
    (bus writer, size, the twin's setpoint budget), `window_from_frame`, `MeasuredComparator.receive`.
    Never raises: {"accepted": True, **comparison} or {"accepted": False, "status", "error",
    "detail"}, what the transport publishes on `{prefix}/{id}/vibration/comparison`."""

    def __init__(self, bearing_id: str, gate: AdmissionGate, comparator: MeasuredComparator):
        self.bearing_id, self.gate, self.comparator = bearing_id, gate, comparator
        self.refused = 0

    def __call__(self, payload: bytes) -> dict:
        try:
            refusal = (
                self.gate.check_bus_writer()
                or self.gate.check_size(len(payload))
                or self.gate.take_setpoint(self.bearing_id)
            )
            if refusal is not None:
                return self._refused(refusal)
            return {"accepted": True, **self.comparator.receive(window_from_frame(bytes(payload)))}
        except InputError as exc:
            self.refused += 1
            return {
                "accepted": False,
                "status": exc.status_code,
                "error": str(exc),
                "detail": [e.model_dump() for e in exc.errors],
            }
        except Exception as exc:  # noqa: BLE001 - a refusal, never a crash
            self.refused += 1
            return {"accepted": False, "status": 422, "error": f"{type(exc).__name__}: {exc}"}

    def _refused(self, refusal: Refusal) -> dict:
        self.refused += 1
        out = {"accepted": False, "status": refusal.status, "error": refusal.message}
        if refusal.retry_after_s is not None:
            out["retry_after_s"] = refusal.retry_after_s
        return out
