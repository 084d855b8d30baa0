"""Setpoints (and local defects, `DefectIntake`; measured temperatures, `TemperatureIntake`)
that arrive as raw payloads (zenoh `{prefix}/{id}/setpoint`): the admission gate, then the same
validation and mailbox as HTTP.

`SetpointIntake(bearing_id, gate, runner)(payload) -> dict` never raises. In order: whether the
bus may write at all (403 when the HTTP API needs a token but zenoh access control is off: see
service.core.admission), the size cap (413), the twin's rate budget (429, shared with HTTP), the
strict setpoint vocabulary and the bearing's limits (422). A payload never carries a token (the
HTTP token would be readable by every subscriber of the key): a "token" field is refused (422,
field `token`, never echoed). The answer is {"accepted": True, "setpoint": {...}} or
{"accepted": False, "status": 403 | 413 | 422 | 429, "error": "...", ...}, what the transport
publishes on the result key.
"""

from __future__ import annotations

import json
import threading
from typing import Any

from service.core.admission import AdmissionGate, Refusal
from service.core.errors import InputError
from service.core.measured_temperature import parse_measured_temperature
from service.core.runner import TwinRunner, parse_update

_TOKEN_FIELD = (
    "zenoh setpoints carry no token (every subscriber of the key could read it): who "
    "may write is zenoh's access control (BEARING_TWIN_ZENOH_WRITERS); remove the field"
)


class SetpointIntake:
    """One twin's payload handler (see the module docstring)."""

    def __init__(self, bearing_id: str, gate: AdmissionGate, runner: TwinRunner):
        self.bearing_id, self.gate, self.runner = bearing_id, gate, runner
        self._lock = threading.Lock()
        self.refused = 0  # payloads refused, any reason

    def __call__(self, payload: bytes | str) -> dict:
        try:
            refusal = self.gate.check_bus_writer() or self.gate.check_size(len(payload))
            if refusal is not None:
                return self._refused(refusal)
            refusal = self.gate.take_setpoint(self.bearing_id)
            if refusal is not None:
                return self._refused(refusal)
            data = _loads(payload)
            if data is _INVALID:
                raise InputError.one(None, "payload is not valid JSON")
            if isinstance(data, dict) and "token" in data:
                raise InputError.one("token", _TOKEN_FIELD)
            return {"accepted": True, **self._apply(data)}
        except InputError as exc:
            self._count()
            return {
                "accepted": False,
                "status": exc.status_code,
                "error": str(exc),
                "detail": [e.model_dump() for e in exc.errors],
            }
        except Exception as exc:  # noqa: BLE001 - a refusal, never a crash
            self._count()
            return {"accepted": False, "status": 422, "error": f"{type(exc).__name__}: {exc}"}

    def _apply(self, data: Any) -> dict:
        setpoint = self.runner.submit(parse_update(data, self.runner.limits))
        return {"setpoint": setpoint.model_dump()}

    def _count(self) -> None:
        with self._lock:
            self.refused += 1

    def _refused(self, refusal: Refusal) -> dict:
        self._count()
        out = {"accepted": False, "status": refusal.status, "error": refusal.message}
        if refusal.retry_after_s is not None:
            out["retry_after_s"] = refusal.retry_after_s
        return out


class DefectIntake(SetpointIntake):
    """Local defects as raw payloads (zenoh `{prefix}/{id}/defects`): the same gate
    (bus writer, size, the twin's setpoint budget), then `TwinRunner.submit_defects` (the
    bearing's own geometry, 422 naming the field). A payload is {"defects": [...]} or the list
    itself; [] clears them. The answer carries "defects": [...] when accepted."""

    def _apply(self, data: Any) -> dict:
        items = self.runner.submit_defects(data)
        return {"defects": [d.model_dump() for d in items]}


class TemperatureIntake(SetpointIntake):
    """Measured temperatures as raw payloads (zenoh `{prefix}/{id}/temperature`): the same gate
    (bus writer, size, the twin's setpoint budget), then the vocabulary of PUT
    `/v1/bearings/{id}/temperature` (service.core.measured_temperature: 422 naming the field and
    its range) and `TwinRunner.submit_temperature` (409 with the fixed oil temperature). A payload
    is {"node": "outer_ring", "temperature_c": 62.5}; the answer carries "node" and
    "temperature_c" when accepted."""

    def _apply(self, data: Any) -> dict:
        measured = parse_measured_temperature(data)
        self.runner.submit_temperature(measured)
        return measured.model_dump()


_INVALID = object()


def _loads(payload: bytes | str) -> Any:
    try:
        return json.loads(payload)
    except (ValueError, UnicodeDecodeError, RecursionError):
        return _INVALID
