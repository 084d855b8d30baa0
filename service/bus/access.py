"""zenoh's own security for the bus: authentication of every link and access-control rules.

Nothing of the HTTP token travels on zenoh. When access control is on (docs/operations.md "zenoh access
control"):

* every link is authenticated by zenoh itself when it opens: the user-password handshake
  (`transport.auth.usrpwd`: the connecting side proves it knows the password of a user of the
  accepting side's users file, an HMAC over a nonce; the password itself is never sent) and/or
  mutual TLS (`transport.link.tls`, `enable_mtls`: both sides show a certificate signed by the
  CA). A peer without credentials cannot open a link, so it receives nothing and nothing it
  sends reaches anyone.
* the node that accepts links (a listening service, `bearing-twin router`) enforces zenoh's
  `access_control` rules, default deny, on every message in and out of each link, matched to
  the link's authenticated user name or certificate common name (`subjects`):

  ========  ==================================================================================
  role      may (keys under the prefix P, one twin id `*`)
  ========  ==================================================================================
  readers   subscribe to P/*/state, P/*/ball/*, P/*/setpoint/result, P/*/defects/result,
            P/*/temperature/result, P/*/alarm, P/*/vibration, P/*/vibration/waveform,
            P/*/vibration/comparison; query P/*/snapshot and P/*/owner; watch and query the
            liveliness tokens P/*/alive
  writers   what readers may, and put P/*/setpoint, P/*/defects, P/*/temperature and
            P/*/vibration/measured
  services  put what readers subscribe to; subscribe to what writers put; declare
            and answer the queryables P/*/snapshot and P/*/owner; declare the liveliness tokens
            P/*/alive; query P/*/owner and the liveliness of P/*/alive (the id clash check)
  ========  ==================================================================================

  Each role's rules cover both directions of its links: what the peer may send in (ingress)
  and what may be sent out to it (egress): a reader is sent states and replies but never a
  setpoint, a writer is told where the setpoint subscribers are, a service is sent setpoints
  and queries. Rules match a message when the rule's key expression includes the message's, so
  a subscriber on a wider expression (`P/**`, `**`) is refused as a whole.

What zenoh (eclipse-zenoh 1.10) cannot do, and what we do instead:

* only the side that ACCEPTS a link authenticates the other one (usrpwd); on the connecting side
  the link carries no user name, so rules keyed by user names cannot match it (it falls to the
  default, deny). Hence a secured service either listens (its own rules) or joins a router (the
  router's rules; the service has no rules of its own and trusts the one router it was told to
  connect to), never both (settings refuse it), and secured nodes do not auto-connect to peers
  learnt by gossip.
* the rules see the user, not the twin: a writer may put the setpoints of every twin under the
  prefix; a service may publish for any twin id (two prefixes with different writer lists need
  two routers or two prefixes' rules, see `acl_config(prefixes=...)`).
* a subscriber never learns who sent a sample, so the service cannot tell writers apart: who may
  write is decided entirely by the rules (no payload carries a token).
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from service.keys import (
    ALARM,
    ALIVE,
    BALL,
    DEFECTS,
    DEFECTS_RESULT,
    OWNER,
    SETPOINT,
    SETPOINT_RESULT,
    SNAPSHOT,
    STATE,
    TEMPERATURE,
    TEMPERATURE_RESULT,
    VIBRATION,
    VIBRATION_COMPARISON,
    VIBRATION_MEASURED,
    VIBRATION_WAVEFORM,
    all_twins,
)
from service.settings import zenoh_access_enabled

# what each role may do: (messages, flow, key suffixes under P/*)
# what a twin publishes: its state, balls, the results of what was written to it, alarm events,
# vibration and the comparisons of measured windows
_OUT = [
    STATE,
    f"{BALL}/*",
    SETPOINT_RESULT,
    DEFECTS_RESULT,
    TEMPERATURE_RESULT,
    ALARM,
    VIBRATION,
    VIBRATION_WAVEFORM,
    VIBRATION_COMPARISON,
]
# what a writer puts to a twin (and a service subscribes to)
_IN = [SETPOINT, DEFECTS, TEMPERATURE, VIBRATION_MEASURED]
_READ_IN = [
    (["declare_subscriber"], "ingress", _OUT),
    (["query"], "ingress", [SNAPSHOT, OWNER]),
    (["declare_liveliness_subscriber", "liveliness_query"], "ingress", [ALIVE]),
]
_READ_OUT = [
    (["put"], "egress", _OUT),
    (["declare_queryable", "reply"], "egress", [SNAPSHOT, OWNER]),
    (["liveliness_token"], "egress", [ALIVE]),
]
_WRITE = [
    (["put"], "ingress", _IN),
    (["declare_subscriber"], "egress", _IN),
]
_SERVICE = [
    (["put"], "ingress", _OUT),
    (["declare_subscriber"], "ingress", _IN),
    (["declare_queryable", "reply"], "ingress", [SNAPSHOT, OWNER]),
    (["liveliness_token"], "ingress", [ALIVE]),
    (["query"], "ingress", [OWNER]),
    (["liveliness_query"], "ingress", [ALIVE]),
    (["put"], "egress", _IN),
    (["declare_subscriber"], "egress", _OUT),
    (["query"], "egress", [SNAPSHOT, OWNER]),
    (["declare_queryable", "reply"], "egress", [OWNER]),
    (["declare_liveliness_subscriber", "liveliness_query", "liveliness_token"], "egress", [ALIVE]),
]
ROLE_RULES = {"readers": _READ_IN + _READ_OUT, "writers": _READ_IN + _READ_OUT + _WRITE, "services": _SERVICE}


@dataclass(frozen=True)
class Roles:
    """Who is who: user names or TLS certificate common names per role."""

    services: tuple[str, ...] = ()
    writers: tuple[str, ...] = ()
    readers: tuple[str, ...] = ()

    def items(self) -> list[tuple[str, tuple[str, ...]]]:
        return [("services", self.services), ("writers", self.writers), ("readers", self.readers)]


def all_twins_canonical(prefix: str, suffix: str) -> str:
    """`{prefix}/*/{suffix}` in zenoh's canonical form (`**/*` is written `*/**`)."""
    import zenoh

    return str(zenoh.KeyExpr.autocanonize(all_twins(prefix, suffix)))


def acl_config(prefixes: str | Sequence[str], roles: Roles, *, tls: bool = False) -> dict:
    """zenoh's `access_control` section (default deny) for the roles under the key prefix(es).

    Each role member is matched by user name, and with `tls` also by certificate common name."""
    prefixes = [prefixes] if isinstance(prefixes, str) else list(prefixes)
    rules: list[dict] = []
    subjects: list[dict] = []
    policies: list[dict] = []
    for role, names in roles.items():
        if not names:
            continue
        ids = []
        for n, (messages, flow, suffixes) in enumerate(ROLE_RULES[role]):
            rule_id = f"{role}-{n}"
            rules.append(
                {
                    "id": rule_id,
                    "messages": messages,
                    "flows": [flow],
                    "permission": "allow",
                    "key_exprs": sorted({all_twins_canonical(p, s) for p in prefixes for s in suffixes}),
                }
            )
            ids.append(rule_id)
        subject_ids = [f"{role}-users"]
        subjects.append({"id": f"{role}-users", "usernames": list(names)})
        if tls:
            subjects.append({"id": f"{role}-certs", "cert_common_names": list(names)})
            subject_ids.append(f"{role}-certs")
        policies.append({"id": role, "rules": ids, "subjects": subject_ids})
    return {"enabled": True, "default_permission": "deny", "rules": rules, "subjects": subjects, "policies": policies}


@dataclass(frozen=True)
class ZenohAccess:
    """The security settings of one zenoh session (see the module docstring).

    `user`/`password`: the credentials this session presents when it connects; `usersfile`: the
    users it accepts on its listen endpoints; `tls_*`: mutual TLS; `roles`: the access-control
    rules it enforces on the links it accepts (None: no rules, e.g. a client)."""

    user: str | None = None
    password: str | None = field(default=None, repr=False)
    usersfile: Path | None = None
    tls_root_ca: Path | None = None
    tls_certificate: Path | None = None
    tls_private_key: Path | None = None
    roles: Roles | None = None

    @property
    def tls(self) -> bool:
        return self.tls_certificate is not None

    @property
    def enabled(self) -> bool:
        return zenoh_access_enabled(self.usersfile, self.user, self.tls_certificate)

    @classmethod
    def from_settings(cls, s: Any, *, enforce: bool = False) -> ZenohAccess:
        """From the `zenoh` settings group (`ZenohAccessConfig` of the service, the router or a
        client). `enforce`: build the access-control rules (a node that accepts links); the
        service's own user is always one of the services."""
        roles = None
        if enforce:
            services = tuple(dict.fromkeys([*s.services, *([s.user] if s.user else [])]))
            roles = Roles(services=services, writers=tuple(s.writers), readers=tuple(s.readers))
        return cls(
            user=s.user,
            password=s.password_value,
            usersfile=s.usersfile,
            tls_root_ca=s.tls_root_ca,
            tls_certificate=s.tls_certificate,
            tls_private_key=s.tls_private_key,
            roles=roles,
        )

    @classmethod
    def from_env(cls) -> ZenohAccess:
        """A client's credentials from BEARING_TWIN_ZENOH_USER / _PASSWORD (and _TLS_*)."""
        from service.settings import ZenohAccessSettings

        return cls.from_settings(ZenohAccessSettings().zenoh)

    def apply(self, config: Any, prefixes: str | Sequence[str], *, listening: bool) -> None:
        """Insert authentication (and, for a node that accepts links, the rules) into a
        zenoh.Config."""
        if not self.enabled:
            return
        if self.user is not None:
            config.insert_json5("transport/auth/usrpwd/user", json.dumps(self.user))
            config.insert_json5("transport/auth/usrpwd/password", json.dumps(self.password))
        if self.usersfile is not None and listening:
            config.insert_json5(
                "transport/auth/usrpwd/dictionary_file", json.dumps(str(Path(self.usersfile).resolve()))
            )
        if self.tls:
            tls = {
                "root_ca_certificate": self.tls_root_ca,
                "listen_certificate": self.tls_certificate,
                "listen_private_key": self.tls_private_key,
                "connect_certificate": self.tls_certificate,
                "connect_private_key": self.tls_private_key,
            }
            for key, path in tls.items():
                if path is None:
                    raise ValueError(
                        f"zenoh TLS needs its {key.replace('_', ' ')}: give CA, certificate and key together"
                    )
                config.insert_json5(f"transport/link/tls/{key}", json.dumps(str(Path(path).resolve())))
            config.insert_json5("transport/link/tls/enable_mtls", "true")
        if self.roles is not None and listening:
            config.insert_json5("access_control", json.dumps(acl_config(prefixes, self.roles, tls=self.tls)))

    def describe(self, *, listening: bool) -> str:
        """One line for the start-up banner (never the password)."""
        if not self.enabled:
            return "no zenoh access control: anyone who reaches the endpoint reads every twin"
        parts = []
        if self.user is not None:
            parts.append(f"connects as {self.user!r}")
        if self.tls:
            parts.append("mutual TLS")
        if listening and self.usersfile is not None:
            parts.append(f"accepts the users of {str(self.usersfile)!r}")
        if listening and self.roles is not None:
            parts.append(
                "rules: " + "; ".join(f"{role} {', '.join(names) or '(none)'}" for role, names in self.roles.items())
            )
        elif not listening:
            parts.append("the rules of the router (or service) it connects to apply")
        return "zenoh access control on: " + ", ".join(parts)
