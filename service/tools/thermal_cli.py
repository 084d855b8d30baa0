"""`bearing-twin thermal`: the thermal steady state of a catalogue bearing at one operating point
(twin.validation.thermal_steady: the network's steady state with the engine's friction in the loop)."""

from __future__ import annotations

import argparse
import json
import sys

from service.tools.arg_types import float_in
from service.tools.messages import OPERATING_FLAGS, error_text
from service.tools.stdout import print_document
from twin.setpoint import FIELD

OIL = FIELD["oil_temperature_c"]  # the ambient / oil-inlet temperature takes the oil temperature's range

THERMAL_FLAGS = {**OPERATING_FLAGS, "oil_temperature_c": "--ambient"}


def add_thermal_command(sub) -> None:
    """Register `thermal` on the `bearing-twin` subparsers."""
    p = sub.add_parser(
        "thermal",
        help="thermal steady state: node temperatures, friction torque, heat by source",
        description="Steady state of the bearing's thermal network (shaft, rings, balls, housing, oil) with the "
        "twin's own friction heat in the loop: the film's viscosity at the inlet temperature the network sets "
        "(fixed-point iteration, twin.validation.thermal_steady).",
    )
    p.add_argument(
        "--bearing", default="6208", help="catalog designation or bearing spec file (.yaml, .json) (default 6208)"
    )
    p.add_argument("--speed", type=float, required=True, help="shaft speed [rad/s]")
    p.add_argument("--radial-load", type=float, required=True, help="radial load [N]")
    p.add_argument("--axial-load", type=float, default=0.0, help="axial load [N] (default 0)")
    p.add_argument(
        "--ambient",
        type=float_in(OIL.low, OIL.high, OIL.unit),
        default=20.0,
        help="ambient (oil bath) temperature [degC] (default 20)",
    )
    p.add_argument(
        "--lubricant", default=None, help="'seed-000' or 'ISO VG n' (default seed-000, or a spec file's own)"
    )
    p.add_argument(
        "--dissipation",
        choices=("housing", "iso_15312"),
        default="housing",
        help="heat path to the surroundings: the housing correlations (default) or ISO 15312's reference dissipation",
    )
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.set_defaults(func=_cmd_thermal)


def _cmd_thermal(args: argparse.Namespace) -> int:
    from pydantic import ValidationError

    from twin import catalog
    from twin.setpoint import SetpointError
    from twin.thermal.settings import ThermalNetworkSettings
    from twin.validation.thermal_steady import steady_operating_point

    try:
        spec = catalog.bearing_or_file(args.bearing)
        if args.lubricant is not None:
            spec = spec.model_copy(update={"lubricant": catalog.lubricant(args.lubricant)})
        r = steady_operating_point(
            spec.designation,
            args.speed,
            args.radial_load,
            args.axial_load,
            args.ambient,
            ThermalNetworkSettings(dissipation=args.dissipation),
            spec=spec,
        )
    except (ValidationError, SetpointError, ValueError) as exc:
        print(f"error: {error_text(exc, THERMAL_FLAGS)}", file=sys.stderr)
        return 2
    if args.json:
        print_document(json.dumps(r, allow_nan=False))
        return 0
    print(
        f"{r['bearing']} at {r['shaft_speed_rad_s']:g} rad/s, Fr = {r['radial_load_n']:g} N, "
        f"Fa = {r['axial_load_n']:g} N, ambient {r['ambient_c']:g} degC ({r['dissipation']} dissipation)"
    )
    print("  temperatures [degC]: " + ", ".join(f"{k} {v:.1f}" for k, v in r["temperatures_c"].items()))
    print(
        f"  inlet {r['inlet_temperature_c']:.1f} degC, viscosity {r['viscosity_pa_s'] * 1e3:.2f} mPa s, "
        f"min Lambda {r['min_lambda'] if r['min_lambda'] is None else round(r['min_lambda'], 2)}"
    )
    print(
        f"  friction torque {r['friction_torque_n_m']:.4f} N m, heat {r['heat_total_w']:.1f} W: "
        + ", ".join(f"{k} {v:.1f}" for k, v in r["heat_w"].items())
        + f" (inner contacts {r['heat_inner_contacts_w']:.1f}, outer {r['heat_outer_contacts_w']:.1f})"
    )
    print(
        "  time constants [s]: "
        + ", ".join(f"{t:.0f}" for t in r["time_constants_s"][:3])
        + ("" if r["converged"] else f"  (not converged after {r['iterations']} iterations)")
    )
    return 0
