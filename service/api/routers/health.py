"""GET /health: service status, uptime, per-twin runner figures (always open: the liveness probe)."""

from __future__ import annotations

from fastapi import APIRouter, Request

from service.api.deps import RegistryDep
from service.api.schemas import Health
from service.api.server import closures

router = APIRouter(tags=["service"])


@router.get("/health", response_model=Health)
def health(registry: RegistryDep, request: Request) -> Health:
    """Service status, uptime and per-twin real-time factor, overruns and drops."""
    tarpit = getattr(request.app.state, "tarpit", None)
    opcua = getattr(registry, "opcua", None)
    return Health(
        **registry.health(),
        http_slow_closed=closures.headers + closures.body,
        opcua_guard=opcua.guard.figures() if opcua is not None else None,
        http_tarpit={**tarpit.record(), "errors_over_budget": registry.gate.errors_over_budget}
        if tarpit is not None
        else None,
    )
