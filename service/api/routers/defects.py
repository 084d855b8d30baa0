"""PUT / DELETE / GET /v1/bearings/{id}/defects: local defects of a twin (the
vocabulary of twin.vibration.defects, validated by service.core.defects against the bearing's
own geometry and applied by the twin's runner at its next frame, like a setpoint)."""

from __future__ import annotations

from typing import Any

from fastapi import APIRouter, Depends
from pydantic import BaseModel, ConfigDict, Field

from service.api.deps import TwinDep, setpoint_rate
from service.api.routers.bearings import INVALID, UNKNOWN_TWIN
from service.api.routers.setpoint import TOO_MANY
from service.core.defects import MAX_DEFECTS

read = APIRouter(prefix="/v1/bearings", tags=["defects"])
write = APIRouter(prefix="/v1/bearings", tags=["defects"])

_VOCABULARY = (
    'Each defect: {"kind": "outer" | "inner" | "ball", "width_m" [m] (along the rolling direction), '
    '"length_m" [m] (across it), "depth_m" [m], "edge_radius_m" [m] (0 = sharp edges)}; outer: '
    '"azimuth_deg" [deg] from the load line; inner: "ring_angle_deg" [deg] on the rotating ring; ball: '
    '"ball_index" [-], "colatitude_deg", "longitude_deg" [deg] in ball body coordinates. The bearing\'s own '
    "limits apply: width up to the ball spacing on the raceway, length up to the groove arc the ball "
    f"touches, depth up to a quarter of the ball diameter; at most {MAX_DEFECTS} at once."
)


class DefectsRequest(BaseModel):
    """The complete set of local defects (replaces the active ones; [] clears them)."""

    model_config = ConfigDict(extra="forbid", strict=True)
    defects: list[dict[str, Any]] = Field(max_length=64, description=_VOCABULARY)


class DefectsResponse(BaseModel):
    """The defects in force from the twin's next frame."""

    bearing_id: str = Field(description="Twin name [text].")
    defects: list[dict[str, Any]] = Field(description="The defects, every field filled in (units in the names).")
    frame_s: float = Field(
        description="They apply at the runner's next frame boundary, within this much simulated time [s]."
    )


def _answer(entry, items: tuple) -> DefectsResponse:
    return DefectsResponse(bearing_id=entry.id, defects=[d.model_dump() for d in items], frame_s=entry.runner.frame_s)


@write.put(
    "/{bearing_id}/defects",
    response_model=DefectsResponse,
    dependencies=[Depends(setpoint_rate)],
    responses={**UNKNOWN_TWIN, **INVALID, **TOO_MANY},
)
def put_defects(entry: TwinDep, body: DefectsRequest) -> DefectsResponse:
    """Inject local defects (outer / inner race spall, ball defect) while the twin runs: checked
    against the bearing's own geometry (422 naming the field and the range), applied by the
    twin's runner at its next frame. Takes the twin's setpoint budget (429 when spent)."""
    return _answer(entry, entry.runner.submit_defects(body.defects))


@write.delete(
    "/{bearing_id}/defects",
    response_model=DefectsResponse,
    dependencies=[Depends(setpoint_rate)],
    responses={**UNKNOWN_TWIN, **INVALID, **TOO_MANY},
)
def delete_defects(entry: TwinDep) -> DefectsResponse:
    """Clear every local defect (healthy raceways and balls from the next frame)."""
    return _answer(entry, entry.runner.submit_defects([]))


@read.get("/{bearing_id}/defects", response_model=DefectsResponse, responses={**UNKNOWN_TWIN, **INVALID})
def get_defects(entry: TwinDep) -> DefectsResponse:
    """The defects accepted last (in force, or applied at the next frame)."""
    return _answer(entry, entry.runner.defect_box.target)
