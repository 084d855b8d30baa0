"""`bearing-twin scenario`: check scenario files, and run one in fast mode (a fresh twin per run)
with its per-sample table, alarms and optional recording."""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING, Any

from service.tools.arg_types import output_file
from service.tools.messages import error_text

if TYPE_CHECKING:
    from service.settings import AlarmSettings


def add_scenario_command(sub: Any) -> None:
    """Register `scenario check` and `scenario run` on the `bearing-twin` subparsers."""
    scenario = sub.add_parser("scenario", help="scenarios: timelines of setpoints and ramps (YAML)")
    scenario_sub = scenario.add_subparsers(dest="scenario_command", required=True)
    run = scenario_sub.add_parser("run", help="run a scenario file in fast mode (fresh twin per run)")
    run.add_argument("file", help="scenario YAML file (see scenarios/ and service/core/scenarios.py)")
    run.add_argument("--record", metavar="OUT.rrd", type=output_file(".rrd"), help="write a rerun recording")
    run.add_argument(
        "--table",
        metavar="OUT.parquet",
        type=output_file(".parquet", ".pq", ".csv"),
        help="write the per-sample table (Parquet; .csv for CSV)",
    )
    run.add_argument("--no-progress", action="store_true", help="no progress bar")
    run.set_defaults(func=_cmd_scenario_run)
    check = scenario_sub.add_parser("check", help="validate scenario files and print what they do")
    check.add_argument("files", nargs="+", help="scenario YAML files (see scenarios/)")
    check.set_defaults(func=_cmd_scenario_check)


def _cmd_scenario_check(args: argparse.Namespace) -> int:
    from service.core.scenario_files import load_scenario
    from service.core.scenarios import ScenarioError

    status = 0
    for file in args.files:
        try:
            scenario = load_scenario(file)
            scenario.check_bearing_limits()  # what `scenario run` checks before it runs
        except ScenarioError as exc:
            print(f"{file}: error: {exc}", file=sys.stderr)
            status = 2
            continue
        runs = scenario.resolved_runs()
        print(
            f"{file}: ok: {scenario.name}, {len(runs)} run(s), {scenario.total_duration_s:g} s simulated, "
            f"sample every {scenario.sample_every_s:g} s"
        )
        for w in scenario.warnings:
            print(f"  warning: {w}")
    return status


def _alarm_settings_from_env() -> AlarmSettings:
    """The alarms from `BEARING_TWIN_ALARMS` (JSON) or `BEARING_TWIN_ALARMS__<FIELD>`, as for `serve`."""
    from service.settings import ScenarioSettings

    return ScenarioSettings().alarms


def _cmd_scenario_run(args: argparse.Namespace) -> int:
    from service.core.scenario_files import load_scenario
    from service.core.scenarios import ScenarioError
    from service.tools.offline import TableSink, run_scenario, write_table

    try:
        scenario = load_scenario(args.file)
        scenario.check_bearing_limits()
    except ScenarioError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    for w in scenario.warnings:
        print(f"warning: {w}", file=sys.stderr)
    try:
        alarm_settings = _alarm_settings_from_env()
    except ValueError as exc:  # pydantic's ValidationError is a ValueError
        print(f"error: BEARING_TWIN_ALARMS: {error_text(exc)[:300]}", file=sys.stderr)
        return 2
    total = scenario.total_duration_s
    runs = scenario.resolved_runs()
    print(f"{scenario.name}: {len(runs)} run(s), {total:g} s of simulated time, fast mode", file=sys.stderr)
    table = TableSink()
    bar = None
    if not args.no_progress:
        from tqdm import tqdm

        bar = tqdm(
            total=round(total * 1000),
            unit="ms",
            desc=scenario.name,
            file=sys.stderr,
            bar_format="{desc}: {percentage:3.0f}%|{bar}| {n_fmt}/{total_fmt} ms simulated [{elapsed}<{remaining}]",
        )

    def progress(done_s: float) -> None:
        if bar is not None:
            bar.n = min(bar.total, round(done_s * 1000))
            bar.refresh()

    try:
        written: list = []
        results = run_scenario(
            scenario,
            record=args.record,
            table=table,
            progress=progress,
            on_recording=written.append,
            alarms=alarm_settings,
        )
    except ScenarioError as exc:
        if bar is not None:
            bar.close()
        print(f"error: {exc}", file=sys.stderr)
        return 2
    if bar is not None:
        bar.close()
    from twin.friction_power import REST_SPEED_RAD_S

    status = 0
    for r in results:
        snap = r.final
        lam = [c.lambda_ for b in (snap.balls if snap else ()) for c in (b.inner, b.outer) if c.lambda_ is not None]
        summary = f"status {snap.status}" if snap else ""
        if snap is not None and lam:
            # the last sample's state; a shaft at rest holds only the tangential springs' elastic torque
            at_rest = abs(snap.shaft_speed_rad_s) < REST_SPEED_RAD_S
            torque = "holding torque at rest" if at_rest else "friction torque"
            summary = (
                f"at the end ({snap.time_s:.3f} s, {snap.shaft_speed_rad_s:.1f} rad/s): min Lambda {min(lam):.2f}, "
                f"{torque} {snap.friction_torque_n_m * 1e3:.2f} mN m, status {snap.status}"
            )
        print(
            f"  {r.run.id} ({r.run.label}): {r.state}, {r.rows} samples, {r.wall_s:.1f} s wall; {summary}"
            + (f"; error: {r.error}" if r.error else "")
        )
        for e in r.alarms:
            print(f"    alarm at {e.time_s:.3f} s: {e.message}")
        if r.state != "done":
            status = 1
    if args.table:
        path = write_table(table.rows, args.table)
        print(f"table: {path} ({len(table.rows)} rows)")
    if args.record:  # the file written: <stem>.run2.rrd when the name was taken
        print(f"recording: {written[0] if written else args.record}")
    return status
