"""The composition root: `TwinService` = the core's `TwinRegistry` with the zenoh bus, the
rerun recorders and the OPC UA facade opened from the settings. This is the ONE module that
touches `service.bus`, `service.recording` and `service.opcua` for the service (imported lazily,
so a service with zenoh, recording or OPC UA off never imports them). The alarm hub of the
registry hands its events to the bus (registry), the service-wide recording and each twin's own
recording, and the OPC UA facade (here).

Every recorder of the service makes its rerun streams through one `RerunStreams` owned by the
`TwinService` (`rerun_streams()`): a per-twin recording gets a new recorder (its own recording
id) per start, and its streams are freed when it stops (rerun-sdk 0.41 would keep them, and
their threads, forever: see the recorder's module doc).
"""

from __future__ import annotations

import contextlib
import logging
import re
from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING, Any

from service.core.admission import AdmissionGate
from service.core.errors import InputError
from service.core.registry import Recorder, TwinEntry, TwinRegistry
from service.settings import ServiceSettings

if TYPE_CHECKING:
    from service.recording import RerunRecorder

log = logging.getLogger(__name__)

__all__ = [
    "TwinEntry",
    "TwinService",
    "WiringError",
    "open_bus",
    "open_live_viewer",
    "open_opcua",
    "open_recorder",
    "recorder_options",
]


class WiringError(RuntimeError):
    """A component the settings ask for is missing or failed to start."""


@contextlib.contextmanager
def _importing(feature: str, package: str, remedy: str):
    """The imports of an enabled `feature`: a WiringError saying `remedy` when they fail."""
    try:
        yield
    except ImportError as exc:
        raise WiringError(f"{feature} is enabled but {package} cannot be imported ({exc}); {remedy}") from exc


def open_bus(settings: ServiceSettings):
    """The service's zenoh bus, or None when zenoh is disabled. WiringError (one line) when it
    cannot be opened (e.g. the listen port is taken)."""
    if not settings.zenoh.enabled:
        return None
    with _importing("zenoh", "service.bus", "install eclipse-zenoh or run with --no-zenoh"):
        from service.bus.access import ZenohAccess
        from service.bus.zenoh_bus import ZenohBus
    owner = {"http": f"http://{settings.http.host}:{settings.http.port}"} if settings.http.port else {}
    try:
        return ZenohBus(
            listen=settings.zenoh.listen,
            connect=settings.zenoh.connect,
            mode=settings.zenoh.mode,
            prefix=settings.zenoh.prefix,
            owner=owner,
            access=ZenohAccess.from_settings(settings.zenoh, enforce=True),
            # another peer's claim on a twin id counts when zenoh authenticated it, or
            # when nothing is secured; never when only the HTTP API is (service.bus.zenoh_bus)
            trust_claims=settings.zenoh.access_control or settings.security.token is None,
        )
    except (RuntimeError, ValueError) as exc:
        text = re.sub(r"\s+at \S+\.rs:\d+\.?", "", " ".join(str(exc).split()))  # zenoh's Rust source lines
        hint = (
            " (is another service listening there? choose another with --zenoh-listen, or --no-zenoh)"
            if "already in use" in text
            else ""
        )
        raise WiringError(text + hint) from exc


def _recorder_class():
    with _importing("recording", "service.recording", "install rerun-sdk or run with --no-record"):
        from service.recording import RerunRecorder
    return RerunRecorder


def recorder_options(settings: ServiceSettings) -> dict:
    """Trend window, sampling of the bearing now, send interval, segment rotation and footer of
    every recording the service writes."""
    return dict(
        **_recorder_class().SERVICE_OPTIONS,
        flush_interval_s=settings.recording.flush_interval_s,
        segment_s=settings.recording.segment_s or None,
        segment_bytes=round(settings.recording.segment_mb * 1e6) or None,
        write_footer=settings.recording.footer,
    )


def open_recorder(settings: ServiceSettings, streams: Any = None):
    """The service-wide rerun recorder, or None when recording (and the viewer) are off.
    `streams`: the service's `RerunStreams`, shared with the per-twin recordings (stream creation
    and reclaim must not run concurrently, see `service.recording.RerunStreams`)."""
    path = settings.recording.active_path
    if path is None and not settings.recording.spawn_viewer and settings.recording.web_port is None:
        return None
    cls = _recorder_class()
    from service.recording import RecordingPathError, RecordingWriteError, Retention

    extra = {} if streams is None else {"streams": streams}
    retention = None
    if path is not None and (settings.recording.keep_mb > 0 or settings.recording.keep_hours > 0):
        retention = Retention.for_recording(
            path, keep_bytes=round(settings.recording.keep_mb * 1e6), keep_age_s=settings.recording.keep_hours * 3600.0
        )
    try:
        return cls(
            path,
            spawn_viewer=settings.recording.spawn_viewer,
            retention=retention,
            **recorder_options(settings),
            **extra,
        )
    except (RecordingPathError, RecordingWriteError, OSError) as exc:
        raise WiringError(
            f"cannot record to {str(path)!r}: {' '.join(str(exc).split())[:300]} "
            "(--record PATH.rrd elsewhere, or --no-record)"
        ) from None


def open_live_viewer(settings: ServiceSettings, recorder):
    """rerun's web viewer serving the live recording (`service.recording.live`), connected to
    `recorder`, or None when `settings.recording.web_port` is unset. WiringError (one line) when it
    cannot start or the bind is refused (a non-loopback address while a token is set)."""
    if settings.recording.web_port is None or recorder is None:
        return None
    from service.recording.live import LiveViewerError, LiveWebViewer, check_bind

    try:
        check_bind(settings.recording.web_bind, settings.security.token is not None)
        live = LiveWebViewer(
            settings.recording.web_port,
            host=settings.recording.web_bind,
            memory_limit_mb=settings.recording.web_memory_mb,
        ).start()
    except (LiveViewerError, ValueError, OSError) as exc:
        raise WiringError(f"rerun web viewer: {exc}") from None
    try:
        recorder.connect_viewer(live.grpc_url)
    except Exception as exc:  # noqa: BLE001 - any failure of rerun's connection is reported as a wiring error
        live.close()
        raise WiringError(f"rerun web viewer: cannot connect the recording: {exc}") from None
    log.warning("rerun web viewer: open %s (bound to %s)", live.url(), live.host)
    return live


def open_opcua(settings: ServiceSettings, registry: TwinRegistry):
    """The OPC UA facade serving `registry` (started), or None when `settings.opcua.endpoint` is unset.
    WiringError (one line) when it cannot start (e.g. the port is taken)."""
    if not settings.opcua.endpoint:
        return None
    with _importing("OPC UA", "service.opcua", "install asyncua or run without --opcua"):
        from service.opcua import OpcUaError, OpcUaFacade
    try:
        return OpcUaFacade(registry, settings.opcua.endpoint).start()
    except (OpcUaError, ValueError) as exc:
        hint = (
            " (is another server listening there? choose another port with --opcua)"
            if "address already in use" in str(exc).lower() or "errno 98" in str(exc).lower()
            else ""
        )
        raise WiringError(f"{exc}{hint}") from exc


class TwinService(TwinRegistry):
    """The twins of one service, wired to zenoh and rerun as the settings say."""

    recorder: RerunRecorder | None  # the service-wide recording (open_recorder)

    def __init__(self, settings: ServiceSettings, gate: AdmissionGate | None = None):
        super().__init__(settings, gate)
        self._rerun_streams = None  # service.recording.RerunStreams, made on first use
        self.opcua = None  # service.opcua.OpcUaFacade when settings.opcua.endpoint is set
        self.live_viewer = None  # service.recording.live.LiveWebViewer when rerun_web_port is set

    def rerun_streams(self):
        """The `RerunStreams` that makes and frees every rerun stream of this service."""
        with self._lock:
            if self._rerun_streams is None:
                _recorder_class()
                from service.recording import RerunStreams

                self._rerun_streams = RerunStreams()
            return self._rerun_streams

    def _open_outputs(self) -> None:
        self.bus = open_bus(self.settings)
        if (
            self.settings.recording.active_path is not None
            or self.settings.recording.spawn_viewer
            or self.settings.recording.web_port is not None
        ):
            self.recorder = open_recorder(self.settings, self.rerun_streams())
        self.live_viewer = open_live_viewer(self.settings, self.recorder)
        if self.recorder is not None:
            self.alarms.subscribe(self.recorder.log_alarm)  # alarm events into the recording
        self.alarms.subscribe(self._alarm_to_twin_recording)
        self.opcua = open_opcua(self.settings, self)
        if self.opcua is not None:
            self.alarms.subscribe(self.opcua.on_alarm)

    def _alarm_to_twin_recording(self, event) -> None:
        """An alarm event into the twin's own recording, if it has one (POST .../recording)."""
        entry = self.find(event.bearing_id)
        rec = entry.recording if entry is not None else None
        if rec is not None:
            rec.log_alarm(event)

    def _close_outputs(self) -> None:
        if self.opcua is not None:
            try:
                self.opcua.close()
            except Exception:
                log.exception("closing the OPC UA server")
        if self.recorder is not None:
            try:
                self.recorder.close()
            except Exception:
                log.exception("closing the recorder")
        if self.live_viewer is not None:
            self.live_viewer.close()
            self.live_viewer = None
        if self.bus is not None:
            try:
                self.bus.close()
            except Exception:
                log.exception("closing the zenoh bus")

    def _unwire(self, e) -> None:
        recorder = self.recorder
        super()._unwire(e)
        if recorder is not None:
            try:
                recorder.remove_twin(e.id)  # its rows are written, its entry freed
            except Exception:
                log.exception("removing twin %s from the recording", e.id)

    # ---- per-twin recordings: append-only, inside the recordings directory ------------------
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

    def start_recording(self, entry, path: str | None) -> Path:
        """Start the twin's own recording in a new file under the recordings directory: created
        exclusively, never through a link, never over an existing file (422 naming `path`, the
        file system unchanged). Without a path: `<id>-<UTC>.rrd` (a taken name gets `.runN`)."""
        target = self.resolve_recording_path(entry.id, path)
        main = getattr(self.recorder, "path", None) or self.settings.recording.active_path
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
                    created = create_exclusive(
                        self.recordings_dir(), target.relative_to(self.recordings_dir()).as_posix()
                    )
                else:
                    created = create_recording(target, rename=True)
            except RecordingPathError as exc:
                raise InputError.one("path", f"{' '.join(str(exc).split())[:300]}") from None
            try:
                rec = recorder_cls(created, **recorder_options(self.settings), streams=streams)
            except (OSError, RuntimeError, ValueError, RecordingWriteError) as exc:
                created.discard()  # removed (it was made for this start), descriptors closed
                raise InputError.one(
                    "path", f"cannot record to {str(target)!r}: {' '.join(str(exc).split())[:200]}"
                ) from None
            rec.add_twin_from(entry.twin, context=lambda: entry.runner.scenario)
            entry.recording, entry.recording_path = rec, created.path
            entry.runner.add_sink(rec)
        return created.path

    # ---- health ----------------------------------------------------------------------------
    def recording_health(self) -> dict:
        """The state of the service's recordings: the service-wide one, and any per-twin one
        that cannot write (`service.recording.recorder` "Faults")."""
        recs = [r for r in [self.recorder, *(e.recording for e in self.entries())] if r is not None]
        faults = [f"{getattr(r, 'path', None)}: {r.fault}" for r in recs if getattr(r, "fault", None)]
        return {
            "recording_status": "off" if not recs else "degraded" if faults else "ok",
            "recording_error": "; ".join(faults) or None,
            "recording_write_errors": sum(int(getattr(r, "write_errors", 0)) for r in recs),
            "recording_rows_lost": sum(int(getattr(r, "rows_lost", 0)) for r in recs),
        }

    def health(self) -> dict:
        out = super().health()
        recording = self.recording_health()
        out.update(recording)
        if recording["recording_status"] == "degraded":
            out["status"] = "degraded"
        return out

    def _new_recording(self, path: Path) -> Recorder:
        recorder_cls = _recorder_class()
        streams = self.rerun_streams()
        try:
            return recorder_cls(path, **recorder_options(self.settings), streams=streams)
        except BaseException:
            streams.reclaim()  # the stream made for the file that failed
            raise
