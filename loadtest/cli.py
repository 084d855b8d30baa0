"""`bearing-twin-loadtest` command line: bench-service, soak and attack, the load tools that drive a
service over HTTP and zenoh (the `loadtest` extra brings their HTTP client, httpx)."""

from __future__ import annotations

import argparse
import importlib
import json
import sys
from pathlib import Path

from loadtest.attack import add_attack_command
from loadtest.benchmark import CLIENT_NICE, run_service_benchmark
from loadtest.soak import add_soak_command
from service.tools.arg_types import positive_float, positive_int
from service.tools.cli import ArgumentParser

SAVE_KIND = "servicebench"  # file kind: not matched by the engine bench's `*-bench*.json`
EXTRA_HINT = "the load tools need httpx: pip install -c constraints.txt '.[loadtest]'"


def build_parser() -> argparse.ArgumentParser:
    parser = ArgumentParser(prog="bearing-twin-loadtest", description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    bsv = sub.add_parser(
        "bench-service",
        help="service benchmark: N twins in real time with zenoh and "
        "recording on: real-time factor and late fraction per twin, HTTP setpoint -> "
        "zenoh state delay (p50/p99)",
    )
    bsv.add_argument(
        "--twins",
        type=_twins,
        default=1,
        help="twins to run: 6208, 6205, 7208, 6208 with 5 A, in turn (default 1); 'auto': as many "
        "twins like the first (6208) as the service's capacity states once the first is calibrated and "
        "the service overhead per twin measured (/health capacity.max_twins)",
    )
    bsv.add_argument("--seconds", type=positive_float, default=10.0, help="measurement time [s of wall time]")
    bsv.add_argument("--rate", type=positive_float, default=20.0, help="setpoints per second, all twins [Hz]")
    bsv.add_argument(
        "--force", action="store_true", help="admission off: run every twin even beyond the measured capacity"
    )
    bsv.add_argument("--no-zenoh", action="store_true", help="without zenoh (then no setpoint delay)")
    bsv.add_argument("--no-record", action="store_true", help="without the rerun recording")
    bsv.add_argument(
        "--client-nice",
        type=int,
        default=CLIENT_NICE,
        help=f"nice of the client's threads while it measures, where allowed (default {CLIENT_NICE}: the "
        "service's I/O threads'; the host's other load is then not counted as the service's latency)",
    )
    bsv.add_argument("--json", action="store_true")
    bsv.add_argument(
        "--save",
        nargs="?",
        const="benchmarks/results",
        default=None,
        metavar="DIR",
        help="also write the result with the CPU model, versions and git commit to "
        "DIR/<UTC date>-<cpu>-servicebench.json (default DIR: benchmarks/results)",
    )
    bsv.set_defaults(func=_cmd_bench_service)
    add_soak_command(sub)
    add_attack_command(sub)
    return parser


def _cmd_bench_service(args: argparse.Namespace) -> int:
    try:
        r = run_service_benchmark(
            twins=args.twins,
            seconds=args.seconds,
            rate_hz=args.rate,
            record=not args.no_record,
            zenoh_on=not args.no_zenoh,
            force=args.force,
            client_nice=args.client_nice,
        )
    except RuntimeError as exc:
        print(f"error: {' '.join(str(exc).split())[:2000]}", file=sys.stderr)
        return 1
    if args.save is not None:
        from service.tools.bench_results import save

        command = "bearing-twin-loadtest bench-service " + " ".join(sys.argv[2:] if len(sys.argv) > 2 else [])
        path = save(r, SAVE_KIND, command.strip(), Path(args.save))
        print(f"saved {path}", file=sys.stderr)
    if args.json:
        print(json.dumps(r))
        return 0
    print(
        f"{len(r['twins'])} twin(s) in real time, frames of {f(r['frame_s'], '{:g}')} s, zenoh "
        f"{'on' if r['zenoh'] else 'off'}, recording {'on' if r['recording'] else 'off'}, admission "
        f"{r['admission']}; {r['setpoints']} setpoints in {r['seconds']:g} s"
    )
    for t in r["twins"]:
        print(
            f"  {t['id']:<14} {t['designation']:<5} real-time factor median "
            f"{f(t['real_time_factor_median'], '{:.3f}')} "
            f"(min {f(t['real_time_factor_min'], '{:.3f}')}), late {f(t['late_fraction'], '{:.2%}')} of "
            f"{t['frames']} frames, dropped {t['dropped']}, PUT -> zenoh p99 {f(t['client_latency_ms_p99'])} ms"
        )
    for t in r["refused"]:
        print(f"  {t['id']:<14} {t['designation']:<5} refused ({t['status']}): {t['message']}")
    print(
        f"  HTTP PUT -> zenoh state [ms]: p50 {f(r['client_latency_ms_p50'])}, "
        f"p99 {f(r['client_latency_ms_p99'])}, max {f(r['client_latency_ms_max'])}, lost {r['client_lost']}"
    )
    if r.get("http_put_ms_p50") is not None:
        print(f"  HTTP PUT round trip [ms]: p50 {f(r['http_put_ms_p50'])}, p99 {f(r['http_put_ms_p99'])}")
    for t in r["twins"]:
        stages = t.get("service_latency_ms") or {}
        if stages:
            print(
                f"  {t['id']:<14} in the service [ms, p50/p99]: "
                + ", ".join(f"{k} {f(v['p50'])}/{f(v['p99'])}" for k, v in stages.items() if isinstance(v, dict))
            )
    cap = r.get("capacity") or {}
    if cap.get("formula"):
        print(f"  capacity: {cap['formula']}")
    overhead = cap.get("service_overhead") or {}
    if overhead.get("overhead_fraction") is not None:
        print(
            f"  service overhead: {f(overhead['overhead_cpu_s_per_s'], '{:.3f}')} CPU s/s beside the engines' "
            f"{f(overhead['engine_cpu_s_per_s'], '{:.3f}')} = {f(overhead['overhead_fraction'], '{:.1%}')} "
            f"(goal <= {overhead['goal_fraction']:.0%})"
        )
    run = r.get("overhead_over_run") or {}
    if run.get("twin_overhead_fraction") is not None:
        roles = ", ".join(
            f"{k.removesuffix('_cpu_s_per_s')} {v:.3f}"
            for k, v in run.items()
            if k.endswith("_cpu_s_per_s") and not k.startswith(("twin_", "engine_"))
        )
        print(f"  over the {run['window_s']:.0f} s measured, by thread [CPU s/s]: {roles}")
        print(
            f"  twin overhead (every thread but http and opcua): {run['twin_overhead_cpu_s_per_s']:.3f} CPU s/s "
            f"beside the engines' {run['engine_cpu_s_per_s']:.3f} = {run['twin_overhead_fraction']:.1%}"
        )
    if cap:
        print(
            f"  capacity: {f(cap.get('used_cpu_s_per_s'), '{:.3f}')} of {f(cap.get('budget_cpu_s_per_s'), '{:.3f}')} "
            f"CPU s per s in use; max twins like the last calibrated one: {cap.get('max_twins')}"
        )
    return 0


def _twins(text: str) -> int | str:
    """--twins: a positive count or 'auto'."""
    return "auto" if text.strip().lower() == "auto" else positive_int(text)


def f(value: float | None, spec: str = "{:.2f}") -> str:
    """A figure of the report, "-" when not measured."""
    return "-" if value is None else spec.format(value)


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        importlib.import_module("httpx")
    except ImportError:
        print(f"error: {EXTRA_HINT}", file=sys.stderr)
        return 2
    status: int = args.func(args)
    return status


if __name__ == "__main__":
    sys.exit(main())
