"""The `CWRU-DE` twin against the measured CWRU drive-end records: `python -m twin.validation.cwru
[--json] [--duration S]` regenerates the table of docs/validation.md; `--data DIR` runs the same
comparison on the records of any directory described by a `manifest.json` in the data set's form
(other motor loads, larger faults: `records_from_manifest`), predicting each from its metadata.

Measured: the 5 s float32 excerpts committed in tests/data/cwru (Case Western Reserve University
Bearing Data Center, engineering.case.edu/bearingdatacenter, 0 hp, 0.007 in EDM faults; manifest
and source there). Simulated: `twin.validation.vibration_simulation.simulate_vibration` of the `CWRU-DE` catalog
entry at the record's speed, the rig's radial load, the record's fault (a pit 0.178 mm across
and 0.279 mm deep: the data center's 0.007 in diameter, 0.011 in depth) at its position (outer
race 6:00, 3:00, 12:00 = 0, 90, 180 deg from the load direction), after SETTLE_S of start-up.

Both signals go through the same analysis (`analyse`): RMS, kurtosis (Pearson, 3 for a
Gaussian), crest factor, the envelope of the 2-5 kHz band (the data README's band: the housing
resonances the impacts excite), its largest line between 0.3 and 12 x shaft, and the expected
line's height in dB over the median of the envelope spectrum within +-20 Hz of it (the data
README's SNR). Nothing here is fitted to a fault record: the only rig values calibrated (on the
healthy record 97) are the housing resonance and the sensor noise (`twin.catalog`,
`calibrate_housing`).

A record of another motor load runs the twin at that record's speed with the same radial load
(the rotor's weight, `twin.catalog.default_radial_load_n`: the coupling's forces are not
published); a larger fault is a pit of the record's diameter, 0.011 in deep (the data center's
fault specifications; a depth given in the manifest as `fault_depth_in` is used instead: any
depth beyond the ball's chord drop over the pit, 16 um at 0.028 in, gives the same twin), on the
SKF 6205 geometry (the data center's 0.028 in faults are in an NTN equivalent). A record sampled
at a multiple of 12 kHz (the 48 kHz healthy records) is decimated to 12 kHz (FIR, zero phase, as
the committed 97 excerpt); each record's RMS is taken relative to the healthy record of the same
motor load in the directory, else to the healthy record of the lowest load.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
from scipy.signal import decimate, hilbert, welch

from twin.validation.vibration_simulation import simulate_vibration
from twin.vibration import indicators as ind
from twin.vibration.analysis import read_matlab5

G_M_S2 = 9.80665
DATA_DIR = Path(__file__).resolve().parents[2] / "tests" / "data" / "cwru"
ENVELOPE_BAND_HZ = (2000.0, 5000.0)
LINE_SEARCH_SHAFT = (0.3, 12.0)  # largest envelope line searched between these multiples of shaft
BACKGROUND_HALF_WIDTH_HZ = 20.0  # the line's background: median within +- this [Hz]
SETTLE_S = 0.3  # simulated start-up discarded before the analysed window [s]
# published multiples of the shaft frequency (CWRU data center, 6205-2RS JEM)
PUBLISHED_MULTIPLES = {"BPFI": 5.4152, "BPFO": 3.5848, "FTF": 0.39828, "2xBSF": 4.7135}


INCH_M = 0.0254
FAULT_WIDTH_M = 0.007 * INCH_M  # 0.178 mm: the committed records' fault diameter
FAULT_DEPTH_M = 0.011 * INCH_M  # 0.279 mm: the data center's depth of its 0.007-0.021 in faults
SAMPLE_RATE_HZ = 12000.0
# the manifest's fault kinds -> the twin's defect and its expected envelope line
FAULT_KINDS: dict[str, tuple[str | None, str | None]] = {
    "normal": (None, None),
    "inner_race": ("inner", "BPFI"),
    "outer_race": ("outer", "BPFO"),
    "ball": ("ball", "2xBSF"),
}
OUTER_RACE_ANGLE_DEG = {"6:00": 0.0, "3:00": 90.0, "12:00": 180.0}  # from the centre of the load zone


@dataclass(frozen=True)
class Record:
    """One CWRU record and the twin case it stands for."""

    number: int
    file: str
    condition: str
    defect: str | None  # 'inner', 'outer', 'ball' or None
    angle_deg: float  # outer race: from the centre of the load zone [deg]
    rpm: float
    expected: str | None  # the defect line: 'BPFI', 'BPFO', '2xBSF'
    fault_diameter_m: float = FAULT_WIDTH_M  # the EDM pit's diameter [m]
    fault_depth_m: float = FAULT_DEPTH_M  # its depth [m]
    load_hp: float = 0.0  # the dynamometer's motor load [hp]
    sample_rate_hz: float = SAMPLE_RATE_HZ  # the file's [Hz]
    variable: str | None = None  # the channel in a `.mat` file (`X105_DE_time`)


def _field(entry: dict, name: str, where: str, kind=float, allowed=None, zero_ok: bool = False):
    """Manifest field `name` of `entry`, checked (a number > 0, or >= 0 with `zero_ok`; or one of
    `allowed`); ValueError naming the record and the field."""
    value = entry.get(name)
    if allowed is not None:
        if value not in allowed:
            raise ValueError(f"{where}: {name} = {value!r}, expected one of {sorted(map(str, allowed))}")
        return value
    try:
        out = kind(value)
    except (TypeError, ValueError):
        raise ValueError(f"{where}: {name} = {value!r} is not a {kind.__name__}") from None
    if kind is float and not (math.isfinite(out) and (out >= 0.0 if zero_ok else out > 0.0)):
        raise ValueError(f"{where}: {name} = {value!r} must be a finite number {'>=' if zero_ok else '>'} 0")
    return out


def _file_name(entry: dict, where: str) -> str:
    name = entry.get("file")
    if not isinstance(name, str) or not name.strip():
        raise ValueError(f"{where}: file = {name!r}, expected the record's file name")
    return name


def _fan_end(entry: dict) -> bool:
    """Whether a manifest entry is of the rig's fan-end bearing (its `bearing` text, or an `_FE_`
    channel), which the `CWRU-DE` twin does not model."""
    bearing = entry.get("bearing")
    variable = entry.get("variable")
    return (isinstance(bearing, str) and ("fan" in bearing.lower() or "6203" in bearing)) or (
        isinstance(variable, str) and "_FE_" in variable
    )


def records_from_manifest(path: Path, left_out: list[str] | None = None) -> list[Record]:
    """The records of a `manifest.json` in the CWRU data set's form (a list of entries with
    `cwru_number`, `file`, `fs_hz`, `rpm`, `fault_kind` normal | inner_race | outer_race | ball,
    `fault_size_in`, `outer_race_position` 6:00 | 3:00 | 12:00, `load_hp`; optional
    `fault_depth_in`, and `variable` for a `.mat` file), by record number. An entry without a
    record number (a derived file without the record's metadata) is left out, and so is a record
    of the fan-end bearing (a 6203, not the drive end's 6205: its `bearing` or `variable` says so),
    with the reason appended to `left_out`. Raises ValueError naming the record and field."""
    entries = json.loads(Path(path).read_text(encoding="utf-8"))
    if not isinstance(entries, list):
        raise ValueError(f"{path}: expected a list of record entries")
    out = []
    for k, e in enumerate(entries):
        if not isinstance(e, dict) or e.get("cwru_number") is None:
            continue
        where = f"{path} entry {k} (record {e.get('cwru_number')})"
        if _fan_end(e):
            if left_out is not None:
                left_out.append(
                    f"record {e.get('cwru_number')} left out: bearing = {e.get('bearing')!r}, variable = "
                    f"{e.get('variable')!r}: the CWRU-DE twin models the drive-end 6205 only"
                )
            continue
        number = _field(e, "cwru_number", where, int)
        kind = _field(e, "fault_kind", where, allowed=FAULT_KINDS)
        defect, expected = FAULT_KINDS[kind]
        angle, condition = 0.0, "healthy"
        diameter, depth = FAULT_WIDTH_M, FAULT_DEPTH_M
        if defect is not None:
            size_in = _field(e, "fault_size_in", where)
            diameter = size_in * INCH_M
            depth = _field(e, "fault_depth_in", where) * INCH_M if e.get("fault_depth_in") is not None else depth
            condition = f"{kind.replace('_', ' ')} {size_in:g} in"
            if defect == "outer":
                position = _field(e, "outer_race_position", where, allowed=OUTER_RACE_ANGLE_DEG)
                angle = OUTER_RACE_ANGLE_DEG[position]
                condition += f" at {position}"
        load_hp = _field(e, "load_hp", where, zero_ok=True)
        out.append(
            Record(
                number,
                _file_name(e, where),
                f"{condition}, {load_hp:g} hp",
                defect,
                angle,
                _field(e, "rpm", where),
                expected,
                diameter,
                depth,
                load_hp,
                _field(e, "fs_hz", where),
                e.get("variable") if isinstance(e.get("variable"), str) else None,
            )
        )
    return sorted(out, key=lambda r: r.number)


def committed_records() -> tuple[Record, ...]:
    """The records of the committed excerpts (tests/data/cwru; () where the tests are not installed)."""
    path = DATA_DIR / "manifest.json"
    return tuple(records_from_manifest(path)) if path.exists() else ()


RECORDS = committed_records()


@dataclass(frozen=True)
class Analysis:
    """Indicators of one signal (SI; line heights in dB)."""

    rms_g: float
    kurtosis: float
    crest_factor: float
    largest_line_hz: float
    largest_line_shaft: float  # its frequency over the shaft frequency [-]
    largest_line_name: str  # nearest defect line name within 1.5 %, else 'other'
    expected_line_hz: float | None
    expected_line_db: float | None  # height over the +-20 Hz median [dB]


def line_height_db(freqs: np.ndarray, amp: np.ndarray, f_hz: float) -> tuple[float, float]:
    """(frequency [Hz], height [dB]) of the largest envelope bin within 1.5 % of f_hz over the median
    of the envelope within +-BACKGROUND_HALF_WIDTH_HZ of f_hz."""
    near = np.abs(freqs - f_hz) <= max(0.015 * f_hz, 2.0 * (freqs[1] - freqs[0]))
    i = int(np.flatnonzero(near)[np.argmax(amp[near])])
    around = np.abs(freqs - f_hz) <= BACKGROUND_HALF_WIDTH_HZ
    return float(freqs[i]), 20.0 * math.log10(amp[i] / max(float(np.median(amp[around])), 1e-300))


def analyse(x_m_s2: np.ndarray, sample_rate_hz: float, rpm: float, expected: str | None) -> Analysis:
    """The module docstring's indicators of a signal [m/s^2] at `rpm`."""
    x = np.asarray(x_m_s2, dtype=float)
    t = ind.time_indicators(x)
    freqs, amp = ind.envelope_spectrum(x, sample_rate_hz, ENVELOPE_BAND_HZ)
    shaft_hz = rpm / 60.0
    sel = (freqs >= LINE_SEARCH_SHAFT[0] * shaft_hz) & (freqs <= LINE_SEARCH_SHAFT[1] * shaft_hz)
    i = int(np.flatnonzero(sel)[np.argmax(amp[sel])])
    ratio = float(freqs[i] / shaft_hz)
    name = "other"
    for key, m in PUBLISHED_MULTIPLES.items():
        for h in (1, 2, 3):
            if abs(ratio / (h * m) - 1.0) <= 0.015:
                name = key if h == 1 else f"{h}x{key}"
                break
        if name != "other":
            break
    f_exp = db = None
    if expected is not None:
        f_exp, db = line_height_db(freqs, amp, PUBLISHED_MULTIPLES[expected] * shaft_hz)
    return Analysis(
        rms_g=t["rms_m_s2"] / G_M_S2,
        kurtosis=t["kurtosis"],
        crest_factor=t["crest_factor"],
        largest_line_hz=float(freqs[i]),
        largest_line_shaft=ratio,
        largest_line_name=name,
        expected_line_hz=f_exp,
        expected_line_db=db,
    )


def _load_g(path: Path, record: Record) -> np.ndarray:
    """A record's samples [g]: a `.npy` vector, or the `variable` (`X105_DE_time`) of the data
    center's own `.mat` file (MATLAB 5). ValueError naming the record for a file it cannot read."""
    if path.suffix.lower() != ".mat":
        return np.load(path).reshape(-1)
    try:
        data = read_matlab5(path)
    except ValueError as exc:
        raise ValueError(f"record {record.number}: {path.name} is not a readable MATLAB 5 .mat file ({exc})") from None
    names = sorted(k for k in data if not k.startswith("__"))
    variable = record.variable if record.variable is not None else drive_end_channel(record.number, names)
    if variable not in data:
        listed = ", ".join(names)
        raise ValueError(f"record {record.number}: variable = {variable!r} is not in {path.name} ({listed})")
    return np.asarray(data[variable]).reshape(-1)


def drive_end_channel(number: int, names: list[str]) -> str | None:
    """The drive-end channel of a data center .mat file whose manifest entry names none: the
    record's own `X<number, 3 digits>_DE_time`, else the file's only `*_DE_time` (a few files
    carry another record's number in their variables' names); None when neither is there (the
    caller then names the file's variables)."""
    own = f"X{number:03d}_DE_time"
    if own in names:
        return own
    drive_end = [n for n in names if n.endswith("_DE_time")]
    return drive_end[0] if len(drive_end) == 1 else None


def measured(record: Record, duration_s: float | None = None, data_dir: Path = DATA_DIR) -> tuple[Analysis, np.ndarray]:
    """The committed excerpt of `record` [m/s^2] (its first `duration_s`, all of it with None) and
    its analysis. Compare with a simulation of the same duration: a line's height over its
    background grows with the record's length (the background per bin falls as 1 / sqrt(length))."""
    x = _load_g(data_dir / record.file, record).astype(float) * G_M_S2
    factor = record.sample_rate_hz / SAMPLE_RATE_HZ
    if abs(factor - round(factor)) > 1e-9 or round(factor) < 1:
        raise ValueError(
            f"record {record.number}: fs_hz = {record.sample_rate_hz:g} Hz is not a whole multiple of "
            f"{SAMPLE_RATE_HZ:g} Hz"
        )
    if round(factor) > 1:
        x = decimate(x, int(round(factor)), ftype="fir", zero_phase=True)
    if duration_s is not None:
        x = x[: int(round(duration_s * SAMPLE_RATE_HZ))]
    return analyse(x, SAMPLE_RATE_HZ, record.rpm, record.expected), x


def simulated(record: Record, duration_s: float = 1.0, settle_s: float = SETTLE_S) -> tuple[Analysis, np.ndarray]:
    """The `CWRU-DE` twin in the conditions of `record`: its signal [m/s^2] and analysis. The
    sensor noise is seeded with the record's number, so a comparison gives the same figures in
    every run (the spec's default is fresh entropy, as a real sensor)."""
    _, x = simulate_vibration(
        "CWRU-DE",
        record.rpm * 2.0 * math.pi / 60.0,
        None,
        defect=record.defect,
        defect_size_m=record.fault_diameter_m,
        defect_length_m=record.fault_diameter_m,
        defect_depth_m=record.fault_depth_m,
        defect_angle_deg=record.angle_deg,
        duration_s=duration_s,
        settle_s=settle_s,
        band=ENVELOPE_BAND_HZ,
        window_s=duration_s,
        noise_seed=record.number,  # the sensor floor's noise, the same in every run of a record
    )
    return analyse(x, SAMPLE_RATE_HZ, record.rpm, record.expected), x


def compare(duration_s: float = 1.0, records=RECORDS, data_dir: Path = DATA_DIR) -> list[dict]:
    """Per record: its conditions, measured and twin analyses, and the RMS relative to the healthy
    record of the same motor load (else of the lowest load), measured and twin each against its own."""
    records = list(records)
    rows = []
    for rec in records:
        m, _ = measured(rec, duration_s, data_dir)
        s, _ = simulated(rec, duration_s)
        rows.append(
            {
                "record": rec.number,
                "condition": rec.condition,
                "rpm": rec.rpm,
                "load_hp": rec.load_hp,
                "fault_diameter_m": rec.fault_diameter_m if rec.defect else None,
                "fault_depth_m": rec.fault_depth_m if rec.defect else None,
                "measured": asdict(m),
                "twin": asdict(s),
            }
        )
    healthy = sorted((r for r, rec in zip(rows, records) if rec.defect is None), key=lambda r: r["load_hp"])
    for r in rows:
        ref = next((h for h in healthy if h["load_hp"] == r["load_hp"]), healthy[0] if healthy else None)
        if ref is not None:
            r["healthy_record"] = ref["record"]
            r["measured"]["rms_ratio"] = r["measured"]["rms_g"] / ref["measured"]["rms_g"]
            r["twin"]["rms_ratio"] = r["twin"]["rms_g"] / ref["twin"]["rms_g"]
    return rows


def markdown(rows: list[dict]) -> str:
    """The comparison as a Markdown table (measured / twin per column)."""

    def db(v):
        return "-" if v is None else f"{v:.1f}"

    out = [
        "| record | condition | RMS [g] | RMS / healthy | kurtosis | crest | largest envelope line "
        "[x shaft] | expected line [dB] |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        m, t = r["measured"], r["twin"]
        out.append(
            f"| {r['record']} | {r['condition']} | {m['rms_g']:.3f} / {t['rms_g']:.3f} | "
            f"{m.get('rms_ratio', float('nan')):.2f} / {t.get('rms_ratio', float('nan')):.2f} | "
            f"{m['kurtosis']:.2f} / {t['kurtosis']:.2f} | {m['crest_factor']:.2f} / {t['crest_factor']:.2f} | "
            f"{m['largest_line_shaft']:.3f} {m['largest_line_name']} / {t['largest_line_shaft']:.3f} "
            f"{t['largest_line_name']} | {db(m['expected_line_db'])} / {db(t['expected_line_db'])} |"
        )
    return "\n".join(out)


def calibrate_housing(
    x_m_s2: np.ndarray, sample_rate_hz: float = SAMPLE_RATE_HZ, search_hz: tuple[float, float] = (2950.0, 3600.0)
) -> tuple[float, float]:
    """(frequency [Hz], damping ratio [-]) of the broadband housing resonance of a healthy record:
    the peak of its Welch power spectrum (512 points) in `search_hz` and its half-power bandwidth
    (linear interpolation of the crossings), zeta = bandwidth / (2 f). Run once on record 97 to
    set `twin.catalog.CWRU_SPRUNG_*`."""
    f, p = welch(np.asarray(x_m_s2, dtype=float), sample_rate_hz, nperseg=512)
    sel = np.flatnonzero((f > search_hz[0]) & (f < search_hz[1]))
    i = int(sel[np.argmax(p[sel])])
    half = 0.5 * p[i]
    lo = i
    while p[lo] > half:
        lo -= 1
    hi = i
    while p[hi] > half:
        hi += 1
    f_lo = f[lo] + (half - p[lo]) / (p[lo + 1] - p[lo]) * (f[lo + 1] - f[lo])
    f_hi = f[hi - 1] + (half - p[hi - 1]) / (p[hi] - p[hi - 1]) * (f[hi] - f[hi - 1])
    return float(f[i]), float((f_hi - f_lo) / (2.0 * f[i]))


RING_DOWN_S = 1.5e-3  # decay fitted over this long after an impact's envelope peak [s]


def ring_down(
    x_m_s2: np.ndarray, rpm: float, line_multiple: float, sample_rate_hz: float = SAMPLE_RATE_HZ
) -> tuple[float, float]:
    """(frequency [Hz], damping ratio [-]) of the mode a fault record's impacts ring: the signal is
    band-passed to ENVELOPE_BAND_HZ (`twin.vibration.indicators.band_pass`); in each period of the
    defect line (`line_multiple` x shaft) the Hilbert envelope's decay rate sigma [1/s] is the
    log-linear fit over RING_DOWN_S after its peak, kept where the peak stands 3 x above the
    envelope's median; the frequency is the band's Welch peak (2048 points), and zeta = median
    sigma / (2 pi f) (a single mode's free decay, exp(-zeta omega t)). An independent check of the
    housing damping calibrated on the healthy record, which has no impacts."""
    y = ind.band_pass(x_m_s2, sample_rate_hz, ENVELOPE_BAND_HZ)
    env = np.abs(hilbert(y))
    period = int(sample_rate_hz * 60.0 / (rpm * line_multiple))
    tail = int(round(RING_DOWN_S * sample_rate_hz))
    t = np.arange(tail) / sample_rate_hz
    floor = float(np.median(env))
    rates = []
    for start in range(0, len(env) - period - tail, period):
        j = start + int(np.argmax(env[start : start + period]))
        if env[j] > 3.0 * floor:
            rates.append(-np.polyfit(t, np.log(env[j : j + tail]), 1)[0])
    if not rates:
        raise ValueError("ring_down: no impact stands 3 x above the envelope's median")
    f, p = welch(y, sample_rate_hz, nperseg=2048)
    f_ring = float(f[np.argmax(p)])
    return f_ring, float(np.median(rates)) / (2.0 * math.pi * f_ring)


FLOOR_BAND_HZ = (2000.0, 2900.0)  # healthy record: between the motor's content and the resonance
RESONANCE_BAND_HZ = (2900.0, 3600.0)  # healthy record: the housing resonance the impacts ring


def band_rms(x_m_s2: np.ndarray, band_hz: tuple[float, float], sample_rate_hz: float = SAMPLE_RATE_HZ) -> float:
    """RMS [m/s^2] of the signal in a frequency band: Welch power spectrum (1024 points, Hann),
    summed over the bins in [lo, hi)."""
    f, p = welch(np.asarray(x_m_s2, dtype=float), sample_rate_hz, nperseg=1024)
    sel = (f >= band_hz[0]) & (f < band_hz[1])
    return float(math.sqrt(p[sel].sum() * (f[1] - f[0])))


def calibrate_background(x_m_s2: np.ndarray, sample_rate_hz: float = SAMPLE_RATE_HZ) -> dict[str, float]:
    """The sensor and rig floor of a healthy record: the white noise density [m/s^2/sqrt(Hz)] whose
    RMS over FLOOR_BAND_HZ is the record's there, and the record's RMS in RESONANCE_BAND_HZ beside
    that floor's share of it (the room left for the bearing's own healthy excitation). Run once on
    record 97 to set `twin.catalog.CWRU_NOISE_DENSITY_M_S2_RTHZ` and bound
    `CWRU_RACE_PROFILE_RMS_M`."""
    floor = band_rms(x_m_s2, FLOOR_BAND_HZ, sample_rate_hz)
    density = floor / math.sqrt(FLOOR_BAND_HZ[1] - FLOOR_BAND_HZ[0])
    return {
        "noise_density_m_s2_rthz": density,
        "resonance_band_rms_m_s2": band_rms(x_m_s2, RESONANCE_BAND_HZ, sample_rate_hz),
        "floor_in_resonance_band_m_s2": density * math.sqrt(RESONANCE_BAND_HZ[1] - RESONANCE_BAND_HZ[0]),
    }


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m twin.validation.cwru",
        description="The CWRU-DE twin against the measured CWRU drive-end records (docs/validation.md).",
    )
    parser.add_argument("--duration", type=float, default=1.0, help="analysed simulated time per record [s]")
    parser.add_argument("--json", action="store_true")
    parser.add_argument(
        "--data",
        type=Path,
        default=None,
        metavar="DIR",
        help="a directory of CWRU drive-end records (.npy in g, or the data center's .mat) with their "
        "manifest.json (default: the committed excerpts, tests/data/cwru)",
    )
    args = parser.parse_args(argv)
    data_dir = args.data if args.data is not None else DATA_DIR
    left_out: list[str] = []
    try:
        records = (
            records_from_manifest(data_dir / "manifest.json", left_out) if args.data is not None else list(RECORDS)
        )
    except (OSError, ValueError) as exc:
        parser.error(str(exc))
    for note in left_out:
        print(note, file=sys.stderr)
    try:
        rows = compare(args.duration, records, data_dir)
    except (OSError, ValueError) as exc:  # a record's file missing or unreadable
        parser.error(str(exc))
    print(json.dumps(rows, indent=1) if args.json else markdown(rows))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
