"""The `recording` settings group: the service-wide rerun recording, its rotation and retention,
and the live viewers (docs/service.md "Recordings")."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from pydantic import BaseModel, ConfigDict, Field, field_validator

from service.settings.flat import flat
from service.settings.values import default_recording_path, optional_path


class RecordingSettings(BaseModel):
    """What the service records, where, and who watches it live."""

    model_config = ConfigDict(extra="forbid", hide_input_in_errors=True)

    enabled: bool = Field(
        default=True,
        json_schema_extra=flat("enable_recording", "--no-record"),
        description="Write the rerun recording [bool].",
    )
    path: Path | None = Field(
        default_factory=default_recording_path,
        json_schema_extra=flat(
            "record",
            metavar="PATH.rrd",
            details="A file of that name is never overwritten: this run then "
            "records beside it as `<stem>.run2.rrd`, `<stem>.run3.rrd`, ...",
        ),
        description="rerun recording written while the service runs [path to a .rrd file].",
    )
    segment_s: float = Field(
        default=600.0,
        ge=0.0,
        le=7 * 24 * 3600.0,
        json_schema_extra=flat(
            "record_segment_s",
            details="The segment is closed (complete, readable) and the recording continues in the next, "
            "`<name>-0001.rrd`, `<name>-0002.rrd`, ... with the same recording id: open them together in the viewer.",
        ),
        description="Rotate the service-wide recording once its open segment "
        "is this old [s of wall time]; 0 = no rotation by age.",
    )
    segment_mb: float = Field(
        default=1000.0,
        ge=0.0,
        le=1e6,
        json_schema_extra=flat("record_segment_mb"),
        description="Also rotate once the open segment holds this much on disk [MB = 10^6 bytes]; "
        "0 = no rotation by size.",
    )
    footer: bool = Field(
        default=False,
        json_schema_extra=flat(
            "record_footer",
            details="That sink holds the chunk manifest in memory until the segment closes. Off: the service writes "
            'the file and `rerun rrd optimize` adds the footer (docs/service.md "Recordings").',
        ),
        description="End each segment with rerun's RRD footer, written by rerun's file sink [bool].",
    )
    flush_interval_s: float = Field(
        default=1.0,
        gt=0.0,
        le=60.0,
        json_schema_extra=flat(
            "record_flush_interval_s",
            details="Each write is one rerun chunk (about 1.5 kB besides its rows) per entity, so a shorter "
            "interval makes larger files.",
        ),
        description="How often the recorder writes what it buffered [s]; a live viewer lags by up to this much.",
    )
    keep_mb: float = Field(
        default=2000.0,
        ge=0.0,
        le=1e9,
        json_schema_extra=flat(
            "record_keep_mb",
            details="The service-wide recordings' segments (same folder and name family) "
            "beyond it are deleted, oldest first; never the open segment.",
        ),
        description="Retention: total size of the newest recording segments kept [MB = 10^6 bytes]; 0 = no limit.",
    )
    keep_hours: float = Field(
        default=0.0,
        ge=0.0,
        le=1e6,
        json_schema_extra=flat(
            "record_keep_hours",
            details="Segments of the service-wide recordings, aged by modification time.",
        ),
        description="Retention: also delete recording segments older than this [h of wall time]; 0 = no age limit.",
    )
    spawn_viewer: bool = Field(
        default=False,
        json_schema_extra=flat("spawn_viewer"),
        description="Also stream to a rerun viewer spawned on this machine [bool].",
    )
    web_port: int | None = Field(
        default=None,
        ge=1,
        le=65534,
        json_schema_extra=flat(
            "rerun_web_port",
            "--rerun-web",
            "--rerun-web-port",
            metavar="PORT",
            details="Its gRPC proxy is on PORT + 1; both are rerun's own server, in a process of its own.",
        ),
        description="Serve the live recording to rerun's web viewer at http://HOST:PORT [TCP port]; unset = off.",
    )
    web_bind: str = Field(
        default="127.0.0.1",
        min_length=1,
        max_length=64,
        json_schema_extra=flat(
            "rerun_web_bind",
            metavar="ADDRESS",
            details="rerun checks no token: with BEARING_TWIN_TOKEN set only "
            "a loopback address is accepted (use an SSH tunnel).",
        ),
        description="Address rerun's web viewer and gRPC proxy bind to [IP address].",
    )
    web_memory_mb: float = Field(
        default=500.0,
        gt=0.0,
        le=1e6,
        json_schema_extra=flat(
            "rerun_web_memory_mb",
            details="Late viewers are those that connect after the recording started.",
        ),
        description="Memory rerun's gRPC proxy keeps of the live recording "
        "for late viewers [MB]; oldest rows dropped first.",
    )

    @field_validator("path", mode="before")
    @classmethod
    def _path(cls, value: Any) -> Any:
        return optional_path(value)

    @property
    def active_path(self) -> Path | None:
        """Where the service records, or None when recording is off."""
        return self.path if self.enabled and self.path is not None else None
