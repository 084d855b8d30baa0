"""`bearing-twin router`: a zenoh router for a fleet of twins on several hosts.

    bearing-twin router --listen tcp/0.0.0.0:7447                 # open router
    BEARING_TWIN_ZENOH_USERSFILE=users.txt BEARING_TWIN_ZENOH_SERVICES=twin \\
    BEARING_TWIN_ZENOH_WRITERS=scada BEARING_TWIN_ZENOH_READERS=dashboard \\
        bearing-twin router --listen tcp/0.0.0.0:7447 --prefix 'plant1/**'   # secured

This is zenoh's own router (a zenoh session opened in "router" mode from the Python API; pip's
eclipse-zenoh ships no `zenohd`), not a relay of ours: services join it with
`serve --zenoh-connect` (as zenoh clients: every message goes through the router), the monitor
and the other clients connect to it the same way. Multicast scouting is off; it listens only
where it is told.

With a users file (or TLS client certificates) it authenticates every link and enforces the
access-control rules of service.bus.access for the key prefix (a pattern: `plant1/**` covers
every line and asset of plant1): services publish and declare liveliness, writers put setpoints,
readers read; a peer without credentials cannot connect. It runs until SIGTERM or Ctrl-C.
"""

from __future__ import annotations

import argparse
import signal
import sys
import threading
from typing import Any

from service.settings import RouterSettings
from service.tools.settings_flags import add_settings_flags, flag_overrides, settings_error_text


def open_router(settings: Any):
    """Open the router session; returns (session, description). RuntimeError (one line) when
    it cannot listen."""
    import zenoh

    from service.bus.access import ZenohAccess
    from service.bus.zenoh_bus import _one_line, make_config

    access = ZenohAccess.from_settings(settings.zenoh, enforce=True)
    config = make_config(settings.zenoh.listen, [], "router", access=access, prefix=settings.zenoh.prefix)
    try:
        session = zenoh.open(config)
    except Exception as exc:
        text = _one_line(exc)
        hint = " (is another router or service listening there?)" if "already in use" in text else ""
        raise RuntimeError(f"zenoh router: cannot listen on {', '.join(settings.zenoh.listen)}: {text}{hint}") from exc
    return session, access.describe(listening=True)


def run_router(settings: Any, stop: threading.Event, out: Any = None) -> int:
    """Run a router until `stop` is set; prints one line when it listens."""
    out = out if out is not None else sys.stdout
    session, access = open_router(settings)
    try:
        print(
            f"bearing-twin router: zenoh router {session.info.zid()} listening on "
            f"{', '.join(settings.zenoh.listen)}, key prefix {settings.zenoh.prefix}; {access}",
            file=out,
            flush=True,
        )
        stop.wait()
    finally:
        session.close()
    print("bearing-twin router: stopped", file=out, flush=True)
    return 0


def _cmd_router(args: argparse.Namespace) -> int:
    from pydantic import ValidationError

    try:
        settings = RouterSettings(**flag_overrides(args))
    except ValidationError as exc:
        print(f"error: {settings_error_text(exc, RouterSettings)}", file=sys.stderr)
        return 2
    stop = threading.Event()
    for sig in (signal.SIGTERM, signal.SIGINT):
        signal.signal(sig, lambda *_: stop.set())
    try:
        return run_router(settings, stop)
    except (RuntimeError, ValueError) as exc:
        print(f"error: {' '.join(str(exc).split())}", file=sys.stderr)
        return 2


def add_router_command(subparsers: Any) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "router",
        help="a zenoh router for a fleet of services (optionally with authentication and access control)",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    add_settings_flags(p, RouterSettings, aliases={"zenoh.prefix": ("--prefix",)})
    p.set_defaults(func=_cmd_router)
    return p
