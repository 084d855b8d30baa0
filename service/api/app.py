"""The HTTP API: `create_app(settings) -> FastAPI`, an app factory (no module-level singletons).

As in vLLM's OpenAI server (`build_app` + lifespan + `app.state`) and full-stack-fastapi-
template (one `APIRouter` per resource, `Depends` in `deps.py`):

* lifespan: opens the service (`service.wiring.TwinService`: the twins, the zenoh bus and the
  rerun recorder as the settings say) unless one was handed in already open (the CLI opens it
  before uvicorn so that a busy zenoh port is a one-line error), and closes it in `finally`
  (runners stopped, zenoh detached and closed, recordings flushed);
* routers (service.api.routers): health, bearings, setpoint, state, alarms, scenarios, recording,
  docs;
  each resource has a `read` and a `write` router, and the factory decides which need the
  bearer token (writes when BEARING_TWIN_TOKEN is set, reads too with read_requires_token;
  /health never) - so the OpenAPI document declares the bearer scheme exactly where it applies,
  without patching;
* dependencies (service.api.deps): the registry, the twin, the token, the setpoint rate;
  middleware (service.api.middleware): the body size cap, the per-client read rate, the token
  of writes answered before routing and the tarpit for clients over their error budget;
* the server (service.api.server): uvicorn with header/body deadlines for slow clients, a
  connection cap and an access log that never shows a token;
* errors (service.api.errors): always {"detail": [{"field", "message", "allowed"}]}.

Run ONE uvicorn worker per service: each worker would run its own lifespan and its own twins.
"""

from __future__ import annotations

import logging
import threading
from contextlib import asynccontextmanager
from typing import Any

from fastapi import Depends, FastAPI
from starlette.concurrency import run_in_threadpool

from service import __version__
from service.api.deps import require_token
from service.api.errors import install_error_handlers
from service.api.middleware import BodySizeLimit, NoSniff, ReadRateLimit, Tarpit, TarpitStats, TokenGate
from service.api.routers import (
    alarms,
    bearings,
    defects,
    docs,
    health,
    measured,
    recording,
    scenarios,
    setpoint,
    state,
    temperature,
)
from service.api.schemas import ErrorResponse
from service.core.registry import TwinRegistry, admission_gate
from service.settings import ServiceSettings, is_loopback_host

log = logging.getLogger(__name__)

_UNAUTHORIZED = {401: {"model": ErrorResponse, "description": "Missing or wrong bearer token"}}


def access_summary(settings: ServiceSettings) -> str:
    """One line: whether a token is required, and for what."""
    if settings.security.token is None:
        return "no token (BEARING_TWIN_TOKEN unset): anyone who can reach the port may change setpoints"
    reads = "reads too (except /health)" if settings.security.read_requires_token else "reads open"
    return f"bearer token required for POST/PUT/DELETE (HTTP only, never sent on zenoh); {reads}"


def create_app(settings: ServiceSettings | None = None, *, service: TwinRegistry | None = None) -> FastAPI:
    """The FastAPI application for one service (see the module docstring). `service`: an
    already open service to serve (and close at shutdown) instead of opening one."""
    settings = settings or ServiceSettings()
    gate = service.gate if service is not None else admission_gate(settings)

    @asynccontextmanager
    async def lifespan(app: FastAPI):
        log.info(
            "bearing-twin: HTTP bound to %s:%s (%s); %s",
            settings.http.host,
            settings.http.port,
            "loopback only" if is_loopback_host(settings.http.host) else "reachable from other machines",
            access_summary(settings),
        )
        opened = service
        if opened is None:
            from service.wiring import TwinService

            opened = TwinService(settings, gate=gate)
            await run_in_threadpool(opened.open)
        app.state.service = opened
        opened.priority.keep_thread(threading.get_native_id())  # the event loop answers /health in time
        try:
            yield
        finally:
            app.state.service = None
            await run_in_threadpool(opened.close)

    app = FastAPI(
        title="bearing-twin",
        version=__version__,
        summary="Real-time DEM digital twin of lubricated ball bearings",
        description="Setpoints in, live contact state out. Units are in every field name and "
        "description (SI, oil temperature in degC). State schema 'bearing-twin/state/1'; the same "
        "snapshots stream on zenoh `bearing/{id}/state` and `bearing/{id}/ball/{i}`.",
        lifespan=lifespan,
        openapi_url=None,
        docs_url=None,
        redoc_url=None,
        telemetry={"tracing": False, "metrics": False, "logs": False},
    )
    app.state.settings = settings
    app.state.gate = gate
    app.state.service = None
    app.state.tarpit = TarpitStats()
    app.add_middleware(BodySizeLimit, gate=gate)
    app.add_middleware(ReadRateLimit, gate=gate)  # a refused read costs the least
    app.add_middleware(TokenGate, gate=gate, reads=settings.security.read_requires_token)
    app.add_middleware(
        Tarpit,
        gate=gate,
        delay_s=settings.security.tarpit_delay_s,
        max_held=settings.security.tarpit_max_held,
        stats=app.state.tarpit,
    )  # sees every refusal
    app.add_middleware(NoSniff)  # outermost: marks every answer, the tarpit's too
    install_error_handlers(app)

    token = [Depends(require_token)] if gate.requires_token else []
    writes: dict[str, Any] = {
        "dependencies": token,
        "responses": {
            **(_UNAUTHORIZED if token else {}),
            413: {"model": ErrorResponse, "description": f"Body larger than {settings.security.max_body_bytes} bytes"},
        },
    }
    reads: dict[str, Any] = (
        {"dependencies": token, "responses": _UNAUTHORIZED} if token and settings.security.read_requires_token else {}
    )
    app.include_router(setpoint.write, **writes)  # first: the latency-critical route is matched first
    app.include_router(health.router)
    for router in (bearings.read, state.read, alarms.read, defects.read, measured.read, scenarios.read, docs.read):
        app.include_router(router, **reads)
    for router in (
        bearings.write,
        defects.write,
        measured.write,
        scenarios.write,
        recording.write,
        temperature.write,
    ):
        app.include_router(router, **writes)
    docs.mount_assets(app)
    return app
