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
        "default recordings/bearing-twin-<UTC timestamp>.rrd.")
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
        "rerun-sdk 0.41 holds the manifest of an open file in memory (about 1 kB per chunk, nearly "
        "as much as the segment's size on disk: ~1 MB/s for one twin at 50 snapshots/s) until it "
        "closes: on = memory grows with each segment (bound it with small segments); off (default) "
        "= flat memory, the files still load in the viewer and with RrdReader.stream(); "
        "`rerun rrd optimize` adds the footer afterwards.")
    record_flush_interval_s: float = Field(
        default=0.1, gt=0.0, le=60.0,
        description="The recorder sends what it buffered every this often, one rerun chunk per "
        "entity [s]; each chunk costs about 1.3 kB on disk besides its rows (and, with the footer, "
        "about 1 kB of memory until its segment closes), so 1 s makes the file about 5x smaller than "
        "0.1 s at 50 snapshots/s (about 0.3 instead of 1.7 MB/s for a 6208 twin), at the cost of a "
        "1 s lag in a live viewer.")
    spawn_viewer: bool = Field(default=False,
                               description="Also stream to a rerun viewer spawned on this machine [bool].")
    fast: bool = Field(default=False,
                       description="Run the twins as fast as possible instead of paced to the wall clock [bool].")
    publish_rate_hz: float = Field(
        default=50.0, gt=0.0, le=1000.0,
        description="Snapshot publishing rate [Hz] (of wall time in real-time mode, of simulated "
        "time in fast mode).")
    frame_s: float = Field(
        default=0.005, ge=1e-5, le=0.1,
        description="Simulated time per frame: setpoints and scenario steps apply between frames [s]. "
        "A stepping thread runs one frame of one twin at a time; 5 ms keeps the Python between frames "
        "a small share of the work (README \"Runner pool\").")
    setpoint_frame_s: float = Field(
        default=0.001, ge=1e-5, le=0.1,
        description="Real-time mode: the frame that applies an outside setpoint (HTTP, zenoh) lasts this "
        "long when shorter than frame_s, and a twin waiting for its next frame starts it at once, so "
        "the state carrying the setpoint is published sooner [s].")
    lateness_s: float = Field(
        default=0.005, ge=0.0, le=1.0,
        description="A frame is late (counted in /health `overruns` and `late_fraction`) when it ends "
        "more than this after its wall-clock deadline [s].")
    stepping_threads: int | None = Field(
        default=None, ge=1, le=64,
        description="Threads that advance the twins, earliest deadline first [count]; unset = one per "
        "core this process may use.")
    admission: Literal["measured", "off"] = Field(
        default="measured",
        description="'measured': a twin created over the API that this host cannot run in real time "
        "(its calibrated CPU need beside the running twins' measured need exceeds the capacity) is "
        "refused with 503, the reason and the figures; 'off': no capacity check (fast mode never "
        "checks) [text].")
    capacity_core_fraction: float = Field(
        default=0.85, gt=0.0, le=1.0,
        description="Share of each core the twins may use in real time; the rest is left to the "
        "zenoh, rerun and HTTP threads [-]. One twin may use at most this much of one core.")
    calibration_s: float = Field(
        default=0.02, ge=0.001, le=1.0,
        description="Simulated time a new twin runs at creation to measure its CPU need [s].")
    enable_zenoh: bool = Field(default=True, description="Start the zenoh bus [bool].")
    enable_recording: bool = Field(default=True, description="Write the rerun recording [bool].")
    gil_switch_interval_s: float = Field(
        default=0.0005, ge=1e-5, le=0.1,
        description="Python thread switch interval set when the service starts [s] (sys.setswitchinterval; "
        "Python's 5 ms default makes a stepping thread wait up to 5 ms for the GIL after each frame "
        "while the publish worker and the zenoh/rerun/HTTP threads run; 0.5 ms keeps that wait a small "
        "share of a frame).")
    max_twins: int | None = Field(
        default=None, ge=1, le=256,
        description="Most twins one service runs at a time [count]; unset = as many as the measured "
        "capacity admits (admission 'measured'), at most 256.")
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
    def twin_limit(self) -> int:
        """The fixed cap on the number of twins (max_twins, or 256 when unset)."""
        return self.max_twins if self.max_twins is not None else 256

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
