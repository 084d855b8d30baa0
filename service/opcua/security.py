"""OPC UA message security of the facade: which policies a mode offers, the server certificate
(given, or self-signed once and reused), and the trusted client certificates.

Modes (setting `opcua_security`, docs/service.md "OPC UA"):

    none              SecurityPolicy#None only (no certificate)
    sign              Basic256Sha256, Aes128_Sha256_RsaOaep, Aes256_Sha256_RsaPss in Sign
    sign_and_encrypt  the same three in SignAndEncrypt
    both              the three in SignAndEncrypt and in Sign
    all               `both` plus None (anonymous read-only there)

The generated certificate follows OPC UA Part 6 6.2.2 (asyncua.crypto.cert_gen): RSA 2048,
SHA-256, the application URI and the host names in subjectAltName, key and extended key usage of
an application instance. Its key is written once with mode 0600 (O_EXCL: never overwritten);
the certificate is reused while it matches the key, holds the application URI and is in date.
"""

from __future__ import annotations

import ipaddress
import logging
import os
import socket
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

from asyncua import ua
from asyncua.common.utils import ServiceError
from asyncua.crypto import cert_gen
from asyncua.crypto.truststore import TrustStore
from asyncua.crypto.validator import CertificateValidator, CertificateValidatorOptions
from cryptography import x509
from cryptography.hazmat.primitives import hashes, serialization
from cryptography.hazmat.primitives.asymmetric import rsa
from cryptography.x509.oid import ExtendedKeyUsageOID

log = logging.getLogger(__name__)

_T = ua.SecurityPolicyType
SIGN_AND_ENCRYPT = [
    _T.Basic256Sha256_SignAndEncrypt,
    _T.Aes128Sha256RsaOaep_SignAndEncrypt,
    _T.Aes256Sha256RsaPss_SignAndEncrypt,
]
SIGN = [_T.Basic256Sha256_Sign, _T.Aes128Sha256RsaOaep_Sign, _T.Aes256Sha256RsaPss_Sign]
POLICIES: dict[str, list[ua.SecurityPolicyType]] = {
    "none": [_T.NoSecurity],
    "sign": SIGN,
    "sign_and_encrypt": SIGN_AND_ENCRYPT,
    "both": SIGN_AND_ENCRYPT + SIGN,
    "all": SIGN_AND_ENCRYPT + SIGN + [_T.NoSecurity],
}
CERT_FILE, KEY_FILE = "server-cert.der", "server-key.pem"
CERT_DAYS = 5 * 365  # validity of a generated certificate [days]


class PkiError(ValueError):
    """A certificate, key or trust folder that cannot be used (the message names the setting)."""


def thumbprint(cert: x509.Certificate) -> str:
    """SHA-1 thumbprint of the DER certificate, upper-case hex (as OPC UA tools show it)."""
    return cert.fingerprint(hashes.SHA1()).hex().upper()


@dataclass(frozen=True)
class ServerPki:
    """The server's certificate and key files, and what operators compare."""

    certificate: Path
    private_key: Path
    thumbprint_sha1: str
    not_after: datetime
    generated_key: bool = False
    generated_certificate: bool = False


def _load_cert(path: Path, field: str) -> x509.Certificate:
    try:
        data = Path(path).read_bytes()
        return x509.load_pem_x509_certificate(data) if b"-----BEGIN" in data else x509.load_der_x509_certificate(data)
    except (OSError, ValueError) as exc:
        raise PkiError(f"{field}: cannot read a certificate from {str(path)!r} ({exc})") from None


def _load_key(path: Path, field: str) -> rsa.RSAPrivateKey:
    try:
        data = Path(path).read_bytes()
        key = (
            serialization.load_pem_private_key(data, None)
            if b"-----BEGIN" in data
            else serialization.load_der_private_key(data, None)
        )
    except (OSError, ValueError, TypeError) as exc:
        raise PkiError(f"{field}: cannot read an unencrypted private key from {str(path)!r} ({exc})") from None
    if not isinstance(key, rsa.RSAPrivateKey):
        raise PkiError(f"{field}: {str(path)!r} is not an RSA key (the OPC UA RSA policies need one)")
    return key


def _same_key(cert: x509.Certificate, key: rsa.RSAPrivateKey) -> bool:
    pub = cert.public_key()
    return isinstance(pub, rsa.RSAPublicKey) and pub.public_numbers() == key.public_key().public_numbers()


def _uris(cert: x509.Certificate) -> list[str]:
    try:
        return cert.extensions.get_extension_for_class(x509.SubjectAlternativeName).value.get_values_for_type(
            x509.UniformResourceIdentifier
        )
    except x509.ExtensionNotFound:
        return []


def _problem(cert: x509.Certificate, application_uri: str) -> str | None:
    now = datetime.now(UTC)
    if cert.not_valid_after_utc <= now:
        return f"it expired on {cert.not_valid_after_utc:%Y-%m-%d}"
    if cert.not_valid_before_utc > now:
        return f"it is valid only from {cert.not_valid_before_utc:%Y-%m-%d}"
    if application_uri not in _uris(cert):
        return (
            f"its subjectAltName has no URI {application_uri} (OPC UA Part 6 6.2.2: the "
            "application URI; it holds " + (", ".join(_uris(cert)) or "none") + ")"
        )
    return None


def given_pki(certificate: Path, private_key: Path, application_uri: str) -> ServerPki:
    """A certificate and key the operator gave (settings opcua_certificate, opcua_private_key)."""
    cert = _load_cert(certificate, "opcua_certificate")
    key = _load_key(private_key, "opcua_private_key")
    if not _same_key(cert, key):
        raise PkiError(f"opcua_private_key: {str(private_key)!r} is not the key of {str(certificate)!r}")
    problem = _problem(cert, application_uri)
    if problem is not None:
        raise PkiError(f"opcua_certificate: {str(certificate)!r} cannot serve: {problem}")
    return ServerPki(Path(certificate), Path(private_key), thumbprint(cert), cert.not_valid_after_utc)


def _host_names(hosts: list[str]) -> list[x509.GeneralName]:
    names: list[x509.GeneralName] = []
    for host in dict.fromkeys([socket.gethostname(), *hosts, "localhost"]):
        if not host:
            continue
        try:
            names.append(x509.IPAddress(ipaddress.ip_address(host)))
        except ValueError:
            names.append(x509.DNSName(host))
    return names


def self_signed_pki(pki_dir: Path, application_uri: str, hosts: list[str]) -> ServerPki:
    """The server certificate in `pki_dir`: the key is made once (0600, never overwritten), the
    certificate is made from it when missing, for another key, without the application URI, or
    out of date; otherwise both are reused (same thumbprint across restarts)."""
    pki_dir = Path(pki_dir)
    try:
        pki_dir.mkdir(mode=0o700, parents=True, exist_ok=True)
    except OSError as exc:
        raise PkiError(f"opcua_pki_dir: cannot make {str(pki_dir)!r} ({exc})") from None
    key_path, cert_path = pki_dir / KEY_FILE, pki_dir / CERT_FILE
    generated_key = False
    if key_path.exists():
        key = _load_key(key_path, "opcua_pki_dir")
        mode = key_path.stat().st_mode & 0o777
        if mode & 0o077:
            log.warning("OPC UA: the server key %s is readable by others (mode %o); chmod 600 it", key_path, mode)
    else:
        key = cert_gen.generate_private_key()  # RSA 2048, e 65537
        try:
            fd = os.open(key_path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        except FileExistsError:  # another process made it just now
            return self_signed_pki(pki_dir, application_uri, hosts)
        except OSError as exc:
            raise PkiError(f"opcua_pki_dir: cannot write the key {str(key_path)!r} ({exc})") from None
        with os.fdopen(fd, "wb") as f:
            f.write(cert_gen.dump_private_key_as_pem(key))
        generated_key = True
        log.info("OPC UA: made the server key %s (RSA 2048, mode 0600)", key_path)
    cert = None
    if cert_path.exists():
        try:
            cert = _load_cert(cert_path, "opcua_pki_dir")
        except PkiError as exc:
            log.warning("OPC UA: %s; making a new certificate", exc)
        if cert is not None:
            problem = "it is for another key" if not _same_key(cert, key) else _problem(cert, application_uri)
            if problem is not None:
                log.warning(
                    "OPC UA: the server certificate %s (SHA-1 %s) is replaced: %s", cert_path, thumbprint(cert), problem
                )
                cert = None
    generated_cert = cert is None
    if cert is None:
        cert = cert_gen.generate_self_signed_app_certificate(
            key,
            "bearing-twin OPC UA server",
            {"organizationName": "bearing-twin"},
            [x509.UniformResourceIdentifier(application_uri), *_host_names(hosts)],
            extended=[ExtendedKeyUsageOID.SERVER_AUTH, ExtendedKeyUsageOID.CLIENT_AUTH],
            days=CERT_DAYS,
        )
        tmp = cert_path.with_suffix(".tmp")
        tmp.write_bytes(cert.public_bytes(serialization.Encoding.DER))
        os.replace(tmp, cert_path)
    return ServerPki(cert_path, key_path, thumbprint(cert), cert.not_valid_after_utc, generated_key, generated_cert)


class ClientTrust:
    """The trusted client certificates (setting opcua_trusted_dir): a client may open a session
    when its certificate, or a CA certificate that signed it, is in the folder (asyncua TrustStore,
    reloaded at each start of the server)."""

    OPTIONS = (
        CertificateValidatorOptions.TIME_RANGE
        | CertificateValidatorOptions.URI
        | CertificateValidatorOptions.TRUSTED
        | CertificateValidatorOptions.PEER_CLIENT
    )

    def __init__(self, folder: Path):
        self.folder = Path(folder)
        self.store = TrustStore([self.folder], [])
        self.count = 0

    async def load(self) -> ClientTrust:
        try:
            await self.store.load()
        except (OSError, ValueError) as exc:
            raise PkiError(
                f"opcua_trusted_dir: cannot read the certificates in {str(self.folder)!r} "
                f"({' '.join(str(exc).split())})"
            ) from None
        # the files asyncua's TrustStore reads: names with a dot ending in der or pem
        self.count = sum(1 for p in self.folder.glob("*.*") if p.name.lower().endswith(("der", "pem")))
        if self.count == 0:
            raise PkiError(
                f"opcua_trusted_dir: {str(self.folder)!r} holds no .der or .pem certificate: no client could connect"
            )
        return self

    def validator(self):
        """asyncua's CertificateValidator (for Server.set_certificate_validator: the certificate
        the client announces at CreateSession), logging each refusal in one line."""
        check = CertificateValidator(self.OPTIONS, self.store)

        async def validate(cert: x509.Certificate, app_description: ua.ApplicationDescription) -> None:
            try:
                await check.validate(cert, app_description)
            except ServiceError as exc:
                log.warning(
                    "OPC UA: session refused (%s): client %s, certificate %s, SHA-1 %s (trusted: the "
                    "certificates in %s)",
                    ua.StatusCode(ua.UInt32(exc.code)).name,
                    app_description.ApplicationUri,
                    cert.subject.rfc4514_string(),
                    thumbprint(cert),
                    self.folder,
                )
                raise

        return validate

    def refusal(self, der: bytes | None) -> str | None:
        """None when the certificate `der` (the secure channel's, DER) is trusted and in date,
        else the OPC UA status name."""
        if not der:
            return "BadCertificateInvalid"
        try:
            cert = x509.load_der_x509_certificate(der)
        except ValueError:
            return "BadCertificateInvalid"
        now = datetime.now(UTC)
        if not cert.not_valid_before_utc <= now < cert.not_valid_after_utc:
            return "BadCertificateTimeInvalid"
        if not self.store.is_trusted(cert):
            return "BadCertificateUntrusted"
        return None
