"""zenoh with its own security: the HTTP token never travels on zenoh; with
zenoh access control on, every link is authenticated by zenoh (user-password handshake) and
zenoh's access-control rules (service.bus.access) decide what each role may put, subscribe,
query, answer and declare as liveliness. Anonymous peers get nothing.

Real zenoh sessions on 127.0.0.1 free ports, multicast scouting off; a real service (uvicorn in a
thread); every wait is bounded. "Reaches no one" is asserted against a positive control that
runs at the same time: the authorised session receives N messages on the same keys while the
other receives none, and the service's subscriber counts every setpoint sample that reached it
(`TwinChannel.setpoints_received`)."""

from __future__ import annotations

import json
import queue
import secrets
import threading
import time
from pathlib import Path

import httpx
import numpy as np
import pytest

from service.core.admission import AdmissionGate
from service.core.intake import SetpointIntake
from service.core.measured import encode_frame
from service.core.runner import TwinRunner
from service.settings import RouterSettings, ServiceSettings

zenoh = pytest.importorskip("zenoh")

from service.bus.access import ROLE_RULES, Roles, ZenohAccess, acl_config  # noqa: E402
from service.bus.zenoh_bus import make_config  # noqa: E402

TOKEN = "http-Token_" + secrets.token_hex(8)
AUTH = {"Authorization": f"Bearer {TOKEN}"}
#: how many messages the authorised session must receive while the other receives none
CONTROL_N = 20


@pytest.fixture
def users(tmp_path):
    """A zenoh users file: the service `twin`, the writer `op`, the reader `viewer`."""
    pw = {name: secrets.token_urlsafe(12) for name in ("twin", "op", "viewer")}
    path = tmp_path / "zenoh-users.txt"
    path.write_text("".join(f"{u}:{p}\n" for u, p in pw.items()))
    path.chmod(0o600)
    return path, pw


class Spy:
    """A zenoh session that records every sample of the key expressions it subscribes to."""

    def __init__(self, endpoint: str, *, mode: str = "client", user: str | None = None, password: str | None = None):
        access = ZenohAccess(user=user, password=password)
        self.session = zenoh.open(make_config([], [endpoint], mode, access=access))
        self.samples: queue.Queue = queue.Queue()
        self.seen: list[tuple[str, bytes]] = []
        self._keep: list = []

    def subscribe(self, *keys: str, liveliness: bool = False) -> None:
        def cb(sample):
            item = (str(sample.key_expr), sample.payload.to_bytes(), sample.kind)
            self.seen.append(item[:2])
            self.samples.put(item)

        for key in keys:
            if liveliness:
                self._keep.append(self.session.liveliness().declare_subscriber(key, cb, history=True))
            else:
                self._keep.append(self.session.declare_subscriber(key, cb))

    def keep(self, entity) -> None:
        self._keep.append(entity)

    def count(self, predicate) -> int:
        return sum(1 for key, payload in list(self.seen) if predicate(key, payload))

    def get(self, key: str, timeout_s: float = 3.0) -> list[bytes]:
        out = []
        for reply in self.session.get(
            key, target=zenoh.QueryTarget.ALL, consolidation=zenoh.ConsolidationMode.NONE, timeout=timeout_s
        ):
            if reply.ok is not None:
                payload = reply.ok.payload.to_bytes()
                self.seen.append((str(reply.ok.key_expr), payload))
                out.append(payload)
        return out

    def alive(self, key: str, timeout_s: float = 3.0) -> list[str]:
        return sorted(
            str(r.ok.key_expr) for r in self.session.liveliness().get(key, timeout=timeout_s) if r.ok is not None
        )

    def close(self) -> None:
        for entity in self._keep:
            try:
                entity.undeclare()
            except Exception:  # noqa: BLE001
                pass
        self.session.close()


def _wait(predicate, timeout_s: float = 30.0, what: str = "condition") -> None:
    deadline = time.monotonic() + timeout_s
    while not predicate():
        if time.monotonic() > deadline:
            raise AssertionError(f"{what}: not met within {timeout_s} s")
        time.sleep(0.05)


def _states(prefix_id: str):
    return lambda key, payload: key == f"{prefix_id}/state"


def _foreign(spy: Spy, *own: str) -> list[str]:
    """Keys of what `spy` received that it did not send itself (a session's own puts and
    tokens are delivered to its own subscribers)."""
    return [k for k, p in list(spy.seen) if k not in own]


def _no_token(*spies: Spy) -> int:
    """Assert that no payload any spy received carries the HTTP token; returns how many were read."""
    n = 0
    for spy in spies:
        for key, payload in list(spy.seen):
            n += 1
            assert TOKEN.encode() not in payload, key
    return n


def _service_settings(hostile, **kw) -> ServiceSettings:
    return ServiceSettings(
        enable_recording=False, scenario_dir=hostile.SCENARIOS, token=TOKEN, publish_rate_hz=25.0, **kw
    )


# ---- the rules themselves ---------------------------------------------------------------------
def test_acl_rules_are_default_deny_and_per_role():
    acl = acl_config("plant1/**", Roles(services=("twin",), writers=("op",), readers=("viewer",)), tls=True)
    assert acl["enabled"] is True and acl["default_permission"] == "deny"
    rules = {r["id"]: r for r in acl["rules"]}
    by_role = {p["id"]: [rules[i] for i in p["rules"]] for p in acl["policies"]}

    def allowed(role, message, flow):
        return {k for r in by_role[role] if message in r["messages"] and flow in r["flows"] for k in r["key_exprs"]}

    # canonical keys: `**/*` is written `*/**`
    assert allowed("writers", "put", "ingress") == {
        "plant1/*/**/setpoint",
        "plant1/*/**/defects",
        "plant1/*/**/temperature",
        "plant1/*/**/vibration/measured",
    }
    assert allowed("readers", "put", "ingress") == set()  # a reader never writes
    assert "plant1/*/**/setpoint" not in allowed("readers", "put", "egress")  # nor sees setpoints
    assert allowed("readers", "liveliness_token", "ingress") == set()  # nor declares a twin
    assert allowed("readers", "reply", "ingress") == set()  # nor answers a query
    assert allowed("services", "liveliness_token", "ingress") == {"plant1/*/**/alive"}
    assert allowed("services", "put", "ingress") == {
        "plant1/*/**/state",
        "plant1/*/**/ball/*",
        "plant1/*/**/setpoint/result",
        "plant1/*/**/defects/result",
        "plant1/*/**/temperature/result",
        "plant1/*/**/alarm",
        "plant1/*/**/vibration",
        "plant1/*/**/vibration/waveform",
        "plant1/*/**/vibration/comparison",
    }
    # what a service subscribes to is exactly what a writer may put
    assert allowed("services", "declare_subscriber", "ingress") == allowed("writers", "put", "ingress")
    assert "plant1/*/**/defects" not in allowed("readers", "put", "egress")  # nor sees defect writes
    assert {s["id"] for s in acl["subjects"]} >= {"writers-users", "writers-certs"}
    assert set(ROLE_RULES) == {"services", "writers", "readers"}
    # an empty role grants nothing (no rule, no subject)
    assert acl_config("bearing", Roles(writers=("op",)))["policies"] == [
        {
            "id": "writers",
            "rules": [f"writers-{i}" for i in range(len(ROLE_RULES["writers"]))],
            "subjects": ["writers-users"],
        }
    ]


def test_settings_refuse_what_zenoh_cannot_guard(tmp_path, users, monkeypatch):
    path, pw = users
    for var in ("ZENOH_USER", "ZENOH_PASSWORD", "ZENOH_USERSFILE", "TOKEN"):
        monkeypatch.delenv(f"BEARING_TWIN_{var}", raising=False)
    with pytest.raises(ValueError, match="zenoh_password"):
        ServiceSettings(zenoh_user="twin")
    with pytest.raises(ValueError, match="zenoh_usersfile"):  # listens, but no users to check
        ServiceSettings(zenoh_user="twin", zenoh_password=pw["twin"])
    with pytest.raises(ValueError, match="either listens .* or joins a router"):
        ServiceSettings(zenoh_usersfile=path, zenoh_listen=["tcp/127.0.0.1:1"], zenoh_connect=["tcp/127.0.0.1:2"])
    with pytest.raises(ValueError, match="zenoh_user: joining a router"):
        ServiceSettings(zenoh_usersfile=path, zenoh_connect=["tcp/127.0.0.1:2"])
    with pytest.raises(ValueError, match="no '\\*'"):
        ServiceSettings(zenoh_prefix="plant1/**")
    bad = tmp_path / "bad.txt"
    bad.write_text("op:secret-pw\nnocolon-secret\n")
    with pytest.raises(ValueError) as err:
        ServiceSettings(zenoh_usersfile=bad)
    assert "line 2" in str(err.value) and "secret" not in str(err.value).replace("bad.txt", "")
    joined = ServiceSettings(zenoh_user="twin", zenoh_password=pw["twin"], zenoh_connect=["tcp/127.0.0.1:2"])
    assert joined.zenoh.listen == [] and joined.zenoh.mode == "client" and joined.zenoh.access_control
    assert pw["twin"] not in repr(joined)
    assert ServiceSettings().zenoh.mode == "peer" and not ServiceSettings().zenoh.access_control
    assert RouterSettings(zenoh_prefix="plant1/**").zenoh.prefix == "plant1/**"


# ---- the intake: no token in payloads -----------------------------------------------------------
@pytest.fixture(scope="module")
def twin():
    from twin.engine import Twin

    tw = Twin("6208")
    tw.advance(0.001)
    return tw


def test_intake_refuses_token_fields_and_closed_bus(twin):
    runner = TwinRunner(twin)  # not started: submissions only hit the mailbox
    open_gate = SetpointIntake(twin.bearing_id, AdmissionGate(bus_writes="authorized"), runner)
    refused = open_gate(json.dumps({"radial_load_n": 3300.0, "token": TOKEN}))
    assert refused["accepted"] is False and refused["status"] == 422
    assert refused["detail"][0]["field"] == "token" and TOKEN not in json.dumps(refused)
    ok = open_gate(json.dumps({"radial_load_n": 3300.0}))
    assert ok["accepted"] is True and ok["setpoint"]["radial_load_n"] == 3300.0
    # an HTTP token and no zenoh access control: the bus may not write (403), whatever it sends
    closed = SetpointIntake(twin.bearing_id, AdmissionGate(token=TOKEN), runner)
    for payload in (json.dumps({"radial_load_n": 3300.0}), json.dumps({"radial_load_n": 3300.0, "token": TOKEN})):
        r = closed(payload)
        assert r["accepted"] is False and r["status"] == 403 and "zenoh access control" in r["error"]
        assert TOKEN not in json.dumps(r)
    assert AdmissionGate().bus_writes == "open" and AdmissionGate(token="t").bus_writes == "closed"


def test_http_token_without_zenoh_access_control(hostile):
    """A service with an HTTP token and no zenoh access control: zenoh setpoints are refused
    (403 on the result key) and nothing on the bus carries the token, while HTTP PUTs with the
    token go on."""
    endpoint = f"tcp/127.0.0.1:{hostile.free_port()}"
    with (
        hostile.ThreadServer(_service_settings(hostile, zenoh_listen=[endpoint])) as srv,
        httpx.Client(base_url=srv.url, timeout=30.0) as http,
    ):
        spy = Spy(endpoint)
        try:
            spy.subscribe("**")
            spy.subscribe("**", liveliness=True)
            _wait(lambda: spy.count(_states("bearing/default")) >= 5, what="state samples")
            for load in (3100.0, 3200.0):
                assert (
                    http.put("/v1/bearings/default/setpoint", json={"radial_load_n": load}, headers=AUTH).status_code
                    == 200
                )
            spy.session.put("bearing/default/setpoint", json.dumps({"radial_load_n": 3300.0}))
            _wait(lambda: spy.count(lambda k, p: k == "bearing/default/setpoint/result") >= 1, what="result")
            result = next(json.loads(p) for k, p in spy.seen if k == "bearing/default/setpoint/result")
            assert result["accepted"] is False and result["status"] == 403
            assert spy.get("bearing/default/snapshot")
            hostile.wait_for(
                lambda: http.get("/v1/bearings/default/state").json(),
                lambda st: st["setpoint"]["radial_load_n"] == 3200.0,
            )
            _wait(
                lambda: spy.count(lambda k, p: k == "bearing/default/state" and b'"radial_load_n":3200.0' in p) >= 1,
                what="a state carrying the HTTP setpoint",
            )
            assert _no_token(spy) >= 5
        finally:
            spy.close()


# ---- a secured service that listens ----------------------------------------------------------------
def test_secured_service_anonymous_gets_nothing_reader_cannot_write(hostile, users):
    path, pw = users
    endpoint = f"tcp/127.0.0.1:{hostile.free_port()}"
    settings = _service_settings(
        hostile, zenoh_listen=[endpoint], zenoh_usersfile=path, zenoh_writers=["op"], zenoh_readers=["viewer"]
    )
    with hostile.ThreadServer(settings) as srv, httpx.Client(base_url=srv.url, timeout=30.0) as http:
        channel = srv.service.find("default").channel
        anon = Spy(endpoint, mode="peer")  # no credentials
        wrong = Spy(endpoint, mode="peer", user="op", password="not-" + pw["op"])
        viewer = Spy(endpoint, user="viewer", password=pw["viewer"])
        op = Spy(endpoint, user="op", password=pw["op"])
        spies = (anon, wrong, viewer, op)
        try:
            for spy in (anon, wrong):
                spy.subscribe("**")
                spy.subscribe("bearing/*/state", "bearing/*/setpoint/result")
            viewer.subscribe("bearing/*/state", "bearing/*/setpoint/result")
            op.subscribe("bearing/*/setpoint/result")
            _wait(lambda: viewer.count(_states("bearing/default")) >= CONTROL_N, what="the reader's states")
            before = channel.setpoints_received
            for spy, load in ((anon, 3300.0), (wrong, 3350.0), (viewer, 3400.0)):
                for _ in range(3):
                    spy.session.put("bearing/default/setpoint", json.dumps({"radial_load_n": load}))
            op.session.put("bearing/default/setpoint", json.dumps({"radial_load_n": 3500.0}))
            _wait(lambda: op.count(lambda k, p: k.endswith("/setpoint/result")) >= 1, what="the writer's result")
            results = [json.loads(p) for k, p in op.seen if k.endswith("/setpoint/result")]
            assert [r["accepted"] for r in results] == [True] and results[0]["setpoint"]["radial_load_n"] == 3500.0
            hostile.wait_for(
                lambda: http.get("/v1/bearings/default/state").json(),
                lambda s: s["setpoint"]["radial_load_n"] == 3500.0,
            )
            time.sleep(0.5)
            # only the writer's one setpoint reached the service's subscriber
            assert channel.setpoints_received - before == 1
            own = "bearing/default/setpoint"
            assert _foreign(anon, own) == [] and _foreign(wrong, own) == []  # not one sample, any key
            assert anon.get("bearing/default/snapshot", timeout_s=1.0) == []
            assert viewer.get("bearing/default/snapshot")  # the reader may query
            assert _no_token(*spies) >= CONTROL_N
        finally:
            for spy in spies:
                spy.close()


def test_secured_service_takes_measurements_from_writers_only(hostile, users):
    """Measured temperatures and accelerometer windows are writes like setpoints: with zenoh
    access control on, the writer's reach the twin and are answered on their result keys (which
    a reader may follow); a reader's and an anonymous peer's never reach the service."""
    path, pw = users
    endpoint = f"tcp/127.0.0.1:{hostile.free_port()}"
    settings = _service_settings(
        hostile, zenoh_listen=[endpoint], zenoh_usersfile=path, zenoh_writers=["op"], zenoh_readers=["viewer"]
    )
    window = np.load(Path(__file__).resolve().parents[1] / "data" / "cwru" / "97_DE_12k_5s.npy")[:12000]
    frame = encode_frame(window, 12000.0, "g")
    results = ("bearing/*/temperature/result", "bearing/*/vibration/comparison")
    with hostile.ThreadServer(settings) as srv:
        inbox = srv.service.find("default").channel.inbox
        anon = Spy(endpoint, mode="peer")
        viewer = Spy(endpoint, user="viewer", password=pw["viewer"])
        op = Spy(endpoint, user="op", password=pw["op"])
        try:
            viewer.subscribe(*results)
            op.subscribe(*results)
            _wait(lambda: srv.service.find("default").runner.latest is not None, what="the first snapshot")
            for spy in (anon, viewer):
                spy.session.put("bearing/default/temperature", json.dumps({"temperature_c": 90.0}))
                spy.session.put("bearing/default/vibration/measured", frame)
            op.session.put("bearing/default/temperature", json.dumps({"temperature_c": 41.5}))
            op.session.put("bearing/default/vibration/measured", frame)
            for spy in (op, viewer):  # the answers reach the writer and the reader
                _wait(lambda s=spy: s.count(lambda k, p: k.endswith("/temperature/result")) >= 1, what="result")
                _wait(lambda s=spy: s.count(lambda k, p: k.endswith("/vibration/comparison")) >= 1, what="comparison")
            time.sleep(0.5)
            temps = [json.loads(p) for k, p in op.seen if k.endswith("/temperature/result")]
            assert [(r["accepted"], r["temperature_c"]) for r in temps] == [(True, 41.5)]
            comparisons = [json.loads(p) for k, p in op.seen if k.endswith("/vibration/comparison")]
            assert [r["accepted"] for r in comparisons] == [True]
            assert inbox.writes_received == {"temperature": 1, "measured": 1}  # none of the others'
        finally:
            for spy in (anon, viewer, op):
                spy.close()


# ---- a secured fleet: router + service + clients --------------------------------------------------------------
def test_secured_router_fleet(hostile, users):
    """The README's secured fleet: `bearing-twin router` with the users file and the roles, a
    service joined with its credentials, a writer, a reader, an anonymous peer and a peer with a
    wrong password, all through the router."""
    from service.tools.router import open_router

    path, pw = users
    endpoint = f"tcp/127.0.0.1:{hostile.free_port()}"
    router, described = open_router(
        RouterSettings(
            zenoh_listen=[endpoint],
            zenoh_prefix="plant1/**",
            zenoh_usersfile=path,
            zenoh_services=["twin"],
            zenoh_writers=["op"],
            zenoh_readers=["viewer"],
        )
    )
    assert "rules: services twin; writers op; readers viewer" in described
    key = "plant1/line2/default"
    settings = _service_settings(
        hostile, zenoh_connect=[endpoint], zenoh_prefix="plant1/line2", zenoh_user="twin", zenoh_password=pw["twin"]
    )
    spies: list[Spy] = []
    try:
        with hostile.ThreadServer(settings) as srv, httpx.Client(base_url=srv.url, timeout=30.0) as http:
            channel = srv.service.find("default").channel
            assert channel.prefix == key
            assert http.get("/v1/bearings/default").json()["zenoh_state_key"] == f"{key}/state"
            anon = Spy(endpoint, mode="peer")
            wrong = Spy(endpoint, mode="peer", user="op", password="not-" + pw["op"])
            viewer = Spy(endpoint, user="viewer", password=pw["viewer"])
            op = Spy(endpoint, user="op", password=pw["op"])
            spies += [anon, wrong, viewer, op]
            for spy in (anon, wrong):
                spy.subscribe("**")
                spy.subscribe("**", liveliness=True)
            viewer.subscribe("plant1/line2/*/state", "plant1/line2/*/setpoint/result")
            viewer.subscribe("plant1/line2/*/setpoint")  # a reader may not see others' setpoints: refused
            viewer.subscribe("plant1/line2/*/alive", liveliness=True)
            op.subscribe("plant1/line2/*/setpoint/result")
            op.subscribe("plant1/line2/*/alive", liveliness=True)
            _wait(lambda: viewer.count(_states(key)) >= CONTROL_N, what="the reader's states")
            # forgeries: a twin's liveliness token and a snapshot answer, by the anonymous peer
            # and by the (authenticated) reader
            for spy, name in ((anon, "ghost-anon"), (viewer, "ghost-viewer"), (wrong, "ghost-wrong")):
                spy.keep(spy.session.liveliness().declare_token(f"plant1/line2/{name}/alive"))
                spy.keep(
                    spy.session.declare_queryable(
                        f"{key}/snapshot", lambda q, n=name: q.reply(f"{key}/snapshot", json.dumps({"forged": n}))
                    )
                )
            before = channel.setpoints_received
            for spy, load in ((anon, 3300.0), (wrong, 3350.0), (viewer, 3400.0)):
                for _ in range(3):
                    spy.session.put(f"{key}/setpoint", json.dumps({"radial_load_n": load}))
            time.sleep(1.0)
            op.session.put(f"{key}/setpoint", json.dumps({"radial_load_n": 3500.0}))
            _wait(lambda: op.count(lambda k, p: k.endswith("/setpoint/result")) >= 1, what="the writer's result")
            hostile.wait_for(
                lambda: http.get("/v1/bearings/default/state").json(),
                lambda s: s["setpoint"]["radial_load_n"] == 3500.0,
            )
            # the writer's query: only the service answers; liveliness: only the real twin
            replies = [json.loads(p) for p in op.get(f"{key}/snapshot")]
            assert len(replies) == 1 and replies[0]["bearing_id"] == "default" and "balls" in replies[0]
            # a liveliness query through the router can come back empty on a loaded host before the
            # router has the service's token in its tables: ask until the real twin answers, then
            # require that it is the only one (no forged token among the answers)
            alive: list[str] = []
            _wait(
                lambda: bool(alive.extend(op.alive("plant1/line2/*/alive")) or alive),
                what="the twin's liveliness token through the router",
            )
            assert sorted(set(alive)) == [f"{key}/alive"], alive
            time.sleep(0.5)
            # a liveliness subscriber with history can get the same token twice (once from the
            # history query, once as the declaration arrives): the point is that no other key shows
            op_alive = [k for k, p in op.seen if k.endswith("/alive")]
            assert sorted(set(op_alive)) == [f"{key}/alive"], op_alive
            assert not any("ghost-anon" in k or "ghost-wrong" in k for k, p in viewer.seen)
            results = [json.loads(p) for k, p in op.seen if k.endswith("/setpoint/result")]
            assert [r["setpoint"]["radial_load_n"] for r in results] == [3500.0]
            assert channel.setpoints_received - before == 1
            # the reader saw no one else's setpoint (only results), the anonymous peers nothing
            assert not any(k.endswith("/setpoint") and b"3500" in p for k, p in viewer.seen)
            for spy, name in ((anon, "ghost-anon"), (wrong, "ghost-wrong")):
                assert _foreign(spy, f"{key}/setpoint", f"plant1/line2/{name}/alive") == [], name
                assert [json.loads(p) for p in spy.get(f"{key}/snapshot", timeout_s=1.0)] == [{"forged": name}]
            # the HTTP token, used meanwhile, is in no payload
            assert (
                http.put("/v1/bearings/default/setpoint", json={"radial_load_n": 3600.0}, headers=AUTH).status_code
                == 200
            )
            _wait(
                lambda: viewer.count(lambda k, p: k == f"{key}/state" and b'"radial_load_n":3600.0' in p) >= 1,
                what="a state carrying the HTTP setpoint",
            )
            assert _no_token(*spies) >= CONTROL_N
    finally:
        for spy in spies:
            spy.close()
        router.close()


def test_a_client_with_wrong_credentials_cannot_join(hostile, users):
    """A zenoh client (which must reach its router) with a wrong password fails to open."""
    from service.tools.router import open_router

    path, pw = users
    endpoint = f"tcp/127.0.0.1:{hostile.free_port()}"
    router, _ = open_router(RouterSettings(zenoh_listen=[endpoint], zenoh_usersfile=path, zenoh_readers=["viewer"]))
    try:
        for user, password in ((None, None), ("viewer", "wrong"), ("nobody", pw["viewer"])):
            with pytest.raises(Exception):  # noqa: B017
                zenoh.open(make_config([], [endpoint], "client", access=ZenohAccess(user=user, password=password)))
        ok = zenoh.open(make_config([], [endpoint], "client", access=ZenohAccess(user="viewer", password=pw["viewer"])))
        ok.close()
    finally:
        router.close()


def test_router_command_runs_until_stopped(hostile, users, capsys):
    from service.tools.router import run_router

    path, _ = users
    endpoint = f"tcp/127.0.0.1:{hostile.free_port()}"
    stop = threading.Event()
    done: dict = {}
    th = threading.Thread(
        target=lambda: done.update(rc=run_router(RouterSettings(zenoh_listen=[endpoint], zenoh_usersfile=path), stop)),
        daemon=True,
    )
    th.start()
    _wait(lambda: "listening on" in capsys.readouterr().out or done, what="router start")
    stop.set()
    th.join(10.0)
    assert not th.is_alive() and done["rc"] == 0


# ---- mutual TLS: roles by certificate common name ----------------------------------------------------
def _certificates(out, names):
    """A throw-away CA and, per name, a certificate (CN = name, SAN 127.0.0.1) and its key."""
    import datetime
    import ipaddress

    from cryptography import x509
    from cryptography.hazmat.primitives import hashes, serialization
    from cryptography.hazmat.primitives.asymmetric import ec
    from cryptography.x509.oid import ExtendedKeyUsageOID, NameOID

    now = datetime.datetime.now(datetime.UTC)
    ca_key = ec.generate_private_key(ec.SECP256R1())
    ca_name = x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, "bearing-twin test CA")])

    def builder(subject, key):
        return (
            x509.CertificateBuilder()
            .subject_name(subject)
            .issuer_name(ca_name)
            .public_key(key.public_key())
            .serial_number(x509.random_serial_number())
            .not_valid_before(now - datetime.timedelta(minutes=5))
            .not_valid_after(now + datetime.timedelta(hours=2))
        )

    ca = (
        builder(ca_name, ca_key)
        .add_extension(x509.BasicConstraints(ca=True, path_length=None), critical=True)
        .add_extension(
            x509.KeyUsage(
                digital_signature=True,
                key_cert_sign=True,
                crl_sign=True,
                content_commitment=False,
                key_encipherment=False,
                data_encipherment=False,
                key_agreement=False,
                encipher_only=False,
                decipher_only=False,
            ),
            critical=True,
        )
        .sign(ca_key, hashes.SHA256())
    )
    (out / "ca.pem").write_bytes(ca.public_bytes(serialization.Encoding.PEM))
    for name in names:
        key = ec.generate_private_key(ec.SECP256R1())
        cert = (
            builder(x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, name)]), key)
            .add_extension(
                x509.SubjectAlternativeName(
                    [x509.DNSName("localhost"), x509.IPAddress(ipaddress.ip_address("127.0.0.1"))]
                ),
                critical=False,
            )
            .add_extension(x509.BasicConstraints(ca=False, path_length=None), critical=True)
            .add_extension(
                x509.ExtendedKeyUsage([ExtendedKeyUsageOID.SERVER_AUTH, ExtendedKeyUsageOID.CLIENT_AUTH]),
                critical=False,
            )
            .sign(ca_key, hashes.SHA256())
        )
        (out / f"{name}.pem").write_bytes(cert.public_bytes(serialization.Encoding.PEM))
        (out / f"{name}.key").write_bytes(
            key.private_bytes(
                serialization.Encoding.PEM, serialization.PrivateFormat.PKCS8, serialization.NoEncryption()
            )
        )


def test_mutual_tls_roles_by_certificate_common_name(hostile, tmp_path):
    """Router and service with TLS client certificates (no users file): roles match the
    certificates' common names; a certificate of the same CA without a role gets nothing, a
    client without a certificate cannot connect."""
    pytest.importorskip("cryptography")
    from service.tools.router import open_router

    _certificates(tmp_path, ["router", "twin", "op", "viewer", "stranger"])

    def tls(name):
        return dict(
            zenoh_tls_root_ca=tmp_path / "ca.pem",
            zenoh_tls_certificate=tmp_path / f"{name}.pem",
            zenoh_tls_private_key=tmp_path / f"{name}.key",
        )

    def client(name):
        return zenoh.open(
            make_config(
                [],
                [endpoint],
                "client",
                access=ZenohAccess(
                    tls_root_ca=tmp_path / "ca.pem",
                    tls_certificate=tmp_path / f"{name}.pem",
                    tls_private_key=tmp_path / f"{name}.key",
                ),
            )
        )

    endpoint = f"tls/127.0.0.1:{hostile.free_port()}"
    with pytest.raises(ValueError, match="tls/HOST:PORT only"):  # a tcp/ endpoint would be open
        RouterSettings(zenoh_listen=[f"tcp/127.0.0.1:{hostile.free_port()}"], **tls("router"))
    router, described = open_router(
        RouterSettings(
            zenoh_listen=[endpoint],
            zenoh_services=["twin"],
            zenoh_writers=["op"],
            zenoh_readers=["viewer"],
            **tls("router"),
        )
    )
    assert "mutual TLS" in described
    sessions: dict = {}
    try:
        with (
            hostile.ThreadServer(_service_settings(hostile, zenoh_connect=[endpoint], **tls("twin"))) as srv,
            httpx.Client(base_url=srv.url, timeout=30.0) as http,
        ):
            channel = srv.service.find("default").channel
            seen: dict = {name: [] for name in ("op", "viewer", "stranger")}
            subs = []
            for name in seen:
                sessions[name] = client(name)
                subs.append(sessions[name].declare_subscriber("bearing/*/state", lambda smp, n=name: seen[n].append(1)))
            with pytest.raises(Exception):  # noqa: B017
                zenoh.open(make_config([], [endpoint], "client"))  # no certificate
            _wait(lambda: len(seen["viewer"]) >= CONTROL_N and len(seen["op"]) >= CONTROL_N, what="states")
            before = channel.setpoints_received
            for name, load in (("stranger", 3300.0), ("viewer", 3400.0)):
                sessions[name].put("bearing/default/setpoint", json.dumps({"radial_load_n": load}))
            time.sleep(1.0)
            sessions["op"].put("bearing/default/setpoint", json.dumps({"radial_load_n": 3500.0}))
            hostile.wait_for(
                lambda: http.get("/v1/bearings/default/state").json(),
                lambda st: st["setpoint"]["radial_load_n"] == 3500.0,
            )
            time.sleep(0.5)
            assert channel.setpoints_received - before == 1
            assert seen["stranger"] == []
            for sub in subs:
                sub.undeclare()
    finally:
        for session in sessions.values():
            session.close()
        router.close()
