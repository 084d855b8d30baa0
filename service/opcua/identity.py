"""Who a session is: the service token as the password of a user-name identity (`TokenUserManager`),
and the asyncua server that asks for that password encrypted with its own key (`TokenServer`).
The rules are in service.opcua.server's module docstring ("Users", "Security").
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import Any

from asyncua import Server, ua
from asyncua.common.utils import ServiceError
from asyncua.crypto.permission_rules import User, UserRole
from asyncua.server.user_managers import UserManager

from service.opcua.security import ClientTrust

log = logging.getLogger(__name__)


@dataclass
class TwinUser(User):
    """A session's user: `authenticated` when it gave the token as its password."""

    authenticated: bool = False


class TokenUserManager(UserManager):
    """asyncua user manager: the service token is the password (see the module docstring).

    `secure`: the server offers secure policies (has a certificate); then a password must come
    encrypted with the server's key and a user name is refused on a None channel. `trust`: the
    trusted client certificates, checked against the secure channel's certificate."""

    def __init__(
        self,
        gate: Any,
        read_requires_token: bool = False,
        *,
        secure: bool = False,
        none_offered: bool = True,
        trust: ClientTrust | None = None,
    ):
        self.gate, self.read_requires_token = gate, read_requires_token
        self.secure, self.none_offered, self.trust = secure, none_offered, trust
        self.password_encrypted: bool | None = None  # set by `decrypt_user_token` just before get_user

    def wrap(self, iserver: Any) -> None:
        """Watch asyncua's InternalServer.decrypt_user_token: it runs in ActivateSession right before
        get_user (same call, no await between), so `password_encrypted` is that token's."""
        decrypt = iserver.decrypt_user_token

        def decrypt_user_token(isession: Any, token: ua.UserNameIdentityToken):
            self.password_encrypted = bool(token.EncryptionAlgorithm)
            return decrypt(isession, token)

        iserver.decrypt_user_token = decrypt_user_token

    def get_user(
        self, iserver: Any, username: str | None = None, password: str | None = None, certificate: Any = None
    ) -> User | None:
        encrypted, self.password_encrypted = self.password_encrypted, None
        if not certificate and not self.none_offered:  # asyncua gives b"" on a None channel
            # asyncua opens a None channel even when None is not offered (discovery needs one);
            # no session may be activated on it
            log.warning("OPC UA: a session on the None security policy is refused (not offered)")
            raise ServiceError(ua.StatusCodes.BadSecurityPolicyRejected)
        if self.trust is not None:
            refusal = self.trust.refusal(certificate)
            if refusal is not None:
                log.warning(
                    "OPC UA: session refused (%s): the client certificate is not in %s", refusal, self.trust.folder
                )
                raise ServiceError(getattr(ua.StatusCodes, refusal))
        if username is None and password is None:
            if self.gate.requires_token and self.read_requires_token:
                self.gate.check_token(None)  # counted as unauthorized
                return None
            # role User: asyncua's ruleset gives the Anonymous role nothing, not even reads
            return TwinUser(role=UserRole.User, name=None, authenticated=not self.gate.requires_token)
        if self.secure and not certificate:
            log.warning("OPC UA: a user name on the None security policy is refused (only anonymous reads there)")
            raise ServiceError(ua.StatusCodes.BadIdentityTokenRejected)
        if self.secure and encrypted is False:
            log.warning(
                "OPC UA: a password sent unencrypted is refused (the endpoint asks for it encrypted "
                "with the server certificate); the token may have been exposed"
            )
            raise ServiceError(ua.StatusCodes.BadIdentityTokenRejected)
        if self.gate.check_token(password or "") is not None:
            return None  # BadUserAccessDenied at ActivateSession
        return TwinUser(role=UserRole.User, name=username or "user", authenticated=True)


class TokenServer(Server):
    """asyncua's Server with the password always encrypted with the server's key: on a secure
    endpoint by the endpoint's own policy (asyncua leaves it in clear inside SignAndEncrypt). The
    None endpoint of a secure server keeps asyncua's choice (the first SignAndEncrypt policy), so
    a client that tries a user name there still sends no password in clear before the refusal."""

    secure: bool = False

    def _set_endpoints(self, policy: Any, mode: ua.MessageSecurityMode, level: int) -> None:
        super()._set_endpoints(policy, mode, level)
        if self.secure and mode != ua.MessageSecurityMode.None_:
            for t in self.iserver.endpoints[-1].UserIdentityTokens:
                if t.TokenType == ua.UserTokenType.UserName:
                    t.SecurityPolicyUri = policy.URI
