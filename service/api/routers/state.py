"""GET /v1/bearings/{id}/state: the latest snapshot, the public contract."""

from __future__ import annotations

from fastapi import APIRouter
from fastapi.responses import Response

from service.api.deps import TwinDep
from service.api.routers.bearings import INVALID, UNKNOWN_TWIN
from service.api.schemas import ErrorResponse
from service.core.errors import InputError
from twin.snapshot import Snapshot

read = APIRouter(prefix="/v1/bearings", tags=["bearings"])


@read.get(
    "/{bearing_id}/state",
    responses={
        200: {"model": Snapshot, "description": "Latest snapshot, schema bearing-twin/state/1"},
        **UNKNOWN_TWIN,
        **INVALID,
        503: {"model": ErrorResponse, "description": "No snapshot yet"},
    },
)
async def get_state(entry: TwinDep) -> Response:
    """The latest published snapshot (the public contract, schema bearing-twin/state/1).

    Served from the JSON the runner's publisher serialised once for that snapshot
    (TwinRunner.latest_json): a read costs no serialisation and no worker thread."""
    body = entry.runner.latest_json()
    if body is None:
        raise InputError.one(None, "no snapshot yet", status_code=503)
    return Response(content=body, media_type="application/json")
