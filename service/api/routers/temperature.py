"""PUT /v1/bearings/{id}/temperature: a measured temperature for the twin's thermal network to
follow (twin.thermal.estimator: a Kalman filter on the dissipation to the surroundings)."""

from __future__ import annotations

from fastapi import APIRouter, Depends
from pydantic import BaseModel, Field

from service.api.deps import TwinDep, setpoint_rate
from service.api.routers.bearings import INVALID, UNKNOWN_TWIN
from service.api.routers.setpoint import TOO_MANY
from service.core.measured_temperature import MeasuredTemperature

write = APIRouter(prefix="/v1/bearings", tags=["thermal"])


class TemperatureResponse(BaseModel):
    """The measurement is assimilated at the twin's next network step."""

    bearing_id: str = Field(description="Twin name [text].")
    node: str = Field(description="Measured node [text].")
    temperature_c: float = Field(description="Measured temperature [degC].")


@write.put(
    "/{bearing_id}/temperature",
    response_model=TemperatureResponse,
    dependencies=[Depends(setpoint_rate)],
    responses={**UNKNOWN_TWIN, **INVALID, **TOO_MANY},
)
def put_temperature(entry: TwinDep, body: MeasuredTemperature) -> TemperatureResponse:
    """Hand a measured temperature to the twin's dissipation estimator; the snapshot's `thermal`
    block then carries the estimate, its uncertainty and the residual (409 with the fixed oil
    temperature, 422 naming the field and its range)."""
    entry.runner.submit_temperature(body)
    return TemperatureResponse(bearing_id=entry.id, node=body.node, temperature_c=body.temperature_c)
