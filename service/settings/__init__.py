"""Settings of the service, the router and the zenoh clients: nested groups (service.settings.roots)
read from defaults, the environment (nested or flat names, service.settings.flat) and keywords."""

from service.settings.alarms import AlarmSettings
from service.settings.flat import ENV_PREFIX, FlatSetting, flat_settings
from service.settings.http import HttpSettings, SecuritySettings
from service.settings.opcua import OpcUaSettings
from service.settings.recording import RecordingSettings
from service.settings.roots import RouterSettings, ScenarioSettings, ServiceSettings, ZenohAccessSettings
from service.settings.runner import RunnerSettings, TwinSettings
from service.settings.values import (
    default_recording_path,
    default_scenario_dir,
    is_loopback_host,
    read_usersfile,
    zenoh_access_enabled,
)
from service.settings.zenoh import DEFAULT_ZENOH_LISTEN, RouterZenohSettings, ZenohAccessConfig, ZenohSettings

__all__ = [
    "DEFAULT_ZENOH_LISTEN",
    "ENV_PREFIX",
    "AlarmSettings",
    "FlatSetting",
    "HttpSettings",
    "OpcUaSettings",
    "RecordingSettings",
    "RouterSettings",
    "RouterZenohSettings",
    "RunnerSettings",
    "ScenarioSettings",
    "SecuritySettings",
    "ServiceSettings",
    "TwinSettings",
    "ZenohAccessConfig",
    "ZenohAccessSettings",
    "ZenohSettings",
    "default_recording_path",
    "default_scenario_dir",
    "flat_settings",
    "is_loopback_host",
    "read_usersfile",
    "zenoh_access_enabled",
]
