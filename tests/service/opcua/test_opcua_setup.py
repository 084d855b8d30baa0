"""The OPC UA facade's set-up: the token as password (TokenUserManager against the service's
admission gate), the endpoint setting and flag, and a busy port as a one-line WiringError."""

from __future__ import annotations

import argparse
import socket

import pytest
from pydantic import ValidationError

pytest.importorskip("asyncua")

from service.core.admission import AdmissionGate  # noqa: E402
from service.opcua.server import TokenUserManager  # noqa: E402
from service.settings import ServiceSettings  # noqa: E402


def test_the_token_is_the_password():
    gate = AdmissionGate(token="s3cret")
    users = TokenUserManager(gate, read_requires_token=False)
    anonymous = users.get_user(None)
    assert anonymous is not None and anonymous.authenticated is False      # reads, cannot write
    good = users.get_user(None, username="op", password="s3cret")
    assert good is not None and good.authenticated and good.name == "op"
    assert gate.unauthorized == 0
    assert users.get_user(None, username="op", password="wrong") is None   # session refused
    assert users.get_user(None, username="op", password=None) is None
    assert gate.unauthorized == 2
    strict = TokenUserManager(gate, read_requires_token=True)
    assert strict.get_user(None) is None and gate.unauthorized == 3          # anonymous refused
    open_gate = TokenUserManager(AdmissionGate(token=None))
    assert open_gate.get_user(None).authenticated is True                   # no token: anyone writes
    assert open_gate.get_user(None, username="x", password="anything").authenticated is True


def test_the_endpoint_setting_and_flag():
    assert ServiceSettings().opcua is None                                   # off by default
    assert ServiceSettings(opcua="opc.tcp://127.0.0.1:4840").opcua == "opc.tcp://127.0.0.1:4840"
    with pytest.raises(ValidationError, match="opcua"):
        ServiceSettings(opcua="http://127.0.0.1:4840")
    from service.tools.cli import _serve_settings, build_parser

    args = build_parser().parse_args(["serve", "--opcua", "opc.tcp://127.0.0.1:4841"])
    assert isinstance(args, argparse.Namespace)
    assert _serve_settings(args).opcua == "opc.tcp://127.0.0.1:4841"


def test_a_busy_port_is_a_one_line_wiring_error():
    from service.wiring import TwinService, WiringError

    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        settings = ServiceSettings(enable_zenoh=False, enable_recording=False, start_twin=False,
                                   opcua=f"opc.tcp://127.0.0.1:{port}")
        with pytest.raises(WiringError) as err:
            TwinService(settings).open()
    text = str(err.value)
    assert "\n" not in text and "address already in use" in text and "--opcua" in text
