"""The `http` (bind address and connection limits) and `security` (token, rate limits, tarpit)
settings groups of `bearing-twin serve` (docs/operations.md)."""

from __future__ import annotations

import socket
from typing import Any

from pydantic import BaseModel, ConfigDict, Field, SecretStr, field_validator

from service.settings.flat import flat


class HttpSettings(BaseModel):
    """Where the HTTP API listens and how long it waits for slow clients."""

    model_config = ConfigDict(extra="forbid", hide_input_in_errors=True)

    host: str = Field(
        default="127.0.0.1",
        json_schema_extra=flat("host"),
        description="HTTP bind address [IP or host name]; loopback only unless set "
        "(0.0.0.0 exposes the API on every interface).",
    )
    port: int = Field(
        default=8000,
        ge=0,
        le=65535,
        json_schema_extra=flat("port"),
        description="HTTP port [TCP port number, 0 = any free port].",
    )
    header_timeout_s: float = Field(
        default=10.0,
        gt=0.0,
        le=600.0,
        json_schema_extra=flat(
            "http_header_timeout_s",
            details="Counted from the connection's opening, or from the next request's "
            "first byte on a kept-alive connection: it cuts off slow clients.",
        ),
        description="Time a request's line and headers may take; then 408 and the connection is closed [s].",
    )
    body_timeout_s: float = Field(
        default=30.0,
        gt=0.0,
        le=3600.0,
        json_schema_extra=flat("http_body_timeout_s"),
        description="Time a request body may take after its headers; then 408 and the connection is closed [s].",
    )
    keep_alive_s: int = Field(
        default=5,
        ge=1,
        le=3600,
        json_schema_extra=flat("http_keep_alive_s"),
        description="An idle kept-alive HTTP connection is closed after this long (uvicorn timeout_keep_alive) [s].",
    )
    max_connections: int = Field(
        default=256,
        ge=8,
        le=100_000,
        json_schema_extra=flat(
            "http_max_connections",
            details="uvicorn's limit_concurrency.",
        ),
        description="Open HTTP connections (or running requests) beyond which a new request gets 503 [count].",
    )

    @field_validator("host")
    @classmethod
    def _bindable_host(cls, value: str) -> str:
        """An address the server can bind: an IP address or a name that resolves (checked here, so
        a typo is refused naming the setting, not reported by the server after the start)."""
        try:
            socket.getaddrinfo(value, None, type=socket.SOCK_STREAM)
        except (OSError, UnicodeError):
            raise ValueError(f"{value!r} is not an IP address nor a host name that resolves") from None
        return value


class SecuritySettings(BaseModel):
    """Who may write and read, and how fast: the bearer token, rate limits and the tarpit."""

    model_config = ConfigDict(extra="forbid", hide_input_in_errors=True)

    token: SecretStr | None = Field(
        default=None,
        json_schema_extra=flat(
            "token",
            details="Reads need it too with read_requires_token. zenoh never uses "
            'it. Environment only: it has no flag (docs/operations.md "Access").',
        ),
        description="Bearer token of mutating HTTP requests, and OPC UA password [text]; unset = no authentication.",
    )
    read_requires_token: bool = Field(
        default=False,
        json_schema_extra=flat("read_requires_token"),
        description="Also require the token for reads (GET), except GET /health [bool].",
    )
    setpoint_rate_hz: float = Field(
        default=50.0,
        ge=0.0,
        le=1e6,
        json_schema_extra=flat(
            "setpoint_rate_hz",
            details="Beyond it: HTTP 429 with Retry-After, and a refusal on the zenoh result key.",
        ),
        description="Sustained setpoint rate per twin, HTTP and zenoh together [1/s]; 0 = no limit.",
    )
    setpoint_burst: int = Field(
        default=100,
        ge=1,
        le=1_000_000,
        json_schema_extra=flat("setpoint_burst"),
        description="Setpoints a twin accepts in a burst before the rate applies [count].",
    )
    max_body_bytes: int = Field(
        default=64 * 1024,
        ge=256,
        le=64 * 1024 * 1024,
        json_schema_extra=flat("max_body_bytes"),
        description="Largest HTTP request body (and zenoh setpoint payload) accepted [bytes]; larger: 413.",
    )
    read_rate_hz: float = Field(
        default=100.0,
        ge=0.0,
        le=1e6,
        json_schema_extra=flat(
            "read_rate_hz",
            details="Beyond it: 429 with Retry-After naming the limit. /health and the docs are not counted.",
        ),
        description="Sustained rate of API reads (GET/HEAD under /v1/) per client address [1/s]; 0 = no limit.",
    )
    read_burst: int = Field(
        default=200,
        ge=1,
        le=1_000_000,
        json_schema_extra=flat("read_burst"),
        description="Reads a client may make in a burst before read_rate_hz applies [count].",
    )
    client_error_rate_hz: float = Field(
        default=5.0,
        ge=0.0,
        le=1e6,
        json_schema_extra=flat(
            "client_error_rate_hz",
            details="Every 4xx answer counts: a wrong or missing token, over a rate limit, invalid, unknown. Beyond "
            "it the client's refusals are held in the tarpit (tarpit_delay_s). /health is never counted nor held.",
        ),
        description="Sustained rate of refused HTTP requests a client address "
        "may cause before the tarpit [1/s]; 0 = no tarpit.",
    )
    client_error_burst: int = Field(
        default=20,
        ge=1,
        le=1_000_000,
        json_schema_extra=flat("client_error_burst"),
        description="Refused requests a client may cause in a burst before client_error_rate_hz applies [count].",
    )
    tarpit_delay_s: float = Field(
        default=2.0,
        ge=0.0,
        le=60.0,
        json_schema_extra=flat(
            "tarpit_delay_s",
            details="Each refusal is answered this long after it was decided, with Retry-After. The wait is an "
            "asyncio timer (no thread, no CPU), so a client that waits for its answers before sending more (a "
            "closed-loop flood) slows itself down.",
        ),
        description="Delay of each refusal to a client over its error "
        "budget (client_error_rate_hz) [s]; 0 = no tarpit.",
    )
    tarpit_max_held: int = Field(
        default=64,
        ge=1,
        le=100_000,
        json_schema_extra=flat(
            "tarpit_max_held",
            details="Refusals answered at once are counted in /health http_tarpit. "
            "Below http_max_connections: the held connections count against it.",
        ),
        description="Refusals held in the tarpit at one time, at most "
        "[count]; beyond it a refusal is answered at once.",
    )

    @field_validator("token", mode="before")
    @classmethod
    def _token(cls, value: Any) -> Any:
        if isinstance(value, SecretStr):
            value = value.get_secret_value()
        if value is None:
            return None
        if isinstance(value, str):
            if not value.strip():
                return None  # BEARING_TWIN_TOKEN="" means no token
            if any(c.isspace() or not c.isprintable() for c in value):
                raise ValueError("the token must be printable characters without spaces")
        return value

    @property
    def token_value(self) -> str | None:
        """The token in clear (None when authentication is off)."""
        return self.token.get_secret_value() if self.token is not None else None
