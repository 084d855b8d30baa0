"""The `opcua` settings group: the OPC UA facade's endpoint, message security, certificates and
per-session limits (docs/service.md "OPC UA")."""

from __future__ import annotations

from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from service.settings.flat import flat
from service.settings.values import optional_path

SecurityChoice = Literal["auto", "none", "sign", "sign_and_encrypt", "both", "all"]


class OpcUaSettings(BaseModel):
    """The OPC UA server that serves the twins, off unless `endpoint` is set."""

    model_config = ConfigDict(extra="forbid", hide_input_in_errors=True)

    endpoint: str | None = Field(
        default=None,
        pattern=r"^opc\.tcp://[^/\s]+:\d{1,5}(/\S*)?$",
        json_schema_extra=flat(
            "opcua",
            metavar="opc.tcp://HOST:PORT",
            details="For example opc.tcp://127.0.0.1:4840.",
        ),
        description="OPC UA endpoint to serve the twins on [opc.tcp://HOST:PORT[/path]]; unset = no OPC UA server.",
    )
    security: SecurityChoice = Field(
        default="auto",
        json_schema_extra=flat(
            "opcua_security",
            details="The policies Basic256Sha256, Aes128_Sha256_RsaOaep and Aes256_Sha256_RsaPss, in Sign, "
            "SignAndEncrypt or both; all adds the None policy for anonymous reads; auto = both with a token, else "
            'none (docs/service.md "OPC UA").',
        ),
        description="OPC UA message security offered [auto | none | sign | sign_and_encrypt | both | all].",
    )
    certificate: Path | None = Field(
        default=None,
        json_schema_extra=flat(
            "opcua_certificate",
            metavar="CERT.der",
            details="Give it with opcua_private_key; its subjectAltName must hold the URI urn:bearing-twin:server "
            "(OPC UA Part 6). The self-signed one is made once and reused.",
        ),
        description="The OPC UA server's certificate [path, DER or PEM]; unset = a self-signed one in opcua_pki_dir.",
    )
    private_key: Path | None = Field(
        default=None,
        json_schema_extra=flat("opcua_private_key", metavar="KEY.pem"),
        description="Private key of opcua_certificate [path, PEM or DER, unencrypted RSA].",
    )
    pki_dir: Path = Field(
        default=Path("opcua-pki"),
        json_schema_extra=flat(
            "opcua_pki_dir",
            metavar="DIR",
            details="The certificate is server-cert.der, the key server-key.pem (mode 0600, never overwritten); made "
            "when a secure policy is on and opcua_certificate is unset.",
        ),
        description="Folder of the generated self-signed OPC UA server certificate and key [path].",
    )
    trusted_dir: Path | None = Field(
        default=None,
        json_schema_extra=flat(
            "opcua_trusted_dir",
            metavar="DIR",
            details="It may hold CA certificates that signed them. When set, only those clients may open a session. "
            "Unset: any client certificate (the token still guards writes).",
        ),
        description="Folder of trusted OPC UA client certificates [path to .der / .pem files]; unset = any client.",
    )
    max_sessions: int = Field(
        default=16,
        ge=1,
        le=10_000,
        json_schema_extra=flat("opcua_max_sessions"),
        description="OPC UA sessions open at once, at most [count] (BadTooManySessions).",
    )
    max_subscriptions_per_session: int = Field(
        default=8,
        ge=1,
        le=10_000,
        json_schema_extra=flat("opcua_max_subscriptions_per_session"),
        description="OPC UA subscriptions per session, at most [count].",
    )
    max_monitored_items_per_session: int = Field(
        default=500,
        ge=1,
        le=1_000_000,
        json_schema_extra=flat("opcua_max_monitored_items_per_session"),
        description="OPC UA monitored items per session, at most [count].",
    )
    max_notifications_per_s: float = Field(
        default=1000.0,
        gt=0,
        le=1e7,
        json_schema_extra=flat(
            "opcua_max_notifications_per_s",
            details="Each item counts at min(publish_rate_hz, queue size x 1000 / publishing interval ms).",
        ),
        description="Notifications one OPC UA session's items may send, at most [1/s].",
    )
    min_publishing_interval_ms: float = Field(
        default=50.0,
        ge=1.0,
        le=3_600_000.0,
        json_schema_extra=flat("opcua_min_publishing_interval_ms"),
        description="Shortest OPC UA publishing interval granted [ms].",
    )
    max_queue_size: int = Field(
        default=10,
        ge=1,
        le=10_000,
        json_schema_extra=flat("opcua_max_queue_size"),
        description="Longest queue of an OPC UA monitored item [values].",
    )
    login_free_failures: int = Field(
        default=3,
        ge=0,
        le=1000,
        json_schema_extra=flat("opcua_login_free_failures"),
        description="Failed OPC UA logins per client address answered before the backoff starts [count].",
    )
    login_backoff_s: float = Field(
        default=1.0,
        gt=0,
        le=3600.0,
        json_schema_extra=flat("opcua_login_backoff_s"),
        description="First OPC UA login backoff of a client address, doubling at each further failure [s].",
    )
    login_backoff_max_s: float = Field(
        default=60.0,
        gt=0,
        le=86_400.0,
        json_schema_extra=flat("opcua_login_backoff_max_s"),
        description="Longest OPC UA login backoff; a burst of failures ends after this long without one [s].",
    )

    @field_validator("endpoint", "certificate", "private_key", "trusted_dir", mode="before")
    @classmethod
    def _optional(cls, value: Any) -> Any:
        return optional_path(value)

    @model_validator(mode="after")
    def _files(self) -> OpcUaSettings:
        """The server certificate and its key go together and exist; the trusted folder exists."""
        if (self.certificate is None) != (self.private_key is None):
            missing = "opcua_private_key" if self.private_key is None else "opcua_certificate"
            raise ValueError(
                f"{missing}: the OPC UA server certificate and its private key go together "
                "(or give neither: a self-signed one is made in opcua_pki_dir)"
            )
        for name, path in (("opcua_certificate", self.certificate), ("opcua_private_key", self.private_key)):
            if path is not None and not Path(path).is_file():
                raise ValueError(f"{name}: {str(path)!r} is not a file")
        if self.trusted_dir is not None and not Path(self.trusted_dir).is_dir():
            raise ValueError(f"opcua_trusted_dir: {str(self.trusted_dir)!r} is not a folder")
        return self

    def security_mode(self, token_set: bool) -> str:
        """The message security actually offered: `auto` is `both` with a token, else `none`."""
        if self.security != "auto":
            return self.security
        return "both" if token_set else "none"
