"""The twins: list, one, create, delete."""

from __future__ import annotations

from typing import Any

from fastapi import APIRouter

from service.api.deps import RegistryDep, TwinDep
from service.api.schemas import BearingCreate, BearingInfo, ErrorResponse, ScenarioStatus
from service.core.registry import TwinEntry
from service.keys import DEFAULT_PREFIX, STATE, twin_key

UNKNOWN_TWIN: dict[int | str, dict[str, Any]] = {404: {"model": ErrorResponse, "description": "Unknown twin"}}
INVALID: dict[int | str, dict[str, Any]] = {
    422: {"model": ErrorResponse, "description": "Invalid input: field, message, allowed range"}
}

read = APIRouter(prefix="/v1/bearings", tags=["bearings"])
write = APIRouter(prefix="/v1/bearings", tags=["bearings"])


def bearing_info(entry: TwinEntry) -> BearingInfo:
    r = entry.runner
    latest = r.latest
    handle = r.scenario
    return BearingInfo(
        id=entry.id,
        designation=entry.designation,
        kind=entry.twin.model.spec.kind,
        ball_count=entry.twin.model.ball_count,
        diametral_clearance_m=entry.diametral_clearance_m,
        lubricant=entry.lubricant,
        mode=r.mode,
        running=r.running,
        time_s=latest.time_s if latest is not None else 0.0,
        setpoint=r.target_setpoint,
        limits=r.limits.as_dict(),
        scenario=ScenarioStatus(**handle.status()) if handle is not None else None,
        state_url=f"/v1/bearings/{entry.id}/state",
        zenoh_state_key=twin_key(
            entry.channel.bus.prefix if entry.channel is not None else DEFAULT_PREFIX, entry.id, STATE
        ),
    )


@read.get("", response_model=list[BearingInfo])
def list_bearings(registry: RegistryDep) -> list[BearingInfo]:
    """The twins of this service."""
    return [bearing_info(e) for e in registry.entries()]


@read.get("/{bearing_id}", response_model=BearingInfo, responses={**UNKNOWN_TWIN, **INVALID})
def get_bearing(entry: TwinDep) -> BearingInfo:
    """One twin: bearing, mounting, setpoint, limits, scenario."""
    return bearing_info(entry)


@write.post(
    "",
    response_model=BearingInfo,
    status_code=201,
    responses={
        409: {"model": ErrorResponse, "description": "Duplicate id or service full"},
        **INVALID,
        503: {
            "model": ErrorResponse,
            "description": "This host cannot run the twin in real time "
            "(measured capacity: the reason and the figures), or the service is stopping",
        },
    },
)
def create_bearing(body: BearingCreate, registry: RegistryDep) -> BearingInfo:
    """Create and start a twin from a catalog designation, a diametral clearance and a
    lubricant, or from a whole bearing spec (`spec`, for a bearing not in the catalog),
    warm-started at the optional initial setpoint."""
    return bearing_info(registry.create_twin(id=body.id, **body.twin_options()))


@write.delete("/{bearing_id}", responses={**UNKNOWN_TWIN, **INVALID})
def delete_bearing(entry: TwinDep, registry: RegistryDep) -> dict:
    """Stop a twin and withdraw it from zenoh (its liveliness token disappears)."""
    return {"deleted": registry.delete_twin(entry.id).id}
