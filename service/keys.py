"""The service's names on the wire, defined once: the twin-id rule, the zenoh key prefix rule and
its default, and every zenoh key a twin publishes, subscribes or answers.

A twin with id `ID` under the prefix `P` (1-8 chunks, e.g. plant1/line2/motor7) lives at `P/ID`:

    P/ID/state             snapshot stream (JSON)          P/ID/setpoint          setpoints in
    P/ID/setpoint/result   answer to each setpoint         P/ID/defects           defects in
    P/ID/defects/result    answer to each defect set       P/ID/snapshot          queryable: latest state
    P/ID/owner             queryable: the owning process   P/ID/alive             liveliness token
    P/ID/alarm             alarm events                    P/ID/ball/N            per-ball stream
    P/ID/temperature       measured temperatures in        P/ID/temperature/result  answer to each
    P/ID/vibration/measured  measured windows in           P/ID/vibration/comparison  answer to each
    P/ID/vibration         vibration block and spectra     P/ID/vibration/waveform  accelerometer samples

An id and every prefix chunk take letters, digits, '_', '.', '-' (an id starts with a letter or a
digit): one key-expression chunk, with none of zenoh's special characters ('/', '*', '$', '?',
'#') and safe in a URL path and a file name. Nothing here imports zenoh.
"""

from __future__ import annotations

import re

from twin.spec import TWIN_ID_PATTERN

__all__ = [
    "DEFAULT_PREFIX",
    "PREFIX_PATTERN",
    "PREFIX_PATTERN_WILDCARD",
    "PREFIX_RE",
    "PREFIX_WILDCARD_RE",
    "TWIN_ID_PATTERN",
    "TWIN_ID_RE",
    "all_twins",
    "ball_key",
    "check_prefix",
    "check_twin_id",
    "twin_key",
]

DEFAULT_PREFIX = "bearing"

# a twin id (also a scenario and run name, which name the twins of an offline run): twin.spec.TwinId
TWIN_ID_RE = re.compile(TWIN_ID_PATTERN)

PREFIX_CHUNK = r"[A-Za-z0-9_.-]+"
PREFIX_MAX_CHUNKS = 8
PREFIX_PATTERN = rf"^{PREFIX_CHUNK}(?:/{PREFIX_CHUNK}){{0,{PREFIX_MAX_CHUNKS - 1}}}$"
"""A concrete key prefix: 1-8 chunks separated by '/', no wildcards."""
PREFIX_RE = re.compile(PREFIX_PATTERN)
PREFIX_PATTERN_WILDCARD = (
    rf"^(?:{PREFIX_CHUNK}|\*|\*\*)(?:/(?:{PREFIX_CHUNK}|\*|\*\*))"
    rf"{{0,{PREFIX_MAX_CHUNKS - 1}}}$"
)
"""A prefix pattern of the router and the monitor: chunks, '*' or '**' (e.g. plant1/**)."""
PREFIX_WILDCARD_RE = re.compile(PREFIX_PATTERN_WILDCARD)

STATE = "state"
BALL = "ball"
SETPOINT = "setpoint"
SETPOINT_RESULT = "setpoint/result"
DEFECTS = "defects"
DEFECTS_RESULT = "defects/result"
SNAPSHOT = "snapshot"
OWNER = "owner"
ALIVE = "alive"
ALARM = "alarm"
VIBRATION = "vibration"
VIBRATION_WAVEFORM = "vibration/waveform"
VIBRATION_MEASURED = "vibration/measured"
VIBRATION_COMPARISON = "vibration/comparison"
TEMPERATURE = "temperature"
TEMPERATURE_RESULT = "temperature/result"


def check_prefix(prefix: str) -> str:
    """A concrete key prefix (1-8 chunks, no wildcards), else ValueError."""
    if not isinstance(prefix, str) or not PREFIX_RE.match(prefix):
        raise ValueError(
            f"key prefix {prefix!r}: 1-{PREFIX_MAX_CHUNKS} chunks of letters, digits, '_', '.', '-' "
            "separated by '/', no wildcards (e.g. plant1/line2/motor7)"
        )
    return prefix


def check_twin_id(twin_id: str) -> str:
    """A valid twin id, else ValueError."""
    if not isinstance(twin_id, str) or not TWIN_ID_RE.match(twin_id):
        raise ValueError(f"twin id {twin_id!r}: 1-64 letters, digits, '_', '.', '-', starting with a letter or a digit")
    return twin_id


def twin_key(prefix: str, twin_id: str, suffix: str | None = None) -> str:
    """`prefix/twin_id`, or `prefix/twin_id/suffix`: a twin's own key or one of its keys."""
    return f"{prefix}/{twin_id}" if suffix is None else f"{prefix}/{twin_id}/{suffix}"


def ball_key(prefix: str, twin_id: str, index: int) -> str:
    """The per-ball stream `prefix/twin_id/ball/index`."""
    return f"{prefix}/{twin_id}/{BALL}/{index}"


def all_twins(prefix: str, suffix: str) -> str:
    """`prefix/*/suffix`: that key of every twin under `prefix` (a prefix pattern may hold '*' or
    '**'; zenoh's canonical form of the result is `service.bus.access.all_twins_canonical`'s job)."""
    return f"{prefix}/*/{suffix}"
