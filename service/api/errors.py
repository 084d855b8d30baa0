"""Exception handlers: every error answer has the body {"detail": [{"field", "message",
"allowed"}]} (service.core.errors.FieldError), never a stack trace."""

from __future__ import annotations

import logging

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from pydantic import ValidationError
from starlette.exceptions import HTTPException as StarletteHTTPException

from service.api.schemas import request_bounds
from service.core.errors import FieldError, InputError, field_errors, setpoint_field_errors
from service.core.scenarios import ScenarioError
from twin.setpoint import SetpointError

log = logging.getLogger(__name__)


def error_response(status: int, errors: list[FieldError], headers: dict | None = None) -> JSONResponse:
    return JSONResponse(
        status_code=status, content={"detail": [e.model_dump() for e in errors]}, headers=headers or None
    )


def _limits_of(request: Request):
    """The setpoint limits of the twin named in the path, if there is one."""
    bearing_id = request.path_params.get("bearing_id")
    registry = getattr(request.app.state, "service", None)
    if bearing_id is None or registry is None:
        return None
    entry = registry.find(bearing_id)
    return entry.runner.limits if entry is not None else None


async def _input_error(request: Request, exc: InputError):
    return error_response(exc.status_code, exc.errors, exc.headers)


async def _request_validation(request: Request, exc: RequestValidationError):
    setpoint_body = request.url.path.rstrip("/").endswith("/setpoint")  # PUT /v1/bearings/{id}/setpoint
    return error_response(
        422, field_errors(list(exc.errors()), _limits_of(request), request_bounds(), setpoint_body=setpoint_body)
    )


async def _validation(request: Request, exc: ValidationError):
    return error_response(422, field_errors(exc.errors(), None, request_bounds()))


async def _setpoint_error(request: Request, exc: SetpointError):
    return error_response(422, setpoint_field_errors(exc))


async def _scenario_error(request: Request, exc: ScenarioError):
    return error_response(422, [FieldError(field=exc.field, message=exc.message, allowed=exc.allowed)])


async def _http_error(request: Request, exc: StarletteHTTPException):
    return error_response(
        exc.status_code, [FieldError(field=None, message=str(exc.detail))], getattr(exc, "headers", None)
    )


async def _unexpected(request: Request, exc: Exception):
    log.exception("unexpected error on %s %s", request.method, request.url.path)
    return error_response(
        500, [FieldError(field=None, message=f"internal error ({type(exc).__name__}); see the service log")]
    )


def install_error_handlers(app: FastAPI) -> None:
    # FastAPI.exception_handler registers each handler for its own exception type (Starlette types
    # add_exception_handler's handler for any Exception)
    app.exception_handler(InputError)(_input_error)
    app.exception_handler(RequestValidationError)(_request_validation)
    app.exception_handler(ValidationError)(_validation)
    app.exception_handler(SetpointError)(_setpoint_error)
    app.exception_handler(ScenarioError)(_scenario_error)
    app.exception_handler(StarletteHTTPException)(_http_error)
    app.exception_handler(Exception)(_unexpected)
