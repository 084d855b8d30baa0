"""A measured node temperature for the twin's thermal network to follow (twin.thermal.estimator:
a Kalman filter on the dissipation to the surroundings), one vocabulary for every way in: HTTP
`PUT /v1/bearings/{id}/temperature`, zenoh `{prefix}/{id}/temperature`, OPC UA and the scenario
step `temperature`."""

from __future__ import annotations

from typing import Any, Literal, get_args

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from service.core.errors import InputError, field_errors
from twin.thermal.coupling import TEMPERATURE_RANGE_C  # what a measured temperature may be [degC]

MeasurableNode = Literal["outer_ring", "housing", "oil"]
MEASURABLE_NODES: tuple[str, ...] = get_args(MeasurableNode)
"""The nodes a measurement may name: twin.thermal.coupling.MEASURABLE_NODES."""


class MeasuredTemperature(BaseModel):
    """One measured node temperature (the nodes of twin.thermal.coupling.MEASURABLE_NODES)."""

    model_config = ConfigDict(frozen=True, extra="forbid", strict=True, allow_inf_nan=False)
    node: MeasurableNode = Field(default="outer_ring", description="Measured node [text].")
    temperature_c: float = Field(
        ge=TEMPERATURE_RANGE_C[0], le=TEMPERATURE_RANGE_C[1], description="Measured temperature [degC]."
    )


def parse_measured_temperature(data: Any) -> MeasuredTemperature:
    """A parsed JSON body as a MeasuredTemperature; InputError (422) naming each field with its
    allowed values for a wrong type, an out-of-range or non-finite number, or an unknown field."""
    if not isinstance(data, dict):
        raise InputError.one(
            None,
            f'a measured temperature is a JSON object {{"node": ..., "temperature_c": ...}}, got {type(data).__name__}',
            ["node", "temperature_c"],
        )
    try:
        return MeasuredTemperature.model_validate(data)
    except ValidationError as exc:
        raise InputError(field_errors(exc.errors(), model=MeasuredTemperature)) from None
