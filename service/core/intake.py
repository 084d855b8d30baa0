"""Setpoints that arrive as raw payloads (zenoh `bearing/{id}/setpoint`): the admission gate,
then the same validation and mailbox as HTTP.

`SetpointIntake(bearing_id, gate, runner)(payload) -> dict` never raises. In order: the size cap
(413), the token (401: with a token configured the payload must be a JSON object carrying it as
"token", removed before validation, never echoed), the twin's rate budget (429, shared with
HTTP), the strict setpoint vocabulary and the bearing's limits (422). The answer is
{"accepted": True, "setpoint": {...}} or {"accepted": False, "status": 401 | 413 | 422 | 429,
"error": "...", ...}, what the transport publishes on the result key.
"""

from __future__ import annotations

import json
import threading
from typing import Any

from service.core.admission import AdmissionGate, Refusal
from service.core.errors import InputError
from service.core.runner import TwinRunner, parse_update

_MISSING_TOKEN = 'missing token: send the setpoint as a JSON object with a "token" field'


class SetpointIntake:
    """One twin's payload handler (see the module docstring)."""

    def __init__(self, bearing_id: str, gate: AdmissionGate, runner: TwinRunner):
        self.bearing_id, self.gate, self.runner = bearing_id, gate, runner
        self._lock = threading.Lock()
        self.refused = 0          # payloads refused, any reason

    def __call__(self, payload: bytes | str) -> dict:
        try:
            refusal = self.gate.check_size(len(payload))
            if refusal is not None:
                return self._refused(refusal)
            data: Any = _NOT_PARSED
            if self.gate.requires_token:
                data = _loads(payload)
                given = data.pop("token", None) if isinstance(data, dict) else None
                if given is not None and not isinstance(given, str):
                    given = ""            # a wrong type is a wrong token, never a crash
                refusal = self.gate.check_token(given, missing=_MISSING_TOKEN)
                if refusal is not None:
                    return self._refused(refusal)
            refusal = self.gate.take_setpoint(self.bearing_id)
            if refusal is not None:
                return self._refused(refusal)
            if data is _NOT_PARSED:
                data = _loads(payload)
            if data is _INVALID:
                raise InputError.one(None, "payload is not valid JSON")
            setpoint = self.runner.submit(parse_update(data, self.runner.limits))
            return {"accepted": True, "setpoint": setpoint.model_dump()}
        except InputError as exc:
            self._count()
            return {"accepted": False, "status": exc.status_code, "error": str(exc),
                    "detail": [e.model_dump() for e in exc.errors]}
        except Exception as exc:  # noqa: BLE001 - a refusal, never a crash
            self._count()
            return {"accepted": False, "status": 422, "error": f"{type(exc).__name__}: {exc}"}

    def _count(self) -> None:
        with self._lock:
            self.refused += 1

    def _refused(self, refusal: Refusal) -> dict:
        self._count()
        out = {"accepted": False, "status": refusal.status, "error": refusal.message}
        if refusal.retry_after_s is not None:
            out["retry_after_s"] = refusal.retry_after_s
        return out


_NOT_PARSED = object()
_INVALID = object()


def _loads(payload: bytes | str) -> Any:
    try:
        return json.loads(payload)
    except (ValueError, UnicodeDecodeError, RecursionError):
        return _INVALID
