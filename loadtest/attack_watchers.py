"""The attack's floods on what watchers use (loadtest.attack runs each in its own process):

* `squat`: an anonymous zenoh peer (no credentials) declares P/{id}/alive and answers P/{id}/owner
  with forged text for fresh ids; the attacker then creates each id over HTTP with the token and
  deletes it again. Counted: `created` (201), `refused_capacity` (503 from the admission by
  measured capacity, either of its verdicts: no capacity left, or a twin costlier than a core's
  share; the admission, not the claim, refused it, and a slow host under the floods has no room
  for a second twin), `blocked` (409: a claim zenoh did not authenticate blocked a create),
  `echoed` (an answer repeated the forged text), any other answer by status in `other`. With
  zenoh access control on the peer cannot even open a link; with only the token set the service
  does not trust it. With nothing secured (no token given to the attack, no `--start`) the
  service trusts every claim by design (docs/operations.md, "Twin-id claims on zenoh"): a
  blocked create is then reported, not a failure (`secure` false); an echo always fails.
* `opcua_logins`: password guesses on a secure OPC UA endpoint (a client certificate made here,
  Basic256Sha256 SignAndEncrypt), as fast as the server answers: `tried`, `refused`, `accepted`
  (a guess that opened a session: never).
* `opcua_sessions`: anonymous sessions opened and kept until the server refuses one
  (`opened`, `refused` with the status names).
* `opcua_subscriptions`: one anonymous session asks for `subscriptions` subscriptions of `items`
  monitored items at 1 ms and counts what it is granted and the notifications it receives.
"""

from __future__ import annotations

import asyncio
import collections
import functools
import json
import secrets
import tempfile
import time
from pathlib import Path
from typing import Any

from service.keys import DEFAULT_PREFIX
from service.settings import ZenohAccessSettings

FORGED_HOST = "evil-squatter"  # the forged owner text; never to be found in an answer
# how the registry words both verdicts of a refused admission ("... refused: this host has no
# capacity left ..." / "... refused: this host cannot run the twin in real time ...")
ADMISSION_REFUSAL = "refused: this host"
WATCHERS = ("squat", "opcua_logins", "opcua_sessions", "opcua_subscriptions")


def target_prefix(started: object | None) -> str:
    """The zenoh key prefix of the attacked service: the default for one the attack started
    (its environment holds no BEARING_TWIN_* setting), else the settings' (flat or nested variable)."""
    return DEFAULT_PREFIX if started is not None else ZenohAccessSettings().zenoh.prefix


def specs(cfg: Any, started: Any, url: str, zenoh_endpoint: str | None, token: str | None) -> list:
    """(target, spec) of each flood of this module the attack `cfg` asks for (a child process each)."""
    specs = []
    if cfg.squat and zenoh_endpoint:
        specs.append(
            (
                run_part,
                {
                    "mode": "squat",
                    "flood": squat,
                    "url": url,
                    "token": token,
                    "secure": started is not None or bool(token),
                    "endpoint": zenoh_endpoint,
                    "seconds": cfg.seconds,
                    "max_ids": 3,
                    "prefix": target_prefix(started),
                },
            )
        )
    opcua_url = started.opcua_url if started is not None else cfg.opcua_url
    if opcua_url:
        common = {
            "flood": opcua,
            "url": opcua_url,
            "seconds": cfg.seconds,
            "bearing_id": cfg.bearing_id,
            "secure": started is not None or bool(token),
        }
        specs += [
            (run_part, {**common, "mode": "opcua_logins"}),
            (run_part, {**common, "mode": "opcua_sessions", "max_sessions": 200}),
            (run_part, {**common, "mode": "opcua_subscriptions", "subscriptions": 50, "items": 100, "connected": None}),
        ]
    return specs


def run_part(spec: dict, go, out) -> None:
    """Child process: run `spec["flood"](spec, go)` and put its report (or the crash) on `out`."""
    try:
        out.put(spec["flood"](spec, go))
    except BaseException as exc:  # noqa: BLE001 - reported to the parent
        out.put({"mode": spec["mode"], "crashed": f"{type(exc).__name__}: {exc}"})


# ---- zenoh id squatting -----------------------------------------------------------------------
def squat(spec: dict, go) -> dict:
    import httpx
    import zenoh

    from service.bus.access import ZenohAccess
    from service.bus.zenoh_bus import client_config

    prefix, url, token = spec["prefix"], spec["url"], spec["token"]
    headers = {"Authorization": f"Bearer {token}"} if token else {}
    counts: collections.Counter = collections.Counter()
    try:  # no credentials: refused where zenoh access control is on
        session = zenoh.open(client_config([spec["endpoint"]], access=ZenohAccess(), prefix=prefix))
    except Exception:  # noqa: BLE001 - the link was refused: the creates run without a claim
        session = None
    go.wait(120.0)
    t0 = time.monotonic()
    try:
        with httpx.Client(base_url=url, timeout=60.0, headers=headers) as http:
            while time.monotonic() - t0 < spec["seconds"] and counts["attempts"] < spec["max_ids"]:
                bid = f"squat-{secrets.token_hex(3)}"
                key = f"{prefix}/{bid}"
                forged = json.dumps(
                    {
                        "key": key,
                        "bearing_id": bid,
                        "pid": 1,
                        "host": FORGED_HOST,
                        "http": f"http://{FORGED_HOST}",
                        "zid": "0",
                    }
                )
                token_ = owner = None
                if session is not None:
                    token_ = session.liveliness().declare_token(f"{key}/alive")
                    owner = session.declare_queryable(f"{key}/owner", functools.partial(_reply, f"{key}/owner", forged))
                time.sleep(0.2)
                counts["attempts"] += 1
                r = http.post("/v1/bearings", json={"id": bid, "designation": "6208"})
                counts[
                    "created"
                    if r.status_code == 201
                    else "blocked"
                    if r.status_code == 409
                    else "refused_capacity"
                    if r.status_code == 503 and ADMISSION_REFUSAL in r.text
                    else f"status_{r.status_code}"
                ] += 1
                counts["echoed"] += FORGED_HOST in r.text
                if r.status_code == 201:
                    http.delete(f"/v1/bearings/{bid}")
                for entity in (owner, token_):
                    if entity is not None:
                        entity.undeclare()
    finally:
        if session is not None:
            session.close()
    return {
        "mode": "squat",
        "seconds": round(time.monotonic() - t0, 2),
        "peer_linked": session is not None,
        "secure": bool(spec["secure"]),
        **{k: counts.get(k, 0) for k in ("attempts", "created", "refused_capacity", "blocked", "echoed")},
        "other": {k: v for k, v in counts.items() if k.startswith("status_")},
    }


# ---- OPC UA ------------------------------------------------------------------------------------
def _reply(key: str, payload: str, query: Any) -> None:
    """Answer a zenoh query on `key` with `payload` (the squatter's forged owner record)."""
    query.reply(key, payload)


def _client_cert(folder: Path) -> tuple[str, str, str]:
    from asyncua.crypto import cert_gen
    from cryptography import x509
    from cryptography.hazmat.primitives import serialization
    from cryptography.x509.oid import ExtendedKeyUsageOID

    uri = "urn:bearing-twin-attack:client"
    key = cert_gen.generate_private_key()
    cert = cert_gen.generate_self_signed_app_certificate(
        key,
        "attack",
        {"organizationName": "attack"},
        [x509.UniformResourceIdentifier(uri)],
        extended=[ExtendedKeyUsageOID.CLIENT_AUTH],
    )
    cert_path, key_path = folder / "attack.der", folder / "attack-key.pem"
    cert_path.write_bytes(cert.public_bytes(serialization.Encoding.DER))
    key_path.write_bytes(cert_gen.dump_private_key_as_pem(key))
    return str(cert_path), str(key_path), uri


async def _client(url: str, cert: tuple[str, str, str] | None, password: str | None = None):
    from asyncua import Client

    c = Client(url, timeout=20, watchdog_intervall=60.0)
    if cert is not None:
        c.application_uri = cert[2]
        await c.set_security_string(f"Basic256Sha256,SignAndEncrypt,{cert[0]},{cert[1]}")
    if password is not None:
        c.set_user("operator")
        c.set_password(password)
    return c


def _status_name(exc: BaseException) -> str:
    from asyncua import ua

    code = getattr(exc, "code", None)
    return ua.StatusCode(code).name if code is not None else type(exc).__name__


def opcua(spec: dict, go) -> dict:
    """One of the OPC UA floods (spec["mode"]), in this child process."""
    import logging

    logging.getLogger("asyncua").setLevel(logging.CRITICAL)
    with tempfile.TemporaryDirectory(prefix="bearing-twin-attack-") as tmp:
        cert = _client_cert(Path(tmp)) if spec["secure"] else None
        flood = {"opcua_logins": _logins, "opcua_sessions": _sessions, "opcua_subscriptions": _subscriptions}
        return asyncio.run(flood[spec["mode"]](spec, cert, go))


async def _wait_for(go) -> None:
    """Wait for the parent's start signal without blocking the event loop."""
    await asyncio.get_running_loop().run_in_executor(None, go.wait, 120.0)


async def _logins(spec: dict, cert, go) -> dict:
    counts: collections.Counter = collections.Counter()
    await _wait_for(go)
    t0 = time.monotonic()
    while time.monotonic() - t0 < spec["seconds"]:
        c = await _client(spec["url"], cert, password=f"guess-{secrets.token_hex(6)}")
        counts["tried"] += 1
        try:
            await c.connect()
            counts["accepted"] += 1
            await c.disconnect()
        except Exception as exc:  # noqa: BLE001 - every refusal is counted by its status
            counts[f"refused_{_status_name(exc)}"] += 1
            c.disconnect_socket()
    return {
        "mode": spec["mode"],
        "seconds": round(time.monotonic() - t0, 2),
        "tried": counts.pop("tried", 0),
        "accepted": counts.pop("accepted", 0),
        "refused": dict(counts),
    }


async def _sessions(spec: dict, cert, go) -> dict:
    opened: list[Any] = []
    refused: collections.Counter[str] = collections.Counter()
    await _wait_for(go)
    t0 = time.monotonic()
    while time.monotonic() - t0 < spec["seconds"] and len(opened) < spec["max_sessions"] and not refused:
        c = await _client(spec["url"], cert)
        try:
            await c.connect()
            opened.append(c)
        except Exception as exc:  # noqa: BLE001
            refused[_status_name(exc)] += 1
            c.disconnect_socket()
    await asyncio.sleep(max(0.0, spec["seconds"] - (time.monotonic() - t0)))  # hold them
    for c in opened:
        try:
            await c.disconnect()
        except Exception:  # noqa: BLE001 - the server may have dropped it
            pass
    return {
        "mode": spec["mode"],
        "seconds": round(time.monotonic() - t0, 2),
        "opened": len(opened),
        "refused": dict(refused),
    }


class _Count:
    def __init__(self):
        self.n = 0

    def datachange_notification(self, node, val, data):
        self.n += 1


async def _subscriptions(spec: dict, cert, go) -> dict:
    """One session opened before the floods start (its place is not taken by the session flood, which
    fills the server's session cap), then its subscriptions requested as fast as they are granted."""
    from asyncua import ua

    from service.opcua.layout import FOLDERS, NAMESPACE_URI, ROOT_FOLDER

    counter, granted, items = _Count(), [], 0
    refused: collections.Counter[str] = collections.Counter()
    c = await _client(spec["url"], cert)
    async with c:
        if spec.get("connected") is not None:
            spec["connected"].set()
        await _wait_for(go)
        t0 = time.monotonic()
        idx = await c.get_namespace_index(NAMESPACE_URI)
        twin = await c.nodes.objects.get_child([f"{idx}:{ROOT_FOLDER}", f"{idx}:{spec['bearing_id']}"])
        nodes = [
            await twin.get_child([f"{idx}:{folder}", f"{idx}:{var.name}"])
            for folder, vars_ in FOLDERS.items()
            for var in vars_
        ]
        nodes = (nodes * (spec["items"] // max(1, len(nodes)) + 1))[: spec["items"]]
        for _ in range(spec["subscriptions"]):
            try:
                sub = await c.create_subscription(1, counter)
            except ua.UaStatusCodeError as exc:
                refused[_status_name(exc)] += 1
                continue
            granted.append(sub.parameters.RequestedPublishingInterval)
            results = await sub.subscribe_data_change(nodes, queuesize=0)
            items += sum(isinstance(r, int) for r in results)
            refused["BadTooManyMonitoredItems"] += sum(not isinstance(r, int) for r in results)
        n0, t1 = counter.n, time.monotonic()
        await asyncio.sleep(max(2.0, spec["seconds"] - (t1 - t0)))  # the rate over at least 2 s
        elapsed, received = time.monotonic() - t1, counter.n - n0
    return {
        "mode": spec["mode"],
        "seconds": round(time.monotonic() - t0, 2),
        "subscriptions": len(granted),
        "publishing_interval_ms": sorted(set(granted)),
        "items": items,
        "refused": dict(refused),
        "notifications": counter.n,
        "notifications_per_s": round(received / elapsed, 1),
    }


# ---- the verdict and the report's lines ----------------------------------------------------------
def failures(report: dict) -> list[str]:
    """What the watchers' floods found that must not happen."""
    out = []
    sq = report.get("squat") or {}
    if sq.get("blocked") and sq.get("secure", True):
        out.append(f"{sq['blocked']} twin creations blocked by a squatter zenoh did not authenticate")
    if sq.get("echoed"):
        out.append(f"{sq['echoed']} answers repeated the squatter's text")
    if (report.get("opcua_logins") or {}).get("accepted"):
        out.append(f"{report['opcua_logins']['accepted']} guessed OPC UA passwords accepted")
    return out


def summary_lines(r: dict) -> list[str]:
    lines = []
    sq = r.get("squat")
    if sq and not sq.get("crashed"):
        lines.append(
            f"  squat: {sq['attempts']} ids claimed by an anonymous peer (linked: {sq['peer_linked']}), "
            f"created {sq['created']}, refused for the host's capacity {sq['refused_capacity']}, "
            f"blocked {sq['blocked']}, text echoed {sq['echoed']}"
            + (f", other answers {sq['other']}" if sq["other"] else "")
            + (
                ""
                if sq.get("secure", True) or not sq["blocked"]
                else " (expected: with nothing secured the service trusts every peer's claim)"
            )
        )
    lg = r.get("opcua_logins")
    if lg and not lg.get("crashed"):
        lines.append(
            f"  OPC UA logins: {lg['tried']} guesses in {lg['seconds']} s, accepted {lg['accepted']}, "
            f"refused {lg['refused']}"
        )
    ss = r.get("opcua_sessions")
    if ss and not ss.get("crashed"):
        lines.append(f"  OPC UA sessions: {ss['opened']} opened, then refused {ss['refused']}")
    sb = r.get("opcua_subscriptions")
    if sb and not sb.get("crashed"):
        lines.append(
            f"  OPC UA subscriptions: {sb['subscriptions']} granted at {sb['publishing_interval_ms']} ms, "
            f"{sb['items']} items, refused {sb['refused']}; {sb['notifications_per_s']} notifications/s"
        )
    return lines
