"""The OPC UA facade's set-up: the token as password (TokenUserManager against the service's
admission gate), the endpoint setting and flag, and a busy port as a one-line WiringError."""

from __future__ import annotations

import argparse
import socket

import pytest
from pydantic import ValidationError

pytest.importorskip("asyncua")

from service.core.admission import AdmissionGate
from service.opcua.identity import TokenUserManager
from service.settings import ServiceSettings


def test_the_token_is_the_password():
    gate = AdmissionGate(token="s3cret")
    users = TokenUserManager(gate, read_requires_token=False)
    anonymous = users.get_user(None)
    assert anonymous is not None and anonymous.authenticated is False  # reads, cannot write
    good = users.get_user(None, username="op", password="s3cret")
    assert good is not None and good.authenticated and good.name == "op"
    assert gate.unauthorized == 0
    assert users.get_user(None, username="op", password="wrong") is None  # session refused
    assert users.get_user(None, username="op", password=None) is None
    assert gate.unauthorized == 2
    strict = TokenUserManager(gate, read_requires_token=True)
    assert strict.get_user(None) is None and gate.unauthorized == 3  # anonymous refused
    open_gate = TokenUserManager(AdmissionGate(token=None))
    assert open_gate.get_user(None).authenticated is True  # no token: anyone writes
    assert open_gate.get_user(None, username="x", password="anything").authenticated is True


def test_the_endpoint_setting_and_flag():
    assert ServiceSettings().opcua.endpoint is None  # off by default
    assert ServiceSettings(opcua="opc.tcp://127.0.0.1:4840").opcua.endpoint == "opc.tcp://127.0.0.1:4840"
    with pytest.raises(ValidationError, match="opcua"):
        ServiceSettings(opcua="http://127.0.0.1:4840")
    from service.tools.cli import build_parser
    from service.tools.serve_cli import serve_settings

    args = build_parser().parse_args(["serve", "--opcua", "opc.tcp://127.0.0.1:4841"])
    assert isinstance(args, argparse.Namespace)
    assert serve_settings(args).opcua.endpoint == "opc.tcp://127.0.0.1:4841"


def test_a_busy_port_is_a_one_line_wiring_error():
    from service.wiring import TwinService, WiringError

    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        settings = ServiceSettings(
            enable_zenoh=False, enable_recording=False, start_twin=False, opcua=f"opc.tcp://127.0.0.1:{port}"
        )
        with pytest.raises(WiringError) as err:
            TwinService(settings).open()
    text = str(err.value)
    assert "\n" not in text and "address already in use" in text and "--opcua" in text


def test_the_security_settings_and_flags(tmp_path):
    """opcua_security `auto`: Sign + SignAndEncrypt with a token, None without; the certificate and
    key go together; a trusted-clients folder needs every session on a secure channel. Each bad
    value is an error naming its field; the serve flags set the same fields."""
    assert ServiceSettings().opcua.security == "auto" and ServiceSettings().opcua_security_mode == "none"
    assert ServiceSettings(token="s3cret").opcua_security_mode == "both"
    assert ServiceSettings(token="s3cret", opcua_security="none").opcua_security_mode == "none"
    assert ServiceSettings().opcua.pki_dir.name == "opcua-pki"
    with pytest.raises(ValidationError, match=r"opcua\.security"):
        ServiceSettings(opcua_security="encrypt")
    cert = tmp_path / "c.der"
    cert.write_bytes(b"x")
    with pytest.raises(ValidationError, match="opcua_private_key: the OPC UA server certificate and its private key"):
        ServiceSettings(opcua_certificate=cert)
    with pytest.raises(ValidationError, match="opcua_certificate: .* is not a file"):
        ServiceSettings(opcua_certificate=tmp_path / "missing.der", opcua_private_key=cert)
    with pytest.raises(ValidationError, match="opcua_trusted_dir: .* is not a folder"):
        ServiceSettings(token="s3cret", opcua_trusted_dir=cert)
    with pytest.raises(ValidationError, match="opcua_trusted_dir: trusting clients by certificate"):
        ServiceSettings(opcua_trusted_dir=tmp_path)  # auto without a token: None
    with pytest.raises(ValidationError, match="opcua_trusted_dir: trusting clients by certificate"):
        ServiceSettings(token="s3cret", opcua_security="all", opcua_trusted_dir=tmp_path)
    assert ServiceSettings(opcua_security="sign", opcua_trusted_dir=tmp_path).opcua.trusted_dir == tmp_path
    from service.tools.cli import build_parser
    from service.tools.serve_cli import serve_settings

    args = build_parser().parse_args(
        [
            "serve",
            "--opcua",
            "opc.tcp://127.0.0.1:4841",
            "--opcua-security",
            "sign_and_encrypt",
            "--opcua-pki-dir",
            str(tmp_path / "pki"),
            "--opcua-trusted-dir",
            str(tmp_path),
        ]
    )
    settings = serve_settings(args)
    assert (settings.opcua.security, settings.opcua.pki_dir, settings.opcua.trusted_dir) == (
        "sign_and_encrypt",
        tmp_path / "pki",
        tmp_path,
    )
    with pytest.raises(SystemExit):
        build_parser().parse_args(["serve", "--opcua-security", "encrypt"])


def test_the_security_rules_of_the_user_manager():
    """TokenUserManager on a secure server: no session on a None channel unless None is offered, no
    user name on a None channel, no password that came unencrypted (asyncua's decrypt hook sets
    `password_encrypted`), BadIdentityTokenRejected / BadSecurityPolicyRejected raised."""
    from asyncua import ua
    from asyncua.common.utils import ServiceError

    gate = AdmissionGate(token="s3cret")
    strict = TokenUserManager(gate, secure=True, none_offered=False)
    with pytest.raises(ServiceError) as err:
        strict.get_user(None, certificate=b"")  # anonymous on None
    assert err.value.code == ua.StatusCodes.BadSecurityPolicyRejected
    relaxed = TokenUserManager(gate, secure=True, none_offered=True)
    assert relaxed.get_user(None, certificate=b"").authenticated is False  # anonymous reads on None
    relaxed.password_encrypted = True
    with pytest.raises(ServiceError) as err:
        relaxed.get_user(None, username="op", password="s3cret", certificate=b"")
    assert err.value.code == ua.StatusCodes.BadIdentityTokenRejected
    relaxed.password_encrypted = False
    with pytest.raises(ServiceError) as err:
        relaxed.get_user(None, username="op", password="s3cret", certificate=b"DER")
    assert err.value.code == ua.StatusCodes.BadIdentityTokenRejected
    relaxed.password_encrypted = True
    assert relaxed.get_user(None, username="op", password="s3cret", certificate=b"DER").authenticated
    assert gate.unauthorized == 0  # refused before the password
