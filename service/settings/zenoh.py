"""The `zenoh` settings group: key prefix, credentials and access roles (every process), and the
endpoints and mode of the service's or the router's session.

Access control is on when a users file, credentials or TLS client certificates are configured
(docs/operations.md "zenoh access control"). Then every zenoh link is authenticated (zenoh's
user-password handshake `transport.auth.usrpwd`, or mutual TLS) and the node that accepts links
(a listening service, `bearing-twin router`) applies zenoh's `access_control` rules built from the
three roles (service.bus.access): readers subscribe to state, ball and result keys, query
snapshots and see liveliness tokens; writers also put setpoints; services publish, answer
queries and declare liveliness tokens. A peer without credentials cannot open a link at all.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, SecretStr, ValidationInfo, field_validator, model_validator
from pydantic_settings import NoDecode

from service.keys import DEFAULT_PREFIX, PREFIX_WILDCARD_RE
from service.settings.flat import flat
from service.settings.values import NAME_RE, optional_path, read_usersfile, split_list, zenoh_access_enabled

DEFAULT_ZENOH_LISTEN = ["tcp/127.0.0.1:7447"]


class ZenohAccessConfig(BaseModel):
    """Key prefix, credentials and roles of a zenoh node: the service, the router and the bundled
    clients (`monitor`, `soak`, benchmarks)."""

    model_config = ConfigDict(extra="forbid", hide_input_in_errors=True)

    prefix: str = Field(
        default=DEFAULT_PREFIX,
        json_schema_extra=flat(
            "zenoh_prefix",
            metavar="PREFIX",
            details="A twin publishes under {prefix}/{id}/...; site / line / asset, up to 8 chunks of letters, "
            "digits, '_', '.', '-'. The router and the monitor also take patterns with '*' and '**' (e.g. plant1/**).",
        ),
        description="Key prefix of the twins on zenoh [key expression, e.g. plant1/line2/motor7].",
    )
    user: str | None = Field(
        default=None,
        json_schema_extra=flat(
            "zenoh_user",
            metavar="USER",
            details="The two are zenoh's user-password authentication.",
        ),
        description="User name this process presents to a zenoh router or peer [text]; with zenoh_password.",
    )
    password: SecretStr | None = Field(
        default=None,
        json_schema_extra=flat(
            "zenoh_password",
            details="Never give it on a command line.",
        ),
        description="Password of zenoh_user [text]; environment only (BEARING_TWIN_ZENOH_PASSWORD).",
    )
    usersfile: Path | None = Field(
        default=None,
        json_schema_extra=flat(
            "zenoh_usersfile",
            metavar="FILE",
            details="The file is zenoh's usrpwd dictionary; keep it readable by the service only.",
        ),
        description="Users allowed to connect to this process's zenoh "
        "endpoints [path to a file of `user:password` lines].",
    )
    writers: Annotated[list[str], NoDecode] = Field(
        default_factory=list,
        json_schema_extra=flat("zenoh_writers", metavar="NAME"),
        description="Users (or TLS certificate common names) that may put setpoints, and read [comma-separated names].",
    )
    readers: Annotated[list[str], NoDecode] = Field(
        default_factory=list,
        json_schema_extra=flat(
            "zenoh_readers",
            metavar="NAME",
            details="They read state, balls, setpoint results, snapshots and liveliness.",
        ),
        description="Users (or certificate common names) that may only read [comma-separated names].",
    )
    services: Annotated[list[str], NoDecode] = Field(
        default_factory=list,
        json_schema_extra=flat(
            "zenoh_services",
            metavar="NAME",
            details="They publish state, answer queries and declare liveliness "
            "tokens; the service's own zenoh_user is always one.",
        ),
        description="Users (or certificate common names) of twin services joining a router [comma-separated names].",
    )
    tls_root_ca: Path | None = Field(
        default=None,
        json_schema_extra=flat(
            "zenoh_tls_root_ca",
            metavar="CA.pem",
            details="With zenoh_tls_certificate and zenoh_tls_private_key: mutual TLS on tls/ endpoints.",
        ),
        description="CA certificate that signed every node's certificate [path, PEM].",
    )
    tls_certificate: Path | None = Field(
        default=None,
        json_schema_extra=flat("zenoh_tls_certificate", metavar="CERT.pem"),
        description="This process's TLS certificate [path, PEM]; its common name is the name the roles match.",
    )
    tls_private_key: Path | None = Field(
        default=None,
        json_schema_extra=flat("zenoh_tls_private_key", metavar="KEY.pem"),
        description="Private key of zenoh_tls_certificate [path, PEM].",
    )

    @field_validator("writers", "readers", "services", mode="before")
    @classmethod
    def _names(cls, value: Any) -> Any:
        names = split_list(value)
        for name in names:
            if not isinstance(name, str) or not NAME_RE.match(name):
                raise ValueError(
                    "role members are user names or certificate common names: 1-128 "
                    "letters, digits, '_', '.', '@', '+', '-'"
                )
        return list(dict.fromkeys(names))

    @field_validator("user", mode="before")
    @classmethod
    def _user(cls, value: Any) -> Any:
        if isinstance(value, str) and not value.strip():
            return None
        if value is not None and (not isinstance(value, str) or not NAME_RE.match(value)):
            raise ValueError("a zenoh user name is 1-128 letters, digits, '_', '.', '@', '+', '-'")
        return value

    @field_validator("password", mode="before")
    @classmethod
    def _password(cls, value: Any) -> Any:
        if isinstance(value, SecretStr):
            value = value.get_secret_value()
        if value is None or (isinstance(value, str) and not value):
            return None
        if isinstance(value, str) and (":" in value or any(c.isspace() or not c.isprintable() for c in value)):
            raise ValueError("the zenoh password must be printable characters without spaces or ':'")
        return value

    @field_validator("usersfile", "tls_root_ca", "tls_certificate", "tls_private_key", mode="before")
    @classmethod
    def _optional_path(cls, value: Any) -> Any:
        return optional_path(value)

    @field_validator("prefix")
    @classmethod
    def _prefix(cls, value: str) -> str:
        value = value.strip().strip("/")
        if len(value) > 200 or not PREFIX_WILDCARD_RE.match(value):
            raise ValueError(
                "a key prefix is 1-8 chunks of letters, digits, '_', '.', '-' separated "
                "by '/' (patterns may use '*' and '**'), e.g. plant1/line2/motor7"
            )
        return value

    @model_validator(mode="after")
    def _access(self) -> ZenohAccessConfig:
        if (self.user is None) != (self.password is None):
            missing = "zenoh_password" if self.password is None else "zenoh_user"
            raise ValueError(
                f"{missing}: zenoh credentials are a user and a password together "
                "(BEARING_TWIN_ZENOH_USER, BEARING_TWIN_ZENOH_PASSWORD)"
            )
        if self.usersfile is not None:
            read_usersfile(self.usersfile)  # ValueError naming the line
        tls = (self.tls_root_ca, self.tls_certificate, self.tls_private_key)
        if any(t is not None for t in tls) and not all(t is not None for t in tls):
            raise ValueError(
                "zenoh_tls_certificate: mutual TLS needs the CA certificate, this "
                "process's certificate and its private key together"
            )
        for name, path in zip(
            ("zenoh_tls_root_ca", "zenoh_tls_certificate", "zenoh_tls_private_key"), tls, strict=True
        ):
            if path is not None and not Path(path).is_file():
                raise ValueError(f"{name}: {str(path)!r} is not a file")
        return self

    @property
    def password_value(self) -> str | None:
        """The password in clear (None without credentials)."""
        return self.password.get_secret_value() if self.password is not None else None

    @property
    def tls(self) -> bool:
        """Mutual TLS configured (CA, certificate and key)."""
        return self.tls_certificate is not None

    @property
    def access_control(self) -> bool:
        """zenoh authentication (and, where links are accepted, access control) is on."""
        return zenoh_access_enabled(self.usersfile, self.user, self.tls_certificate)

    @property
    def prefix_is_pattern(self) -> bool:
        """The prefix holds '*' or '**' (a router's or a monitor's pattern)."""
        return "*" in self.prefix


def check_tls_endpoints(zenoh: ZenohAccessConfig, listen: list[str]) -> None:
    """With TLS client certificates as the only authentication, a tcp/ listen endpoint would
    accept anyone: every listen endpoint must then be tls/ (or quic/)."""
    if zenoh.tls and zenoh.usersfile is None:
        plain = [e for e in listen if not e.startswith(("tls/", "quic/"))]
        if plain:
            raise ValueError(
                f"zenoh_listen: {plain[0]!r} would accept peers without a client "
                "certificate; with TLS (and no users file) listen on tls/HOST:PORT only"
            )


class RouterZenohSettings(ZenohAccessConfig):
    """The zenoh group of `bearing-twin router`: access, and the endpoints it listens on."""

    listen: Annotated[list[str], NoDecode] = Field(
        default_factory=lambda: list(DEFAULT_ZENOH_LISTEN),
        json_schema_extra=flat("zenoh_listen", "--listen", "--zenoh-listen", metavar="ENDPOINT"),
        description="zenoh endpoints the router listens on [zenoh locator, e.g. tcp/0.0.0.0:7447].",
    )

    @field_validator("listen", mode="before")
    @classmethod
    def _endpoints(cls, value: Any) -> Any:
        return split_list(value)

    @model_validator(mode="after")
    def _router(self) -> RouterZenohSettings:
        if not self.listen:
            raise ValueError("zenoh_listen: a router listens on at least one endpoint")
        check_tls_endpoints(self, self.listen)
        return self


class ZenohSettings(ZenohAccessConfig):
    """The zenoh group of `bearing-twin serve`: access, the session's endpoints and mode."""

    enabled: bool = Field(
        default=True, json_schema_extra=flat("enable_zenoh", "--no-zenoh"), description="Start the zenoh bus [bool]."
    )
    connect: Annotated[list[str], NoDecode] = Field(
        default_factory=list,
        json_schema_extra=flat("zenoh_connect", metavar="ENDPOINT"),
        description="zenoh endpoints (routers or peers) to connect to [zenoh locator].",
    )
    listen: Annotated[list[str], NoDecode] = Field(
        default=None,
        validate_default=True,
        json_schema_extra=flat(
            "zenoh_listen",
            metavar="ENDPOINT",
            details="With zenoh_connect the service joins a router.",
        ),
        description="zenoh endpoints to listen on [zenoh locator]; unset "
        "= tcp/127.0.0.1:7447, or none with zenoh_connect.",
    )
    mode: Literal["peer", "client", "router"] = Field(
        default=None,
        validate_default=True,
        json_schema_extra=flat(
            "zenoh_mode",
            details="A service that only connects joins a router: every message goes through it.",
        ),
        description="zenoh session mode [peer | client | router]; unset "
        "= client when the service only connects, else peer.",
    )

    @field_validator("connect", mode="before")
    @classmethod
    def _connect(cls, value: Any) -> Any:
        return split_list(value)

    @field_validator("listen", mode="before")
    @classmethod
    def _listen(cls, value: Any, info: ValidationInfo) -> Any:
        if value is None:
            return [] if info.data.get("connect") else list(DEFAULT_ZENOH_LISTEN)
        return split_list(value)

    @field_validator("mode", mode="before")
    @classmethod
    def _mode(cls, value: Any, info: ValidationInfo) -> Any:
        if value is None:
            return "client" if info.data.get("connect") and not info.data.get("listen") else "peer"
        return value

    @model_validator(mode="after")
    def _session(self) -> ZenohSettings:
        """Refuse what zenoh's access control cannot guard (docs/operations.md "zenoh access
        control")."""
        if self.prefix_is_pattern:
            raise ValueError(
                "zenoh_prefix: a service publishes under a concrete prefix: no '*' "
                "or '**' (those are for the router and the monitor)"
            )
        if not self.enabled or not self.access_control:
            return self
        if self.listen and self.connect:
            raise ValueError(
                "zenoh_connect: with zenoh access control a service either listens (its own access "
                "rules guard who connects) or joins a router (the router's rules guard everyone), "
                "not both: zenoh authenticates only the side that connects, so the links this "
                "service opens would match none of its own rules"
            )
        if self.listen and self.usersfile is None and not self.tls:
            raise ValueError(
                "zenoh_usersfile: a service that listens with zenoh access control needs the users "
                "allowed to connect (BEARING_TWIN_ZENOH_USERSFILE) or TLS client certificates; "
                "to join a router instead give --zenoh-connect"
            )
        if self.connect and self.user is None and not self.tls:
            raise ValueError(
                "zenoh_user: joining a router with access control needs this service's credentials "
                "(BEARING_TWIN_ZENOH_USER and BEARING_TWIN_ZENOH_PASSWORD) or a TLS certificate"
            )
        check_tls_endpoints(self, self.listen)
        return self
