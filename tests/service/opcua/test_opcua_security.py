"""OPC UA message security of the facade (service.opcua.security) against REAL asyncua servers and
clients on 127.0.0.1 (free ports): a service with a token (default `auto` = Sign and
SignAndEncrypt, no None endpoint), its self-signed server certificate in a temporary PKI folder and
a folder of trusted client certificates. Client certificates are made here with asyncua's
cert_gen (RSA 2048, SHA-256, application URI in subjectAltName). Every wait is bounded; no
wall-clock figure is asserted."""

from __future__ import annotations

import asyncio
import hashlib
import json
import stat
from collections.abc import Awaitable
from pathlib import Path

import pytest

asyncua = pytest.importorskip("asyncua")
from asyncua import Client, ua  # noqa: E402
from asyncua.crypto import cert_gen, security_policies  # noqa: E402
from cryptography import x509  # noqa: E402
from cryptography.hazmat.primitives import hashes, serialization  # noqa: E402
from cryptography.x509.oid import ExtendedKeyUsageOID  # noqa: E402

from service.opcua.layout import APPLICATION_URI, LAST_RESULT, NAMESPACE_URI, ROOT_FOLDER  # noqa: E402
from service.opcua.security import CERT_FILE, KEY_FILE  # noqa: E402
from service.settings import ServiceSettings  # noqa: E402

TOKEN = "opc-secure-token-456"
WAIT_S = 60.0
B256 = security_policies.SecurityPolicyBasic256Sha256
AES128 = security_policies.SecurityPolicyAes128Sha256RsaOaep
AES256 = security_policies.SecurityPolicyAes256Sha256RsaPss
S, SE = ua.MessageSecurityMode.Sign, ua.MessageSecurityMode.SignAndEncrypt


def run(coro: Awaitable, timeout: float = WAIT_S):
    return asyncio.run(asyncio.wait_for(coro, timeout))


def make_client_cert(folder: Path, name: str) -> tuple[Path, Path, str]:
    """A client application instance certificate (DER) and key (PEM); returns them and the URI."""
    uri = f"urn:bearing-twin-test:{name}"
    key = cert_gen.generate_private_key()
    cert = cert_gen.generate_self_signed_app_certificate(
        key,
        name,
        {"organizationName": "bearing-twin tests"},
        [x509.UniformResourceIdentifier(uri)],
        extended=[ExtendedKeyUsageOID.CLIENT_AUTH],
    )
    cert_path, key_path = folder / f"{name}.der", folder / f"{name}-key.pem"
    cert_path.write_bytes(cert.public_bytes(serialization.Encoding.DER))
    key_path.write_bytes(cert_gen.dump_private_key_as_pem(key))
    return cert_path, key_path, uri


@pytest.fixture(scope="module")
def pki(tmp_path_factory):
    root = tmp_path_factory.mktemp("opcua-security")
    trusted, clients = root / "trusted", root / "clients"
    trusted.mkdir()
    clients.mkdir()
    good = make_client_cert(clients, "operator-hmi")
    bad = make_client_cert(clients, "stranger")
    (trusted / "operator-hmi.der").write_bytes(good[0].read_bytes())  # trusted: copied in
    return {"root": root, "server": root / "server-pki", "trusted": trusted, "good": good, "bad": bad}


@pytest.fixture(scope="module")
def server(support, pki):
    settings = ServiceSettings(
        enable_zenoh=False,
        enable_recording=False,
        token=TOKEN,
        max_twins=2,
        opcua=f"opc.tcp://127.0.0.1:{support.free_port()}",
        opcua_pki_dir=pki["server"],
        opcua_trusted_dir=pki["trusted"],
    )
    assert settings.opcua.security == "auto" and settings.opcua_security_mode == "both"
    with support.ThreadServer(settings, start_timeout_s=120.0, stop_timeout_s=30.0) as srv:
        yield srv


async def secure_client(facade, who, policy=B256, mode=SE, password: str | None = TOKEN) -> Client:
    cert, key, uri = who
    c = Client(facade.url, timeout=20, watchdog_intervall=10.0)
    c.application_uri = uri
    # the server certificate pinned: the one the facade made and logged (what an operator trusts)
    await c.set_security(policy, str(cert), str(key), server_certificate=str(facade.pki.certificate), mode=mode)
    if password is not None:
        c.set_user("operator")
        c.set_password(password)
    return c


async def setpoint_node(c: Client, name: str):
    idx = await c.get_namespace_index(NAMESPACE_URI)
    twin = await c.nodes.objects.get_child([f"{idx}:{ROOT_FOLDER}", f"{idx}:default"])
    return (
        await twin.get_child([f"{idx}:Setpoint", f"{idx}:{name}"]),
        await twin.get_child([f"{idx}:Setpoint", f"{idx}:{LAST_RESULT}"]),
    )


def test_basic256sha256_sign_and_encrypt_writes_a_setpoint_that_lands(facade, pki, http, support):
    """(1) Basic256Sha256 SignAndEncrypt, the client's own certificate (trusted), the token as
    password: the write is accepted and the twin runs with it (its published state)."""

    async def main():
        c = await secure_client(facade, pki["good"])
        async with c:
            server_der = c.security_policy.peer_certificate
            node, last = await setpoint_node(c, "radial_load_n")
            await node.write_value(4200.0)
            return server_der, json.loads(await last.read_value()), await node.read_value()

    server_der, last, value = run(main())
    assert hashlib.sha1(server_der).hexdigest().upper() == facade.pki.thumbprint_sha1
    assert last["accepted"] is True and last["setpoint"]["radial_load_n"] == 4200.0 and value == 4200.0
    support.wait_for(
        lambda: http.get("/v1/bearings/default/state").json()["setpoint"]["radial_load_n"],
        lambda v: v == 4200.0,
        timeout=WAIT_S,
    )


@pytest.mark.parametrize(
    "policy, mode",
    [(B256, S), (AES128, SE), (AES128, S), (AES256, SE), (AES256, S)],
    ids=[
        "Basic256Sha256-Sign",
        "Aes128_Sha256_RsaOaep-SignAndEncrypt",
        "Aes128_Sha256_RsaOaep-Sign",
        "Aes256_Sha256_RsaPss-SignAndEncrypt",
        "Aes256_Sha256_RsaPss-Sign",
    ],
)
def test_every_offered_policy_and_mode_authenticates_and_writes(facade, pki, policy, mode):
    """The other five endpoints: each session authenticates with the token and may write."""
    value = {S: 1500.0, SE: 2500.0}[mode] + (100.0 if policy is AES128 else 200.0 if policy is AES256 else 0.0)

    async def main():
        async with await secure_client(facade, pki["good"], policy, mode) as c:
            node, last = await setpoint_node(c, "radial_load_n")
            await node.write_value(value)
            return json.loads(await last.read_value())

    last = run(main())
    assert last["accepted"] is True and last["setpoint"]["radial_load_n"] == value


def test_the_endpoints_offer_six_secure_policies_and_encrypt_the_password(facade):
    assert facade.security == "both"  # the default `auto` with a token: Sign and SignAndEncrypt

    async def main():
        return await Client(facade.url, timeout=20).connect_and_get_server_endpoints()

    endpoints = run(main())
    offered = {(e.SecurityPolicyUri.split("#")[1], e.SecurityMode) for e in endpoints}
    assert offered == {
        (p, m) for p in ("Basic256Sha256", "Aes128_Sha256_RsaOaep", "Aes256_Sha256_RsaPss") for m in (S, SE)
    }
    for e in endpoints:
        assert hashlib.sha1(e.ServerCertificate).hexdigest().upper() == facade.pki.thumbprint_sha1
        names = [t for t in e.UserIdentityTokens if t.TokenType == ua.UserTokenType.UserName]
        assert [t.SecurityPolicyUri for t in names] == [e.SecurityPolicyUri]  # password RSA-encrypted


def test_a_client_on_the_none_policy_is_refused(facade, server, monkeypatch):
    """(2) No None endpoint: asyncua's client finds none (UaError before any session); a client that
    skips that check gets a None channel (asyncua opens one for discovery) but its session is
    refused at ActivateSession with BadSecurityPolicyRejected."""

    async def plain():
        c = Client(facade.url, timeout=20, watchdog_intervall=10.0)
        c.set_user("operator")
        c.set_password(TOKEN)
        with pytest.raises(ua.UaError, match="No matching endpoints") as err:
            await c.connect()
        c.disconnect_socket()
        return err.value

    async def pushy():
        c = Client(facade.url, timeout=20, watchdog_intervall=10.0)
        # ignore the server's offer: go on with the None channel
        monkeypatch.setattr(Client, "find_endpoint", staticmethod(lambda endpoints, mode, uri: endpoints[0]))
        with pytest.raises(ua.UaStatusCodeError) as err:
            await c.connect()
        c.disconnect_socket()
        return err.value.code

    assert not isinstance(run(plain()), ua.UaStatusCodeError)
    assert run(pushy()) == ua.StatusCodes.BadSecurityPolicyRejected


def test_a_password_sent_unencrypted_is_refused(facade, pki, server):
    """The user-name policy asks for the password encrypted with the server's key; a client that
    sends it in clear (here inside a SignAndEncrypt channel) is refused, its password not tried."""
    unauthorized = server.service.gate.unauthorized

    async def main():
        c = await secure_client(facade, pki["good"])
        c.server_policy = lambda token_type: ua.UserTokenPolicy(
            PolicyId="username", TokenType=token_type, SecurityPolicyUri=security_policies.SecurityPolicyNone.URI
        )
        with pytest.raises(ua.UaStatusCodeError) as err:
            await c.connect()
        c.disconnect_socket()
        return err.value.code

    assert run(main()) == ua.StatusCodes.BadIdentityTokenRejected
    assert server.service.gate.unauthorized == unauthorized


def test_only_trusted_client_certificates_open_a_session(facade, pki):
    """(3) With opcua_trusted_dir: the stranger's certificate is refused at CreateSession
    (BadCertificateUntrusted, asyncua's CertificateValidator + TrustStore); a stranger that opens
    the channel with its own certificate but announces the trusted one at CreateSession is refused
    at ActivateSession (the facade checks the channel's certificate); the trusted one reads."""

    async def stranger():
        c = await secure_client(facade, pki["bad"])
        with pytest.raises(ua.UaStatusCodeError) as err:
            await c.connect()
        c.disconnect_socket()
        return err.value.code

    async def impostor():
        c = await secure_client(facade, pki["bad"])
        c.application_uri = pki["good"][2]
        trusted_der = pki["good"][0].read_bytes()
        create = c.uaclient.create_session

        async def lying_create_session(params):
            params.ClientCertificate = trusted_der
            return await create(params)

        c.uaclient.create_session = lying_create_session
        with pytest.raises(ua.UaStatusCodeError) as err:
            await c.connect()
        c.disconnect_socket()
        return err.value.code

    async def friend():
        async with await secure_client(facade, pki["good"], password=None) as c:  # anonymous: reads
            idx = await c.get_namespace_index(NAMESPACE_URI)
            node = await c.nodes.objects.get_child(
                [f"{idx}:{ROOT_FOLDER}", f"{idx}:default", f"{idx}:Identification", f"{idx}:designation"]
            )
            return await node.read_value()

    assert run(stranger()) == ua.StatusCodes.BadCertificateUntrusted
    assert run(impostor()) == ua.StatusCodes.BadCertificateUntrusted
    assert run(friend()) == "6208"


# ---- the server certificate: made once, reused; a given one checked ------------------------------------
def _open(settings):
    from service.wiring import TwinService

    return TwinService(settings).open()


def _light(support, tmp_path, **extra) -> ServiceSettings:
    """A service without twins, zenoh or recording: only the OPC UA facade."""
    return ServiceSettings(
        enable_zenoh=False,
        enable_recording=False,
        start_twin=False,
        token=TOKEN,
        opcua=f"opc.tcp://127.0.0.1:{support.free_port()}",
        **extra,
    )


def test_the_generated_certificate_is_kept_across_a_restart(support, tmp_path):
    """(4) First start: key (0600, folder 0700) and certificate made; second start (a new port, the
    same folder): the same key bytes and the same certificate (SHA-1 thumbprint), and a client
    that pinned the first run's certificate connects to the second."""
    folder = tmp_path / "pki"
    first = _open(_light(support, tmp_path, opcua_pki_dir=folder))
    try:
        pki1 = first.opcua.pki
        key_bytes, cert_bytes = (folder / KEY_FILE).read_bytes(), (folder / CERT_FILE).read_bytes()
        assert pki1.generated_key and pki1.generated_certificate
    finally:
        first.close()
    pinned = tmp_path / "pinned-server.der"
    pinned.write_bytes(cert_bytes)
    second = _open(_light(support, tmp_path, opcua_pki_dir=folder))
    try:
        pki2 = second.opcua.pki
        client = make_client_cert(tmp_path, "restart-client")

        async def main():
            c = Client(second.opcua.url, timeout=20, watchdog_intervall=10.0)
            c.application_uri = client[2]
            await c.set_security(B256, str(client[0]), str(client[1]), server_certificate=str(pinned), mode=SE)
            async with c:
                return await c.get_namespace_array()

        namespaces = run(main())
    finally:
        second.close()
    assert not pki2.generated_key and not pki2.generated_certificate
    assert pki2.thumbprint_sha1 == pki1.thumbprint_sha1 == hashlib.sha1(cert_bytes).hexdigest().upper()
    assert (folder / KEY_FILE).read_bytes() == key_bytes and (folder / CERT_FILE).read_bytes() == cert_bytes
    assert stat.S_IMODE((folder / KEY_FILE).stat().st_mode) == 0o600
    assert stat.S_IMODE(folder.stat().st_mode) == 0o700
    assert NAMESPACE_URI in namespaces
    # what the certificate is (OPC UA Part 6 6.2.2): RSA 2048, SHA-256, the application URI
    cert = x509.load_der_x509_certificate(cert_bytes)
    assert cert.public_key().key_size == 2048 and isinstance(cert.signature_hash_algorithm, hashes.SHA256)
    san = cert.extensions.get_extension_for_class(x509.SubjectAlternativeName).value
    assert APPLICATION_URI in san.get_values_for_type(x509.UniformResourceIdentifier)
    assert "localhost" in san.get_values_for_type(x509.DNSName)


def test_a_given_certificate_is_used_and_checked(support, tmp_path):
    """opcua_certificate / opcua_private_key: used as given (its thumbprint); one without the
    application URI, or a key of another certificate, is a one-line error naming the setting."""
    from service.wiring import WiringError

    def server_cert(name: str, uri: str):
        key = cert_gen.generate_private_key()
        cert = cert_gen.generate_self_signed_app_certificate(
            key, name, {}, [x509.UniformResourceIdentifier(uri)], extended=[ExtendedKeyUsageOID.SERVER_AUTH]
        )
        c, k = tmp_path / f"{name}.pem", tmp_path / f"{name}-key.pem"
        c.write_bytes(cert.public_bytes(serialization.Encoding.PEM))
        k.write_bytes(cert_gen.dump_private_key_as_pem(key))
        return c, k, cert

    good_cert, good_key, cert = server_cert("plant-issued", APPLICATION_URI)
    wrong_cert, wrong_key, _ = server_cert("other-app", "urn:someone-else:server")
    svc = _open(
        _light(
            support,
            tmp_path,
            opcua_certificate=good_cert,
            opcua_private_key=good_key,
            opcua_pki_dir=tmp_path / "unused",
        )
    )
    try:
        assert svc.opcua.pki.thumbprint_sha1 == cert.fingerprint(hashes.SHA1()).hex().upper()
        assert not (tmp_path / "unused").exists()  # nothing generated
    finally:
        svc.close()
    with pytest.raises(WiringError) as err:
        _open(_light(support, tmp_path, opcua_certificate=wrong_cert, opcua_private_key=wrong_key))
    assert "\n" not in str(err.value) and "opcua_certificate" in str(err.value) and APPLICATION_URI in str(err.value)
    with pytest.raises(WiringError) as err:
        _open(_light(support, tmp_path, opcua_certificate=good_cert, opcua_private_key=wrong_key))
    assert "opcua_private_key" in str(err.value) and "is not the key of" in str(err.value)


def test_all_mode_offers_none_for_anonymous_reads_only(support, tmp_path):
    """`all`: the None endpoint too, where an anonymous session reads and a user name is refused
    (BadIdentityTokenRejected: writes only over a signed channel)."""
    svc = _open(_light(support, tmp_path, opcua_security="all", opcua_pki_dir=tmp_path / "pki"))
    try:
        url = svc.opcua.url

        async def anonymous():
            async with Client(url, timeout=20, watchdog_intervall=10.0) as c:
                return await c.get_namespace_array()

        async def user():
            c = Client(url, timeout=20, watchdog_intervall=10.0)
            c.set_user("operator")
            c.set_password(TOKEN)
            with pytest.raises(ua.UaStatusCodeError) as err:
                await c.connect()
            c.disconnect_socket()
            return err.value.code

        assert NAMESPACE_URI in run(anonymous())
        assert run(user()) == ua.StatusCodes.BadIdentityTokenRejected
    finally:
        svc.close()
