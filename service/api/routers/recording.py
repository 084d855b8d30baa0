"""POST /v1/bearings/{id}/recording: a recording of one twin, besides the service-wide one."""

from __future__ import annotations

from fastapi import APIRouter

from service.api.deps import RegistryDep, TwinDep
from service.api.routers.bearings import INVALID, UNKNOWN_TWIN
from service.api.schemas import RecordingRequest, RecordingStatus
from service.core.errors import InputError

write = APIRouter(prefix="/v1/bearings", tags=["recording"])


@write.post("/{bearing_id}/recording", response_model=RecordingStatus, responses={**UNKNOWN_TWIN, **INVALID})
def post_recording(entry: TwinDep, body: RecordingRequest, registry: RegistryDep) -> RecordingStatus:
    """Start ({"action": "start", "path": "name.rrd"}) or stop ({"action": "stop"}) a rerun
    recording of this twin alone, besides the service-wide one. Paths are relative to the
    service's recordings directory."""
    if body.action == "start":
        path = registry.start_recording(entry, body.path)
        return RecordingStatus(bearing_id=entry.id, recording=True, path=str(path), rows_logged=0)
    if body.path is not None:
        raise InputError.one("path", "give a path only with action 'start'")
    stopped, rows = registry.stop_recording(entry)
    return RecordingStatus(
        bearing_id=entry.id, recording=False, path=str(stopped) if stopped is not None else None, rows_logged=rows
    )
