"""The `twin` (what the service runs) and `runner` (pacing, threads, admission) settings groups of
`bearing-twin serve` (docs/service.md "Runner pool")."""

from __future__ import annotations

from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator

from service.keys import TWIN_ID_PATTERN
from service.settings.flat import flat
from service.settings.values import default_scenario_dir, optional_path
from twin.catalog import DEFAULT_DESIGNATION

TWIN_LIMIT = 256


class TwinSettings(BaseModel):
    """The twin started with the service, and where named scenarios are found."""

    model_config = ConfigDict(extra="forbid", hide_input_in_errors=True)

    id: str = Field(
        default="default",
        pattern=TWIN_ID_PATTERN,
        json_schema_extra=flat(
            "twin_id",
            metavar="ID",
            details="Give each service on one zenoh network its own: the keys are bearing/{id}/...",
        ),
        description="Name of the twin started with the service [text].",
    )
    start: bool = Field(
        default=True, json_schema_extra=flat("start_twin"), description="Start that twin with the service [bool]."
    )
    bearing: str = Field(
        default=DEFAULT_DESIGNATION,
        json_schema_extra=flat(
            "bearing",
            details="A spec file is .yaml or .json.",
        ),
        description="Bearing of the twin started with the service [catalog designation, e.g. 6208, or spec file path].",
    )
    housing: bool = Field(
        default=False,
        json_schema_extra=flat(
            "housing",
            details="Its outer ring sits on the housing support: the twin has vibration indicators and a waveform, "
            "and defects show in the signal. Other twins choose with POST /v1/bearings `housing`.",
        ),
        description="Put the twin started with the service on the housing support with the accelerometer [bool].",
    )
    scenario_dir: Path | None = Field(
        default=None,
        json_schema_extra=flat("scenario_dir", metavar="DIR"),
        description="Directory of named scenarios [path]; unset = ./scenarios "
        "if it exists, else the source tree's scenarios/.",
    )

    @field_validator("scenario_dir", mode="before")
    @classmethod
    def _scenario_dir(cls, value: Any) -> Any:
        return optional_path(value)

    @property
    def scenarios_path(self) -> Path:
        """The directory named scenarios are looked up in."""
        return self.scenario_dir if self.scenario_dir is not None else default_scenario_dir()


class RunnerSettings(BaseModel):
    """How the twins are paced, stepped and admitted."""

    model_config = ConfigDict(extra="forbid", hide_input_in_errors=True)

    fast: bool = Field(
        default=False,
        json_schema_extra=flat("fast"),
        description="Run the twins as fast as possible instead of paced to the wall clock [bool].",
    )
    publish_rate_hz: float = Field(
        default=50.0,
        gt=0.0,
        le=1000.0,
        json_schema_extra=flat("publish_rate_hz", "--publish-rate", "--publish-rate-hz", metavar="HZ"),
        description="Snapshot publishing rate [Hz] (of wall time in real-time mode, of simulated time in fast mode).",
    )
    frame_s: float = Field(
        default=0.02,
        ge=1e-5,
        le=0.1,
        json_schema_extra=flat(
            "frame_s",
            details="A stepping thread runs one frame of one twin at a time and publishes at its end; 20 ms (one "
            "publish period at 50 Hz) keeps the thread wake-ups and the Python between frames a small share of the "
            'work, and an outside setpoint cuts the frame in progress (docs/service.md "Runner pool").',
        ),
        description="Simulated time per frame; setpoints and scenario steps apply between frames [s].",
    )
    setpoint_frame_s: float = Field(
        default=0.00025,
        ge=1e-5,
        le=0.1,
        json_schema_extra=flat(
            "setpoint_frame_s",
            details="It applies when shorter than frame_s, and a twin waiting for its next frame starts it at once, "
            "so the state carrying the setpoint is published sooner. 0.25 ms costs about 0.07 ms of engine CPU for "
            "the default twin on the 2-core EPYC VM, 1 ms about 0.27 ms (the `step` stage of the setpoint latency, "
            "with its waits for a core, is in docs/performance.md).",
        ),
        description="Real-time mode: length of the frame that applies an outside setpoint (HTTP, zenoh) [s].",
    )
    frame_lead_s: float = Field(
        default=0.02,
        ge=0.0,
        le=0.1,
        json_schema_extra=flat(
            "frame_lead_s",
            details="The twin runs up to this much ahead of the wall clock, so a wait for the GIL or the CPU between "
            "frames is absorbed instead of making a late frame (service.core.pacing).",
        ),
        description="Real-time mode: how long before its wall-clock start "
        "a frame is released [s]; 0 = on the wall clock.",
    )
    lateness_s: float = Field(
        default=0.005,
        ge=0.0,
        le=1.0,
        json_schema_extra=flat(
            "lateness_s",
            details="Late frames are counted in /health `overruns` and `late_fraction`.",
        ),
        description="A frame is late when it ends more than this after its wall-clock deadline [s].",
    )
    stepping_threads: int | None = Field(
        default=None,
        ge=1,
        le=64,
        json_schema_extra=flat("stepping_threads"),
        description="Threads that advance the twins, earliest deadline first [count]; unset = one per "
        "core this process may use.",
    )
    io_thread_nice: int = Field(
        default=-5,
        ge=-20,
        le=19,
        json_schema_extra=flat(
            "io_thread_nice",
            details="All threads but the stepping threads and the publish worker. "
            "A value below the process's nice needs CAP_SYS_NICE.",
        ),
        description="Nice value of the other service threads, HTTP loop "
        "included (Linux, per thread) [-]; 0 = the process's nice.",
    )
    gc_freeze: bool = Field(
        default=True,
        json_schema_extra=flat(
            "gc_freeze",
            details='gc.freeze: full collections then walk only what was made since (docs/service.md "Runner pool").',
        ),
        description="Freeze the start-up heap out of Python's cyclic "
        "garbage collector once the service is open [bool].",
    )
    stepping_thread_nice: int = Field(
        default=-10,
        ge=-20,
        le=0,
        json_schema_extra=flat(
            "stepping_thread_nice",
            details="A priority above the process's own needs CAP_SYS_NICE; without it the threads keep "
            "the process's nice (/health thread_priority).",
        ),
        description="Nice value asked for the stepping threads and the "
        "publish worker (Linux, per thread) [-]; 0 = not raised.",
    )
    admission: Literal["measured", "off"] = Field(
        default="measured",
        json_schema_extra=flat(
            "admission",
            details="'measured': a twin this host cannot run in real time (its calibrated CPU need beside the "
            "running twins' measured need exceeds the capacity) is refused with 503, the reason and the figures. "
            "Fast mode never checks.",
        ),
        description="Admission of twins created over the API [measured | off]; off = no capacity check.",
    )
    capacity_core_fraction: float = Field(
        default=0.85,
        gt=0.0,
        le=1.0,
        json_schema_extra=flat(
            "capacity_core_fraction",
            details="The rest is left to the zenoh, rerun and HTTP threads.",
        ),
        description="Share of each core the twins may use in real time "
        "[-]; one twin uses at most this much of one core.",
    )
    capacity_reserve_cores: float = Field(
        default=0.5,
        ge=0.0,
        le=64.0,
        json_schema_extra=flat(
            "capacity_reserve_cores",
            details="The other threads are zenoh's, rerun's, HTTP's and the publishing ones. The reserve is never "
            'below one twin\'s share (docs/service.md "Runner pool").',
        ),
        description="CPU kept from the twins' capacity for the service's other threads and the machine [cores].",
    )
    calibration_s: float = Field(
        default=0.02,
        ge=0.001,
        le=1.0,
        json_schema_extra=flat("calibration_s"),
        description="Simulated time a new twin runs at creation to measure its CPU need [s].",
    )
    gil_switch_interval_s: float = Field(
        default=0.0005,
        ge=1e-5,
        le=0.1,
        json_schema_extra=flat(
            "gil_switch_interval_s",
            details="Python's 5 ms default makes a stepping thread wait up to 5 ms for the GIL after each frame "
            "while the publish worker and the zenoh/rerun/HTTP threads run; 0.5 ms keeps that wait a small share of "
            "a frame.",
        ),
        description="Python thread switch interval set when the service starts (sys.setswitchinterval) [s].",
    )
    max_twins: int | None = Field(
        default=None,
        ge=1,
        le=TWIN_LIMIT,
        json_schema_extra=flat(
            "max_twins",
            details="The capacity is the measured one (admission 'measured').",
        ),
        description="Most twins one service runs at a time [count]; unset "
        "= as many as the capacity admits, at most 256.",
    )

    @property
    def twin_limit(self) -> int:
        """The fixed cap on the number of twins (max_twins, or 256 when unset)."""
        return self.max_twins if self.max_twins is not None else TWIN_LIMIT
