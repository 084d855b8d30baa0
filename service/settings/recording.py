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
        json_schema_extra=flat("record", metavar="PATH.rrd"),
        description="rerun recording written while the service runs [path to a .rrd file]; "
        "default recordings/bearing-twin-<UTC timestamp>.rrd. A file of that name is never "
        "overwritten: this run then records beside it as <stem>.run2.rrd, <stem>.run3.rrd, ...",
    )
    segment_s: float = Field(
        default=600.0,
        ge=0.0,
        le=7 * 24 * 3600.0,
        json_schema_extra=flat("record_segment_s"),
        description="Rotate the service-wide recording: once its open segment is this old, close it "
        "(complete, readable) and continue in the next, <name>-0001.rrd, <name>-0002.rrd, ... (same "
        "recording id: open them together in the viewer) [s of wall time]; 0 = no rotation by age.",
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
        json_schema_extra=flat("record_footer"),
        description="End each segment with rerun's RRD footer, written by rerun's file sink that holds the chunk "
        "manifest in memory until the segment closes [bool]; off: the service writes the file and "
        "`rerun rrd optimize` adds the footer (docs/service.md).",
    )
    flush_interval_s: float = Field(
        default=1.0,
        gt=0.0,
        le=60.0,
        json_schema_extra=flat("record_flush_interval_s"),
        description="The recorder writes what it buffered this often, one rerun chunk (about 1.5 kB besides its rows) "
        "per entity [s]; shorter: larger files, and a live viewer lags by up to this much.",
    )
    keep_mb: float = Field(
        default=2000.0,
        ge=0.0,
        le=1e9,
        json_schema_extra=flat("record_keep_mb"),
        description="Retention: the newest segments of the service-wide recordings (same folder and name family) kept "
        "up to this total, older ones deleted [MB = 10^6 bytes]; 0 = no limit; never the open segment.",
    )
    keep_hours: float = Field(
        default=0.0,
        ge=0.0,
        le=1e6,
        json_schema_extra=flat("record_keep_hours"),
        description="Retention: also delete segments of the service-wide recordings older than this "
        "[h of wall time, by modification time]; 0 = no age limit.",
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
        json_schema_extra=flat("rerun_web_port", "--rerun-web", "--rerun-web-port", metavar="PORT"),
        description="Serve the live recording to rerun's web viewer: http://HOST:PORT, its gRPC proxy on "
        "PORT + 1 (rerun's own server, in a process of its own) [TCP port]; unset = off.",
    )
    web_bind: str = Field(
        default="127.0.0.1",
        min_length=1,
        max_length=64,
        json_schema_extra=flat("rerun_web_bind", metavar="ADDRESS"),
        description="Address rerun's web viewer and gRPC proxy bind to [IP address]. rerun checks no "
        "token: with BEARING_TWIN_TOKEN set only a loopback address is accepted (use an SSH tunnel).",
    )
    web_memory_mb: float = Field(
        default=500.0,
        gt=0.0,
        le=1e6,
        json_schema_extra=flat("rerun_web_memory_mb"),
        description="What rerun's gRPC proxy keeps of the live recording for viewers that connect late "
        "(oldest rows dropped first) [MB].",
    )

    @field_validator("path", mode="before")
    @classmethod
    def _path(cls, value: Any) -> Any:
        return optional_path(value)

    @property
    def active_path(self) -> Path | None:
        """Where the service records, or None when recording is off."""
        return self.path if self.enabled and self.path is not None else None
