"""`bearing-twin ehl`: the seed-003 point-contact EHL solver from the command line.

    bearing-twin ehl solve [--load N] [--entrainment-speed M_S] [--current A] [--grid N] [--json]
    bearing-twin ehl calibrate [--out PATH] [--grid N] [--anchor]
    bearing-twin ehl bench [--grid N] [--repeats N] [--json]

Defaults are seed 003 Appendix 2 (twin/ehl_solver/params.py). `solve` prints h_min, h_c, the
maximum pressure, the temperature rise, convergence and the Hamrock-Dowson h_min of the same
inputs (exit code 1 when the solver did not converge: the numbers are then not a solution);
`calibrate` regenerates the film-reduction table shipped with twin.ehl_solver; `bench` times
the isothermal solve at the default speed (default 129 x 129, the solver's speed figure).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from typing import Any

from service.tools.arg_types import float_in, int_in, non_negative_float
from service.tools.stdout import print_document
from twin.setpoint import FIELD

GRIDS = (17, 33, 65, 129, 257, 513)  # nodes per direction the solver takes (2^k + 1; 513: minutes per solve)
OIL = FIELD["oil_temperature_c"]  # the base temperature takes the twin's oil range, where the oil laws hold


def _grid(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value not in GRIDS:
        raise argparse.ArgumentTypeError(f"must be one of {', '.join(map(str, GRIDS))} (2^k + 1), got {text}")
    return value


def add_ehl_command(subparsers: Any) -> argparse.ArgumentParser:
    """Register `ehl solve`, `ehl calibrate` and `ehl bench` on an argparse subparsers object
    (service/tools/cli.py does; `python -m service.tools.ehl_cli ehl ...` runs them on their own);
    each sets `func(args) -> exit code`. The module docstring is the command's help."""
    from twin.ehl_solver import params as prm

    ehl = subparsers.add_parser(
        "ehl",
        help="thermal EHL point-contact solver with current heating (seed 003)",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = ehl.add_subparsers(dest="ehl_command", required=True)

    solve = sub.add_parser("solve", help="solve one contact (defaults: seed 003 Appendix 2)")
    solve.add_argument(
        "--load",
        type=float_in(0.0, 1.0e5, "N", low_open=True),
        default=prm.LOAD_N,
        help=f"load on the ball [N] (default {prm.LOAD_N})",
    )
    solve.add_argument(
        "--entrainment-speed",
        type=float_in(0.0, 100.0, "m/s", low_open=True),
        default=prm.DEFAULT_ENTRAINMENT_SPEED_M_S,
        help=f"mean entrainment speed [m/s] (default {prm.DEFAULT_ENTRAINMENT_SPEED_M_S}; "
        "seed 003 Fig. 1 spans 0.832-4.16)",
    )
    solve.add_argument(
        "--current",
        type=float_in(0.0, 100.0, "A"),
        default=0.0,
        help="current through the contact [A] (default 0: isothermal unless --thermal)",
    )
    solve.add_argument("--grid", type=_grid, default=129, help="nodes per direction, 2^k + 1 (default 129)")
    solve.add_argument(
        "--thermal",
        action="store_true",
        help="include shear heating (eq. 6) also at 0 A (with current it is always on)",
    )
    solve.add_argument(
        "--base-temperature",
        type=float_in(OIL.low, OIL.high, OIL.unit),
        default=prm.BASE_TEMPERATURE_C,
        help=f"oil (boundary) temperature [degC] (default {prm.BASE_TEMPERATURE_C})",
    )
    solve.add_argument(
        "--bearing-resistance",
        type=non_negative_float,
        default=prm.DEFAULT_BEARING_RESISTANCE_OHM,
        help=f"equivalent bearing resistance R_b of eq. 10 [ohm] "
        f"(default {prm.DEFAULT_BEARING_RESISTANCE_OHM:g}, anchored on seed 003 Fig. 2)",
    )
    solve.add_argument(
        "--max-iter", type=int_in(1, 10000), default=200, help="multigrid cycle cap, 1-10000 (default 200)"
    )
    solve.add_argument("--json", action="store_true", help="print JSON instead of a table")
    solve.set_defaults(func=_cmd_solve)

    cal = sub.add_parser("calibrate", help="regenerate the film-reduction table (current x speed) for the twin")
    cal.add_argument("--out", default=None, help="output JSON (default: the table shipped in twin/ehl_solver)")
    cal.add_argument("--grid", type=_grid, default=None, help="nodes per direction (default 257)")
    cal.add_argument(
        "--anchor", action="store_true", help="re-anchor the bearing resistance on 84.8 %% reduction at 30 A first"
    )
    cal.set_defaults(func=_cmd_calibrate)

    bench = sub.add_parser("bench", help="time the isothermal solve at the default speed (after a warm-up)")
    bench.add_argument("--grid", type=_grid, default=129, help="nodes per direction (default 129)")
    bench.add_argument("--repeats", type=int_in(1, 1000), default=3, help="timed solves, 1-1000 (default 3)")
    bench.add_argument("--json", action="store_true", help="print JSON instead of text")
    bench.set_defaults(func=_cmd_bench)
    return ehl


def benchmark_solve(grid: int = 129, repeats: int = 3) -> dict:
    """Wall time of an isothermal solve at the Appendix 2 defaults (default speed) on grid x grid
    nodes, one process, after one warm-up solve (numba compilation / cache load). Returns the
    median and the individual times [s], cycles and h_min."""
    import statistics
    import time

    from twin.ehl_solver import solve_point_contact

    solve_point_contact(grid=grid, thermal=False)  # warm-up
    times = []
    for _ in range(max(1, repeats)):
        t0 = time.perf_counter()
        res = solve_point_contact(grid=grid, thermal=False)
        times.append(time.perf_counter() - t0)
    return {
        "grid": grid,
        "median_s": statistics.median(times),
        "times_s": times,
        "iterations": res.iterations,
        "converged": res.converged,
        "h_min_m": res.h_min_m,
        "h_c_m": res.h_c_m,
    }


def _cmd_bench(args: argparse.Namespace) -> int:
    doc = _finite(benchmark_solve(args.grid, args.repeats))
    if args.json:
        print_document(json.dumps(doc, indent=1))
    else:
        print(
            f"isothermal solve, {doc['grid']} x {doc['grid']}, default speed: median {doc['median_s']:.2f} s "
            f"over {len(doc['times_s'])} solves ({doc['iterations']} cycles, converged {doc['converged']})"
        )
    return 0 if doc["converged"] else 1


def solve_to_dict(args: argparse.Namespace) -> dict:
    """Run the solver for parsed `ehl solve` arguments; the JSON document (no NaN/inf)."""
    from twin.ehl_solver import solve_point_contact

    thermal = bool(args.thermal or args.current > 0)
    res = solve_point_contact(
        args.load,
        args.entrainment_speed,
        current_a=args.current,
        grid=args.grid,
        thermal=thermal,
        base_temperature_c=args.base_temperature,
        bearing_resistance_ohm=args.bearing_resistance,
        max_iter=args.max_iter,
    )
    doc = {
        "schema": "bearing-twin/ehl-solve/1",
        "h_min_m": res.h_min_m,
        "h_c_m": res.h_c_m,
        "max_pressure_pa": res.max_pressure_pa,
        "hertz_pressure_pa": res.hertz["p_hertz_pa"],
        "temperature_rise_k": res.temperature_rise_k,
        "current_temperature_rise_k": res.current_temperature_rise_k,
        "converged": res.converged,
        "iterations": res.iterations,
        "message": res.message,
        "hamrock_dowson_h_min_m": res.hamrock_dowson_h_min_m,
        "hamrock_dowson_h_c_m": res.hamrock_dowson_h_c_m,
        "wall_time_s": res.wall_time_s,
        "final_pressure_change": res.history["dp"][-1] if res.history["dp"] else None,
        "final_load_error": res.history["load_error"][-1] if res.history["load_error"] else None,
        "inputs": res.inputs,
        "hertz": res.hertz,
    }
    return _finite(doc)


def _finite(obj):
    """JSON never carries NaN or Infinity (docs/architecture.md): non-finite floats become null."""
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {k: _finite(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_finite(v) for v in obj]
    return obj


def _cmd_solve(args: argparse.Namespace) -> int:
    doc = solve_to_dict(args)
    if args.json:
        print_document(json.dumps(doc, indent=1))
    else:
        inp = doc["inputs"]
        print(
            f"point contact (seed 003): w = {inp['load_n']:g} N, u = {inp['entrainment_speed_m_s']:g} m/s, "
            f"I = {inp['current_a']:g} A, grid {inp['grid']} x {inp['grid']}, "
            f"{'thermal' if inp['thermal'] else 'isothermal'}, eta0 = {inp['eta0_pa_s']:g} Pa s at "
            f"{inp['base_temperature_c']:g} degC"
        )

        def nm(v):
            return "-" if v is None else f"{v * 1e9:.1f} nm"

        print(f"  h_min {nm(doc['h_min_m'])}   (Hamrock-Dowson {nm(doc['hamrock_dowson_h_min_m'])})")
        print(f"  h_c   {nm(doc['h_c_m'])}   (Hamrock-Dowson {nm(doc['hamrock_dowson_h_c_m'])})")
        if doc["max_pressure_pa"] is not None:
            print(f"  p_max {doc['max_pressure_pa'] / 1e9:.3f} GPa (Hertz {doc['hertz_pressure_pa'] / 1e9:.3f} GPa)")
        rise = doc["temperature_rise_k"]
        print(
            f"  temperature rise {'-' if rise is None else f'{rise:.1f} K'} (current, eq. 10: "
            f"{doc['current_temperature_rise_k']:.1f} K)"
        )
        print(
            f"  converged {doc['converged']} after {doc['iterations']} cycles in {doc['wall_time_s']:.1f} s"
            + (f": {doc['message']}" if doc["message"] else "")
        )
    return 0 if doc["converged"] else 1


def _cmd_calibrate(args: argparse.Namespace) -> int:
    from twin.ehl_solver import film_reduction as calibration

    out = args.out or str(calibration.TABLE_PATH)
    grid = args.grid or calibration.CALIBRATION_GRID
    prog = "python -m service.tools.ehl_cli" if sys.argv and sys.argv[0].endswith("ehl_cli.py") else "bearing-twin"
    command = (
        f"{prog} ehl calibrate"
        + (f" --out {args.out}" if args.out else "")
        + (f" --grid {args.grid}" if args.grid else "")
        + (" --anchor" if args.anchor else "")
    )

    def log(msg: str) -> None:
        print(msg, file=sys.stderr, flush=True)

    return calibration.run_calibration(out, grid=grid, anchor=args.anchor, command=command, log=log)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="bearing-twin")
    sub = parser.add_subparsers(dest="command", required=True)
    add_ehl_command(sub)
    args = parser.parse_args(argv)
    return args.func(args)


if __name__ == "__main__":
    raise SystemExit(main())
