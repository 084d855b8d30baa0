"""The composition root: `TwinService` = the core's `TwinRegistry` with the zenoh bus, the
rerun recorders and the OPC UA facade opened from the settings. This is the ONE module that
touches `service.bus`, `service.recorder` and `service.opcua` for the service (imported lazily,
so a service with zenoh, recording or OPC UA off never imports them). The alarm hub of the
registry hands its events to the bus (registry), the recorder and the OPC UA facade (here).

Every recorder of the service makes its rerun streams through one `RerunStreams` owned by the
`TwinService` (`rerun_streams()`): a per-twin recording gets a new recorder (its own recording
id) per start, and its streams are freed when it stops (rerun-sdk 0.41 would keep them, and
their threads, forever: see the recorder's module doc).
"""

from __future__ import annotations

import logging
import re
from pathlib import Path
from typing import Any

from service.core.admission import AdmissionGate
from service.core.registry import Recorder, TwinEntry, TwinRegistry
from service.settings import ServiceSettings

log = logging.getLogger(__name__)

__all__ = ["TwinEntry", "TwinService", "WiringError", "open_bus", "open_opcua", "open_recorder",
           "recorder_options"]


class WiringError(RuntimeError):
    """A component the settings ask for is missing or failed to start."""


def open_bus(settings: ServiceSettings):
    """The service's zenoh bus, or None when zenoh is disabled. WiringError (one line) when it
    cannot be opened (e.g. the listen port is taken)."""
    if not settings.enable_zenoh:
        return None
    try:
        from service.bus.zenoh_bus import ZenohBus
    except ImportError as exc:
        raise WiringError(f"zenoh is enabled but service.bus cannot be imported ({exc}); "
                          "install eclipse-zenoh or run with --no-zenoh") from exc
    try:
        return ZenohBus(listen=settings.zenoh_listen, connect=settings.zenoh_connect, mode=settings.zenoh_mode)
    except (RuntimeError, ValueError) as exc:
        text = re.sub(r"\s+at \S+\.rs:\d+\.?", "", " ".join(str(exc).split()))   # zenoh's Rust source lines
        hint = (" (is another service listening there? choose another with --zenoh-listen, or --no-zenoh)"
                if "already in use" in text else "")
        raise WiringError(text + hint) from exc


def _recorder_class():
    try:
        from service.recorder import RerunRecorder
    except ImportError as exc:
        raise WiringError(f"recording is enabled but service.recorder cannot be imported ({exc}); "
                          "install rerun-sdk or run with --no-record") from exc
    return RerunRecorder


def recorder_options(settings: ServiceSettings) -> dict:
    """Send interval, segment rotation and footer of every recording the service writes."""
    return dict(flush_interval_s=settings.record_flush_interval_s,
                segment_s=settings.record_segment_s or None,
                segment_bytes=round(settings.record_segment_mb * 1e6) or None,
                write_footer=settings.record_footer)


def open_recorder(settings: ServiceSettings, streams: Any = None):
    """The service-wide rerun recorder, or None when recording (and the viewer) are off.
    `streams`: the service's `RerunStreams`, shared with the per-twin recordings (stream creation
    and reclaim must not run concurrently, see `service.recorder.RerunStreams`)."""
    path = settings.recording_path
    if path is None and not settings.spawn_viewer:
        return None
    extra = {} if streams is None else {"streams": streams}
    return _recorder_class()(path, spawn_viewer=settings.spawn_viewer, **recorder_options(settings), **extra)


def open_opcua(settings: ServiceSettings, registry: TwinRegistry):
    """The OPC UA facade serving `registry` (started), or None when `settings.opcua` is unset.
    WiringError (one line) when it cannot start (e.g. the port is taken)."""
    if not settings.opcua:
        return None
    try:
        from service.opcua import OpcUaError, OpcUaFacade
    except ImportError as exc:
        raise WiringError(f"OPC UA is enabled but service.opcua cannot be imported ({exc}); "
                          "install asyncua or run without --opcua") from exc
    try:
        return OpcUaFacade(registry, settings.opcua).start()
    except (OpcUaError, ValueError) as exc:
        hint = (" (is another server listening there? choose another port with --opcua)"
                if "address already in use" in str(exc).lower() or "errno 98" in str(exc).lower() else "")
        raise WiringError(f"{exc}{hint}") from exc


class TwinService(TwinRegistry):
    """The twins of one service, wired to zenoh and rerun as the settings say."""

    def __init__(self, settings: ServiceSettings, gate: AdmissionGate | None = None):
        super().__init__(settings, gate)
        self._rerun_streams = None          # service.recorder.RerunStreams, made on first use
        self.opcua = None                   # service.opcua.OpcUaFacade when settings.opcua is set

    def rerun_streams(self):
        """The `RerunStreams` that makes and frees every rerun stream of this service."""
        with self._lock:
            if self._rerun_streams is None:
                _recorder_class()
                from service.recorder import RerunStreams

                self._rerun_streams = RerunStreams()
            return self._rerun_streams

    def _open_outputs(self) -> None:
        self.bus = open_bus(self.settings)
        if self.settings.recording_path is not None or self.settings.spawn_viewer:
            self.recorder = open_recorder(self.settings, self.rerun_streams())
        if self.recorder is not None and hasattr(self.recorder, "log_alarm"):
            self.alarms.subscribe(self.recorder.log_alarm)     # alarm events into the recording
        self.opcua = open_opcua(self.settings, self)
        if self.opcua is not None:
            self.alarms.subscribe(self.opcua.on_alarm)

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
        if self.bus is not None:
            try:
                self.bus.close()
            except Exception:
                log.exception("closing the zenoh bus")

    def _new_recording(self, path: Path) -> Recorder:
        recorder_cls = _recorder_class()
        streams = self.rerun_streams()
        try:
            return recorder_cls(path, **recorder_options(self.settings), streams=streams)
        except BaseException:
            streams.reclaim()            # the stream made for the file that failed
            raise
