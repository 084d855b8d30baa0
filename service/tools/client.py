"""What the client tools that drive a service (`soak`, `attack`) share: the service they drive
(`TargetConfig`: its URL, zenoh endpoint, token, twin, or an own one with `start`; their
command-line flags), the loopback check, and the strict reading of its JSON (also `monitor`'s).
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from typing import Any
from urllib.parse import urlparse

from service.settings import is_loopback_host

DEFAULT_URL = "http://127.0.0.1:8000"


@dataclass(kw_only=True)
class TargetConfig:
    """The service a client tool drives (keyword fields; each tool adds its own)."""

    url: str = DEFAULT_URL  # ignored with start
    zenoh_connect: str | None = None  # zenoh endpoint of the service, or None: no zenoh
    token: str | None = None  # the service's bearer token (with start: generated when None)
    start: bool = False  # launch an own `bearing-twin serve` on free loopback ports
    bearing_id: str = "default"  # the twin driven
    seed: int | None = None  # random seed
    record: bool = True  # with start: the service records
    log: Any = field(default=None, repr=False)  # callable(str) for progress lines, or None


def zenoh_endpoint_host(endpoint: str) -> str:
    """The host of a zenoh locator: `tcp/127.0.0.1:7447` -> `127.0.0.1`, `tcp/[::1]:7447` -> `::1`."""
    return endpoint.split("/", 1)[-1].rsplit(":", 1)[0].strip("[]")


def url_is_loopback(url: str) -> bool:
    return is_loopback_host(urlparse(url).hostname)


def check_loopback(url: str, zenoh_connect: str | None) -> None:
    """ValueError unless the URL and the zenoh endpoint are on this machine's loopback."""
    if not url_is_loopback(url):
        raise ValueError(f"url = {url!r}: the attack runs against loopback only (127.0.0.1, ::1, localhost)")
    if zenoh_connect and not is_loopback_host(zenoh_endpoint_host(zenoh_connect)):
        raise ValueError(f"zenoh_connect = {zenoh_connect!r}: loopback endpoints only")


def strict_json(text: bytes | str):
    """json.loads refusing the NaN / Infinity literals (ValueError "non-finite NaN")."""

    def reject(name):
        raise ValueError(f"non-finite {name}")

    return json.loads(text, parse_constant=reject)


def add_target_arguments(p, *, url_help: str, zenoh_help: str, start_help: str, twin_help: str) -> None:
    """--url, --zenoh-connect, --token, --start, --twin-id (read back by `target_arguments`)."""
    p.add_argument("--url", default=DEFAULT_URL, help=url_help)
    p.add_argument("--zenoh-connect", metavar="ENDPOINT", help=zenoh_help)
    p.add_argument(
        "--token",
        help="the service's bearer token (default: $BEARING_TWIN_TOKEN; with --start a random one is generated)",
    )
    p.add_argument("--start", action="store_true", help=start_help)
    p.add_argument("--twin-id", default="default", help=twin_help)


def target_arguments(args) -> dict:
    """The `TargetConfig` fields of parsed flags (`add_target_arguments`, --seed)."""
    return {
        "url": args.url,
        "zenoh_connect": args.zenoh_connect,
        "token": args.token or os.environ.get("BEARING_TWIN_TOKEN") or None,
        "start": args.start,
        "bearing_id": args.twin_id,
        "seed": args.seed,
    }
