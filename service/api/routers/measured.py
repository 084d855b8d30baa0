"""POST /v1/bearings/{id}/vibration/measured and GET .../vibration/comparison: measured
accelerometer windows beside the twin (service.core.measured).

Upload: `Content-Type: application/json` with {"sample_rate_hz", "units": "m/s2" | "g",
"samples": [...], "shaft_hz" (optional; 0 or absent: the twin's shaft speed)}, or
`Content-Type: application/octet-stream` with raw little-endian float32 samples and the same fields
as query parameters (`?sample_rate_hz=12000&units=g`). The body obeys the service's body limit
(max_body_bytes: 64 KiB by default, 16 384 float32 samples). The answer is the comparison:
`measured` (the twin's analysis of the window), `predicted`, `residual` and `alarms`."""

from __future__ import annotations

import json
from typing import Any

from fastapi import APIRouter, Depends, Request
from fastapi.concurrency import run_in_threadpool

from service.api.deps import TwinDep, setpoint_rate
from service.api.routers.bearings import INVALID, UNKNOWN_TWIN
from service.api.routers.setpoint import TOO_MANY
from service.core.errors import InputError
from service.core.measured import window_from_float32, window_from_json

read = APIRouter(prefix="/v1/bearings", tags=["vibration"])
write = APIRouter(prefix="/v1/bearings", tags=["vibration"])


@write.post(
    "/{bearing_id}/vibration/measured",
    dependencies=[Depends(setpoint_rate)],
    responses={**UNKNOWN_TWIN, **INVALID, **TOO_MANY},
)
async def post_measured(
    entry: TwinDep,
    request: Request,
    sample_rate_hz: float | None = None,
    units: str = "m/s2",
    shaft_hz: float | None = None,
) -> dict[str, Any]:
    """Analyse one measured window with the twin's analysis and compare it with the twin's
    prediction at the same operating point (module docstring). 422 names the field and the
    allowed range (sample_rate_hz, units, samples, shaft_hz); takes the twin's setpoint budget."""
    body = await request.body()
    kind = request.headers.get("content-type", "application/json").split(";")[0].strip().lower()
    if kind == "application/octet-stream":
        if sample_rate_hz is None:
            raise InputError.one("sample_rate_hz", "required as a query parameter with a float32 body")
        window = window_from_float32(body, sample_rate_hz, units, shaft_hz)
    elif kind == "application/json":
        try:
            data = json.loads(body)
        except (ValueError, UnicodeDecodeError, RecursionError):
            raise InputError.one(None, "body is not valid JSON") from None
        window = window_from_json(data)
    else:
        raise InputError.one(
            None,
            f"content type {kind!r}: application/json or application/octet-stream",
            ["application/json", "application/octet-stream"],
            status_code=415,
        )
    comparator = entry.measured
    assert comparator is not None  # every twin gets one at creation (TwinRegistry)
    return await run_in_threadpool(comparator.receive, window)


@read.get("/{bearing_id}/vibration/comparison", responses={**UNKNOWN_TWIN})
def get_comparison(entry: TwinDep) -> dict[str, Any]:
    """The comparison of the last measured window (404 before the first one)."""
    latest = entry.measured.latest
    if latest is None:
        raise InputError.one(None, f"no measured window received yet for {entry.id!r}", status_code=404)
    return latest
