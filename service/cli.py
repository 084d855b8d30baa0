"""`bearing-twin` command line: simulate, bench, report, serve, monitor, scenario.

Heavy imports (FastAPI, zenoh, rerun, matplotlib) happen inside the subcommand that needs them.
"""

from __future__ import annotations

import argparse
import json
import sys


def _positive_float(text: str) -> float:
    value = float(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"must be > 0, got {text}")
    return value


def _cmd_simulate(args: argparse.Namespace) -> int:
    from pydantic import ValidationError

    from twin.engine import Twin
    from twin.setpoint import Setpoint, SetpointError
    from twin.spec import ModelOptions

    try:
        options = ModelOptions(time_step_s=args.dt, film_formula=args.film_formula)
        setpoint = Setpoint(shaft_speed_rad_s=args.speed, radial_load_n=args.radial_load,
                            axial_load_n=args.axial_load, oil_temperature_c=args.oil_temperature)
        twin = Twin(args.bearing, options=options, setpoint=setpoint,
                    diametral_clearance_m=args.clearance)
        twin.advance(args.duration)
    except (ValidationError, SetpointError, ValueError) as exc:
        print(f"error: {_one_line(exc)}", file=sys.stderr)
        return 2
    snap = twin.snapshot()
    if args.json:
        print(snap.to_json())
    else:
        _print_table(snap)
    return 0


def _one_line(exc: Exception) -> str:
    from pydantic import ValidationError

    if isinstance(exc, ValidationError):
        return "; ".join(f"{'.'.join(str(p) for p in e['loc'])}: {e['msg']}" for e in exc.errors())
    return str(exc)


def _print_table(snap) -> None:
    from rich.console import Console
    from rich.table import Table

    table = Table(title=f"{snap.designation} at t = {snap.time_s:.4f} s, status {snap.status}")
    for col in ("ball", "azimuth deg", "spin rad/s", "Q in N", "Q out N", "Lambda in", "Lambda out",
                "regime in", "regime out"):
        table.add_column(col, justify="right")
    for b in snap.balls:
        lam = lambda c: "-" if c.lambda_ is None else f"{c.lambda_:.2f}"  # noqa: E731
        table.add_row(str(b.index), f"{b.azimuth_rad * 57.29578:.1f}", f"{b.spin_rad_s:.1f}",
                      f"{b.inner.load_n:.0f}", f"{b.outer.load_n:.0f}", lam(b.inner), lam(b.outer),
                      b.inner.regime, b.outer.regime)
    console = Console()
    console.print(table)
    console.print(f"cage {snap.cage_speed_rad_s:.2f} rad/s, friction torque "
                  f"{snap.friction_torque_n_m * 1e3:.2f} mN m")


def _cmd_bench(args: argparse.Namespace) -> int:
    from twin.bench import run_engine_benchmark

    result = run_engine_benchmark(seconds=args.seconds, repeats=args.repeats)
    if args.json:
        print(json.dumps(result))
    else:
        print(f"{result['bearing']} at {result['radial_load_n']:.0f} N, {result['shaft_speed_rad_s']:.0f} rad/s, "
              f"dt = {result['time_step_s'] * 1e6:.1f} us, full model")
        print(f"  real-time factor (best of {result['repeats']}): {result['real_time_factor']:.3f}")
        print(f"  real-time factor (median): {result['real_time_factor_median']:.3f}")
        print(f"  ns per step (best): {result['ns_per_step']:.0f}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="bearing-twin", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)

    sim = sub.add_parser("simulate", help="run one twin for a duration, print the final snapshot")
    sim.add_argument("--bearing", default="6208", help="catalog designation (default 6208)")
    sim.add_argument("--radial-load", type=float, default=3000.0, help="radial load [N]")
    sim.add_argument("--axial-load", type=float, default=0.0, help="axial load [N]")
    sim.add_argument("--speed", type=float, default=500.0, help="shaft speed [rad/s]")
    sim.add_argument("--oil-temperature", type=float, default=40.0, help="oil temperature [degC]")
    sim.add_argument("--clearance", type=float, default=0.0, help="diametral clearance [m], negative = preload")
    sim.add_argument("--duration", type=float, default=0.05, help="simulated time [s]")
    sim.add_argument("--dt", type=float, default=1e-6, help="time step [s]")
    sim.add_argument("--film-formula", choices=["hamrock_dowson", "masjedi_khonsari"], default="hamrock_dowson")
    sim.add_argument("--json", action="store_true", help="print the snapshot as JSON")
    sim.set_defaults(func=_cmd_simulate)

    bench = sub.add_parser("bench", help="engine speed: real-time factor and ns per step (6208, 3000 N, 500 rad/s)")
    bench.add_argument("--seconds", type=_positive_float, default=0.2, help="simulated seconds per repeat")
    bench.add_argument("--repeats", type=int, default=5, help="repeats (best and median reported)")
    bench.add_argument("--json", action="store_true")
    bench.set_defaults(func=_cmd_bench)
    report = sub.add_parser("report", help="validation report against the seeds (Markdown + PNG plots)")
    report.add_argument("--out", default="reports", help="output directory (default reports/)")
    report.add_argument("--quick", action="store_true", help="fewer points and shorter runs")
    report.set_defaults(func=_cmd_report)
    return parser


def _cmd_report(args: argparse.Namespace) -> int:
    from service.report import write_report

    path = write_report(args.out, quick=args.quick)
    print(f"report written to {path}")
    return 0


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    return args.func(args)


if __name__ == "__main__":
    sys.exit(main())
