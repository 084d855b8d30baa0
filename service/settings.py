"""Service settings: built-in defaults < `BEARING_TWIN_*` environment variables < command-line flags.

Every field carries its unit in the description. List fields (`zenoh_listen`, `zenoh_connect`)
accept a JSON list (`'["tcp/127.0.0.1:7447"]'`) or a comma-separated string
(`tcp/127.0.0.1:7447,tcp/[::1]:7447`) from the environment; an empty string means no endpoint.
"""

from __future__ import annotations

import ipaddress
import json
import re
from datetime import UTC, datetime
from pathlib import Path
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, SecretStr, field_validator, model_validator
from pydantic_settings import BaseSettings, NoDecode, SettingsConfigDict


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


DEFAULT_ZENOH_LISTEN = ["tcp/127.0.0.1:7447"]
_CHUNK = r"[A-Za-z0-9_.-]+"
_PREFIX_RE = re.compile(rf"^{_CHUNK}(?:/{_CHUNK}){{0,7}}$")
_PATTERN_RE = re.compile(rf"^(?:{_CHUNK}|\*|\*\*)(?:/(?:{_CHUNK}|\*|\*\*)){{0,7}}$")
_NAME_RE = re.compile(r"^[A-Za-z0-9_.@+-]{1,128}$")


def _split_names(value):
    if value is None:
        return []
    if isinstance(value, str):
        text = value.strip()
        if text.startswith("["):
            return json.loads(text)
        return [part.strip() for part in text.split(",") if part.strip()]
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
            raise ValueError(f"{str(path)!r} line {number}: expected `user:password` "
                             "(both non-empty)")
        users.append(user.strip())
    if not users:
        raise ValueError(f"{str(path)!r} holds no `user:password` line")
    return users


def zenoh_access_enabled(usersfile: Path | None, user: str | None, tls_certificate: Path | None) -> bool:
    """zenoh authentication (and, where links are accepted, access control) is on: a users file, a
    user of one's own, or mutual TLS (a certificate)."""
    return usersfile is not None or user is not None or tls_certificate is not None


class ZenohAccessSettings(BaseSettings):
    """Who may do what on zenoh (docs/operations.md "zenoh access control"), read by the service, the router
    and the bundled clients (`monitor`, `soak`, benchmarks) from `BEARING_TWIN_ZENOH_*`.

    Access control is on when a users file, credentials or TLS client certificates are
    configured. Then every zenoh link is authenticated (zenoh's user-password handshake
    `transport.auth.usrpwd`, or mutual TLS) and the node that accepts links (a listening service,
    `bearing-twin router`) applies zenoh's `access_control` rules built from the three roles
    (service.bus.access): readers subscribe to state, ball and result keys, query snapshots and
    see liveliness tokens; writers also put setpoints; services publish, answer queries and
    declare liveliness tokens. A peer without credentials cannot open a link at all."""

    model_config = SettingsConfigDict(env_prefix="BEARING_TWIN_", extra="ignore",
                                      validate_default=True, hide_input_in_errors=True)

    zenoh_prefix: str = Field(
        default="bearing",
        description="Key prefix of the twins on zenoh [key expression chunks, e.g. plant1/line2/motor7]: "
        "a twin publishes under {prefix}/{id}/...; site / line / asset, up to 8 chunks of letters, "
        "digits, '_', '.', '-'. The router and the monitor also take patterns with '*' and '**' "
        "(e.g. plant1/**).")
    zenoh_user: str | None = Field(
        default=None,
        description="User name this process presents when it connects to a zenoh router or peer "
        "[text]; with zenoh_password (zenoh user-password authentication).")
    zenoh_password: SecretStr | None = Field(
        default=None,
        description="Password of zenoh_user [text]; give it in the environment "
        "(BEARING_TWIN_ZENOH_PASSWORD), never on a command line.")
    zenoh_usersfile: Path | None = Field(
        default=None,
        description="Users allowed to connect to this process's zenoh endpoints [path to a file of "
        "`user:password` lines, zenoh's usrpwd dictionary]; keep it readable by the service only.")
    zenoh_writers: Annotated[list[str], NoDecode] = Field(
        default_factory=list,
        description="Users (or TLS certificate common names) that may put setpoints, and read "
        "[comma-separated names].")
    zenoh_readers: Annotated[list[str], NoDecode] = Field(
        default_factory=list,
        description="Users (or certificate common names) that may only read: state, balls, "
        "setpoint results, snapshots, liveliness [comma-separated names].")
    zenoh_services: Annotated[list[str], NoDecode] = Field(
        default_factory=list,
        description="Users (or certificate common names) of twin services joining a router: they "
        "publish state, answer queries and declare liveliness tokens [comma-separated names]; "
        "the service's own zenoh_user is always one.")
    zenoh_tls_root_ca: Path | None = Field(
        default=None, description="CA certificate that signed every node's certificate [path, PEM]; "
        "with zenoh_tls_certificate and zenoh_tls_private_key: mutual TLS on tls/ endpoints.")
    zenoh_tls_certificate: Path | None = Field(
        default=None, description="This process's TLS certificate [path, PEM]; its common name is "
        "the name the roles match.")
    zenoh_tls_private_key: Path | None = Field(
        default=None, description="Private key of zenoh_tls_certificate [path, PEM].")

    @field_validator("zenoh_writers", "zenoh_readers", "zenoh_services", mode="before")
    @classmethod
    def _names(cls, value):
        names = _split_names(value)
        for name in names:
            if not isinstance(name, str) or not _NAME_RE.match(name):
                raise ValueError("role members are user names or certificate common names: 1-128 "
                                 "letters, digits, '_', '.', '@', '+', '-'")
        return list(dict.fromkeys(names))

    @field_validator("zenoh_user", mode="before")
    @classmethod
    def _user(cls, value):
        if isinstance(value, str) and not value.strip():
            return None
        if value is not None and (not isinstance(value, str) or not _NAME_RE.match(value)):
            raise ValueError("a zenoh user name is 1-128 letters, digits, '_', '.', '@', '+', '-'")
        return value

    @field_validator("zenoh_password", mode="before")
    @classmethod
    def _password(cls, value):
        if isinstance(value, SecretStr):
            value = value.get_secret_value()
        if value is None or (isinstance(value, str) and not value):
            return None
        if isinstance(value, str) and (":" in value or any(c.isspace() or not c.isprintable() for c in value)):
            raise ValueError("the zenoh password must be printable characters without spaces or ':'")
        return value

    @field_validator("zenoh_usersfile", "zenoh_tls_root_ca", "zenoh_tls_certificate",
                     "zenoh_tls_private_key", mode="before")
    @classmethod
    def _optional_path(cls, value):
        if isinstance(value, str) and value.strip().lower() in ("", "none", "off"):
            return None
        return value

    @field_validator("zenoh_prefix")
    @classmethod
    def _prefix(cls, value: str) -> str:
        value = value.strip().strip("/")
        if len(value) > 200 or not _PATTERN_RE.match(value):
            raise ValueError("a key prefix is 1-8 chunks of letters, digits, '_', '.', '-' separated "
                             "by '/' (patterns may use '*' and '**'), e.g. plant1/line2/motor7")
        return value

    @model_validator(mode="after")
    def _access(self):
        if (self.zenoh_user is None) != (self.zenoh_password is None):
            missing = "zenoh_password" if self.zenoh_password is None else "zenoh_user"
            raise ValueError(f"{missing}: zenoh credentials are a user and a password together "
                             "(BEARING_TWIN_ZENOH_USER, BEARING_TWIN_ZENOH_PASSWORD)")
        if self.zenoh_usersfile is not None:
            read_usersfile(self.zenoh_usersfile)            # ValueError naming the line
        tls = (self.zenoh_tls_root_ca, self.zenoh_tls_certificate, self.zenoh_tls_private_key)
        if any(t is not None for t in tls) and not all(t is not None for t in tls):
            raise ValueError("zenoh_tls_certificate: mutual TLS needs the CA certificate, this "
                             "process's certificate and its private key together")
        for name, path in zip(("zenoh_tls_root_ca", "zenoh_tls_certificate", "zenoh_tls_private_key"),
                              tls, strict=True):
            if path is not None and not Path(path).is_file():
                raise ValueError(f"{name}: {str(path)!r} is not a file")
        return self

    @property
    def zenoh_password_value(self) -> str | None:
        return self.zenoh_password.get_secret_value() if self.zenoh_password is not None else None

    @property
    def zenoh_tls(self) -> bool:
        """Mutual TLS configured (CA, certificate and key)."""
        return self.zenoh_tls_certificate is not None

    @property
    def zenoh_access_control(self) -> bool:
        """zenoh authentication (and, where links are accepted, access control) is on."""
        return zenoh_access_enabled(self.zenoh_usersfile, self.zenoh_user, self.zenoh_tls_certificate)

    @property
    def zenoh_prefix_is_pattern(self) -> bool:
        return "*" in self.zenoh_prefix


class RouterSettings(ZenohAccessSettings):
    """Configuration of `bearing-twin router` (env prefix `BEARING_TWIN_`)."""

    zenoh_listen: Annotated[list[str], NoDecode] = Field(
        default_factory=lambda: list(DEFAULT_ZENOH_LISTEN),
        description="zenoh endpoints the router listens on [zenoh locator, e.g. tcp/0.0.0.0:7447].")

    @field_validator("zenoh_listen", mode="before")
    @classmethod
    def _endpoints(cls, value):
        return _split_endpoints(value)

    @model_validator(mode="after")
    def _router(self):
        if not self.zenoh_listen:
            raise ValueError("zenoh_listen: a router listens on at least one endpoint")
        _check_tls_endpoints(self)
        return self


def _check_tls_endpoints(s) -> None:
    """With TLS client certificates as the only authentication, a tcp/ listen endpoint would
    accept anyone: every listen endpoint must then be tls/ (or quic/)."""
    if s.zenoh_tls and s.zenoh_usersfile is None:
        plain = [e for e in s.zenoh_listen if not e.startswith(("tls/", "quic/"))]
        if plain:
            raise ValueError(f"zenoh_listen: {plain[0]!r} would accept peers without a client "
                             "certificate; with TLS (and no users file) listen on tls/HOST:PORT only")




class AlarmSettings(BaseModel):
    """Alarm thresholds and timing (service.core.alarms; docs/service.md "Alarms"). Times are simulated
    seconds (the twin's clock). Give them in the environment as JSON:
    `BEARING_TWIN_ALARMS='{"machine_group": 1, "support": "flexible"}'`."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    machine_group: Literal[1, 2] = Field(
        default=2, description="ISO 20816-3 machine group [1 | 2]: 1 = large machines (300 kW to "
        "50 MW, Table A.1), 2 = medium machines (15 kW to 300 kW, Table A.2).")
    support: Literal["rigid", "flexible"] = Field(
        default="rigid", description="ISO 20816-3 support class [rigid | flexible] (clause 4.4).")
    clear_ratio: float = Field(
        default=0.9, gt=0.0, lt=1.0,
        description="Hysteresis of the 'above' alarms: an alarm raised at threshold T clears below "
        "clear_ratio x T (the 'below' alarms clear above T / clear_ratio) [-].")
    clear_hold_s: float = Field(
        default=1.0, ge=0.0, le=3600.0,
        description="The value must stay on the clear side of the clear threshold this long before "
        "an alarm clears or steps down [s of simulated time].")
    vibration_delay_s: float = Field(
        default=0.0, ge=0.0, le=3600.0,
        description="A vibration zone alarm rises after the velocity RMS stays in zone C or D this long [s].")
    lubrication_delay_s: float = Field(
        default=1.0, ge=0.0, le=3600.0,
        description="A lubrication alarm rises after kappa < kappa_threshold, or a loaded contact in "
        "the boundary regime, lasts this long [s of simulated time].")
    kappa_threshold: float = Field(
        default=1.0, gt=0.0, le=10.0,
        description="Viscosity ratio kappa = nu / nu1 (ISO 281:2007 clause 9.3) below which the "
        "lubrication alarm rises [-].")
    boundary_lambda: float = Field(
        default=1.0, gt=0.0, le=10.0,
        description="Film parameter at or below which a contact is in the boundary regime (seed "
        "000 Table 2: Lambda <= 1) [-].")
    loaded_contact_fraction: float = Field(
        default=0.1, ge=0.0, le=1.0,
        description="A contact counts as loaded when it carries at least this fraction of the "
        "largest contact load of the snapshot [-].")
    discharge_delay_s: float = Field(
        default=0.0, ge=0.0, le=3600.0,
        description="The electrical alarm rises after the discharge risk stays 'possible' or "
        "'likely' this long [s of simulated time].")
    defect_amplitude_m_s2: float = Field(
        default=0.5, gt=0.0, le=1e4,
        description="Envelope amplitude of a defect line (FTF, BPFO, BPFI, BSF) above which its "
        "alarm rises [m/s^2]; a line must also stand defect_significance x the envelope noise "
        "floor above it when the floor is known.")
    defect_significance: float = Field(
        default=4.0, ge=1.0, le=100.0,
        description="Times the envelope noise floor (median) a defect line must exceed [-] "
        "(twin.vibration.indicators.SIGNIFICANCE).")
    defect_delay_s: float = Field(
        default=0.0, ge=0.0, le=3600.0, description="A defect alarm rises after its line stays above "
        "the threshold this long [s of simulated time].")
    life_used_warning: float = Field(
        default=0.5, gt=0.0, le=10.0,
        description="Palmgren-Miner damage fraction above which the life alarm is a warning [-].")
    life_used_critical: float = Field(
        default=0.9, gt=0.0, le=10.0,
        description="Damage fraction above which the life alarm is critical [-].")
    history: int = Field(default=200, ge=1, le=100000,
                         description="Alarm events kept per twin for GET .../alarms [count].")

    @model_validator(mode="after")
    def _ordered(self) -> "AlarmSettings":
        if self.life_used_critical < self.life_used_warning:
            raise ValueError(f"life_used_critical = {self.life_used_critical:g} must be >= "
                             f"life_used_warning = {self.life_used_warning:g}")
        return self


class ServiceSettings(ZenohAccessSettings):
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
    housing: bool = Field(default=False,
                          description="The twin started with the service has its outer ring on the housing "
                          "support with the accelerometer (vibration indicators, waveform, defects "
                          "show in the signal) [bool]; other twins choose with POST /v1/bearings `housing`.")
    twin_id: str = Field(default="default", pattern=r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,63}$",
                         description="Name of the twin started with the service [text]; give each "
                         "service on one zenoh network its own (keys are bearing/{id}/...).")
    start_twin: bool = Field(default=True, description="Start that twin with the service [bool].")
    zenoh_listen: Annotated[list[str] | None, NoDecode] = Field(
        default=None,
        description="zenoh endpoints to listen on [zenoh locator, e.g. tcp/127.0.0.1:7447]; default "
        "tcp/127.0.0.1:7447, or none when zenoh_connect is given (the service joins a router).")
    zenoh_connect: Annotated[list[str], NoDecode] = Field(
        default_factory=list,
        description="zenoh endpoints (routers or peers) to connect to [zenoh locator].")
    zenoh_mode: Literal["peer", "client", "router"] | None = Field(
        default=None, description="zenoh session mode [peer | client | router]; default client when "
        "the service only connects (joins a router: every message goes through it), else peer.")
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
    frame_s: float = Field(
        default=0.005, ge=1e-5, le=0.1,
        description="Simulated time per frame: setpoints and scenario steps apply between frames [s]. "
        "A stepping thread runs one frame of one twin at a time; 5 ms keeps the Python between frames "
        "a small share of the work (docs/service.md \"Runner pool\").")
    setpoint_frame_s: float = Field(
        default=0.001, ge=1e-5, le=0.1,
        description="Real-time mode: the frame that applies an outside setpoint (HTTP, zenoh) lasts this "
        "long when shorter than frame_s, and a twin waiting for its next frame starts it at once, so "
        "the state carrying the setpoint is published sooner [s].")
    frame_lead_s: float = Field(
        default=0.005, ge=0.0, le=0.1,
        description="Real-time mode: a frame is released this long before the wall clock reaches its start, so "
        "the twin runs up to this much ahead of the wall clock and a wait for the GIL or the CPU between frames "
        "is absorbed instead of making a late frame [s] (service.core.pacing). 0: frames start on the wall clock.")
    lateness_s: float = Field(
        default=0.005, ge=0.0, le=1.0,
        description="A frame is late (counted in /health `overruns` and `late_fraction`) when it ends "
        "more than this after its wall-clock deadline [s].")
    stepping_threads: int | None = Field(
        default=None, ge=1, le=64,
        description="Threads that advance the twins, earliest deadline first [count]; unset = one per "
        "core this process may use.")
    io_thread_nice: int = Field(
        default=-5, ge=-20, le=19,
        description="Nice value given to every thread of the service but the stepping threads and the publish "
        "worker, the HTTP event loop included (Linux, per thread; service.core.priority) [-]. Between the stepping "
        "threads' (-10) and the host's other processes' (0): these threads hold the GIL the stepping threads wait "
        "for, and below the load they are preempted while holding it (priority inversion; `attack` measures the "
        "real-time factor under a flood). Below the process's nice needs root or "
        "CAP_SYS_NICE (refused: counted in /health thread_priority errors). 0: the process's nice.")
    gc_freeze: bool = Field(
        default=True,
        description="Freeze the start-up heap out of Python's cyclic garbage collector once the service is open "
        "(gc.freeze; service.core.heap.freeze_heap): full collections then walk only what was made since, "
        "instead of stalling every thread for ~70 ms every ~10 s [bool].")
    stepping_thread_nice: int = Field(
        default=-10, ge=-20, le=0,
        description="Nice value asked for the stepping threads and the publish worker (Linux, per thread; "
        "service.core.priority) [-]: real time before every other process of the host. A priority above the "
        "process's own needs root or CAP_SYS_NICE; without it they keep the process's nice (/health "
        "thread_priority says which). 0: not raised.")
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
    capacity_reserve_cores: float = Field(
        default=0.5, ge=0.0, le=64.0,
        description="Cores' worth of CPU kept from the twins' capacity for the service's own zenoh, rerun, HTTP and "
        "publishing threads and the machine (never below one twin's share) [cores]. 0.5: on the 2-core VM two default "
        "6208 twins admitted under 2 x 0.85 ran at 0.93-0.97 of real time with 93-96 % of frames late.")
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
    # ---- hardening (docs/operations.md) -------------------------------------------------------
    token: SecretStr | None = Field(
        default=None,
        description="Bearer token [text]: when set, every mutating HTTP request (POST, PUT, DELETE) "
        "needs `Authorization: Bearer <token>`; unset "
        "(default) = no authentication. It never travels on zenoh: zenoh has its own access "
        "control (zenoh_usersfile ...), and without it a service with a token refuses zenoh "
        "setpoints. Give it in the environment (BEARING_TWIN_TOKEN), not on a "
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
    read_rate_hz: float = Field(
        default=100.0, ge=0.0, le=1e6,
        description="Sustained rate of API reads (GET/HEAD under /v1/) per client address [1/s]; 0 = no "
        "limit. Beyond it: 429 with Retry-After naming the limit. /health and the docs are not counted.")
    read_burst: int = Field(
        default=200, ge=1, le=1_000_000,
        description="Reads a client may make in a burst before read_rate_hz applies [count].")
    http_header_timeout_s: float = Field(
        default=10.0, gt=0.0, le=600.0,
        description="A request's line and headers must be complete this long after the connection "
        "opened (or the next request's first byte arrived); else 408 and the connection is closed "
        "(slow clients) [s].")
    http_body_timeout_s: float = Field(
        default=30.0, gt=0.0, le=3600.0,
        description="A request body must be complete this long after its headers; else 408 and the "
        "connection is closed [s].")
    http_keep_alive_s: int = Field(
        default=5, ge=1, le=3600,
        description="An idle kept-alive HTTP connection is closed after this long (uvicorn "
        "timeout_keep_alive) [s].")
    http_max_connections: int = Field(
        default=256, ge=8, le=100_000,
        description="Open HTTP connections (or running requests) beyond which a new request gets 503 "
        "(uvicorn limit_concurrency) [count].")
    client_error_rate_hz: float = Field(
        default=5.0, ge=0.0, le=1e6,
        description="Sustained rate of refused HTTP requests (any 4xx answer: wrong or missing token, over a rate "
        "limit, invalid, unknown) a client address may cause before its refusals are held in the tarpit "
        "(tarpit_delay_s) [1/s]; 0 = no tarpit. /health is never counted nor held.")
    client_error_burst: int = Field(
        default=20, ge=1, le=1_000_000,
        description="Refused requests a client may cause in a burst before client_error_rate_hz applies [count].")
    tarpit_delay_s: float = Field(
        default=2.0, ge=0.0, le=60.0,
        description="A client over its error budget (client_error_rate_hz) gets each refusal this long after it "
        "was decided, with Retry-After; the wait is an asyncio timer (no thread, no CPU), so a client that waits "
        "for its answers before sending more (a closed-loop flood) slows itself down [s]; 0 = no tarpit.")
    tarpit_max_held: int = Field(
        default=64, ge=1, le=100_000,
        description="Refusals held in the tarpit at one time, at most [count]; beyond it a refusal is answered at "
        "once (counted in /health http_tarpit). Below http_max_connections: the held connections count "
        "against it.")
    scenario_dir: Path | None = Field(
        default=None,
        description="Directory of named scenarios [path]; default ./scenarios if it exists, else "
        "the scenarios/ folder of the source tree.")

    # ---- alarms and the OPC UA facade (docs/service.md "Alarms", "OPC UA") -------------------------------
    alarms: AlarmSettings = Field(default_factory=AlarmSettings,
                                  description="Alarm thresholds and timing [see AlarmSettings].")
    opcua: str | None = Field(
        default=None, pattern=r"^opc\.tcp://[^/\s]+:\d{1,5}(/\S*)?$",
        description="OPC UA endpoint to serve the twins on [opc.tcp://HOST:PORT[/path]], e.g. "
        "opc.tcp://127.0.0.1:4840; unset (default) = no OPC UA server.")
    opcua_security: Literal["auto", "none", "sign", "sign_and_encrypt", "both", "all"] = Field(
        default="auto",
        description="OPC UA message security the endpoint offers [choice]: `sign` / "
        "`sign_and_encrypt` = the Basic256Sha256, Aes128_Sha256_RsaOaep and Aes256_Sha256_RsaPss "
        "policies in that mode; `both` = both modes; `all` = both modes plus the None policy for "
        "anonymous read-only sessions (a user name is refused there); `none` = only the None policy "
        "(no certificate; with a token the password then crosses the network in clear). `auto` "
        "(default) = `both` when a token is set, else `none`.")
    opcua_certificate: Path | None = Field(
        default=None,
        description="The OPC UA server's certificate [path, DER or PEM], with opcua_private_key; its "
        "subjectAltName must hold the URI urn:bearing-twin:server (OPC UA Part 6). Unset (default) = "
        "a self-signed one made once in opcua_pki_dir and reused.")
    opcua_private_key: Path | None = Field(
        default=None,
        description="Private key of opcua_certificate [path, PEM or DER, unencrypted RSA].")
    opcua_pki_dir: Path = Field(
        default=Path("opcua-pki"),
        description="Folder of the generated self-signed OPC UA server certificate "
        "(server-cert.der) and key (server-key.pem, mode 0600, never overwritten) [path]; made when "
        "a secure policy is on and opcua_certificate is unset. Default ./opcua-pki.")
    opcua_trusted_dir: Path | None = Field(
        default=None,
        description="Folder of trusted OPC UA client certificates (or CA certificates that signed "
        "them) [path to a folder of .der / .pem files]: when set, only those clients may open a "
        "session. Unset (default) = any client certificate (the token still guards writes).")

    @field_validator("zenoh_listen", "zenoh_connect", mode="before")
    @classmethod
    def _endpoints(cls, value):
        if value is None:
            return None
        return _split_endpoints(value)

    @model_validator(mode="after")
    def _zenoh(self):
        """Resolve the listen default and the mode; refuse what zenoh's access control cannot
        guard (docs/operations.md "zenoh access control")."""
        if self.zenoh_listen is None:
            self.zenoh_listen = [] if self.zenoh_connect else list(DEFAULT_ZENOH_LISTEN)
        if self.zenoh_mode is None:
            self.zenoh_mode = "client" if self.zenoh_connect and not self.zenoh_listen else "peer"
        if self.zenoh_prefix_is_pattern:
            raise ValueError("zenoh_prefix: a service publishes under a concrete prefix: no '*' "
                             "or '**' (those are for the router and the monitor)")
        if not self.enable_zenoh or not self.zenoh_access_control:
            return self
        if self.zenoh_listen and self.zenoh_connect:
            raise ValueError(
                "zenoh_connect: with zenoh access control a service either listens (its own access "
                "rules guard who connects) or joins a router (the router's rules guard everyone), "
                "not both: zenoh authenticates only the side that connects, so the links this "
                "service opens would match none of its own rules")
        if self.zenoh_listen and self.zenoh_usersfile is None and not self.zenoh_tls:
            raise ValueError(
                "zenoh_usersfile: a service that listens with zenoh access control needs the users "
                "allowed to connect (BEARING_TWIN_ZENOH_USERSFILE) or TLS client certificates; "
                "to join a router instead give --zenoh-connect")
        if self.zenoh_connect and self.zenoh_user is None and not self.zenoh_tls:
            raise ValueError(
                "zenoh_user: joining a router with access control needs this service's credentials "
                "(BEARING_TWIN_ZENOH_USER and BEARING_TWIN_ZENOH_PASSWORD) or a TLS certificate")
        _check_tls_endpoints(self)
        return self

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

    @field_validator("opcua_certificate", "opcua_private_key", "opcua_trusted_dir", mode="before")
    @classmethod
    def _opcua_optional_path(cls, value):
        if isinstance(value, str) and value.strip().lower() in ("", "none", "off"):
            return None
        return value

    @property
    def opcua_security_mode(self) -> str:
        """The OPC UA security actually offered: `auto` resolved (both with a token, else none)."""
        if self.opcua_security != "auto":
            return self.opcua_security
        return "both" if self.token is not None else "none"

    @model_validator(mode="after")
    def _tarpit(self):
        if self.tarpit_max_held >= self.http_max_connections:
            raise ValueError(f"tarpit_max_held: {self.tarpit_max_held} held refusals would take every one of the "
                             f"http_max_connections ({self.http_max_connections}); allowed [1, "
                             f"{self.http_max_connections - 1}]")
        return self

    @model_validator(mode="after")
    def _opcua_security(self):
        """The OPC UA certificate and trust settings (docs/service.md "OPC UA")."""
        if (self.opcua_certificate is None) != (self.opcua_private_key is None):
            missing = "opcua_private_key" if self.opcua_private_key is None else "opcua_certificate"
            raise ValueError(f"{missing}: the OPC UA server certificate and its private key go together "
                             "(or give neither: a self-signed one is made in opcua_pki_dir)")
        for name in ("opcua_certificate", "opcua_private_key"):
            path = getattr(self, name)
            if path is not None and not Path(path).is_file():
                raise ValueError(f"{name}: {str(path)!r} is not a file")
        if self.opcua_trusted_dir is not None:
            if not Path(self.opcua_trusted_dir).is_dir():
                raise ValueError(f"opcua_trusted_dir: {str(self.opcua_trusted_dir)!r} is not a folder")
            if self.opcua_security_mode in ("none", "all"):
                raise ValueError(
                    "opcua_trusted_dir: trusting clients by certificate needs every session on a "
                    "secure channel: opcua_security sign, sign_and_encrypt or both (it is "
                    f"{self.opcua_security!r}" + (", and `auto` without a token is none" if
                                                  self.opcua_security == "auto" else "") + ")")
        return self

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
