"""Settings as nested groups (service.settings): the nested environment names of pydantic-settings
(`BEARING_TWIN_HTTP__PORT`), the flat names of existing unit files (`BEARING_TWIN_PORT`), flat and
nested keywords, the `BEARING_TWIN_OPCUA` name that is both a flat setting and a group, and the
`serve` flags generated from the model."""

from __future__ import annotations

import argparse
import json

import pytest
from pydantic import SecretStr, ValidationError

from service.settings import RouterSettings, ServiceSettings, ZenohAccessSettings, flat_settings
from service.tools.cli import build_parser
from service.tools.serve_cli import serve_settings
from service.tools.settings_flags import flag_of

# Every flat environment name ServiceSettings accepts beside the nested ones, with the group path it
# sets: the names users have in their unit files (docs/configuration.md).
FLAT_PATHS = {
    "zenoh_prefix": "zenoh.prefix",
    "zenoh_user": "zenoh.user",
    "zenoh_password": "zenoh.password",
    "zenoh_usersfile": "zenoh.usersfile",
    "zenoh_writers": "zenoh.writers",
    "zenoh_readers": "zenoh.readers",
    "zenoh_services": "zenoh.services",
    "zenoh_tls_root_ca": "zenoh.tls_root_ca",
    "zenoh_tls_certificate": "zenoh.tls_certificate",
    "zenoh_tls_private_key": "zenoh.tls_private_key",
    "host": "http.host",
    "port": "http.port",
    "bearing": "twin.bearing",
    "housing": "twin.housing",
    "twin_id": "twin.id",
    "start_twin": "twin.start",
    "zenoh_listen": "zenoh.listen",
    "zenoh_connect": "zenoh.connect",
    "zenoh_mode": "zenoh.mode",
    "record": "recording.path",
    "record_segment_s": "recording.segment_s",
    "record_segment_mb": "recording.segment_mb",
    "record_footer": "recording.footer",
    "record_flush_interval_s": "recording.flush_interval_s",
    "record_keep_mb": "recording.keep_mb",
    "record_keep_hours": "recording.keep_hours",
    "spawn_viewer": "recording.spawn_viewer",
    "rerun_web_port": "recording.web_port",
    "rerun_web_bind": "recording.web_bind",
    "rerun_web_memory_mb": "recording.web_memory_mb",
    "fast": "runner.fast",
    "publish_rate_hz": "runner.publish_rate_hz",
    "frame_s": "runner.frame_s",
    "setpoint_frame_s": "runner.setpoint_frame_s",
    "frame_lead_s": "runner.frame_lead_s",
    "lateness_s": "runner.lateness_s",
    "stepping_threads": "runner.stepping_threads",
    "io_thread_nice": "runner.io_thread_nice",
    "gc_freeze": "runner.gc_freeze",
    "stepping_thread_nice": "runner.stepping_thread_nice",
    "admission": "runner.admission",
    "capacity_core_fraction": "runner.capacity_core_fraction",
    "capacity_reserve_cores": "runner.capacity_reserve_cores",
    "calibration_s": "runner.calibration_s",
    "enable_zenoh": "zenoh.enabled",
    "enable_recording": "recording.enabled",
    "gil_switch_interval_s": "runner.gil_switch_interval_s",
    "max_twins": "runner.max_twins",
    "token": "security.token",
    "read_requires_token": "security.read_requires_token",
    "setpoint_rate_hz": "security.setpoint_rate_hz",
    "setpoint_burst": "security.setpoint_burst",
    "max_body_bytes": "security.max_body_bytes",
    "read_rate_hz": "security.read_rate_hz",
    "read_burst": "security.read_burst",
    "http_header_timeout_s": "http.header_timeout_s",
    "http_body_timeout_s": "http.body_timeout_s",
    "http_keep_alive_s": "http.keep_alive_s",
    "http_max_connections": "http.max_connections",
    "client_error_rate_hz": "security.client_error_rate_hz",
    "client_error_burst": "security.client_error_burst",
    "tarpit_delay_s": "security.tarpit_delay_s",
    "tarpit_max_held": "security.tarpit_max_held",
    "scenario_dir": "twin.scenario_dir",
    "opcua": "opcua.endpoint",
    "opcua_security": "opcua.security",
    "opcua_certificate": "opcua.certificate",
    "opcua_private_key": "opcua.private_key",
    "opcua_pki_dir": "opcua.pki_dir",
    "opcua_trusted_dir": "opcua.trusted_dir",
    "opcua_max_sessions": "opcua.max_sessions",
    "opcua_max_subscriptions_per_session": "opcua.max_subscriptions_per_session",
    "opcua_max_monitored_items_per_session": "opcua.max_monitored_items_per_session",
    "opcua_max_notifications_per_s": "opcua.max_notifications_per_s",
    "opcua_min_publishing_interval_ms": "opcua.min_publishing_interval_ms",
    "opcua_max_queue_size": "opcua.max_queue_size",
    "opcua_login_free_failures": "opcua.login_free_failures",
    "opcua_login_backoff_s": "opcua.login_backoff_s",
    "opcua_login_backoff_max_s": "opcua.login_backoff_max_s",
}

# A value for each flat name that differs from the default (as an environment string), to show
# that the flat variable reaches its group field.
SAMPLE = {
    "zenoh_prefix": ("plant1/line2", "plant1/line2"),
    "host": ("0.0.0.0", "0.0.0.0"),
    "port": ("8123", 8123),
    "bearing": ("6205", "6205"),
    "housing": ("true", True),
    "twin_id": ("motor7", "motor7"),
    "start_twin": ("false", False),
    "zenoh_connect": ("tcp/127.0.0.1:7999", ["tcp/127.0.0.1:7999"]),
    "zenoh_mode": ("client", "client"),
    "record_segment_s": ("60", 60.0),
    "record_footer": ("1", True),
    "rerun_web_port": ("9876", 9876),
    "fast": ("true", True),
    "publish_rate_hz": ("20", 20.0),
    "frame_s": ("0.002", 0.002),
    "max_twins": ("4", 4),
    "enable_zenoh": ("false", False),
    "enable_recording": ("false", False),
    "read_requires_token": ("true", True),
    "setpoint_burst": ("7", 7),
    "http_max_connections": ("512", 512),
    "tarpit_max_held": ("10", 10),
    "opcua": ("opc.tcp://127.0.0.1:4849", "opc.tcp://127.0.0.1:4849"),
    "opcua_max_sessions": ("3", 3),
    "admission": ("off", "off"),
    "io_thread_nice": ("0", 0),
}


def _get(settings, path: str):
    group, field = path.split(".")
    return getattr(getattr(settings, group), field)


@pytest.fixture
def clean_env(monkeypatch):
    import os

    for name in list(os.environ):
        if name.upper().startswith("BEARING_TWIN_"):
            monkeypatch.delenv(name)
    return monkeypatch


def test_every_flat_name_of_the_single_level_model_maps_to_one_group_field():
    mapped = {s.flat: s.path for s in flat_settings(ServiceSettings)}
    assert mapped == FLAT_PATHS
    assert len(mapped) == 79  # 80 fields before, `alarms` is its own group


@pytest.mark.parametrize("name", sorted(SAMPLE))
def test_flat_environment_names_keep_working(clean_env, name):
    text, expected = SAMPLE[name]
    clean_env.setenv(f"BEARING_TWIN_{name.upper()}", text)
    assert _get(ServiceSettings(), FLAT_PATHS[name]) == expected


@pytest.mark.parametrize("name", sorted(SAMPLE))
def test_nested_environment_names(clean_env, name):
    text, expected = SAMPLE[name]
    group, field = FLAT_PATHS[name].split(".")
    clean_env.setenv(f"BEARING_TWIN_{group.upper()}__{field.upper()}", text)
    assert _get(ServiceSettings(), FLAT_PATHS[name]) == expected


def test_the_nested_name_wins_over_the_flat_one_and_a_keyword_over_both(clean_env):
    clean_env.setenv("BEARING_TWIN_PORT", "8100")
    clean_env.setenv("BEARING_TWIN_HTTP__PORT", "8200")
    assert ServiceSettings().http.port == 8200
    assert ServiceSettings(port=8300).http.port == 8300
    assert ServiceSettings(http={"port": 8400}).http.port == 8400
    clean_env.setenv("BEARING_TWIN_HOST", "0.0.0.0")
    # a keyword for one field of a group keeps the environment's other fields of that group
    merged = ServiceSettings(http={"port": 8500})
    assert (merged.http.host, merged.http.port) == ("0.0.0.0", 8500)


def test_flat_and_nested_keywords(clean_env):
    s = ServiceSettings(port=9001, token="s3cret", zenoh_connect=["tcp/127.0.0.1:7448"], record_footer=True)
    assert (s.http.port, s.security.token_value, s.zenoh.connect, s.recording.footer) == (
        9001,
        "s3cret",
        ["tcp/127.0.0.1:7448"],
        True,
    )
    assert s.zenoh.listen == [] and s.zenoh.mode == "client"  # joins a router: client, no listen
    assert ServiceSettings(runner={"fast": True}, fast=False).runner.fast is False  # flat given last wins


def test_an_unknown_name_is_an_error_naming_it(clean_env):
    with pytest.raises(ValidationError, match="prot"):
        ServiceSettings(prot=8000)
    clean_env.setenv("BEARING_TWIN_HTTP__PROT", "8000")
    with pytest.raises(ValidationError, match="prot"):
        ServiceSettings()


def test_a_bad_value_names_its_group_field_and_range(clean_env):
    clean_env.setenv("BEARING_TWIN_PORT", "70000")
    with pytest.raises(ValidationError) as err:
        ServiceSettings()
    assert err.value.errors()[0]["loc"] == ("http", "port") and "65535" in str(err.value)


def test_opcua_is_both_the_flat_endpoint_and_the_group(clean_env):
    """`BEARING_TWIN_OPCUA` of existing unit files is the endpoint; a JSON object there is the
    whole group; the nested names set the group's other fields beside the flat endpoint."""
    assert ServiceSettings().opcua.endpoint is None
    clean_env.setenv("BEARING_TWIN_OPCUA", "opc.tcp://127.0.0.1:4841")
    clean_env.setenv("BEARING_TWIN_OPCUA__SECURITY", "sign")
    clean_env.setenv("BEARING_TWIN_OPCUA_MAX_SESSIONS", "5")
    s = ServiceSettings()
    assert (s.opcua.endpoint, s.opcua.security, s.opcua.max_sessions) == ("opc.tcp://127.0.0.1:4841", "sign", 5)
    clean_env.setenv("BEARING_TWIN_OPCUA", json.dumps({"endpoint": "opc.tcp://127.0.0.1:4842", "max_sessions": 2}))
    clean_env.delenv("BEARING_TWIN_OPCUA_MAX_SESSIONS")
    s = ServiceSettings()
    assert (s.opcua.endpoint, s.opcua.security, s.opcua.max_sessions) == ("opc.tcp://127.0.0.1:4842", "sign", 2)
    assert ServiceSettings(opcua="opc.tcp://127.0.0.1:4843").opcua.endpoint == "opc.tcp://127.0.0.1:4843"
    clean_env.setenv("BEARING_TWIN_OPCUA", "http://nope")
    with pytest.raises(ValidationError) as err:
        ServiceSettings()
    assert err.value.errors()[0]["loc"] == ("opcua", "endpoint")


def test_alarms_as_json_or_field_by_field(clean_env):
    clean_env.setenv("BEARING_TWIN_ALARMS", '{"machine_group": 1}')
    clean_env.setenv("BEARING_TWIN_ALARMS__SUPPORT", "flexible")
    s = ServiceSettings()
    assert (s.alarms.machine_group, s.alarms.support) == (1, "flexible")


def test_secrets_stay_secret_and_have_no_flag(clean_env):
    clean_env.setenv("BEARING_TWIN_TOKEN", "tok-123")
    clean_env.setenv("BEARING_TWIN_ZENOH_USER", "svc")
    clean_env.setenv("BEARING_TWIN_ZENOH_PASSWORD", "pw-456")
    clean_env.setenv("BEARING_TWIN_ENABLE_ZENOH", "false")
    s = ServiceSettings()
    assert isinstance(s.security.token, SecretStr) and isinstance(s.zenoh.password, SecretStr)
    assert "tok-123" not in repr(s) and "pw-456" not in repr(s)
    assert (s.security.token_value, s.zenoh.password_value) == ("tok-123", "pw-456")
    assert flag_of(ServiceSettings, "security.token") is None and flag_of(ServiceSettings, "zenoh.password") is None
    for flag in ("--token", "--zenoh-password"):
        with pytest.raises(SystemExit):
            build_parser().parse_args(["serve", flag, "x"])


def test_router_and_client_roots_read_the_same_zenoh_names(clean_env):
    clean_env.setenv("BEARING_TWIN_ZENOH_PREFIX", "plant1/**")
    clean_env.setenv("BEARING_TWIN_ZENOH_LISTEN", "tcp/127.0.0.1:7601,tcp/127.0.0.1:7602")
    assert RouterSettings().zenoh.listen == ["tcp/127.0.0.1:7601", "tcp/127.0.0.1:7602"]
    assert RouterSettings().zenoh.prefix == ZenohAccessSettings().zenoh.prefix == "plant1/**"
    with pytest.raises(ValidationError, match="concrete prefix"):
        ServiceSettings()


# Every flag `serve` had before the flags were generated, with a value and the field it sets.
FLAGS = [
    (["--host", "0.0.0.0"], "http.host", "0.0.0.0"),
    (["--port", "8123"], "http.port", 8123),
    (["--bearing", "6205"], "twin.bearing", "6205"),
    (["--housing"], "twin.housing", True),
    (["--twin-id", "m7"], "twin.id", "m7"),
    (
        ["--zenoh-listen", "tcp/127.0.0.1:7701", "--zenoh-listen", "tcp/127.0.0.1:7702"],
        "zenoh.listen",
        ["tcp/127.0.0.1:7701", "tcp/127.0.0.1:7702"],
    ),
    (["--zenoh-connect", "tcp/127.0.0.1:7703"], "zenoh.connect", ["tcp/127.0.0.1:7703"]),
    (["--zenoh-mode", "client"], "zenoh.mode", "client"),
    (["--zenoh-prefix", "site/a"], "zenoh.prefix", "site/a"),
    (["--spawn-viewer"], "recording.spawn_viewer", True),
    (["--rerun-web", "9011"], "recording.web_port", 9011),
    (["--rerun-web-bind", "127.0.0.2"], "recording.web_bind", "127.0.0.2"),
    (["--fast"], "runner.fast", True),
    (["--publish-rate", "25"], "runner.publish_rate_hz", 25.0),
    (["--opcua", "opc.tcp://127.0.0.1:4844"], "opcua.endpoint", "opc.tcp://127.0.0.1:4844"),
    (["--opcua-security", "sign"], "opcua.security", "sign"),
    (["--no-zenoh"], "zenoh.enabled", False),
    (["--no-record"], "recording.enabled", False),
]


@pytest.mark.parametrize(("argv", "path", "expected"), FLAGS, ids=[f[0][0] for f in FLAGS])
def test_every_existing_serve_flag_sets_its_field(clean_env, argv, path, expected):
    assert _get(serve_settings(build_parser().parse_args(["serve", *argv])), path) == expected


def test_a_flag_for_every_setting_named_after_it_and_only_given_flags_override(clean_env, tmp_path):
    parser = build_parser()
    args = parser.parse_args(["serve"])
    assert not any("." in dest for dest in vars(args))  # argparse.SUPPRESS: nothing given
    clean_env.setenv("BEARING_TWIN_PORT", "8111")
    clean_env.setenv("BEARING_TWIN_FAST", "true")
    s = serve_settings(
        parser.parse_args(
            [
                "serve",
                "--publish-rate-hz",
                "10",
                "--record",
                str(tmp_path / "a.rrd"),
                "--frame-s",
                "0.002",
                "--no-gc-freeze",
            ]
        )
    )
    assert (s.http.port, s.runner.fast, s.runner.publish_rate_hz, s.runner.frame_s, s.runner.gc_freeze) == (
        8111,
        True,
        10.0,
        0.002,
        False,
    )
    assert s.recording.active_path == tmp_path / "a.rrd"
    for setting in flat_settings(ServiceSettings):
        flag = flag_of(ServiceSettings, setting.path)
        assert flag is None or flag in setting.flags
        if flag is not None and setting.flat != "enable_zenoh" and setting.flat != "enable_recording":
            assert setting.flat.replace("_", "-") in " ".join(setting.flags), setting.flat


def test_the_help_of_a_flag_is_its_description(clean_env):
    text = build_parser()._subparsers._group_actions[0].choices["serve"].format_help()  # type: ignore[union-attr]
    flat_text = " ".join(text.split())
    assert "HTTP port [TCP port number, 0 = any free port] (default 8000) [BEARING_TWIN_PORT]" in flat_text
    assert "[BEARING_TWIN_PUBLISH_RATE_HZ]" in flat_text


def test_a_bad_flag_value_is_refused(clean_env):
    with pytest.raises(SystemExit):
        build_parser().parse_args(["serve", "--port", "eighty"])
    with pytest.raises(ValidationError, match="publish_rate_hz"):
        serve_settings(argparse.Namespace(**{"runner.publish_rate_hz": -1.0}))


def test_a_serve_error_names_the_group_field_its_variable_and_flag(clean_env, capsys):
    from service.tools.cli import main

    clean_env.setenv("BEARING_TWIN_PORT", "70000")
    assert main(["serve"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: http.port (BEARING_TWIN_PORT, --port): ") and "65535" in err
    clean_env.delenv("BEARING_TWIN_PORT")
    clean_env.setenv("BEARING_TWIN_ALARMS", "{not json")
    assert main(["serve"]) == 2
    assert capsys.readouterr().err.startswith('error: error parsing value for field "alarms"')
    clean_env.delenv("BEARING_TWIN_ALARMS")
    assert main(["serve", "--no-zenoh", "--tarpit-max-held", "300"]) == 2
    assert "tarpit_max_held: 300 held refusals" in capsys.readouterr().err


def test_scenario_run_reads_the_alarms_as_serve_does(clean_env):
    from service.tools.scenario_cli import _alarm_settings_from_env

    assert _alarm_settings_from_env().machine_group == 2  # ISO 20816-3 default group
    clean_env.setenv("BEARING_TWIN_ALARMS__MACHINE_GROUP", "1")
    assert _alarm_settings_from_env().machine_group == 1
    clean_env.setenv("BEARING_TWIN_ALARMS__MACHINE_GROUP", "3")
    with pytest.raises(ValueError, match="machine_group"):
        _alarm_settings_from_env()


def test_router_flags_are_generated_too_and_keep_their_names(clean_env):
    from service.tools.settings_flags import flag_overrides

    clean_env.setenv("BEARING_TWIN_ZENOH_WRITERS", "scada")
    parser = build_parser()
    for argv in (
        ["--listen", "tcp/127.0.0.1:7801", "--prefix", "plant1/**"],
        ["--zenoh-listen", "tcp/127.0.0.1:7801", "--zenoh-prefix", "plant1/**"],
    ):
        s = RouterSettings(**flag_overrides(parser.parse_args(["router", *argv])))
        assert (s.zenoh.listen, s.zenoh.prefix, s.zenoh.writers) == (["tcp/127.0.0.1:7801"], "plant1/**", ["scada"])
    assert RouterSettings(**flag_overrides(parser.parse_args(["router"]))).zenoh.listen == ["tcp/127.0.0.1:7447"]


def test_a_check_across_fields_of_a_group_is_one_line_naming_its_setting(clean_env, capsys):
    from service.tools.cli import main

    clean_env.setenv("BEARING_TWIN_ZENOH_USER", "svc")  # a user without a password
    assert main(["serve"]) == 2
    assert capsys.readouterr().err == (
        "error: zenoh_password: zenoh credentials are a user and a password "
        "together (BEARING_TWIN_ZENOH_USER, BEARING_TWIN_ZENOH_PASSWORD)\n"
    )


def test_an_http_host_that_cannot_be_bound_is_refused_naming_it(clean_env):
    """`--host 999.1.1.1` (a typo) is refused when the settings are read, naming the setting, its
    environment name and its flag, rather than by the server after the twins started; an IP
    address, a wildcard or a name that resolves is taken."""
    with pytest.raises(ValidationError) as info:
        ServiceSettings(http={"host": "999.1.1.1"})
    assert "is not an IP address nor a host name that resolves" in str(info.value)
    for host in ("127.0.0.1", "0.0.0.0", "localhost"):
        assert ServiceSettings(http={"host": host}).http.host == host
