"""Value rules shared by the settings groups: hosts, default paths, list parsing, zenoh users files."""

from __future__ import annotations

import ipaddress
import json
import re
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

NAME_RE = re.compile(r"^[A-Za-z0-9_.@+-]{1,128}$")
OFF_WORDS = ("", "none", "off")


def is_loopback_host(host: str | None) -> bool:
    """Whether `host` (an IP address, bracketed or not, or a host name) is this machine's
    loopback: 127.0.0.0/8, ::1 or `localhost`."""
    if not host:
        return False
    host = host.strip("[]")
    if host.lower() == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def default_recording_path() -> Path:
    """`recordings/bearing-twin-<UTC timestamp>.rrd` (relative to the working directory)."""
    stamp = datetime.now(UTC).strftime("%Y%m%dT%H%M%SZ")
    return Path("recordings") / f"bearing-twin-{stamp}.rrd"


def default_scenario_dir() -> Path:
    """./scenarios if it exists, else the scenarios/ folder next to the installed packages."""
    here = Path("scenarios")
    if here.is_dir():
        return here
    return Path(__file__).resolve().parent.parent.parent / "scenarios"


def split_list(value: Any) -> Any:
    """A list setting from the environment: a JSON list (`'["a", "b"]'`) or comma-separated text
    (`a,b`); an empty text or None is the empty list; anything else passes unchanged."""
    if value is None:
        return []
    if isinstance(value, str):
        text = value.strip()
        if not text:
            return []
        if text.startswith("["):
            return json.loads(text)
        return [part.strip() for part in text.split(",") if part.strip()]
    return value


def optional_path(value: Any) -> Any:
    """An optional path setting: '', 'none' or 'off' (any case) mean unset."""
    if isinstance(value, str) and value.strip().lower() in OFF_WORDS:
        return None
    return value


def read_usersfile(path: Path) -> list[str]:
    """The user names of a zenoh users file (`user:password`, one a line, blank lines skipped;
    zenoh's `transport.auth.usrpwd.dictionary_file` format). ValueError naming the line, never
    the password, when it is not one."""
    try:
        text = Path(path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"cannot read {str(path)!r}: {type(exc).__name__}") from None
    users = []
    for number, line in enumerate(text.splitlines(), 1):
        line = line.strip()
        if not line:
            continue
        user, sep, password = line.partition(":")
        if not sep or not user.strip() or not password.strip():
            raise ValueError(f"{str(path)!r} line {number}: expected `user:password` (both non-empty)")
        users.append(user.strip())
    if not users:
        raise ValueError(f"{str(path)!r} holds no `user:password` line")
    return users


def zenoh_access_enabled(usersfile: Path | None, user: str | None, tls_certificate: Path | None) -> bool:
    """zenoh authentication (and, where links are accepted, access control) is on: a users file, a
    user of one's own, or mutual TLS (a certificate)."""
    return usersfile is not None or user is not None or tls_certificate is not None
