"""The settings roots: `ServiceSettings` (`bearing-twin serve`), `RouterSettings`
(`bearing-twin router`) and `ZenohAccessSettings` (the zenoh clients: `monitor`, the load tools).

Built-in defaults < environment (`BEARING_TWIN_<GROUP>__<FIELD>`, or the flat
`BEARING_TWIN_<NAME>`; service.settings.flat) < keyword arguments (the command-line flags).
List fields accept a JSON list (`'["tcp/127.0.0.1:7447"]'`) or comma-separated text
(`tcp/127.0.0.1:7447,tcp/[::1]:7447`) from the environment; an empty text means none.
"""

from __future__ import annotations

from pydantic import Field, model_validator

from service.settings.alarms import AlarmSettings
from service.settings.flat import NestedSettings
from service.settings.http import HttpSettings, SecuritySettings
from service.settings.opcua import OpcUaSettings
from service.settings.recording import RecordingSettings
from service.settings.runner import RunnerSettings, TwinSettings
from service.settings.zenoh import RouterZenohSettings, ZenohAccessConfig, ZenohSettings


class ZenohAccessSettings(NestedSettings):
    """A zenoh client's key prefix and credentials (`monitor`, `soak`, benchmarks)."""

    zenoh: ZenohAccessConfig = Field(
        default_factory=ZenohAccessConfig, description="Key prefix, credentials and access roles on zenoh."
    )


class RouterSettings(NestedSettings):
    """Configuration of `bearing-twin router`."""

    zenoh: RouterZenohSettings = Field(
        default_factory=RouterZenohSettings, description="Access rules and listen endpoints of the router."
    )


class ServiceSettings(NestedSettings):
    """Configuration of `bearing-twin serve`, one group per concern."""

    http: HttpSettings = Field(default_factory=HttpSettings, description="HTTP bind address and connection limits.")
    security: SecuritySettings = Field(
        default_factory=SecuritySettings, description="Bearer token, rate limits and the tarpit."
    )
    twin: TwinSettings = Field(
        default_factory=TwinSettings, description="The twin started with the service and the named scenarios."
    )
    runner: RunnerSettings = Field(
        default_factory=RunnerSettings, description="Pacing, stepping threads and admission of the twins."
    )
    zenoh: ZenohSettings = Field(
        default_factory=ZenohSettings, description="zenoh bus: key prefix, endpoints, mode and access control."
    )
    recording: RecordingSettings = Field(
        default_factory=RecordingSettings, description="rerun recording, rotation, retention and live viewers."
    )
    opcua: OpcUaSettings = Field(
        default_factory=OpcUaSettings, description="OPC UA facade: endpoint, security and limits."
    )
    alarms: AlarmSettings = Field(
        default_factory=AlarmSettings, description="Alarm thresholds and timing [see AlarmSettings]."
    )

    @property
    def opcua_security_mode(self) -> str:
        """The OPC UA security actually offered: `auto` resolved (both with a token, else none)."""
        return self.opcua.security_mode(self.security.token is not None)

    @model_validator(mode="after")
    def _across_groups(self) -> ServiceSettings:
        """Checks that join two groups: the tarpit against the HTTP connection limit, trusted OPC UA
        clients against the security actually offered."""
        if self.security.tarpit_max_held >= self.http.max_connections:
            raise ValueError(
                f"tarpit_max_held: {self.security.tarpit_max_held} held refusals would take every "
                f"one of the http_max_connections ({self.http.max_connections}); allowed [1, "
                f"{self.http.max_connections - 1}]"
            )
        if self.opcua.trusted_dir is not None and self.opcua_security_mode in ("none", "all"):
            raise ValueError(
                "opcua_trusted_dir: trusting clients by certificate needs every session on a "
                "secure channel: opcua_security sign, sign_and_encrypt or both (it is "
                f"{self.opcua.security!r}"
                + (", and `auto` without a token is none" if self.opcua.security == "auto" else "")
                + ")"
            )
        return self


class ScenarioSettings(NestedSettings):
    """Configuration of `bearing-twin scenario run`: the alarms judged on every sample, as for `serve`."""

    alarms: AlarmSettings = Field(
        default_factory=AlarmSettings, description="Alarm thresholds and timing [see AlarmSettings]."
    )
