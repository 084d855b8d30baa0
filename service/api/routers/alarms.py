"""GET /v1/bearings/{id}/alarms: the twin's alarms (service.core.alarms) and its latest events."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Query
from pydantic import BaseModel, Field

from service.api.deps import RegistryDep, TwinDep
from service.api.routers.bearings import INVALID, UNKNOWN_TWIN
from service.core.alarms import Alarm, AlarmEvent

read = APIRouter(prefix="/v1/bearings", tags=["alarms"])


class AlarmList(BaseModel):
    """The alarms of one twin."""

    bearing_id: str = Field(description="Twin name [text].")
    active: list[Alarm] = Field(description="The active alarms [list].")
    alarms: list[Alarm] = Field(
        description="Every alarm the twin has, active or not, with its latest value and thresholds [list]."
    )
    events: list[AlarmEvent] = Field(
        description="The latest alarm events (raised, escalated, deescalated, cleared), oldest first [list]."
    )


@read.get(
    "/{bearing_id}/alarms",
    response_model=AlarmList,
    response_model_by_alias=True,
    responses={**UNKNOWN_TWIN, **INVALID},
)
def get_alarms(
    entry: TwinDep,
    registry: RegistryDep,
    events: Annotated[int, Query(ge=0, le=100000, description="How many of the latest events [count].")] = 50,
) -> AlarmList:
    """The twin's alarms: active ones, every alarm's state (value, thresholds, hysteresis) and
    the latest events; the same events stream on zenoh `bearing/{id}/alarm`."""
    states = registry.alarms.states(entry.id)
    return AlarmList(
        bearing_id=entry.id,
        active=[a for a in states if a.active],
        alarms=states,
        events=registry.alarms.events(entry.id, events),
    )
