"""`bearing-twin` command line: simulate, bench, timestep-study, report, serve, router, scenario, monitor,
ehl, life, vibration, thermal (the load tools soak, attack and bench-service are `bearing-twin-loadtest`).

Heavy imports (FastAPI, zenoh, rerun, matplotlib) happen inside the subcommand that needs them.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import sys
from pathlib import Path

from service import __version__
from service.tools.arg_types import float_in, output_file, positive_float
from service.tools.bench_results import save as save_result
from service.tools.messages import OPERATING_FLAGS, error_text
from service.tools.scenario_cli import add_scenario_command
from service.tools.serve_cli import add_serve_command
from service.tools.stdout import print_document
from service.tools.vibration_cli import add_analyse_command
from twin.catalog import DEFAULT_DESIGNATION

SIMULATE_FLAGS = {**OPERATING_FLAGS, "time_step_s": "--dt", "film_formula": "--film-formula"}
VIBRATION_FLAGS = {
    **OPERATING_FLAGS,
    "width_m": "--defect-size",
    "length_m": "--defect-length",
    "depth_m": "--defect-depth",
    "defect_angle_deg": "--defect-angle",
    "noise_density_m_s2_rthz": "--noise-density",
    "sample_rate_hz": "--sample-rate",
    "duration_s": "--duration",
}

DEFECT_FLAGS = {  # `vibration`'s defect options -> simulate_vibration's keywords (its defaults apply when not given)
    "defect_size": "defect_size_m",
    "defect_length": "defect_length_m",
    "defect_depth": "defect_depth_m",
    "defect_angle": "defect_angle_deg",
}
SIMULATE_MAX_S = 3600.0  # `simulate --duration` at most [s of simulated time]
VIBRATION_MAX_S = 600.0  # `vibration --duration` at most [s]: 600 s at 51.2 kHz is 250 MB of samples


class ArgumentParser(argparse.ArgumentParser):
    """argparse with whole option names only (no abbreviations: `--clear` is not `--clearance`)
    that takes '-1e-5' as a negative number, like '-1' and '-1.5' (Python 3.11's argparse takes
    a value in scientific notation for an option: `--clearance -1e-5` would fail)."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("allow_abbrev", False)
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = re.compile(r"^-(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?$")


def _time_step(text: str) -> float | str:
    from twin.timestep import parse_time_step

    try:
        return parse_time_step(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _cmd_simulate(args: argparse.Namespace) -> int:
    from pydantic import ValidationError

    from twin import catalog
    from twin.engine import Twin
    from twin.setpoint import SetpointError, SetpointUpdate
    from twin.spec import ModelOptions

    try:
        options = ModelOptions(time_step_s=args.dt, film_formula=args.film_formula)
        update = SetpointUpdate(
            shaft_speed_rad_s=args.speed,
            radial_load_n=args.radial_load,
            axial_load_n=args.axial_load,
            oil_temperature_c=args.oil_temperature,
        )
        twin = Twin(
            catalog.bearing_or_file(args.bearing), options=options, diametral_clearance_m=args.clearance, warm=False
        )
        twin.set_setpoint(update)  # checked once, against this bearing's limits
        twin.reset()  # warm start at it
        twin.advance(args.duration)
    except (ValidationError, SetpointError, ValueError) as exc:
        print(f"error: {error_text(exc, SIMULATE_FLAGS)}", file=sys.stderr)
        return 2
    snap = twin.snapshot()
    if args.json:
        print_document(snap.to_json())
    else:
        _print_table(snap)
    return 0


def _print_table(snap) -> None:
    from rich import box
    from rich.console import Console
    from rich.table import Table

    # two-line headers, no vertical rules: the nine columns fit an 80-column terminal uncut
    table = Table(
        title=f"{snap.designation} at t = {snap.time_s:.4f} s, status {snap.status}",
        box=box.SIMPLE_HEAD,
        padding=(0, 0, 0, 1),
        pad_edge=False,
    )
    for col in (
        "ball",
        "azimuth\ndeg",
        "spin\nrad/s",
        "Q in\nN",
        "Q out\nN",
        "Lambda\nin",
        "Lambda\nout",
        "regime\nin",
        "regime\nout",
    ):
        table.add_column(col, justify="right", no_wrap=True)
    for b in snap.balls:
        lam = lambda c: "-" if c.lambda_ is None else f"{c.lambda_:.2f}"  # noqa: E731
        table.add_row(
            str(b.index),
            f"{b.azimuth_rad * 57.29578:.1f}",
            f"{b.spin_rad_s:.1f}",
            f"{b.inner.load_n:.0f}",
            f"{b.outer.load_n:.0f}",
            lam(b.inner),
            lam(b.outer),
            b.inner.regime,
            b.outer.regime,
        )
    console = Console()
    console.print(table)
    console.print(f"cage {snap.cage_speed_rad_s:.2f} rad/s, friction torque {snap.friction_torque_n_m * 1e3:.2f} mN m")


def _cmd_bench(args: argparse.Namespace) -> int:
    from twin.validation.bench import run_engine_benchmark, summary_text

    try:
        result = run_engine_benchmark(seconds=args.seconds, repeats=args.repeats)
    except ValueError as exc:
        print(f"error: {error_text(exc, {'seconds': '--seconds', 'repeats': '--repeats'})}", file=sys.stderr)
        return 2
    print_document(json.dumps(result) if args.json else summary_text(result))
    if args.save is not None:
        command = "bearing-twin " + " ".join(sys.argv[1:])
        print(f"saved: {save_result(result, 'bench', command, Path(args.save))}", file=sys.stderr)
    return 0


def _cmd_timestep_study(args: argparse.Namespace) -> int:
    from twin.validation import subrate_study, timestep_study

    study = subrate_study if args.subrates else timestep_study
    options = {"against_1us": True} if args.subrates else {}
    result = study.run_all(
        quick=args.quick,
        progress=lambda case, step: print(f"{case.id}: {step}", file=sys.stderr, flush=True),
        **options,
    )
    print(study.as_json(result) if args.json else study.markdown(result))
    return 0


def _cmd_vibration(args: argparse.Namespace) -> int:
    from pydantic import ValidationError

    from twin import catalog
    from twin.setpoint import SetpointError
    from twin.validation.vibration_simulation import simulate_vibration

    if args.speed is None:
        print("error: vibration: --speed required (or `vibration analyse FILE`)", file=sys.stderr)
        return 2
    given = {keyword: getattr(args, flag) for flag, keyword in DEFECT_FLAGS.items() if getattr(args, flag) is not None}
    if args.defect is None and given:
        flag = next(f for f, k in DEFECT_FLAGS.items() if k in given)
        print(
            f"error: --{flag.replace('_', '-')}: describes a defect; give --defect outer, inner or ball with it",
            file=sys.stderr,
        )
        return 2
    try:
        result, samples = simulate_vibration(
            catalog.bearing_or_file(args.bearing),
            args.speed,
            args.radial_load,
            args.axial_load,
            defect=args.defect,
            **given,
            duration_s=args.duration,
            noise_density_m_s2_rthz=args.noise_density,
            sample_rate_hz=args.sample_rate,
            diametral_clearance_m=args.clearance,
        )
    except (ValidationError, SetpointError, ValueError) as exc:
        print(f"error: {error_text(exc, VIBRATION_FLAGS)}", file=sys.stderr)
        return 2
    except RuntimeError as exc:  # the twin halted: the setpoint cannot be held (its status says why)
        print(f"error: {error_text(exc, VIBRATION_FLAGS)}", file=sys.stderr)
        return 1
    if args.waveform:
        import numpy as np

        np.save(args.waveform, np.asarray(samples, dtype=np.float64))
    if args.plot:
        from service.reports.vibration import plot_vibration

        plot_vibration(samples, result, args.plot)
    if args.json:
        result.pop("per_window", None)
        print_document(json.dumps(result, allow_nan=False))
        return 0
    f = result["defect_frequencies_hz"]
    print(
        f"{result['bearing']} at {result['shaft_speed_rad_s']:g} rad/s, Fr = {result['radial_load_n']:g} N, "
        f"Fa = {result['axial_load_n']:g} N, defect: {(result['defect'] or {}).get('kind', 'none')}, "
        f"{result['duration_s']:g} s at {result['sample_rate_hz']:g} Hz (dt = {result['time_step_s'] * 1e6:.3f} us)"
    )
    print(
        f"  FTF {f['ftf']:.2f}, BPFO {f['bpfo']:.2f}, BPFI {f['bpfi']:.2f}, BSF {f['bsf']:.2f} Hz "
        f"(contact angle {result['contact_angle_deg']:.2f} deg)"
    )
    print(
        f"  RMS {result['rms_m_s2']:.4g} m/s2, peak {result['peak_m_s2']:.4g} m/s2, crest "
        f"{result['crest_factor']:.2f}, "
        f"kurtosis {result['kurtosis']:.2f} (band {result['band_kurtosis']:.2f}), "
        f"velocity RMS {result['velocity_rms_mm_s']:.4g} mm/s"
    )
    peaks = ", ".join(f"{p['frequency_hz']:.1f} Hz ({p['amplitude']:.3g} m/s2)" for p in result["envelope_peaks_hz"])
    print(
        f"  envelope peaks ({result['envelope_band_hz'][0]:.0f}-{result['envelope_band_hz'][1]:.0f} Hz band): {peaks}"
    )
    if args.plot:
        print(f"  figure: {args.plot}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = ArgumentParser(prog="bearing-twin", description=__doc__)
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)

    sim = sub.add_parser("simulate", help="run one twin for a duration, print the final snapshot")
    sim.add_argument(
        "--bearing",
        default=DEFAULT_DESIGNATION,
        help=f"catalog designation (default {DEFAULT_DESIGNATION}) or a bearing spec file (.yaml, .json)",
    )
    sim.add_argument("--radial-load", type=float, default=3000.0, help="radial load [N] (default 3000)")
    sim.add_argument("--axial-load", type=float, default=0.0, help="axial load [N] (default 0)")
    sim.add_argument("--speed", type=float, default=500.0, help="shaft speed [rad/s] (default 500)")
    sim.add_argument("--oil-temperature", type=float, default=40.0, help="oil temperature [degC] (default 40)")
    sim.add_argument(
        "--clearance", type=float, default=0.0, help="diametral clearance [m], negative = preload (default 0)"
    )
    sim.add_argument(
        "--duration",
        type=float_in(0.0, SIMULATE_MAX_S, "s"),
        default=0.05,
        help=f"simulated time [s] (default 0.05, at most {SIMULATE_MAX_S:g}; longer runs: `serve` or a scenario)",
    )
    sim.add_argument(
        "--dt",
        type=_time_step,
        default="auto",
        help="time step [s] or 'auto' (default: from the critical step, twin.timestep)",
    )
    sim.add_argument(
        "--film-formula",
        choices=["hamrock_dowson", "masjedi_khonsari"],
        default="hamrock_dowson",
        help="minimum film thickness formula: seed 000 eq. 6 (hamrock_dowson, default) or seed 004 eq. 6 "
        "(masjedi_khonsari)",
    )
    sim.add_argument("--json", action="store_true", help="print the snapshot as JSON")
    sim.set_defaults(func=_cmd_simulate)

    bench = sub.add_parser(
        "bench", help="engine speed: real-time factor at the default step and at 1 us, further cases, per-pass timing"
    )
    bench.add_argument(
        "--seconds", type=positive_float, default=0.2, help="simulated seconds per repeat [s] (default 0.2, at most 60)"
    )
    bench.add_argument(
        "--repeats", type=int, default=5, help="repeats, 5 to 100 (best and median reported) (default 5)"
    )
    bench.add_argument("--json", action="store_true", help="print the result as JSON")
    bench.add_argument(
        "--save",
        nargs="?",
        const="benchmarks/results",
        default=None,
        metavar="DIR",
        help="also write the result with the CPU model, versions and git commit as "
        "DIR/<UTC date>-<cpu>-bench.json (default DIR: benchmarks/results)",
    )
    bench.set_defaults(func=_cmd_bench)
    study = sub.add_parser("timestep-study", help="the auto time step against 1 us over the operating envelope")
    study.add_argument("--quick", action="store_true", help="a subset of the cases (the test suite's)")
    study.add_argument(
        "--subrates",
        action="store_true",
        help="the tribology and traction sub-rates (periods) at the auto step instead of the step",
    )
    study.add_argument("--json", action="store_true", help="print the result as JSON")
    study.set_defaults(func=_cmd_timestep_study)
    report = sub.add_parser("report", help="validation report against the seeds (Markdown + PNG plots)")
    report.add_argument("--out", default="reports", help="output directory (default reports/)")
    report.add_argument("--quick", action="store_true", help="fewer points and shorter runs")
    report.set_defaults(func=_cmd_report)

    add_serve_command(sub)

    add_scenario_command(sub)

    vib = sub.add_parser(
        "vibration",
        help="housing acceleration with a local defect: indicators, defect frequencies, envelope peaks",
        description="Run the twin with its outer ring on the housing (Sawalhi & Randall 2008 support, accelerometer "
        "sampled in the kernel) and an optional local defect, discard 0.05 s, analyse `--duration` of the signal "
        "(twin.validation.vibration_simulation.simulate_vibration).",
    )
    vib.add_argument(
        "--bearing",
        default=DEFAULT_DESIGNATION,
        help=f"catalog designation (default {DEFAULT_DESIGNATION}; CWRU-DE: the CWRU rig's drive end) "
        "or a BearingSpec file (.yaml, .yml, .json)",
    )
    vib.add_argument("--speed", type=float, default=None, help="shaft speed [rad/s] (required)")
    vib.add_argument(
        "--radial-load",
        type=float,
        default=None,
        help="radial load [N] (default: the rig's, for CWRU-DE; required otherwise)",
    )
    vib.add_argument("--axial-load", type=float, default=0.0, help="axial load [N]")
    vib.add_argument("--defect", choices=["outer", "inner", "ball"], help="local defect (default: none, healthy)")
    vib.add_argument(
        "--defect-size",
        type=float,
        default=None,
        help="defect width along the rolling direction, width_m [m] (default 0.5e-3)",
    )
    vib.add_argument(
        "--defect-length",
        type=float,
        default=None,
        help="defect length across the rolling direction, length_m [m] (default 0.6 x ball radius)",
    )
    vib.add_argument(
        "--defect-depth",
        type=float,
        default=None,
        help="defect depth, depth_m [m] (default 50e-6)",
    )
    vib.add_argument(
        "--defect-angle",
        type=float,
        default=None,
        help="defect position [deg]: outer race from the centre of the load zone (CWRU 6:00, 3:00, "
        "12:00 = 0, 90, 180), inner race from the ring's mark (default 0)",
    )
    vib.add_argument(
        "--clearance",
        type=float,
        default=None,
        help="mounted diametral clearance [m], -50e-6 .. 200e-6, negative = preload (default: the bearing's; "
        "CWRU-DE 12.5e-6)",
    )
    vib.add_argument(
        "--duration",
        type=float_in(0.0, VIBRATION_MAX_S, "s", low_open=True),
        default=1.0,
        help=f"analysed simulated time [s] (default 1, at most {VIBRATION_MAX_S:g}: the waveform is kept in memory)",
    )
    vib.add_argument(
        "--noise-density",
        type=float,
        default=None,
        help="sensor noise density [m/s2/sqrt(Hz)] (default: the spec's, 0)",
    )
    vib.add_argument(
        "--sample-rate",
        type=float,
        default=None,
        help="accelerometer rate [Hz] (default: the spec's; 51200, 12000 for CWRU-DE)",
    )
    vib.add_argument("--json", action="store_true", help="print the result as JSON")
    vib.add_argument(
        "--waveform",
        metavar="FILE.npy",
        type=output_file(".npy"),
        help="write the analysed accelerometer signal [m/s2] at the sample rate (float64 .npy)",
    )
    vib.add_argument(
        "--plot",
        metavar="FILE.png",
        type=output_file(".png", ".pdf", ".svg", ".jpg", ".jpeg", ".webp"),
        help="waveform, spectrum and envelope spectrum with the defect frequencies marked (.png, .pdf, .svg, ...)",
    )
    vib.set_defaults(func=_cmd_vibration)
    add_analyse_command(vib)

    _add_monitor(sub)
    from service.tools.router import add_router_command

    add_router_command(sub)
    _add_moved_load_tools(sub)
    from service.tools.ehl_cli import add_ehl_command

    add_ehl_command(sub)
    from service.tools.life_cli import add_life_command

    add_life_command(sub)
    from service.tools.thermal_cli import add_thermal_command

    add_thermal_command(sub)
    return parser


LOAD_TOOLS = ("bench-service", "soak", "attack")


def _add_moved_load_tools(sub) -> None:
    """The load tools live in the `loadtest` package (`bearing-twin-loadtest`, extra `loadtest`):
    `bearing-twin NAME` answers with where to find them."""
    for name in LOAD_TOOLS:
        sub.add_parser(name, help=f"a load tool: `bearing-twin-loadtest {name}` (pip install '.[loadtest]')")


def _moved_load_tool(name: str) -> int:
    print(
        f"error: `{name}` is a load tool: run `bearing-twin-loadtest {name} ...` "
        "(install it with pip install '.[loadtest]')",
        file=sys.stderr,
    )
    return 2


def _add_monitor(sub) -> None:
    """`monitor` comes from service.tools.monitor (zenoh); if it cannot be imported the subcommand
    still exists and says why."""
    import importlib.util

    try:
        available = importlib.util.find_spec("service.tools.monitor") is not None
    except (ImportError, ValueError):
        available = False
    if not available:
        return
    try:
        from service.tools.monitor import add_monitor_command
    except Exception as exc:  # noqa: BLE001 - keep the other subcommands working
        reason = f"{type(exc).__name__}: {exc}"
        stub = sub.add_parser("monitor", help="live table of the twins on the zenoh bus (unavailable)")
        stub.set_defaults(func=lambda _args: _unavailable("monitor", reason))
        return
    add_monitor_command(sub)


def _unavailable(name: str, reason: str) -> int:
    print(f"error: `bearing-twin {name}` is unavailable: {reason}", file=sys.stderr)
    return 2


def _cmd_report(args: argparse.Namespace) -> int:
    from service.reports.report import write_report

    path = write_report(args.out, quick=args.quick)
    print(f"report written to {path}")
    return 0


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv and argv[0] in LOAD_TOOLS:
        return _moved_load_tool(argv[0])
    args = build_parser().parse_args(argv)
    try:
        status = args.func(args)
        sys.stdout.flush()
        return status
    except BrokenPipeError:
        # the reader went away (`bearing-twin simulate --json | head -c 100`): stop quietly, as
        # a command killed by SIGPIPE would (status 128 + 13), without a traceback; stdout goes
        # to /dev/null so that the interpreter's final flush does not fail again
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 141


if __name__ == "__main__":
    sys.exit(main())
