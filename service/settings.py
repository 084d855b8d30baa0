"""Service settings: built-in defaults < `BEARING_TWIN_*` environment variables < command-line flags.

Every field carries its unit in the description. List fields (`zenoh_listen`, `zenoh_connect`)
accept a JSON list (`'["tcp/127.0.0.1:7447"]'`) or a comma-separated string
(`tcp/127.0.0.1:7447,tcp/[::1]:7447`) from the environment; an empty string means no endpoint.
"""

from __future__ import annotations

import json
from datetime import UTC, datetime
from pathlib import Path
from typing import Annotated, Literal

from pydantic import Field, SecretStr, field_validator
from pydantic_settings import BaseSettings, NoDecode, SettingsConfigDict


def default_recording_path() -> Path:
    """`recordings/bearing-twin-<UTC timestamp>.rrd` (relative to the working directory)."""
    stamp = datetime.now(UTC).strftime("%Y%m%dT%H%M%SZ")
    return Path("recordings") / f"bearing-twin-{stamp}.rrd"


def default_scenario_dir() -> Path:
    """./scenarios if it exists, else the scenarios/ folder next to the installed packages."""
    here = Path("scenarios")
    if here.is_dir():
        return here
    return Path(__file__).resolve().parent.parent / "scenarios"


def _split_endpoints(value):
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


class ServiceSettings(BaseSettings):
    """Configuration of `bearing-twin serve` (env prefix `BEARING_TWIN_`)."""

    model_config = SettingsConfigDict(env_prefix="BEARING_TWIN_", extra="ignore",
                                      validate_default=True, hide_input_in_errors=True)

    host: str = Field(default="127.0.0.1",
                      description="HTTP bind address [IP or host name]; loopback only unless set "
                      "(0.0.0.0 exposes the API on every interface).")
    port: int = Field(default=8000, ge=0, le=65535,
                      description="HTTP port [TCP port number, 0 = any free port].")
    bearing: str = Field(default="6208",
                         description="Catalog designation of the twin started with the service [designation, e.g. 6208].")
    twin_id: str = Field(default="default", pattern=r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,63}$",
                         description="Name of the twin started with the service [text]; give each "
                         "service on one zenoh network its own (keys are bearing/{id}/...).")
    start_twin: bool = Field(default=True, description="Start that twin with the service [bool].")
    zenoh_listen: Annotated[list[str], NoDecode] = Field(
        default_factory=lambda: ["tcp/127.0.0.1:7447"],
        description="zenoh endpoints to listen on [zenoh locator, e.g. tcp/127.0.0.1:7447].")
    zenoh_connect: Annotated[list[str], NoDecode] = Field(
        default_factory=list,
        description="zenoh endpoints (routers or peers) to connect to [zenoh locator].")
    zenoh_mode: Literal["peer", "client", "router"] = Field(
        default="peer", description="zenoh session mode [peer | client | router].")
    record: Path | None = Field(
        default_factory=default_recording_path,
        description="rerun recording written while the service runs [path to a .rrd file]; "
        "default recordings/bearing-twin-<UTC timestamp>.rrd. A file of that name is never "
        "overwritten: this run then records beside it as <stem>.run2.rrd, <stem>.run3.rrd, ...")
    record_segment_s: float = Field(
        default=600.0, ge=0.0, le=7 * 24 * 3600.0,
        description="Rotate the service-wide recording: once its open segment is this old, close it "
        "(complete, readable) and continue in the next, <name>-0001.rrd, <name>-0002.rrd, ... (same "
        "recording id: open them together in the viewer) [s of wall time]; 0 = no rotation by age.")
    record_segment_mb: float = Field(
        default=1000.0, ge=0.0, le=1e6,
        description="Also rotate once the open segment holds this much on disk [MB = 10^6 bytes]; "
        "0 = no rotation by size.")
    record_footer: bool = Field(
        default=False,
        description="End each recording segment with rerun's RRD footer (chunk manifest) [bool]. "
        "On: rerun's own file sink writes the segment and holds the manifest in memory (about 2 kB "
        "per chunk, about 25 chunks/s per twin) until the segment closes, and a write error shows only "
        "as a failed flush. Off (default): the service writes the file itself (flat memory, exact "
        "write-error handling); the viewer and RrdReader.stream() read it, `rerun rrd optimize` adds "
        "the footer afterwards.")
    record_flush_interval_s: float = Field(
        default=1.0, gt=0.0, le=60.0,
        description="The recorder sends and writes what it buffered every this often: one rerun chunk "
        "per entity with all rows of the interval [s]. Each chunk costs about 1.5 kB besides its rows, "
        "so shorter intervals make larger files with more chunks (0.1 s: about 10x the chunks) and a "
        "live viewer lags by up to this much.")
    record_keep_mb: float = Field(
        default=2000.0, ge=0.0, le=1e9,
        description="Retention: keep the newest segments of the service-wide recordings (this run's and "
        "earlier runs' in the same folder, same name family) up to this total size and delete older "
        "ones [MB = 10^6 bytes]; 0 = no size limit. The open segment and per-twin recordings are "
        "never deleted; nothing else deletes recordings.")
    record_keep_hours: float = Field(
        default=0.0, ge=0.0, le=1e6,
        description="Retention: also delete segments of the service-wide recordings older than this "
        "[h of wall time, by modification time]; 0 = no age limit.")
    spawn_viewer: bool = Field(default=False,
                               description="Also stream to a rerun viewer spawned on this machine [bool].")
    fast: bool = Field(default=False,
                       description="Run the twins as fast as possible instead of paced to the wall clock [bool].")
    publish_rate_hz: float = Field(
        default=50.0, gt=0.0, le=1000.0,
        description="Snapshot publishing rate [Hz] (of wall time in real-time mode, of simulated "
        "time in fast mode).")
    frame_s: float = Field(default=0.001, ge=1e-5, le=0.1,
                           description="Simulated time per frame: setpoints apply between frames [s].")
    enable_zenoh: bool = Field(default=True, description="Start the zenoh bus [bool].")
    enable_recording: bool = Field(default=True, description="Write the rerun recording [bool].")
    gil_switch_interval_s: float = Field(
        default=0.0005, ge=1e-5, le=0.1,
        description="Python thread switch interval set when the service starts [s] (sys.setswitchinterval; "
        "Python's 5 ms default makes a runner thread wait up to 5 ms for the GIL after each 1 ms "
        "frame while the zenoh/rerun/HTTP threads run; 0.5 ms keeps the real-time factor at 1).")
    max_twins: int = Field(default=8, ge=1, le=256,
                           description="Most twins one service runs at a time [count].")
    # ---- hardening (README "Hardening") -------------------------------------------------------
    token: SecretStr | None = Field(
        default=None,
        description="Bearer token [text]: when set, every mutating HTTP request (POST, PUT, DELETE) "
        "needs `Authorization: Bearer <token>` and every zenoh setpoint a \"token\" field; unset "
        "(default) = no authentication. Give it in the environment (BEARING_TWIN_TOKEN), not on a "
        "command line other users can read.")
    read_requires_token: bool = Field(
        default=False,
        description="Also require the token for reads (GET), except GET /health [bool].")
    setpoint_rate_hz: float = Field(
        default=50.0, ge=0.0, le=1e6,
        description="Sustained setpoint rate per twin, HTTP and zenoh together [1/s]; 0 = no limit. "
        "Beyond it: HTTP 429 with Retry-After, zenoh refusal on the result key.")
    setpoint_burst: int = Field(
        default=100, ge=1, le=1_000_000,
        description="Setpoints a twin accepts in a burst before the rate applies [count].")
    max_body_bytes: int = Field(
        default=64 * 1024, ge=256, le=64 * 1024 * 1024,
        description="Largest HTTP request body (and zenoh setpoint payload) accepted [bytes]; "
        "larger: 413.")
    scenario_dir: Path | None = Field(
        default=None,
        description="Directory of named scenarios [path]; default ./scenarios if it exists, else "
        "the scenarios/ folder of the source tree.")

    @field_validator("zenoh_listen", "zenoh_connect", mode="before")
    @classmethod
    def _endpoints(cls, value):
        return _split_endpoints(value)

    @field_validator("token", mode="before")
    @classmethod
    def _token(cls, value):
        if isinstance(value, SecretStr):
            value = value.get_secret_value()
        if value is None:
            return None
        if isinstance(value, str):
            if not value.strip():
                return None   # BEARING_TWIN_TOKEN="" means no token
            if any(c.isspace() or not c.isprintable() for c in value):
                raise ValueError("the token must be printable characters without spaces")
        return value

    @property
    def token_value(self) -> str | None:
        """The token in clear (None when authentication is off)."""
        return self.token.get_secret_value() if self.token is not None else None

    @field_validator("record", mode="before")
    @classmethod
    def _record(cls, value):
        if isinstance(value, str) and value.strip().lower() in ("", "none", "off"):
            return None
        return value

    @property
    def scenarios_path(self) -> Path:
        """The directory named scenarios are looked up in."""
        if self.scenario_dir is not None:
            return self.scenario_dir
        return default_scenario_dir()

    @property
    def recording_path(self) -> Path | None:
        """Where the service records, or None when recording is off."""
        return self.record if self.enable_recording and self.record is not None else None
