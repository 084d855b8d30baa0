"""The HTTP API: `create_app(settings) -> FastAPI` (a factory: no module-level singletons).

The lifespan opens a `TwinService` (zenoh bus if enabled, rerun recorder if enabled, the
`default` twin) and closes it in `finally` (runners stopped, zenoh detached and closed,
recordings flushed). Run ONE uvicorn worker per service: each worker would run its own lifespan
and its own twins.

Errors always have the body {"detail": [{"field", "message", "allowed"}]}: 422 for invalid
input (the field, what is wrong, the allowed [low, high] in the field's unit), 404 for an unknown
twin, 409 for a duplicate twin id, never a stack trace.
"""

from __future__ import annotations

import logging
from contextlib import asynccontextmanager
from typing import Annotated

from fastapi import Body, FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse, Response
from pydantic import ValidationError
from starlette.concurrency import run_in_threadpool
from starlette.exceptions import HTTPException as StarletteHTTPException

from service.core.scenarios import (
    ScenarioError,
    find_scenario,
    list_scenarios,
    load_scenario,
    scenario_from_dict,
)
from service.api.schemas import (
    BearingCreate,
    BearingInfo,
    ErrorResponse,
    FieldError,
    Health,
    InputError,
    RecordingRequest,
    RecordingStatus,
    ScenarioAccepted,
    ScenarioList,
    ScenarioRequest,
    ScenarioStatus,
    SetpointResponse,
    field_errors,
    parse_setpoint,
    setpoint_error,
)
from service.core.admission import HardeningMiddleware
from service.settings import ServiceSettings
from service.core.registry import TwinEntry, TwinService
from twin.setpoint import SetpointError, SetpointUpdate
from twin.snapshot import SetpointState, Snapshot

log = logging.getLogger(__name__)

_ERRORS = {404: {"model": ErrorResponse, "description": "Unknown twin"},
           422: {"model": ErrorResponse, "description": "Invalid input: field, message, allowed range"}}


def _error(status: int, errors: list[FieldError]) -> JSONResponse:
    return JSONResponse(status_code=status, content={"detail": [e.model_dump() for e in errors]})


def _info(entry: TwinEntry) -> BearingInfo:
    r = entry.runner
    latest = r.latest
    handle = r.scenario
    return BearingInfo(
        id=entry.id, designation=entry.designation, kind=entry.twin.model.spec.kind,
        ball_count=entry.twin.model.ball_count, diametral_clearance_m=entry.diametral_clearance_m,
        lubricant=entry.lubricant, mode=r.mode, running=r.running,
        time_s=latest.time_s if latest is not None else 0.0,
        setpoint=SetpointState(**r.target_setpoint.model_dump()),
        limits={k: (float(lo), float(hi)) for k, (lo, hi) in r.limits.items()},
        scenario=ScenarioStatus(**handle.status()) if handle is not None else None,
        state_url=f"/v1/bearings/{entry.id}/state", zenoh_state_key=f"bearing/{entry.id}/state")


def _loopback(host: str) -> bool:
    return host in ("127.0.0.1", "localhost", "::1") or host.startswith("127.")


def access_summary(settings: ServiceSettings) -> str:
    """One line: whether a token is required, and for what."""
    if settings.token is None:
        return ("no token (BEARING_TWIN_TOKEN unset): anyone who can reach the port may change "
                "setpoints")
    reads = "reads too (except /health)" if settings.read_requires_token else "reads open"
    return f"bearer token required for POST/PUT/DELETE and zenoh setpoints; {reads}"


def _document_hardening(app: FastAPI, settings: ServiceSettings) -> None:
    """OpenAPI: the bearer scheme (when a token is set) and the 401/413/429 answers."""
    base_openapi = app.openapi

    def openapi() -> dict:
        if app.openapi_schema is not None:
            return app.openapi_schema
        schema = base_openapi()
        error_ref = {"content": {"application/json": {"schema": {"$ref": "#/components/schemas/ErrorResponse"}}}}
        if settings.token is not None:
            schema.setdefault("components", {}).setdefault("securitySchemes", {})["bearerToken"] = {
                "type": "http", "scheme": "bearer",
                "description": "BEARING_TWIN_TOKEN of the service"}
        for path, item in schema.get("paths", {}).items():
            for method, op in item.items():
                if method not in ("get", "put", "post", "delete", "patch"):
                    continue
                responses = op.setdefault("responses", {})
                mutating = method != "get"
                if settings.token is not None and (mutating or (settings.read_requires_token and path != "/health")):
                    op["security"] = [{"bearerToken": []}]
                    responses.setdefault("401", {"description": "Missing or wrong bearer token", **error_ref})
                if mutating:
                    responses.setdefault("413", {"description": f"Body larger than {settings.max_body_bytes} bytes",
                                                 **error_ref})
                if method == "put" and path.endswith("/setpoint") and settings.setpoint_rate_hz:
                    responses.setdefault("429", {"description": "Too many setpoints for this twin; see Retry-After",
                                                 "headers": {"Retry-After": {"schema": {"type": "integer"},
                                                                             "description": "seconds"}},
                                                 **error_ref})
        app.openapi_schema = schema
        return schema

    app.openapi = openapi


def create_app(settings: ServiceSettings | None = None) -> FastAPI:
    """The FastAPI application for one service (see the module docstring)."""
    settings = settings or ServiceSettings()

    @asynccontextmanager
    async def lifespan(app: FastAPI):
        log.info("bearing-twin: HTTP bound to %s:%s (%s); %s", settings.host, settings.port,
                 "loopback only" if _loopback(settings.host) else "reachable from other machines",
                 access_summary(settings))
        service = TwinService(settings)
        await run_in_threadpool(service.open)
        app.state.service = service
        try:
            yield
        finally:
            await run_in_threadpool(service.close)

    app = FastAPI(
        title="bearing-twin",
        version="0.1.0",
        summary="Real-time DEM digital twin of lubricated ball bearings",
        description="Setpoints in, live contact state out. Units are in every field name and "
        "description (SI, oil temperature in degC). State schema 'bearing-twin/state/1'; the same "
        "snapshots stream on zenoh `bearing/{id}/state` and `bearing/{id}/ball/{i}`.",
        lifespan=lifespan,
    )
    app.state.settings = settings
    app.state.service = None
    app.add_middleware(HardeningMiddleware, token=settings.token_value,
                       read_requires_token=settings.read_requires_token,
                       max_body_bytes=settings.max_body_bytes,
                       get_service=lambda: app.state.service)
    _document_hardening(app, settings)

    def svc(request: Request) -> TwinService:
        return request.app.state.service

    # ---- error handlers ---------------------------------------------------------------------
    @app.exception_handler(InputError)
    async def _input_error(request: Request, exc: InputError):
        return _error(exc.status_code, exc.errors)

    @app.exception_handler(RequestValidationError)
    async def _request_validation(request: Request, exc: RequestValidationError):
        limits = None
        bearing_id = request.path_params.get("bearing_id")
        if bearing_id is not None and request.url.path.endswith("/setpoint"):
            try:
                limits = svc(request).get(bearing_id).runner.limits
            except Exception:  # noqa: BLE001
                limits = None
        return _error(422, field_errors(list(exc.errors()), limits))

    @app.exception_handler(ValidationError)
    async def _validation(request: Request, exc: ValidationError):
        return _error(422, field_errors(exc.errors()))

    @app.exception_handler(SetpointError)
    async def _setpoint_error(request: Request, exc: SetpointError):
        return _error(422, [setpoint_error(exc)])

    @app.exception_handler(ScenarioError)
    async def _scenario_error(request: Request, exc: ScenarioError):
        return _error(422, [FieldError(field=exc.field, message=exc.message, allowed=exc.allowed)])

    @app.exception_handler(StarletteHTTPException)
    async def _http_error(request: Request, exc: StarletteHTTPException):
        return _error(exc.status_code, [FieldError(field=None, message=str(exc.detail))])

    @app.exception_handler(Exception)
    async def _unexpected(request: Request, exc: Exception):
        log.exception("unexpected error on %s %s", request.method, request.url.path)
        return _error(500, [FieldError(field=None, message=f"internal error ({type(exc).__name__}); "
                                       "see the service log")])

    # ---- health -----------------------------------------------------------------------------
    @app.get("/health", response_model=Health, tags=["service"])
    def health(request: Request) -> Health:
        """Service status, uptime and per-twin real-time factor, overruns and drops."""
        return Health(**svc(request).health())

    # ---- bearings ---------------------------------------------------------------------------
    @app.get("/v1/bearings", response_model=list[BearingInfo], tags=["bearings"])
    def list_bearings(request: Request) -> list[BearingInfo]:
        """The twins of this service."""
        return [_info(e) for e in svc(request).entries()]

    @app.post("/v1/bearings", response_model=BearingInfo, status_code=201, tags=["bearings"],
              responses={409: {"model": ErrorResponse, "description": "Duplicate id or service full"},
                         422: _ERRORS[422]})
    def create_bearing(request: Request, body: BearingCreate) -> BearingInfo:
        """Create and start a twin from a catalog designation, a diametral clearance and a
        lubricant (warm-started at the optional initial setpoint)."""
        return _info(svc(request).create_twin(body))

    @app.get("/v1/bearings/{bearing_id}", response_model=BearingInfo, tags=["bearings"], responses=_ERRORS)
    def get_bearing(request: Request, bearing_id: str) -> BearingInfo:
        """One twin: bearing, mounting, setpoint, limits, scenario."""
        return _info(svc(request).get(bearing_id))

    @app.delete("/v1/bearings/{bearing_id}", tags=["bearings"], responses=_ERRORS)
    def delete_bearing(request: Request, bearing_id: str) -> dict:
        """Stop a twin and withdraw it from zenoh (its liveliness token disappears)."""
        entry = svc(request).delete_twin(bearing_id)
        return {"deleted": entry.id}

    @app.put("/v1/bearings/{bearing_id}/setpoint", response_model=SetpointResponse, tags=["bearings"],
             responses=_ERRORS)
    def put_setpoint(request: Request, bearing_id: str,
                     update: Annotated[SetpointUpdate, Body(description="Partial setpoint: missing fields keep "
                                                            "their value; units in the field names.")]) -> SetpointResponse:
        """Partial setpoint update, validated against the bearing's limits; applied by the twin's
        runner at its next frame. Returns the complete setpoint."""
        entry = svc(request).get(bearing_id)
        setpoint = entry.runner.submit(parse_setpoint(update, entry.runner.limits))
        return SetpointResponse(bearing_id=entry.id, setpoint=SetpointState(**setpoint.model_dump()),
                                frame_s=entry.runner.frame_s)

    @app.get("/v1/bearings/{bearing_id}/state", tags=["bearings"],
             responses={200: {"model": Snapshot, "description": "Latest snapshot, schema bearing-twin/state/1"},
                        **_ERRORS, 503: {"model": ErrorResponse, "description": "No snapshot yet"}})
    def get_state(request: Request, bearing_id: str) -> Response:
        """The latest published snapshot (the public contract, schema bearing-twin/state/1)."""
        entry = svc(request).get(bearing_id)
        snap = entry.runner.latest
        if snap is None:
            raise InputError.one(None, "no snapshot yet", status_code=503)
        return Response(content=snap.to_json(), media_type="application/json")

    # ---- scenarios --------------------------------------------------------------------------
    @app.get("/v1/scenarios", response_model=ScenarioList, tags=["scenarios"])
    def get_scenarios() -> ScenarioList:
        """Named scenarios (files in the scenarios directory)."""
        directory = settings.scenarios_path
        out: dict[str, str] = {}
        for name, path in list_scenarios(directory).items():
            try:
                out[name] = load_scenario(path).description.strip()
            except ScenarioError as exc:
                out[name] = f"(invalid: {exc})"
        return ScenarioList(directory=str(directory), scenarios=out)

    @app.post("/v1/bearings/{bearing_id}/scenario", response_model=ScenarioAccepted, status_code=202,
              tags=["scenarios"], responses=_ERRORS)
    def post_scenario(request: Request, bearing_id: str, body: ScenarioRequest) -> ScenarioAccepted:
        """Run a named scenario (scenarios/<name>.yaml) or an inline one on this twin, in its
        runner (a scenario already running is cancelled). Returns at once."""
        entry = svc(request).get(bearing_id)
        if (body.name is None) == (body.scenario is None):
            raise InputError.one("name", "give either 'name' (a scenario file) or 'scenario' (inline)",
                                 sorted(list_scenarios(settings.scenarios_path)))
        if body.name is not None:
            scenario = find_scenario(body.name, settings.scenarios_path)
        else:
            try:
                scenario = scenario_from_dict(body.scenario)
            except ScenarioError as exc:
                raise ScenarioError(f"scenario.{exc.field}", exc.message, exc.allowed) from None
        runs = scenario.resolved_runs()
        if body.run is None:
            run = runs[0]
        else:
            matching = [r for r in runs if r.id == body.run]
            if not matching:
                raise InputError.one("run", f"scenario {scenario.name!r} has no run {body.run!r}",
                                     [r.id for r in runs])
            run = matching[0]
        run.check_twin(entry.designation, entry.diametral_clearance_m, entry.lubricant,
                       entry.twin.model.spec.thermal)
        _handle, replaced = entry.runner.start_scenario(run, restart=body.restart)
        return ScenarioAccepted(accepted=True, bearing_id=entry.id, name=scenario.name, run=run.id,
                                expected_duration_s=run.duration_s, mode=entry.runner.mode,
                                replaced=replaced.name if replaced is not None else None,
                                warnings=scenario.warnings)

    @app.get("/v1/bearings/{bearing_id}/scenario", response_model=ScenarioStatus | None,
             tags=["scenarios"], responses=_ERRORS)
    def get_scenario(request: Request, bearing_id: str) -> ScenarioStatus | None:
        """The running (or last) scenario of this twin, null if none ran."""
        handle = svc(request).get(bearing_id).runner.scenario
        return ScenarioStatus(**handle.status()) if handle is not None else None

    @app.delete("/v1/bearings/{bearing_id}/scenario", response_model=ScenarioStatus | None,
                tags=["scenarios"], responses=_ERRORS)
    def cancel_scenario(request: Request, bearing_id: str) -> ScenarioStatus | None:
        """Cancel the running scenario; the setpoint stays where the scenario left it."""
        handle = svc(request).get(bearing_id).runner.cancel_scenario()
        return ScenarioStatus(**handle.status()) if handle is not None else None

    # ---- recording --------------------------------------------------------------------------
    @app.post("/v1/bearings/{bearing_id}/recording", response_model=RecordingStatus, tags=["recording"],
              responses=_ERRORS)
    def post_recording(request: Request, bearing_id: str, body: RecordingRequest) -> RecordingStatus:
        """Start ({"action": "start", "path": "name.rrd"}) or stop ({"action": "stop"}) a rerun
        recording of this twin alone, besides the service-wide one. Paths are relative to the
        service's recordings directory."""
        service = svc(request)
        entry = service.get(bearing_id)
        if body.action == "start":
            path = service.start_recording(entry, body.path)
            return RecordingStatus(bearing_id=entry.id, recording=True, path=str(path), rows_logged=0)
        if body.path is not None:
            raise InputError.one("path", "give a path only with action 'start'")
        path, rows = service.stop_recording(entry)
        return RecordingStatus(bearing_id=entry.id, recording=False,
                               path=str(path) if path is not None else None, rows_logged=rows)

    return app
