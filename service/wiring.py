"""`TwinService`: the twins of one service and their wiring to the zenoh bus and rerun.

This is the ONE place that touches `service.bus` and `service.recording` (imported lazily, so the
HTTP layer and the tests that disable them never import zenoh or rerun):

    create twin -> TwinRunner (not started) -> bus.attach_twin(...) -> channel as a sink
                -> recorder.add_twin_from(twin), recorder as a sink -> runner.start()
    delete twin -> runner.stop() -> channel.detach() -> recorder.remove_twin -> per-twin recording closed
    close       -> every runner stopped (all asked first, then joined) -> channels detached
                -> per-twin recordings closed -> service recording closed (drained, flushed)
                -> zenoh session closed

Every recorder of the service makes its rerun streams through one `service.recording.RerunStreams`
owned by the `TwinService` (`rerun_streams()`): a per-twin recording gets a new recorder (its
own recording id) per start, and its streams are freed when it stops (rerun-sdk 0.41 would keep
them, and their threads, forever: see the recorder's module doc).

A setpoint arriving over zenoh goes through `TwinRunner.submit_setpoint_json`, which uses the
same validation as HTTP (`service.schemas.parse_setpoint` + the bearing's limits).
"""

from __future__ import annotations

import logging
import os
import re
import sys
import threading
import time
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from service.runner import TwinRunner
from service.schemas import (
    BearingCreate,
    FieldError,
    InputError,
    field_errors,
    setpoint_error,
)
from service.settings import ServiceSettings
from twin import catalog
from twin.engine import Twin
from twin.setpoint import SetpointError

log = logging.getLogger(__name__)

_ID_RE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,63}$")


class WiringError(RuntimeError):
    """A component the settings ask for is missing or failed to start."""


def open_bus(settings: ServiceSettings):
    """The service's zenoh bus, or None when zenoh is disabled."""
    if not settings.enable_zenoh:
        return None
    try:
        from service.bus import ZenohBus
    except ImportError as exc:
        raise WiringError(f"zenoh is enabled but service.bus cannot be imported ({exc}); "
                          "install eclipse-zenoh or run with --no-zenoh") from exc
    return ZenohBus(listen=settings.zenoh_listen, connect=settings.zenoh_connect, mode=settings.zenoh_mode)


def _recorder_class():
    try:
        from service.recording import RerunRecorder
    except ImportError as exc:
        raise WiringError(f"recording is enabled but service.recording cannot be imported ({exc}); "
                          "install rerun-sdk or run with --no-record") from exc
    return RerunRecorder


def open_recorder(settings: ServiceSettings, streams: Any = None):
    """The service-wide rerun recorder, or None when recording (and the viewer) are off.
    `streams`: the service's `RerunStreams`, shared with the per-twin recordings (stream creation
    and reclaim must not run concurrently, see `service.recording.streams`). A recording path
    that exists already (an earlier run) is kept: this run records under the next free name
    (`service.recording.paths`). Retention (`record_keep_mb`, `record_keep_hours`) applies to the
    family of the service-wide recording only."""
    path = settings.recording_path
    if path is None and not settings.spawn_viewer:
        return None
    cls = _recorder_class()
    from service.recording import RecordingPathError, RecordingWriteError, Retention

    extra = {} if streams is None else {"streams": streams}
    retention = None
    if path is not None and (settings.record_keep_mb > 0 or settings.record_keep_hours > 0):
        retention = Retention.for_recording(path, keep_bytes=round(settings.record_keep_mb * 1e6),
                                            keep_age_s=settings.record_keep_hours * 3600.0)
    try:
        return cls(path, spawn_viewer=settings.spawn_viewer, retention=retention, **recorder_options(settings), **extra)
    except (RecordingPathError, RecordingWriteError, OSError) as exc:
        raise WiringError(f"cannot record to {str(path)!r}: {' '.join(str(exc).split())[:300]} "
                          "(--record PATH.rrd elsewhere, or --no-record)") from None


def recorder_options(settings: ServiceSettings) -> dict:
    """Send interval, segment rotation and footer of every recording the service writes."""
    return dict(flush_interval_s=settings.record_flush_interval_s,
                segment_s=settings.record_segment_s or None,
                segment_bytes=round(settings.record_segment_mb * 1e6) or None,
                write_footer=settings.record_footer)


@dataclass
class TwinEntry:
    """One twin of the service and what is wired to it."""

    id: str
    twin: Twin
    runner: TwinRunner
    lubricant: str
    channel: Any = None                 # zenoh TwinChannel
    recording: Any = None               # this twin's own RerunRecorder (POST .../recording)
    recording_path: Path | None = None
    created_wall_s: float = field(default_factory=time.time)

    @property
    def designation(self) -> str:
        return self.twin.model.spec.designation

    @property
    def diametral_clearance_m(self) -> float:
        return float(self.twin.model.spec.mounting.diametral_clearance_m)


class TwinService:
    """Owns the twins, the bus and the recorder of one service (no module-level state)."""

    def __init__(self, settings: ServiceSettings):
        self.settings = settings
        self.bus = None
        self.recorder = None
        self.started_wall_s = time.monotonic()
        self._twins: dict[str, TwinEntry] = {}
        self._reserved: set[str] = set()    # ids of twins being built
        self._recording_lock = threading.RLock()
        self._lock = threading.RLock()
        self._closed = False
        self._rerun_streams = None          # service.recorder.RerunStreams, made on first use

    def rerun_streams(self):
        """The `RerunStreams` that makes and frees every rerun stream of this service."""
        with self._lock:
            if self._rerun_streams is None:
                _recorder_class()
                from service.recording import RerunStreams

                self._rerun_streams = RerunStreams()
            return self._rerun_streams

    # ---- life cycle ------------------------------------------------------------------------
    def open(self, *, default_twin: bool = True) -> TwinService:
        """Start the bus (if enabled), the recorder (if enabled) and the `default` twin."""
        if sys.getswitchinterval() > self.settings.gil_switch_interval_s:
            sys.setswitchinterval(self.settings.gil_switch_interval_s)  # process-wide, see settings
        try:
            self.bus = open_bus(self.settings)
            if self.settings.recording_path is not None or self.settings.spawn_viewer:
                self.recorder = open_recorder(self.settings, self.rerun_streams())
            if default_twin and self.settings.start_twin:
                self.create_twin(BearingCreate(id=self.settings.twin_id, designation=self.settings.bearing))
        except BaseException:
            self.close()
            raise
        return self

    def close(self) -> None:
        """Stop every runner, detach zenoh, close recordings (nothing queued is lost), close the
        session. Idempotent; never raises."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
            entries = list(self._twins.values())
            self._twins.clear()
        for e in entries:                     # ask all to stop first, then join
            e.runner.request_stop()
        for e in entries:
            try:
                e.runner.stop(timeout=5.0)
            except Exception:
                log.exception("stopping twin %s", e.id)
        for e in entries:
            self._unwire(e)
        if self.recorder is not None:
            try:
                self.recorder.close()
            except Exception:
                log.exception("closing the recorder")
        if self.bus is not None:
            try:
                self.bus.close()
            except Exception:
                log.exception("closing the zenoh bus")

    def _unwire(self, e: TwinEntry) -> None:
        if e.channel is not None:
            try:
                e.runner.remove_sink(e.channel)
                e.channel.detach()
            except Exception:
                log.exception("detaching twin %s from zenoh", e.id)
            e.channel = None
        if self.recorder is not None:
            e.runner.remove_sink(self.recorder)
            try:
                self.recorder.remove_twin(e.id)   # its rows are written, its entry freed
            except Exception:
                log.exception("removing twin %s from the recording", e.id)
        self.stop_recording(e)

    # ---- twins -----------------------------------------------------------------------------
    def entries(self) -> list[TwinEntry]:
        with self._lock:
            return list(self._twins.values())

    def get(self, bearing_id: str) -> TwinEntry:
        with self._lock:
            entry = self._twins.get(bearing_id)
            known = sorted(self._twins)
        if entry is None:
            raise InputError.one("bearing_id", f"unknown twin {bearing_id!r}; known: "
                                 f"{', '.join(known) or 'none'}", known, status_code=404)
        return entry

    def _new_id(self, designation: str) -> str:
        n = 1
        while f"{designation}-{n}" in self._twins or f"{designation}-{n}" in self._reserved:
            n += 1
        return f"{designation}-{n}"

    def build_twin(self, req: BearingCreate, bearing_id: str) -> Twin:
        """A warm-started Twin from a creation request (InputError naming the field if invalid)."""
        designation = req.designation.strip().upper()
        if designation not in catalog.designations():
            raise InputError.one("designation", f"unknown bearing {req.designation!r}",
                                 catalog.designations())
        try:
            lubricant = catalog.lubricant(req.lubricant)
        except ValueError as exc:
            raise InputError.one("lubricant", str(exc).removeprefix("lubricant: ")) from None
        try:
            spec = catalog.bearing(designation, diametral_clearance_m=req.diametral_clearance_m,
                                   lubricant=lubricant, **({"thermal": req.thermal} if req.thermal else {}))
        except ValidationError as exc:
            raise InputError(field_errors(exc.errors())) from None
        try:
            twin = Twin(spec, bearing_id=bearing_id)  # at the bearing's default setpoint
            if req.setpoint is not None:
                twin.set_setpoint(req.setpoint)
                twin.reset()  # warm start at the requested setpoint
            return twin
        except SetpointError as exc:
            err = setpoint_error(exc)
            raise InputError([FieldError(field=f"setpoint.{err.field}", message=err.message,
                                         allowed=err.allowed)]) from None

    def create_twin(self, req: BearingCreate) -> TwinEntry:
        """Create, wire and start a twin. InputError 409 on a duplicate id or when full."""
        s = self.settings
        with self._lock:
            if self._closed:
                raise InputError.one(None, "the service is shutting down", status_code=503)
            bearing_id = req.id or self._new_id(req.designation.strip().upper())
            if not _ID_RE.match(bearing_id):
                raise InputError.one("id", f"{bearing_id!r}: letters, digits, '_', '.', '-' only "
                                     "(it is used in URLs and zenoh key expressions)")
            if bearing_id in self._twins or bearing_id in self._reserved:
                raise InputError.one("id", f"a twin named {bearing_id!r} already exists",
                                     status_code=409)
            if len(self._twins) + len(self._reserved) >= s.max_twins:
                raise InputError.one(None, f"this service already runs {len(self._twins)} twins "
                                     f"(max_twins = {s.max_twins})", [0, s.max_twins], status_code=409)
            # reserve the id while the (slow) model is built outside the lock
            self._reserved.add(bearing_id)
        entry = None
        try:
            twin = self.build_twin(req, bearing_id)
            runner = TwinRunner(twin, fast=s.fast, publish_rate_hz=s.publish_rate_hz, frame_s=s.frame_s,
                                token=s.token_value, setpoint_rate_hz=s.setpoint_rate_hz or None,
                                setpoint_burst=s.setpoint_burst, max_payload_bytes=s.max_body_bytes)
            entry = TwinEntry(id=bearing_id, twin=twin, runner=runner,
                              lubricant=twin.model.spec.lubricant.name)
            if self.bus is not None:
                entry.channel = self.bus.attach_twin(bearing_id, runner.latest_snapshot,
                                                     runner.submit_setpoint_json)
                runner.add_sink(entry.channel)
            if self.recorder is not None:
                self.recorder.add_twin_from(twin, context=lambda: runner.scenario)
                runner.add_sink(self.recorder)
            runner.start()
        except BaseException:
            with self._lock:
                self._reserved.discard(bearing_id)
            if entry is not None:
                entry.runner.stop(timeout=2.0)
                self._unwire(entry)
            raise
        with self._lock:
            self._reserved.discard(bearing_id)
            if self._closed:   # closed while building: do not leak a running thread
                entry.runner.stop(timeout=2.0)
                self._unwire(entry)
                raise InputError.one(None, "the service is shutting down", status_code=503)
            self._twins[bearing_id] = entry
        log.info("twin %s started (%s, Pd = %g m, %s, %s mode)", bearing_id, entry.designation,
                 entry.diametral_clearance_m, entry.lubricant, runner.mode)
        return entry

    def delete_twin(self, bearing_id: str) -> TwinEntry:
        with self._lock:
            entry = self._twins.get(bearing_id)
            if entry is None:
                self.get(bearing_id)  # raises the 404
            del self._twins[bearing_id]
        entry.runner.stop(timeout=5.0)
        self._unwire(entry)
        return entry

    # ---- per-twin recordings ---------------------------------------------------------------
    def recordings_dir(self) -> Path:
        rec = self.settings.record
        return rec.parent if rec is not None else Path("recordings")

    def resolve_recording_path(self, bearing_id: str, path: str | None) -> Path:
        """The checked relative path (or the default name) under the recordings directory; the
        file system is not touched (InputError 422 naming `path`)."""
        from service.recording.paths import RecordingPathError, check_relative_path

        if not path:
            stamp = datetime.now(UTC).strftime("%Y%m%dT%H%M%SZ")
            return self.recordings_dir() / f"{bearing_id}-{stamp}.rrd"
        try:
            rel = check_relative_path(path)
        except RecordingPathError as exc:
            raise InputError.one("path", str(exc)) from None
        return self.recordings_dir() / rel

    def start_recording(self, entry: TwinEntry, path: str | None) -> Path:
        """Start the twin's own recording in a new file under the recordings directory: created
        exclusively, never through a link, never over an existing file (422 naming `path`, the
        file system unchanged). Without a path: `<id>-<UTC>.rrd` (a taken name gets `.runN`)."""
        target = self.resolve_recording_path(entry.id, path)
        main = getattr(self.recorder, "path", None) or self.settings.recording_path
        if main is not None:
            from service.recording import is_segment_of

            if is_segment_of(main, target):
                raise InputError.one("path", f"{str(target)!r} is the service-wide recording or one of its segments")
        recorder_cls = _recorder_class()
        from service.recording import RecordingPathError, RecordingWriteError, create_exclusive, create_recording

        streams = self.rerun_streams()
        with self._recording_lock:
            self.stop_recording(entry)
            try:
                if path:
                    created = create_exclusive(self.recordings_dir(), target.relative_to(self.recordings_dir()).as_posix())
                else:
                    created = create_recording(target, rename=True)
            except RecordingPathError as exc:
                raise InputError.one("path", f"{' '.join(str(exc).split())[:300]}") from None
            try:
                rec = recorder_cls(created, **recorder_options(self.settings), streams=streams)
            except (OSError, RuntimeError, ValueError, RecordingWriteError) as exc:
                created.discard()            # removed (it was made for this start), descriptors closed
                raise InputError.one("path", f"cannot record to {str(target)!r}: "
                                     f"{' '.join(str(exc).split())[:200]}") from None
            rec.add_twin_from(entry.twin, context=lambda: entry.runner.scenario)
            entry.recording, entry.recording_path = rec, created.path
            entry.runner.add_sink(rec)
        return created.path

    def stop_recording(self, entry: TwinEntry) -> tuple[Path | None, int]:
        """Finish the twin's own recording (flushed, complete; its rerun streams freed);
        returns (path, rows written)."""
        with self._recording_lock:
            rec, path = entry.recording, entry.recording_path
            if rec is None:
                return None, 0
            entry.runner.remove_sink(rec)
            entry.recording = None
        try:
            rec.close()
        except Exception:
            log.exception("closing the recording of %s", entry.id)
        return path, int(getattr(rec, "rows_logged", 0))

    # ---- health ----------------------------------------------------------------------------
    def recording_health(self) -> dict:
        """The state of the service's recordings: the service-wide one, and any per-twin one
        that cannot write (`service.recording.recorder` "Faults")."""
        recs = [r for r in [self.recorder, *(e.recording for e in self.entries())] if r is not None]
        faults = [f"{getattr(r, 'path', None)}: {r.fault}" for r in recs if getattr(r, "fault", None)]
        return {"recording_status": "off" if not recs else "degraded" if faults else "ok",
                "recording_error": "; ".join(faults) or None,
                "recording_write_errors": sum(int(getattr(r, "write_errors", 0)) for r in recs),
                "recording_rows_lost": sum(int(getattr(r, "rows_lost", 0)) for r in recs)}

    def health(self) -> dict:
        twins = [e.runner.stats() for e in self.entries()]
        recording = self.recording_health()
        degraded = any((not t["running"]) or t["errors"] for t in twins) or recording["recording_status"] == "degraded"
        rec = self.recorder
        return {
            "status": "degraded" if degraded else "ok",
            "uptime_s": time.monotonic() - self.started_wall_s,
            "twins": twins,
            "zenoh": self.bus is not None and not getattr(self.bus, "closed", False),
            "zenoh_listen": list(self.settings.zenoh_listen) if self.bus is not None else [],
            "recording": str(rec.path) if rec is not None and getattr(rec, "path", None) else None,
            "recording_rows": int(getattr(rec, "rows_logged", 0)) if rec is not None else 0,
            **recording,
            "pid": os.getpid(),
            "rss_bytes": _own_rss_bytes(),
        }


def _own_rss_bytes() -> int | None:
    """Resident set size of this process from /proc/self/status (None elsewhere)."""
    try:
        with open("/proc/self/status", encoding="ascii") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        return None
    return None
