"""`bearing-twin vibration analyse FILE`: the twin's vibration analysis of a measured record.

Reads one accelerometer channel and prints `twin.vibration.analysis.analyse_signal` of it, the
same JSON as a simulation's analysis, with an `input` block (file, format, units, sample rate,
speed, bearing, the line multiples used).

Formats: `.npy` (a 1-D array, or 2-D with --column), `.csv` (numbers, comma separated, one row per
sample; --column picks the column, lines starting with '#' and a non-numeric header row are
skipped), `.wav` (scipy.io.wavfile: float samples as they are, integer PCM scaled to +-1 at full
scale and multiplied by --full-scale; the file's rate is the sample rate, --sample-rate must
agree when given), `.mat` (MATLAB 5, as the CWRU Bearing Data Center publishes its records:
--variable names the channel, by default the one `*_DE_time` variable, or the file's only
numeric vector; without --rpm the file's one `*RPM` value is the speed). Units: --units g
(x 9.80665) or m/s2.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import warnings
from pathlib import Path

import numpy as np

from service.tools.arg_types import positive_float
from service.tools.stdout import print_document

STANDARD_GRAVITY_M_S2 = 9.80665
UNITS = {"g": STANDARD_GRAVITY_M_S2, "m/s2": 1.0}
FORMATS = (".npy", ".csv", ".wav", ".mat")


class RecordError(ValueError):
    """A record that cannot be read: `field` names the option or argument at fault."""

    def __init__(self, field_name: str, message: str):
        super().__init__(f"{field_name}: {message}")
        self.field = field_name


def _pick_column(data: np.ndarray, column: int, what: str) -> np.ndarray:
    if data.ndim == 1:
        if column != 0:
            raise RecordError("--column", f"{column}: the {what} has one column; allowed 0")
        return data
    if data.ndim != 2:
        raise RecordError("FILE", f"the {what} has {data.ndim} dimensions; need 1 (or 2 with --column)")
    if not 0 <= column < data.shape[1]:
        raise RecordError(
            "--column", f"{column}: the {what} has {data.shape[1]} columns; allowed 0-{data.shape[1] - 1}"
        )
    return data[:, column]


def _load_mat(path: Path) -> dict:
    """The variables of a MATLAB 5 .mat file (twin.vibration.analysis.read_matlab5). RecordError
    naming FILE for anything else."""
    from twin.vibration.analysis import read_matlab5

    try:
        return read_matlab5(path)
    except ValueError as exc:
        raise RecordError("FILE", f"{path.name} is not a readable MATLAB 5 .mat record ({exc})") from None


def _mat_channel(data: dict, name: str, variable: str | None) -> np.ndarray:
    """The channel of a .mat record's variables `data` (of file `name`): `variable`, else the one
    `*_DE_time` (the CWRU drive end's), else the file's only numeric vector. RecordError naming
    --variable with the file's variables."""
    vectors = {
        k: v
        for k, v in data.items()
        if not k.startswith("__") and isinstance(v, np.ndarray) and v.dtype.kind in "iuf" and v.size > 1
    }
    names = ", ".join(sorted(vectors)) or "none"
    if variable is not None:
        if variable not in vectors:
            raise RecordError("--variable", f"{variable!r} is not a numeric vector of {name}; allowed: {names}")
        chosen = variable
    else:
        drive_end = [k for k in vectors if k.endswith("_DE_time")]
        candidates = drive_end if drive_end else list(vectors)
        if len(candidates) != 1:
            raise RecordError("--variable", f"{name} holds {len(candidates)} candidate channels; pick one of: {names}")
        chosen = candidates[0]
    v = np.asarray(vectors[chosen])
    if v.ndim == 2 and 1 in v.shape:
        v = v.reshape(-1)
    return v


def _mat_rpm(data: dict) -> float | None:
    """The speed a .mat record's variables `data` state [rev/min]: its one scalar `*RPM` variable
    (the CWRU data center's `X105RPM`), else None."""
    found = [
        float(np.asarray(v).reshape(-1)[0])
        for k, v in data.items()
        if k.upper().endswith("RPM") and isinstance(v, np.ndarray) and v.size == 1 and v.dtype.kind in "iuf"
    ]
    return found[0] if len(found) == 1 else None


def read_record(
    path: Path, column: int = 0, full_scale: float = 1.0, variable: str | None = None
) -> tuple[np.ndarray, float | None, float | None]:
    """(samples in the file's units, the file's sample rate [Hz] or None, the speed it states
    [rev/min] or None) of a .npy, .csv, .wav or .mat record (module docstring). Raises
    RecordError naming FILE / --column / --variable."""
    suffix = path.suffix.lower()
    if suffix not in FORMATS:
        raise RecordError("FILE", f"{path.name}: unknown format {suffix or '(none)'}; allowed {', '.join(FORMATS)}")
    if not path.is_file():
        raise RecordError("FILE", f"{path}: no such file")
    rate = rpm = None
    try:
        if suffix == ".npy":
            data = np.load(path, allow_pickle=False)
        elif suffix == ".mat":
            variables = _load_mat(path)
            data, rpm = _mat_channel(variables, path.name, variable), _mat_rpm(variables)
        elif suffix == ".csv":
            with warnings.catch_warnings():  # an empty file: refused below by its sample count, in one line
                warnings.simplefilter("ignore", UserWarning)
                try:
                    data = np.loadtxt(path, delimiter=",", comments="#", ndmin=1)
                except ValueError:
                    data = np.loadtxt(path, delimiter=",", comments="#", ndmin=1, skiprows=1)
        else:
            import scipy.io.wavfile

            rate, data = scipy.io.wavfile.read(path)
            if data.dtype.kind == "i":
                data = data.astype(float) / -float(np.iinfo(data.dtype).min) * full_scale
            elif data.dtype.kind == "u":
                half = 0.5 * (float(np.iinfo(data.dtype).max) + 1.0)
                data = (data.astype(float) - half) / half * full_scale
            rate = float(rate)
    except RecordError:
        raise
    except (OSError, ValueError, EOFError) as exc:
        raise RecordError("FILE", f"{path.name} is not a readable {suffix} record ({exc})") from None
    data = np.asarray(data)
    if data.dtype.kind not in "iuf":
        raise RecordError("FILE", f"{path.name} holds {data.dtype} values; need real numbers")
    return _pick_column(data.astype(float), column, f"{suffix} record"), rate, rpm


def _parse_line(text: str) -> tuple[str, float]:
    name, sep, value = text.partition("=")
    try:
        multiple = float(value)
    except ValueError:
        multiple = float("nan")
    if not sep or not name or not (math.isfinite(multiple) and multiple > 0.0):
        raise argparse.ArgumentTypeError(f"{text!r}: need NAME=MULTIPLE with MULTIPLE > 0 (e.g. BPFI=5.4152)")
    return name, multiple


def analyse_file(args: argparse.Namespace) -> dict:
    """The JSON of `vibration analyse` (module docstring). Raises RecordError / ValueError naming
    the option. The analysis (scipy.signal) is imported here, not with the parser: every other
    `bearing-twin` command starts without it."""
    from twin.vibration.analysis import MAX_SAMPLE_RATE_HZ, AnalysisInputError, analyse_signal, defect_multiples_of

    path = Path(args.file)
    x, file_rate, file_rpm = read_record(path, args.column, args.full_scale, args.variable)
    if file_rate is not None and args.sample_rate is not None and abs(file_rate - args.sample_rate) > 1e-9 * file_rate:
        raise RecordError("--sample-rate", f"{args.sample_rate:g} Hz disagrees with the file's {file_rate:g} Hz")
    rate = file_rate if file_rate is not None else args.sample_rate
    if rate is None:
        raise RecordError(
            "--sample-rate", f"required for {path.suffix} records; allowed (0, {MAX_SAMPLE_RATE_HZ:g}] Hz"
        )
    if not (math.isfinite(rate) and 0.0 < rate <= MAX_SAMPLE_RATE_HZ):
        raise RecordError("--sample-rate", f"{rate:g} is out of range; allowed (0, {MAX_SAMPLE_RATE_HZ:g}] Hz")
    if args.rpm is None:
        args.rpm = file_rpm
        if args.rpm is None:
            raise RecordError("--rpm", "required (a .mat record may state it as one *RPM value); allowed > 0 rev/min")
    if not (math.isfinite(args.rpm) and 0.0 < args.rpm <= 3.0 * rate):
        raise RecordError("--rpm", f"{args.rpm:g}; allowed (0, {3.0 * rate:g}] (the shaft at most fs / 20)")
    if args.line:
        multiples = dict(args.line)
        bearing = args.bearing
    elif args.bearing:
        from service.tools.messages import error_text
        from twin import catalog

        try:
            spec = catalog.bearing_or_file(args.bearing)
        except KeyError as exc:
            raise RecordError("--bearing", str(exc).strip("'\"")) from None
        except ValueError as exc:  # a spec file's field (pydantic's ValidationError is one), or the file itself
            raise RecordError("--bearing", error_text(exc)) from None
        multiples = defect_multiples_of(spec.geometry)
        bearing = spec.designation
    else:
        raise RecordError("--bearing", "required (a catalog designation), or give the lines with --line NAME=MULTIPLE")
    band = tuple(args.band) if args.band else None
    shaft_hz = args.rpm / 60.0
    try:
        analysis = analyse_signal(x * UNITS[args.units], rate, shaft_hz, multiples, band)
    except AnalysisInputError as exc:
        option = {
            "signal_m_s2": "FILE",
            "sample_rate_hz": "--sample-rate",
            "shaft_hz": "--rpm",
            "band_hz": "--band",
        }.get(exc.field, exc.field)
        raise RecordError(option, str(exc).split(": ", 1)[1]) from None
    return {
        "input": {
            "file": str(path),
            "format": path.suffix.lower().lstrip("."),
            "units": args.units,
            "sample_rate_hz": rate,
            "rpm": args.rpm,
            "bearing": bearing,
            "line_multiples": multiples,
        },
        **analysis.to_dict(spectrum=args.spectrum),
    }


def _cmd_analyse(args: argparse.Namespace) -> int:
    try:
        result = analyse_file(args)
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    if args.json:
        print_document(json.dumps(result, allow_nan=False))
        return 0
    g = STANDARD_GRAVITY_M_S2
    print(
        f"{result['input']['file']}: {result['n_samples']} samples at {result['sample_rate_hz']:g} Hz "
        f"({result['duration_s']:.3g} s), shaft {result['shaft_hz']:.3f} Hz"
    )
    print(
        f"  RMS {result['rms_m_s2']:.4g} m/s2 ({result['rms_m_s2'] / g:.4g} g), kurtosis {result['kurtosis']:.2f}, "
        f"crest factor {result['crest_factor']:.2f}"
    )
    lo, hi = result["envelope_band_hz"]
    print(f"  envelope band {lo:.0f}-{hi:.0f} Hz ({result['envelope_band_source']})")
    for d in result["defect_lines"]:
        print(
            f"  {d['name']:>8}: expected {d['expected_hz']:8.2f} Hz, peak {d['peak_hz']:8.2f} Hz "
            f"({100 * d['relative_error']:+.2f} %), {d['height_db']:5.1f} dB over +-20 Hz"
        )
    tops = ", ".join(
        f"{p['frequency_hz']:.1f} Hz {p['label'] or '?'} ({p['height_db']:.1f} dB)" for p in result["largest_lines"]
    )
    print(f"  largest envelope lines: {tops}")
    return 0


def add_analyse_command(vibration_parser: argparse.ArgumentParser) -> None:
    """`vibration analyse FILE ...` under the `vibration` command's parser."""
    sub = vibration_parser.add_subparsers(dest="vibration_command")
    an = sub.add_parser(
        "analyse",
        help="analyse a measured accelerometer record (.npy, .csv, .wav, .mat)",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    an.add_argument("file", metavar="FILE", help="record: .npy, .csv, .wav or .mat")
    an.add_argument("--sample-rate", type=float, default=None, help="sample rate [Hz] (.wav: from the file)")
    an.add_argument(
        "--rpm", type=float, default=None, help="shaft speed [rev/min] (a .mat record's own *RPM value when left out)"
    )
    an.add_argument(
        "--bearing",
        default=None,
        help="catalog designation or bearing spec file (.yaml, .json): the defect lines from its geometry",
    )
    an.add_argument(
        "--line",
        type=_parse_line,
        action="append",
        metavar="NAME=MULTIPLE",
        help="a defect line as a multiple of the shaft frequency (repeatable; replaces the "
        "bearing's lines), e.g. --line BPFI=5.4152",
    )
    an.add_argument(
        "--band",
        type=float,
        nargs=2,
        metavar=("LO", "HI"),
        help="envelope band [Hz] (default: Antoni's fast kurtogram)",
    )
    an.add_argument("--units", choices=sorted(UNITS), default="m/s2", help="units of the samples (default m/s2)")
    an.add_argument("--column", type=int, default=0, help="column of a 2-D .npy or .csv (default 0)")
    an.add_argument(
        "--variable",
        default=None,
        help="variable of a .mat record (default: the one *_DE_time, the CWRU drive end's, or the only vector)",
    )
    an.add_argument(
        "--full-scale",
        type=positive_float,
        default=1.0,
        help="value, in --units, of an integer .wav's full scale, > 0 (default 1)",
    )
    an.add_argument("--spectrum", action="store_true", help="include the envelope spectrum in the JSON")
    an.add_argument("--json", action="store_true", help="print the result as JSON")
    an.set_defaults(func=_cmd_analyse)
