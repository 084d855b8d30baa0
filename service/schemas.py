"""HTTP request/response models and the ONE validation path for setpoints (HTTP and zenoh).

Every field's description carries its unit in brackets ("[rad/s]", "[-]" for counts and
dimensionless numbers, "[text]" for names). The state snapshot itself is `twin.snapshot.Snapshot`.
"""

from __future__ import annotations

import json
import math
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from twin.setpoint import _UNITS as SETPOINT_UNITS
from twin.setpoint import SetpointError, SetpointUpdate
from twin.snapshot import SetpointState
from twin.spec import Thermal

ID_PATTERN = r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,63}$"
_STRICT = ConfigDict(extra="forbid", allow_inf_nan=False)


# ---- errors -----------------------------------------------------------------------------------
class FieldError(BaseModel):
    """One thing wrong with a request."""

    field: str | None = Field(description="Where: the field name or path (e.g. 'radial_load_n', 'steps[2].at_s'); null when the request as a whole is wrong [text].")
    message: str = Field(description="What is wrong, with the allowed range and unit when there is one [text].")
    allowed: list[Any] | None = Field(default=None, description="Allowed [low, high] in the field's unit, or the allowed names; null when not applicable [field unit].")


class ErrorResponse(BaseModel):
    """Body of every 4xx/5xx answer."""

    detail: list[FieldError] = Field(description="The problems found [list].")


class InputError(Exception):
    """Bad input: carries the FieldErrors and the HTTP status to answer with."""

    def __init__(self, errors: list[FieldError], status_code: int = 422):
        self.errors, self.status_code = errors, status_code
        super().__init__("; ".join(f"{e.field}: {e.message}" if e.field else e.message for e in errors))

    @classmethod
    def one(cls, field: str | None, message: str, allowed: list | None = None,
            status_code: int = 422) -> InputError:
        return cls([FieldError(field=field, message=message, allowed=allowed)], status_code)


def _loc_text(loc: tuple | list, skip: tuple[str, ...] = ("body",)) -> str | None:
    parts = list(loc)
    while parts and parts[0] in skip:
        parts.pop(0)
    out = ""
    for part in parts:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out or None


def field_errors(errors: list[dict], limits: dict[str, tuple[float, float]] | None = None) -> list[FieldError]:
    """pydantic error dicts -> FieldErrors naming the field and, for setpoint fields, the twin's
    allowed range (the bearing's limits) or else the schema's bounds. Never echoes the input
    (it may hold NaN, which JSON cannot carry)."""
    out = []
    for e in errors:
        loc = tuple(e.get("loc", ()))
        field = _loc_text(loc)
        leaf = str(loc[-1]) if loc else None
        msg = str(e.get("msg", "invalid")).removeprefix("Value error, ")
        ctx = e.get("ctx") or {}
        allowed = None
        if limits and leaf in limits:
            low, high = limits[leaf]
            allowed = [low, high]
            unit = SETPOINT_UNITS.get(leaf, "")
            msg = f"{msg}; allowed range [{low:g}, {high:g}] {unit} for this bearing"
        else:
            low = ctx.get("ge", ctx.get("gt"))
            high = ctx.get("le", ctx.get("lt"))
            if low is not None or high is not None:
                known = _field_bounds().get(leaf or "")
                if known is not None:
                    low = known[0] if low is None else low
                    high = known[1] if high is None else high
                allowed = [_jsonable(low), _jsonable(high)]
                unit = unit_of(leaf or "")
                msg = f"{msg}; allowed range [{_fmt(low)}, {_fmt(high)}]{' ' + unit if unit else ''}"
        if e.get("type") == "extra_forbidden" and leaf is not None:
            msg = f"unknown field {leaf!r}"
            if limits:
                allowed = sorted(limits)
        if e.get("type") == "json_invalid":
            field = None
            msg = f"body is not valid JSON: {ctx.get('error', msg)}"
        out.append(FieldError(field=field, message=msg, allowed=allowed))
    return out


_UNIT_SUFFIXES = (("_rad_s", "rad/s"), ("_m2_s", "m^2/s"), ("_pa_s", "Pa s"), ("_hz", "Hz"),
                  ("_n", "N"), ("_m", "m"), ("_c", "degC"), ("_s", "s"), ("_a", "A"), ("_v", "V"))


def unit_of(field: str) -> str:
    """The unit a field name carries in its suffix ('radial_load_n' -> 'N'), '' if none."""
    for suffix, unit in _UNIT_SUFFIXES:
        if field.endswith(suffix):
            return unit
    return ""


def _fmt(value: Any) -> str:
    return "-inf" if value is None else (f"{value:g}" if isinstance(value, (int, float)) else str(value))


_BOUNDS: dict[str, tuple[Any, Any]] | None = None


def _field_bounds() -> dict[str, tuple[Any, Any]]:
    """field name -> (low, high) declared on the request models (both sides of a range, since a
    pydantic error names only the bound that was crossed)."""
    global _BOUNDS
    if _BOUNDS is None:
        from service.scenarios import Scenario, ScenarioRun, ScenarioStep

        bounds: dict[str, tuple[Any, Any]] = {}
        for model in (SetpointUpdate, BearingCreate, RecordingRequest, ScenarioRequest, Scenario,
                      ScenarioRun, ScenarioStep):
            for name, info in model.model_fields.items():
                low = high = None
                for m in info.metadata:
                    low = getattr(m, "ge", getattr(m, "gt", low)) if low is None else low
                    high = getattr(m, "le", getattr(m, "lt", high)) if high is None else high
                if (low is not None or high is not None) and name not in bounds:
                    bounds[name] = (low, high)
        _BOUNDS = bounds
    return _BOUNDS


def _jsonable(value: Any) -> Any:
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, (int, float, str)) or value is None:
        return value
    return str(value)


def setpoint_error(exc: SetpointError) -> FieldError:
    return FieldError(field=exc.field, message=str(exc), allowed=[exc.low, exc.high])


def parse_setpoint(data: Any, limits: dict[str, tuple[float, float]]) -> SetpointUpdate:
    """Validate a parsed setpoint body (dict) with SetpointUpdate; raises InputError naming the
    field and the bearing's range. The bearing limits themselves are checked by the runner on the
    merged setpoint (TwinRunner.submit)."""
    if isinstance(data, SetpointUpdate):
        return data
    if not isinstance(data, dict):
        raise InputError.one(None, f"a setpoint is a JSON object of fields {sorted(limits)}, got "
                             f"{type(data).__name__}", sorted(limits))
    try:
        return SetpointUpdate.model_validate(data)
    except ValidationError as exc:
        raise InputError(field_errors(exc.errors(), limits)) from None


def parse_setpoint_json(payload: bytes | str, limits: dict[str, tuple[float, float]]) -> SetpointUpdate:
    """Same as parse_setpoint for raw JSON text (zenoh). NaN/Infinity literals parse and are then
    refused by field (SetpointUpdate forbids non-finite numbers)."""
    try:
        data = json.loads(payload)
    except (ValueError, UnicodeDecodeError) as exc:
        raise InputError.one(None, f"payload is not valid JSON: {exc}") from None
    return parse_setpoint(data, limits)


# ---- bearings -----------------------------------------------------------------------------------
class BearingCreate(BaseModel):
    """A new twin: catalog bearing, mounting, lubricant, optional name and initial setpoint."""

    model_config = _STRICT
    id: str | None = Field(default=None, pattern=ID_PATTERN, description="Twin name used in URLs and zenoh keys [text: letters, digits, _ . -]; default '<designation>-<n>'.")
    designation: str = Field(default="6208", max_length=32, description="Catalog designation, e.g. '6208', '7208', '6200'..'6210' [text].")
    diametral_clearance_m: float = Field(default=0.0, ge=-50e-6, le=200e-6, description="Diametral clearance Pd [m]; negative = preload (seed 000: +-12.6e-6 m).")
    lubricant: str = Field(default="seed-000", max_length=64, description="Lubricant: 'seed-000' (0.04 Pa s at 40 degC) or an ISO grade such as 'ISO VG 68' [text].")
    setpoint: SetpointUpdate | None = Field(default=None, description="Initial setpoint (partial, defaults for the rest); the twin is warm-started at it [fields with units].")
    thermal: Thermal | None = Field(default=None, description="Electro-thermal options (seed 003): shear_heating, current_heating, equivalent_resistance_ohm [ohm], crater_depth_m [m], ...; default: the spec's (shear heating off).")


class ScenarioStatus(BaseModel):
    """The scenario a twin runs or ran last."""

    name: str = Field(description="Scenario name [text].")
    run: str = Field(description="Run id within the scenario [text].")
    state: Literal["pending", "running", "done", "cancelled", "failed"] = Field(description="Where it is [text].")
    scenario_time_s: float = Field(description="Simulated time since the scenario started [s].")
    duration_s: float = Field(description="Scenario length [s of simulated time].")
    progress: float = Field(description="scenario_time_s / duration_s [-], 0..1.")
    phase: str | None = Field(default=None, description="Label of the current phase, if the scenario names phases [text].")
    error: str | None = Field(default=None, description="Why it failed, if it did [text].")


class BearingInfo(BaseModel):
    """One twin of this service."""

    id: str = Field(description="Twin name [text].")
    designation: str = Field(description="Catalog designation [text].")
    kind: str = Field(description="'deep_groove' or 'angular_contact' [text].")
    ball_count: int = Field(description="Number of balls [-].")
    diametral_clearance_m: float = Field(description="Diametral clearance Pd [m]; negative = preload.")
    lubricant: str = Field(description="Lubricant name [text].")
    mode: Literal["real_time", "fast"] = Field(description="Pacing: real_time (paced to the wall clock) or fast [text].")
    running: bool = Field(description="Whether the runner thread is alive [bool].")
    time_s: float = Field(description="Simulated time of the latest snapshot [s].")
    setpoint: SetpointState = Field(description="The setpoint in force or pending (latest accepted) [fields with units].")
    limits: dict[str, tuple[float, float]] = Field(description="Allowed [low, high] of each setpoint field for this bearing, in the unit its name carries (shaft_speed_rad_s in rad/s, ...) [field unit].")
    scenario: ScenarioStatus | None = Field(default=None, description="Current or last scenario [object].")
    state_url: str = Field(description="Where to GET the latest snapshot [URL path].")
    zenoh_state_key: str = Field(description="zenoh key expression of the snapshot stream [key expression].")


# ---- setpoint -----------------------------------------------------------------------------------
class SetpointResponse(BaseModel):
    """The setpoint after a PUT: applied at the runner's next frame (<= one frame later)."""

    bearing_id: str = Field(description="Twin name [text].")
    setpoint: SetpointState = Field(description="The complete setpoint now in force for the next frame [fields with units].")
    frame_s: float = Field(description="Frame length: the update applies at the next frame boundary [s of simulated time].")


# ---- scenario -----------------------------------------------------------------------------------
class ScenarioRequest(BaseModel):
    """Run a named scenario (from the service's scenarios/ directory) or an inline one."""

    model_config = _STRICT
    name: str | None = Field(default=None, max_length=128, description="Name of a scenario file in scenarios/ (without .yaml) [text].")
    scenario: dict[str, Any] | None = Field(default=None, description="Inline scenario, same format as the YAML files (see service/scenarios.py) [object, times in s, setpoint fields with units].")
    run: str | None = Field(default=None, max_length=64, description="Which run of a multi-run scenario (default: the first) [text].")
    restart: bool = Field(default=False, description="Warm-restart the twin at the scenario's initial setpoint before it starts (else the initial setpoint is applied as a step) [bool].")


class ScenarioAccepted(BaseModel):
    """A scenario handed to the twin's runner."""

    accepted: bool = Field(description="Always true in a 202 answer [bool].")
    bearing_id: str = Field(description="Twin name [text].")
    name: str = Field(description="Scenario name [text].")
    run: str = Field(description="Run id [text].")
    expected_duration_s: float = Field(description="Scenario length [s of simulated time]; in real-time mode also about the wall time it takes.")
    mode: Literal["real_time", "fast"] = Field(description="Pacing of the twin that runs it [text].")
    replaced: str | None = Field(default=None, description="Name of a scenario that was still running and is cancelled [text].")
    warnings: list[str] = Field(default_factory=list, description="Fields skipped by the loader and why [text].")


class ScenarioList(BaseModel):
    """Named scenarios this service can run."""

    directory: str = Field(description="Where they are read from [path].")
    scenarios: dict[str, str] = Field(description="name -> description [text].")


# ---- recording ----------------------------------------------------------------------------------
class RecordingRequest(BaseModel):
    """Start or stop a rerun recording of one twin."""

    model_config = _STRICT
    action: Literal["start", "stop"] = Field(description="'start' or 'stop' [text].")
    path: str | None = Field(default=None, max_length=512, description="For start: .rrd file, relative to the service's recordings directory [path]; default <id>-<UTC timestamp>.rrd.")


class RecordingStatus(BaseModel):
    """A twin's own recording (besides the service-wide one)."""

    bearing_id: str = Field(description="Twin name [text].")
    recording: bool = Field(description="Whether a recording of this twin is being written [bool].")
    path: str | None = Field(default=None, description="The .rrd file [path].")
    rows_logged: int = Field(default=0, description="Snapshots written to it so far [-].")


# ---- health -------------------------------------------------------------------------------------
class TwinHealth(BaseModel):
    """Runner figures of one twin."""

    id: str = Field(description="Twin name [text].")
    running: bool = Field(description="Whether the runner thread is alive [bool].")
    status: str = Field(description="'ok' or what went wrong [text].")
    mode: Literal["real_time", "fast"] = Field(description="Pacing [text].")
    time_s: float = Field(description="Simulated time [s].")
    real_time_factor: float | None = Field(description="Simulated seconds per wall second over the last second [-]; null before it is measured.")
    frames: int = Field(description="Frames advanced [-].")
    overruns: int = Field(description="Frames that finished after their wall-clock deadline (real-time mode) [-].")
    resyncs: int = Field(description="Times the schedule was re-anchored after falling far behind [-].")
    published: int = Field(description="Snapshots published [-].")
    dropped: int = Field(description="Snapshots dropped by the sinks' bounded queues [-].")
    errors: int = Field(description="Exceptions caught in the runner loop (each followed by a warm restart) [-].")
    restarts: int = Field(description="Engine warm restarts after a diverged or overloaded state [-].")
    setpoints_accepted: int = Field(description="Setpoint updates accepted [-].")
    setpoints_refused: int = Field(default=0, description="zenoh setpoints refused (token, size, rate, validation) [-].")
    setpoints_rate_limited: int = Field(default=0, description="Setpoints refused by the rate limit, HTTP 429 and zenoh [-].")
    fallbacks: int = Field(default=0, description="Times the twin could not hold its setpoint and was warm-restarted at the last safe one [-].")
    last_safe_setpoint: SetpointState | None = Field(default=None, description="The newest setpoint held without a restart, the fallback [fields with units].")


class Health(BaseModel):
    """Service health."""

    status: Literal["ok", "degraded"] = Field(description="'ok', or 'degraded' when a twin's runner stopped or reports errors, or a recording cannot be written [text].")
    uptime_s: float = Field(description="Wall time since the service started [s].")
    twins: list[TwinHealth] = Field(description="One entry per twin [list].")
    zenoh: bool = Field(description="Whether the zenoh bus is open [bool].")
    zenoh_listen: list[str] = Field(description="zenoh endpoints listened on [zenoh locator].")
    recording: str | None = Field(description="The service-wide .rrd being written [path]; null when off.")
    recording_rows: int = Field(default=0, description="Snapshots written to the service-wide recording (never those a write error lost) [-].")
    recording_status: Literal["ok", "degraded", "off"] = Field(default="off", description="'degraded' while a recording cannot be written (disk full, permission): the twins keep running, the recorder retries with a new segment [text].")
    recording_error: str | None = Field(default=None, description="Why a recording is degraded [text]; null when none is.")
    recording_write_errors: int = Field(default=0, description="Recording writes that failed [-].")
    recording_rows_lost: int = Field(default=0, description="Snapshots that could not be written to a recording [-].")
    pid: int | None = Field(default=None, description="Process id of the service [-] (for soak tests and monitoring).")
    rss_bytes: int | None = Field(default=None, description="Resident memory of the service process [bytes]; null where /proc is unavailable.")
