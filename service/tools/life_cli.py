"""`bearing-twin life`: ISO 281 rating life and the contact-load life of a catalogue bearing at
one steady operating point (twin.life.rate_operating_point)."""

from __future__ import annotations

import argparse
import json
import sys

from service.tools.messages import OPERATING_FLAGS, error_text
from service.tools.stdout import print_document
from twin.catalog import DEFAULT_DESIGNATION

_CONTAMINATION = (
    "extreme_cleanliness",
    "high_cleanliness",
    "normal_cleanliness",
    "slight_to_typical_contamination",
    "severe_contamination",
    "very_severe_contamination",
)


def add_life_command(sub) -> None:
    """Register `life` on the `bearing-twin` subparsers."""
    p = sub.add_parser(
        "life",
        help="rating life: ISO 281 L10 / L10m (a_ISO, kappa) and the Lundberg-Palmgren life from the "
        "ball loads of the quasi-static equilibrium",
        description="ISO 281:2007 basic and modified rating life of a catalogue bearing at one steady operating "
        "point, and the life from the contact loads (Lundberg-Palmgren per raceway, ISO/TS 16281 spirit) of the "
        "twin's quasi-static equilibrium (a short DEM run where the equilibrium does not converge).",
    )
    p.add_argument(
        "--bearing",
        default=DEFAULT_DESIGNATION,
        help=f"catalog designation (default {DEFAULT_DESIGNATION}) or a bearing spec file (.yaml, .json)",
    )
    p.add_argument("--radial-load", type=float, required=True, help="radial load [N]")
    p.add_argument("--axial-load", type=float, default=0.0, help="axial load [N] (default 0)")
    p.add_argument("--speed", type=float, required=True, help="shaft speed [rad/s]")
    p.add_argument("--oil-temperature", type=float, default=40.0, help="oil temperature [degC] (default 40)")
    p.add_argument(
        "--clearance",
        type=float,
        default=None,
        help="diametral clearance [m], negative = preload (default 0, or a spec file's own)",
    )
    p.add_argument(
        "--contamination",
        choices=_CONTAMINATION,
        default="normal_cleanliness",
        help="contamination level (ISO 281 Table 13 / Annex A, oil; default normal_cleanliness)",
    )
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.set_defaults(func=_cmd_life)


def _fmt(value, spec: str = "{:.4g}") -> str:
    return "-" if value is None else spec.format(value)


def _cmd_life(args: argparse.Namespace) -> int:
    from pydantic import ValidationError

    from twin import catalog
    from twin.life.settings import LifeSettings
    from twin.setpoint import SetpointError
    from twin.validation.life_rating import rate_operating_point

    try:
        spec = catalog.bearing_or_file(args.bearing)
        clearance = spec.mounting.diametral_clearance_m if args.clearance is None else args.clearance
        result = rate_operating_point(
            spec,
            args.radial_load,
            args.axial_load,
            args.speed,
            oil_temperature_c=args.oil_temperature,
            diametral_clearance_m=clearance,
            settings=LifeSettings(contamination=args.contamination),
        )
    except (ValidationError, SetpointError, ValueError) as exc:
        print(f"error: {error_text(exc, OPERATING_FLAGS)}", file=sys.stderr)
        return 2
    if args.json:
        print_document(json.dumps(result, allow_nan=False))
        return 0
    r = result
    print(
        f"{r['bearing']} ({r['kind']}, {r['nominal_contact_angle_deg']:g} deg) at Fr = {r['radial_load_n']:g} N, "
        f"Fa = {r['axial_load_n']:g} N, {r['shaft_speed_rad_s']:g} rad/s, oil {r['oil_temperature_c']:g} degC"
    )
    print(
        f"  C = {r['dynamic_load_rating_n']:.0f} N, C0 = {r['static_load_rating_n']:.0f} N, "
        f"Pu = {r['fatigue_load_limit_n']:.0f} N ({r['ratings_source']})"
    )
    print(f"  P = {r['x_factor']:g} Fr + {r['y_factor']:g} Fa = {r['equivalent_load_n']:.0f} N (e = {r['e_factor']:g})")
    print(f"  kappa = {_fmt(r['kappa'])}, e_C = {r['contamination_factor']:.3g}, a_ISO = {_fmt(r['a_iso'])}")
    print(
        f"  L10 = {_fmt(r['l10_h'], '{:.0f}')} h, L10m = {_fmt(r['l10m_h'], '{:.0f}')} h, "
        f"contact-load life = {_fmt(r['l10_contact_loads_h'], '{:.0f}')} h"
    )
    print(f"  contact loads from: {r['contact_loads_from']}")
    if r["reason"]:
        print(f"  note: {r['reason']}")
    return 0
