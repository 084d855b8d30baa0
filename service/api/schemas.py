"""HTTP request and response models. Every field's description carries its unit in brackets
("[rad/s]", "[-]" for counts and dimensionless numbers, "[text]" for names). The setpoint is
`twin.setpoint` (Setpoint, SetpointUpdate), the state snapshot `twin.snapshot.Snapshot`: the
HTTP layer has no vocabulary of its own.
"""

from __future__ import annotations

from functools import cache
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field

from service.core.errors import Bounds, FieldError, InputError, models_bounds
from service.core.measured_temperature import MeasuredTemperature
from service.core.runner import RunMode
from twin import catalog
from twin.setpoint import Setpoint, SetpointUpdate
from twin.spec import (
    BearingSpec,
    Clearance,
    Electrical,
    Geometry,
    Lubricant,
    Lubrication,
    Material,
    Mounting,
    Surface,
    Thermal,
    TwinId,
)
from twin.vibration.housing import Accelerometer, Housing
from twin.vibration.surface import SurfaceProfile

__all__ = [
    "BearingCreate",
    "BearingInfo",
    "ErrorResponse",
    "FieldError",
    "Health",
    "InputError",
    "RecordingRequest",
    "RecordingStatus",
    "ScenarioAccepted",
    "ScenarioList",
    "ScenarioRequest",
    "ScenarioStatus",
    "SetpointResponse",
    "TwinHealth",
    "request_bounds",
]

_STRICT = ConfigDict(extra="forbid", strict=True, allow_inf_nan=False)


class ErrorResponse(BaseModel):
    """Body of every 4xx/5xx answer."""

    detail: list[FieldError] = Field(description="The problems found [list].")


# ---- bearings -----------------------------------------------------------------------------------
class BearingCreate(BaseModel):
    """A new twin: a catalog bearing (designation, mounting, lubricant) or a whole bearing spec,
    optional name and initial setpoint."""

    model_config = _STRICT
    id: TwinId | None = Field(
        default=None,
        description="Twin name used in URLs and zenoh keys [text: letters, digits, _ . -]; default '<designation>-<n>' "
        "(the spec's designation with a spec).",
    )
    designation: str = Field(
        default=catalog.DEFAULT_DESIGNATION,
        max_length=32,
        description="Catalog designation, e.g. '6208', '7208', '6200'..'6210', 'CWRU-DE' [text]; not with spec.",
    )
    spec: BearingSpec | None = Field(
        default=None,
        description="A bearing that is not in the catalog: a whole bearing spec (twin.spec.BearingSpec: designation, "
        "geometry [m], material [Pa, kg/m^3], surface, lubricant [m^2/s], mounting [m, kg], electrical, thermal, "
        "lubrication, housing, surface_profile; each field with its unit), validated as the catalog's. Instead of "
        "designation; it carries the clearance, lubricant, thermal options and housing itself, so those fields stay "
        "unset beside it [object].",
    )
    diametral_clearance_m: Clearance = 0.0
    lubricant: str = Field(
        default="seed-000",
        max_length=64,
        description="Lubricant: 'seed-000' (0.04 Pa s at 40 degC) or an ISO grade such as 'ISO VG 68' [text].",
    )
    setpoint: SetpointUpdate | None = Field(
        default=None,
        description="Initial setpoint (partial, defaults for the rest); the twin is warm-started at it [fields with "
        "units].",
    )
    thermal: Thermal | None = Field(
        default=None,
        description="Electro-thermal options (seed 003): shear_heating, current_heating, equivalent_resistance_ohm "
        "[ohm], crater_depth_m [m], ...; default: the spec's (shear heating on).",
    )
    housing: Housing | None = Field(
        default=None,
        description='Housing and accelerometer (twin.vibration.housing.Housing): {"enabled": true} puts the outer ring '
        "on the housing support (Sawalhi & Randall 2008 defaults) and samples the accelerometer (vibration indicators, "
        "waveform); other fields: pedestal_mass_kg [kg], radial_stiffness_n_m [N/m], ..., accelerometer "
        "{sample_rate_hz [Hz], ...}; default: rigid outer ring, no vibration.",
    )

    def twin_options(self) -> dict[str, Any]:
        """The bearing options of `TwinRegistry.create_twin`: `spec`, or the designation and its
        overrides. InputError naming the field when a spec comes with a designation or with a
        field that belongs inside the spec."""
        common: dict[str, Any] = {"setpoint": self.setpoint}
        if self.spec is None:
            return {
                **common,
                "designation": self.designation,
                "diametral_clearance_m": self.diametral_clearance_m,
                "lubricant": self.lubricant,
                "thermal": self.thermal,
                "housing": self.housing,
            }
        inside = {
            "designation": "spec.designation",
            "diametral_clearance_m": "spec.mounting.diametral_clearance_m",
            "lubricant": "spec.lubricant",
            "thermal": "spec.thermal",
            "housing": "spec.housing",
        }
        for name, where in inside.items():
            if name in self.model_fields_set:
                what = (
                    "give either 'designation' (a catalog bearing) or 'spec' (a whole bearing spec), not both"
                    if name == "designation"
                    else f"with a spec, {name} belongs inside it: set {where}"
                )
                raise InputError.one(name, what)
        return {**common, "spec": self.spec}


class ScenarioStatus(BaseModel):
    """The scenario a twin runs or ran last."""

    name: str = Field(description="Scenario name [text].")
    run: str = Field(description="Run id within the scenario [text].")
    state: Literal["pending", "running", "done", "cancelled", "failed"] = Field(description="Where it is [text].")
    scenario_time_s: float = Field(description="Simulated time since the scenario started [s].")
    duration_s: float = Field(description="Scenario length [s of simulated time].")
    progress: float = Field(description="scenario_time_s / duration_s [-], 0..1.")
    phase: str | None = Field(
        default=None, description="Label of the current phase, if the scenario names phases [text]."
    )
    error: str | None = Field(default=None, description="Why it failed, if it did [text].")


class BearingInfo(BaseModel):
    """One twin of this service."""

    id: str = Field(description="Twin name [text].")
    designation: str = Field(
        description="Catalog designation, or the designation of the spec the twin was created from [text]."
    )
    kind: str = Field(description="'deep_groove' or 'angular_contact' [text].")
    ball_count: int = Field(description="Number of balls [-].")
    diametral_clearance_m: float = Field(description="Diametral clearance Pd [m]; negative = preload.")
    lubricant: str = Field(description="Lubricant name [text].")
    mode: RunMode = Field(description="Pacing: real_time (paced to the wall clock) or fast [text].")
    running: bool = Field(description="Whether the twin is being stepped (started, neither stopped nor failed) [bool].")
    time_s: float = Field(description="Simulated time of the latest snapshot [s].")
    setpoint: Setpoint = Field(description="The setpoint in force or pending (latest accepted) [fields with units].")
    limits: dict[str, tuple[float, float]] = Field(
        description="Allowed [low, high] of each setpoint field for this bearing, in the unit its name carries "
        "(shaft_speed_rad_s in rad/s, ...) [field unit]."
    )
    scenario: ScenarioStatus | None = Field(default=None, description="Current or last scenario [object].")
    state_url: str = Field(description="Where to GET the latest snapshot [URL path].")
    zenoh_state_key: str = Field(description="zenoh key expression of the snapshot stream [key expression].")


# ---- setpoint -----------------------------------------------------------------------------------
class SetpointResponse(BaseModel):
    """The setpoint after a PUT: applied at the runner's next frame (<= one frame later)."""

    bearing_id: str = Field(description="Twin name [text].")
    setpoint: Setpoint = Field(description="The complete setpoint now in force for the next frame [fields with units].")
    frame_s: float = Field(
        description="Frame length: the update applies at the next frame boundary [s of simulated time]."
    )


# ---- scenario -----------------------------------------------------------------------------------
class ScenarioRequest(BaseModel):
    """Run a named scenario (from the service's scenarios/ directory) or an inline one."""

    model_config = _STRICT
    name: str | None = Field(
        default=None, max_length=128, description="Name of a scenario file in scenarios/ (without .yaml) [text]."
    )
    scenario: dict[str, Any] | None = Field(
        default=None,
        description="Inline scenario, same format as the YAML files (see service/core/scenarios.py) [object, times in "
        "s, setpoint fields with units].",
    )
    run: str | None = Field(
        default=None, max_length=64, description="Which run of a multi-run scenario (default: the first) [text]."
    )
    restart: bool = Field(
        default=False,
        description="Warm-restart the twin at the scenario's initial setpoint before it starts (else the initial "
        "setpoint is applied as a step) [bool].",
    )


class ScenarioAccepted(BaseModel):
    """A scenario handed to the twin's runner."""

    accepted: bool = Field(description="Always true in a 202 answer [bool].")
    bearing_id: str = Field(description="Twin name [text].")
    name: str = Field(description="Scenario name [text].")
    run: str = Field(description="Run id [text].")
    expected_duration_s: float = Field(
        description="Scenario length [s of simulated time]; in real-time mode also about the wall time it takes."
    )
    mode: RunMode = Field(description="Pacing of the twin that runs it [text].")
    replaced: str | None = Field(
        default=None, description="Name of a scenario that was still running and is cancelled [text]."
    )
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
    path: str | None = Field(
        default=None,
        max_length=512,
        description="For start: .rrd file, relative to the service's recordings directory [path]; default <id>-<UTC "
        "timestamp>.rrd.",
    )


class RecordingStatus(BaseModel):
    """A twin's own recording (besides the service-wide one)."""

    bearing_id: str = Field(description="Twin name [text].")
    recording: bool = Field(description="Whether a recording of this twin is being written [bool].")
    path: str | None = Field(default=None, description="The .rrd file [path].")
    rows_logged: int = Field(default=0, description="Snapshots written to it so far [-].")


class TwinCost(BaseModel):
    """CPU a twin needs in real time (service.core.capacity)."""

    engine_cpu_s_per_sim_s: float = Field(
        description="Engine CPU time per simulated second [CPU s / s]: 1 / the real-time factor the twin would have "
        "alone on a core."
    )
    publish_cpu_s_per_s: float = Field(
        description="CPU time spent building its snapshots per wall second, at the publish rate [CPU s / s]."
    )
    cpu_s_per_s: float = Field(description="The sum: CPU time the twin needs per wall second in real time [CPU s / s].")
    publish_fraction: float | None = Field(
        default=None, description="Snapshot building per engine CPU time [-]; null for an engine that costs nothing."
    )


class Capacity(BaseModel):
    """The host's capacity for twins in real time, as measured (admission rule: docs/service.md "Runner pool")."""

    admission: Literal["measured", "off"] = Field(
        description="Whether new twins are checked against the capacity [text]."
    )
    cores: int = Field(description="Cores this process may use [-].")
    stepping_threads: int = Field(description="Threads that advance the twins [-].")
    core_fraction: float = Field(
        description="Share of each core the twins may use; also the most one twin may use [-]."
    )
    budget_cpu_s_per_s: float = Field(description="min(stepping threads, cores) x core_fraction [CPU s / s].")
    used_cpu_s_per_s: float = Field(
        description="What the running twins need, as measured: engines plus the service share each [CPU s / s]."
    )
    over_budget: bool = Field(default=False, description="Whether the running twins need more than the budget [bool].")
    max_twins: int | None = Field(
        default=None,
        description="Twins this host holds in real time: the running ones plus as many more like the last calibrated "
        "one as the budget has room for (capped by max_twins when set) [-]; null before a calibration.",
    )
    max_twins_set: int | None = Field(default=None, description="The max_twins setting; null = unset [-].")
    last_calibration: TwinCost | None = Field(
        default=None, description="The cost measured at the last twin creation [CPU s / s]; null before one."
    )
    alike_engine_cpu_s_per_sim_s: float | None = Field(
        default=None,
        description="The mean measured engine cost of the running twins alike the last calibrated one (the same spec "
        "and model options); a twin like it counts at the larger of this and its calibration; null while none is "
        "measured [CPU s per simulated s].",
    )
    over_capacity: str | None = Field(
        default=None, description="Why the configured twin runs although it does not fit; null when it fits [text]."
    )
    reserve_cores: float = Field(
        default=0.0, description="CPU kept for the service's other threads, taken from the budget [CPU s / s]."
    )
    service_overhead_per_twin_cpu_s_per_s: float | None = Field(
        default=None,
        description="The service's CPU per twin beside the engines over the last closed window, HTTP not counted; "
        "each twin's need counts it [CPU s / s]; null before a window closes.",
    )
    formula: str | None = Field(
        default=None,
        description="How max_twins is reached, with the figures of the moment: budget = cores x core_fraction - "
        "reserve; max_twins = running + floor((budget - in use) / need of a twin like the last calibrated: its "
        "engine (the larger of its calibration and what the running twins alike it measure) plus the service overhead "
        "per twin) [text].",
    )
    service_overhead: dict[str, float | None] | None = Field(
        default=None,
        description="The process's CPU beside the engines over the last window of at least 1 s between two /health "
        "reads (service.core.capacity.ServiceOverheadMeter): `window_s` [s], `process_cpu_s_per_s`, "
        "`engine_cpu_s_per_s`, `overhead_cpu_s_per_s`, `overhead_per_twin_cpu_s_per_s` [CPU s / s], "
        "`overhead_fraction` (overhead / engines) against `goal_fraction` (0.10) [-]; by the job of the threads that "
        "spend it (service.core.thread_cpu): `<role>_cpu_s_per_s` and `<role>_cpu_s_total` for stepping (beside the "
        "engines), publish_worker, zenoh_outbox, zenoh_inbox, alarms, recording, http, opcua, other, native, "
        "`twin_overhead_cpu_s_per_s` (every role but http and opcua), `twin_overhead_per_twin_cpu_s_per_s`, "
        "`twin_overhead_fraction` (of the engines' CPU), `twin_overhead_cpu_s_total`, `engine_cpu_s_total` [CPU s / s,"
        " CPU s, -]; only the totals before a window closes.",
    )


# ---- health -------------------------------------------------------------------------------------
class TwinHealth(BaseModel):
    """Runner figures of one twin."""

    id: str = Field(description="Twin name [text].")
    running: bool = Field(description="Whether the twin is being stepped (started, neither stopped nor failed) [bool].")
    status: str = Field(description="'ok' or what went wrong [text].")
    mode: RunMode = Field(description="Pacing [text].")
    time_s: float = Field(description="Simulated time [s].")
    real_time_factor: float | None = Field(
        description="Simulated seconds per wall second over the last second [-]; null before it is measured."
    )
    late_fraction: float | None = Field(
        default=None,
        description="Late frames (ended more than lateness_s after their wall-clock deadline) / frames over the last "
        "10 s of wall time [-]; null in fast mode and before the first frame.",
    )
    lateness_s: float | None = Field(default=None, description="How late a frame may end before it counts as late [s].")
    frame_s: float | None = Field(default=None, description="Simulated time per frame [s].")
    frames: int = Field(description="Frames advanced [-].")
    overruns: int = Field(
        description="Frames that ended more than lateness_s after their wall-clock deadline, since the start "
        "(real-time mode) [-]."
    )
    resyncs: int = Field(description="Times the schedule was re-anchored after falling far behind [-].")
    published: int = Field(description="Snapshots published [-].")
    dropped: int = Field(description="Snapshots dropped by the sinks' bounded queues [-].")
    errors: int = Field(description="Exceptions caught in the runner loop (each followed by a warm restart) [-].")
    restarts: int = Field(description="Engine warm restarts after a diverged or overloaded state [-].")
    setpoints_accepted: int = Field(description="Setpoint updates accepted [-].")
    setpoints_refused: int = Field(
        default=0,
        description="zenoh setpoints refused (bus closed to writes, size, rate, validation, control queue full) [-].",
    )
    setpoints_rate_limited: int = Field(
        default=0, description="Setpoints refused by the rate limit, HTTP 429 and zenoh [-]."
    )
    fallbacks: int = Field(
        default=0,
        description="Times the twin could not hold its setpoint and was warm-restarted at the last safe one [-].",
    )
    last_safe_setpoint: Setpoint | None = Field(
        default=None, description="The newest setpoint held without a restart, the fallback [fields with units]."
    )
    cost: TwinCost | None = Field(
        default=None,
        description="CPU this twin needs in real time, as measured (its calibration until measured while running) [CPU "
        "s / s]; null when not measured.",
    )
    setpoint_latency_ms: dict[str, Any] | None = Field(
        default=None,
        description="Latency of the newest 1000 outside setpoints inside the service [ms]: `http` (HTTP setpoints: "
        "the request read by the server -> submitted to the twin: parsing, middleware, routing, token, rate and body "
        "checks), `admission` (-> accepted: merged and checked against the bearing's limits), `apply` (-> "
        "applied at a frame boundary), `step` (-> the frame that applies it captured), `build` (-> its snapshot "
        "built), `publish` (-> handed to every sink, the zenoh state put), `total`, each {p50, p99, max}, and `count`; "
        "null before the first.",
    )


class ThreadPriorityHealth(BaseModel):
    """Scheduling priority of the service's threads (service.core.priority)."""

    active: bool = Field(description="Whether the service sets its threads' priorities (Linux) [bool].")
    io_thread_nice: int = Field(
        description="Nice value asked for every thread but the stepping threads and the publish worker, the HTTP event "
        "loop included [-]; 0 when not active."
    )
    stepping_thread_nice_asked: int = Field(
        description="Nice value asked for the stepping threads and the publish worker [-]."
    )
    stepping_thread_nice: list[int] = Field(
        description="Nice values found on the stepping threads and the publish worker [-] (the process's own where "
        "raising a priority is not permitted)."
    )
    threads_reniced: int = Field(description="Threads given io_thread_nice since the start [-].")
    errors: int = Field(description="io_thread_nice changes the system refused [-].")
    stepping_priority_refused: int = Field(
        description="Raises of a stepping thread's priority refused (no root or CAP_SYS_NICE) [-]."
    )
    egress_threads: list[int] = Field(
        default_factory=list,
        description="Nice values found on zenoh's transmit threads, kept at the lower of io_thread_nice and the "
        "process's nice like the event loop (they send the state messages) [-]; empty without a zenoh link.",
    )
    egress_priority_refused: int = Field(
        default=0, description="Transmit threads that could not be brought to that nice (no root or CAP_SYS_NICE) [-]."
    )


class Health(BaseModel):
    """Service health."""

    status: Literal["ok", "degraded"] = Field(
        description="'ok', or 'degraded' when a twin's runner stopped or reports errors, or a recording cannot be "
        "written [text]."
    )
    uptime_s: float = Field(description="Wall time since the service started [s].")
    twins: list[TwinHealth] = Field(description="One entry per twin [list].")
    capacity: Capacity | None = Field(
        default=None, description="The host's measured capacity for twins in real time [CPU s / s, counts]."
    )
    zenoh: bool = Field(description="Whether the zenoh bus is open [bool].")
    zenoh_listen: list[str] = Field(description="zenoh endpoints listened on [zenoh locator].")
    recording: str | None = Field(description="The service-wide .rrd being written [path]; null when off.")
    recording_rows: int = Field(
        default=0, description="Snapshots written to the service-wide recording (never those a write error lost) [-]."
    )
    recording_status: Literal["ok", "degraded", "off"] = Field(
        default="off",
        description="'degraded' while a recording cannot be written (disk full, permission): the twins keep running, "
        "the recorder retries with a new segment [text].",
    )
    recording_error: str | None = Field(
        default=None, description="Why a recording is degraded [text]; null when none is."
    )
    recording_write_errors: int = Field(default=0, description="Recording writes that failed [-].")
    recording_rows_lost: int = Field(default=0, description="Snapshots that could not be written to a recording [-].")
    reads_rate_limited: int = Field(
        default=0, description="API reads refused with 429 by the per-client read rate [-]."
    )
    thread_priority: ThreadPriorityHealth | None = Field(
        default=None,
        description="Priority of the stepping threads over the service's I/O threads [nice values, counts].",
    )
    http_tarpit: dict[str, bool | int | float] | None = Field(
        default=None,
        description="The tarpit for HTTP clients over their error budget (service.api.middleware.Tarpit): `active`, "
        "`delay_s` [s], `max_held`, `held_now`, `held` (refusals held so far), `answered_at_once` (over budget with "
        "max_held held already), `errors_over_budget` [counts].",
    )
    opcua_guard: dict[str, Any] | None = Field(
        default=None,
        description="What the OPC UA limits refused (service.opcua.guard): `sessions` open, `refused` by status name, "
        "`failed_logins`, `refused_in_backoff`, `addresses_in_backoff` [counts]; null without OPC UA.",
    )
    http_slow_closed: int = Field(
        default=0,
        description="HTTP connections closed (408) because their headers or body were not complete in time, in this "
        "process [-].",
    )
    pid: int | None = Field(default=None, description="Process id of the service [-] (for soak tests and monitoring).")
    rss_bytes: int | None = Field(
        default=None, description="Resident memory of the service process [bytes]; null where /proc is unavailable."
    )


@cache
def request_bounds() -> dict[str, Bounds]:
    """field name -> (low, high) declared on the request models (both sides of a range, since a
    pydantic error names only the bound that was crossed)."""
    from service.core.scenarios import Scenario, ScenarioRun, ScenarioStep

    spec_parts = (
        BearingSpec,
        Geometry,
        Material,
        Surface,
        Lubricant,
        Mounting,
        Lubrication,
        Electrical,
        Housing,
        Accelerometer,
        SurfaceProfile,
    )
    return models_bounds(
        (
            BearingCreate,
            RecordingRequest,
            MeasuredTemperature,
            ScenarioRequest,
            Scenario,
            ScenarioRun,
            ScenarioStep,
            Thermal,
            *spec_parts,
        )
    )
