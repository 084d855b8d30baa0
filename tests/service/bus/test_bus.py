"""ZenohBus, TwinChannel and the monitor against real zenoh sessions.

Peer mode, loopback endpoints on free ports, multicast scouting off; every wait is bounded.
"""

from __future__ import annotations

import io
import json
import queue
import threading
import time

import pytest

zenoh = pytest.importorskip("zenoh")

from service.bus.twin_outbox import Matching, matched  # noqa: E402
from service.bus.zenoh_bus import ZenohBus, make_config  # noqa: E402
from service.tools.monitor import add_monitor_command, run_monitor  # noqa: E402
from twin.engine import Twin  # noqa: E402
from twin.setpoint import SetpointLimits, SetpointUpdate  # noqa: E402

WAIT_S = 10.0


def reject(name: str):
    raise AssertionError(f"JSON carries {name}")


def loads(payload: bytes) -> dict:
    return json.loads(payload, parse_constant=reject)


@pytest.fixture(scope="module")
def twin():
    tw = Twin("6208", bearing_id="t1")
    tw.advance(0.002)
    return tw


@pytest.fixture
def endpoint(support):
    return support.free_endpoint()


@pytest.fixture
def bus(endpoint):
    b = ZenohBus(listen=[endpoint], connect=[])
    yield b
    b.close()


@pytest.fixture
def client(endpoint, bus, support):
    """A separate peer session (another process in real life) connected to the bus."""
    c = support.Peer(endpoint, timeout_s=WAIT_S)
    yield c
    c.close()


def validating_on_setpoint(applied: list):
    def on_setpoint(payload: bytes) -> dict:
        update = SetpointUpdate.model_validate_json(payload)  # raises on bad types
        SetpointLimits.static().check(update)  # and on values out of range
        applied.append(update)
        return {"accepted": True, "setpoint": update.model_dump(exclude_none=True)}

    return on_setpoint


# ---- (a) state and ball messages ------------------------------------------------------------
def test_state_and_ball_messages_reach_a_remote_session(bus, client, twin, support):
    snap = twin.snapshot()
    channel = bus.attach_twin("t1", lambda: snap, lambda p: {"accepted": False, "error": "n/a"})
    client.subscribe("bearing/t1/state")
    client.subscribe("bearing/t1/ball/0")
    got = {}

    def is_new(item):
        key, _, payload = item
        got.setdefault(key, loads(payload))
        return "bearing/t1/state" in got and "bearing/t1/ball/0" in got

    client.wait_for(is_new, poke=lambda: channel.publish(snap))
    state, ball = got["bearing/t1/state"], got["bearing/t1/ball/0"]
    assert state["schema"] == "bearing-twin/state/1"
    assert state["bearing_id"] == "t1" and state["designation"] == "6208"
    assert state["seq"] == snap.seq and len(state["balls"]) == len(snap.balls)
    assert state == json.loads(snap.to_json())
    assert ball["schema"] == "bearing-twin/state/1"
    assert ball["bearing_id"] == "t1" and ball["time_s"] == snap.time_s and ball["index"] == 0
    assert ball["inner"] == state["balls"][0]["inner"]
    # the ball message is the head's three fields and the ball's, nothing else (pydantic-serialised, spliced)
    assert ball == {"schema": state["schema"], "bearing_id": "t1", "time_s": snap.time_s, **state["balls"][0]}
    assert support.wait_until(lambda: channel.published >= 1, 5.0) and channel.errors == 0


def test_every_ball_is_published(bus, client, twin):
    snap = twin.snapshot()
    channel = bus.attach_twin("t1", lambda: snap, lambda p: {})
    client.subscribe("bearing/t1/ball/*")
    seen: set[str] = set()

    def all_balls(item):
        seen.add(item[0])
        return len(seen) == len(snap.balls)

    client.wait_for(all_balls, poke=lambda: channel.publish(snap))
    assert seen == {f"bearing/t1/ball/{b.index}" for b in snap.balls}


# ---- (b) queryable ---------------------------------------------------------------------------
def test_queryable_answers_with_the_latest_snapshot(bus, client, twin):
    latest = {"snap": None}
    bus.attach_twin("t1", lambda: latest["snap"], lambda p: {})

    def query(selector):
        replies = []
        deadline = time.monotonic() + WAIT_S
        while not replies and time.monotonic() < deadline:  # the queryable may not be known yet
            replies = list(client.session.get(selector, timeout=2.0))
            if not replies:
                time.sleep(0.1)
        assert replies, "no reply"
        return replies

    # no snapshot yet: an error reply, not a hang
    (reply,) = query("bearing/t1/snapshot")
    assert reply.err is not None and "no snapshot" in reply.err.payload.to_string()

    latest["snap"] = twin.snapshot()
    (reply,) = query("bearing/t1/snapshot")
    assert reply.ok is not None
    assert str(reply.ok.key_expr) == "bearing/t1/snapshot"
    data = loads(reply.ok.payload.to_bytes())
    assert data["seq"] == latest["snap"].seq and data["schema"] == "bearing-twin/state/1"

    latest["snap"] = twin.snapshot()  # newer
    (reply,) = query("bearing/*/snapshot")  # wildcard query, concrete reply key
    assert str(reply.ok.key_expr) == "bearing/t1/snapshot"
    assert loads(reply.ok.payload.to_bytes())["seq"] == latest["snap"].seq


# ---- (c) setpoints ---------------------------------------------------------------------------
def test_setpoints_are_applied_and_refusals_reported(bus, client, twin):
    applied: list = []
    snap = twin.snapshot()
    channel = bus.attach_twin("t1", lambda: snap, validating_on_setpoint(applied))
    client.subscribe("bearing/t1/setpoint/result")
    pub = client.session.declare_publisher("bearing/t1/setpoint")

    def put_and_wait(payload: bytes) -> dict:
        client.drain()
        # put again every 0.5 s until a result arrives: the first put may precede route discovery
        _, _, data = client.wait_for(lambda item: True, poke=lambda: pub.put(payload), poke_every_s=0.5)
        return loads(data)

    result = put_and_wait(b'{"shaft_speed_rad_s": 300.0}')
    assert result["accepted"] is True and result["bearing_id"] == "t1"
    assert result["setpoint"] == {"shaft_speed_rad_s": 300.0}
    assert applied and applied[-1].shaft_speed_rad_s == 300.0

    for bad in (
        b"not json",
        b'{"shaft_speed_rad_s": "fast"}',
        b'{"shaft_speed_rad_s": NaN}',
        b'{"shaft_speed_rad_s": -5}',
        b'{"warp_factor": 9}',
        b"\xff\xfe",
        b"",
    ):
        result = put_and_wait(bad)
        assert result["accepted"] is False, bad
        assert isinstance(result["error"], str) and result["error"], bad
    assert "shaft_speed_rad_s" in put_and_wait(b'{"shaft_speed_rad_s": "fast"}')["error"]

    # the bus keeps working: a good setpoint after the bad ones, and state still flows
    result = put_and_wait(b'{"radial_load_n": 4000.0}')
    assert result["accepted"] is True and applied[-1].radial_load_n == 4000.0
    client.subscribe("bearing/t1/state")
    client.wait_for(lambda item: item[0] == "bearing/t1/state", poke=lambda: channel.publish(snap))
    pub.undeclare()


def test_handler_that_misbehaves_is_a_refusal(bus, client, twin):
    calls = {"n": 0}

    def on_setpoint(payload: bytes):
        calls["n"] += 1
        if payload == b"boom":
            raise RuntimeError("handler exploded")
        if payload == b"none":
            return None
        if payload == b"nan":
            return {"accepted": True, "setpoint": {"shaft_speed_rad_s": float("nan")}}
        return {"accepted": True}

    bus.attach_twin("t1", lambda: None, on_setpoint)
    client.subscribe("bearing/t1/setpoint/result")
    results = {}
    deadline = time.monotonic() + WAIT_S
    while len(results) < 4 and time.monotonic() < deadline:
        for payload in (b"boom", b"none", b"nan", b"ok"):
            if payload not in results:
                client.session.put("bearing/t1/setpoint", payload)
                try:
                    _, _, data = client.inbox.get(timeout=0.5)
                    results[payload] = loads(data)
                except queue.Empty:
                    pass
    assert results[b"boom"]["accepted"] is False and "exploded" in results[b"boom"]["error"]
    assert results[b"none"]["accepted"] is False
    assert results[b"nan"]["accepted"] is False  # result itself not valid contract JSON
    assert results[b"ok"]["accepted"] is True


# ---- (d) liveliness --------------------------------------------------------------------------
def test_liveliness_token_follows_attach_and_detach(bus, client):
    client.subscribe("bearing/*/alive", liveliness=True)
    channel = bus.attach_twin("t1", lambda: None, lambda p: {})
    key, kind, _ = client.wait_for(lambda item: True)
    assert key == "bearing/t1/alive" and kind == zenoh.SampleKind.PUT
    replies = list(client.session.liveliness().get("bearing/*/alive", timeout=2.0))
    assert [str(r.ok.key_expr) for r in replies if r.ok] == ["bearing/t1/alive"]

    channel.detach()
    key, kind, _ = client.wait_for(lambda item: True)
    assert key == "bearing/t1/alive" and kind == zenoh.SampleKind.DELETE
    channel.detach()  # idempotent
    assert "t1" not in bus.channels
    # the id can be attached again after a detach
    bus.attach_twin("t1", lambda: None, lambda p: {})
    key, kind, _ = client.wait_for(lambda item: True)
    assert kind == zenoh.SampleKind.PUT


def test_closing_the_bus_withdraws_every_token(endpoint, twin, support):
    bus = ZenohBus(listen=[endpoint], connect=[])
    client = support.Peer(endpoint, timeout_s=WAIT_S)
    try:
        client.subscribe("bearing/*/alive", liveliness=True)
        for name in ("a", "b"):
            bus.attach_twin(name, lambda: None, lambda p: {})
        alive: dict[str, bool] = {}

        def track(item):
            alive[item[0]] = item[1] == zenoh.SampleKind.PUT
            return len(alive) == 2 and all(alive.values())

        client.wait_for(track)
        bus.close()
        bus.close()  # idempotent
        client.wait_for(lambda item: track(item) or (len(alive) == 2 and not any(alive.values())))
        assert alive == {"bearing/a/alive": False, "bearing/b/alive": False}
        with pytest.raises(RuntimeError):
            bus.attach_twin("c", lambda: None, lambda p: {})
    finally:
        bus.close()
        client.close()


def test_bad_ids_and_duplicates_are_refused(bus):
    for bad in ("", "a/b", "a*", "**", "a$b", "what?", "x#1"):
        with pytest.raises(ValueError):
            bus.attach_twin(bad, lambda: None, lambda p: {})
    bus.attach_twin("ok-1", lambda: None, lambda p: {})
    with pytest.raises(ValueError):
        bus.attach_twin("ok-1", lambda: None, lambda p: {})


def test_twin_ids_are_unique_per_prefix_across_buses(endpoint, support, caplog):
    """One id per key prefix on the whole zenoh network: a second bus (another process in real
    life) refuses an id the first runs, with a 409 naming the owner by the zenoh id zenoh reports
    (its owner answer P/{id}/owner goes to the log, not the answer); another prefix may use it;
    after a detach the id is free again."""
    import logging
    import os

    from service.core.errors import InputError

    bus1 = ZenohBus(listen=[endpoint], connect=[], prefix="plant1/line2", owner={"http": "http://127.0.0.1:8001"})
    bus2 = ZenohBus(listen=[], connect=[endpoint], mode="client", prefix="plant1/line2")
    bus3 = ZenohBus(listen=[], connect=[endpoint], mode="client", prefix="plant1/line3")
    try:
        first = bus1.attach_twin("x", lambda: None, lambda p: {})
        assert first.prefix == "plant1/line2/x"
        owners = bus2._owners("plant1/line2/x")
        assert owners == [
            {
                "key": "plant1/line2/x",
                "bearing_id": "x",
                "pid": os.getpid(),
                "host": bus1.owner("x")["host"],
                "http": "http://127.0.0.1:8001",
                "zid": bus1.zid,
            }
        ]
        with pytest.raises(InputError) as err:
            bus2.attach_twin("x", lambda: None, lambda p: {})
        assert err.value.status_code == 409 and err.value.errors[0].field == "id"
        message = err.value.errors[0].message
        assert bus1.zid in message and "8001" not in message and f"process {os.getpid()}" not in message
        logged = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
        assert any(f"in process '{os.getpid()}'" in m and "'http://127.0.0.1:8001'" in m for m in logged), logged
        assert "x" not in bus2.channels
        assert bus3.attach_twin("x", lambda: None, lambda p: {}).prefix == "plant1/line3/x"
        first.detach()
        assert support.wait_until(lambda: not bus2._alive_elsewhere("plant1/line2/x"), WAIT_S)
        assert bus2.attach_twin("x", lambda: None, lambda p: {}).prefix == "plant1/line2/x"
        with pytest.raises(InputError):  # and now the first one is refused
            bus1.attach_twin("x", lambda: None, lambda p: {})
    finally:
        bus3.close()
        bus2.close()
        bus1.close()


def _squat(endpoint: str, key: str, answer: dict):
    """An anonymous peer that declares `key`/alive and answers `key`/owner with `answer`."""
    evil = zenoh.open(make_config([], [endpoint], "peer"))
    token = evil.liveliness().declare_token(f"{key}/alive")
    owner = evil.declare_queryable(f"{key}/owner", lambda q: q.reply(f"{key}/owner", json.dumps(answer)))
    return evil, token, owner


def test_an_unauthenticated_claim_never_blocks_an_untrusting_bus(endpoint, support, caplog):
    """The squat of the attack (README "Attack"): with an HTTP token but no zenoh access control
    the service does not trust claims (`trust_claims=False`); a peer holding P/{id}/alive and
    answering P/{id}/owner with forged text neither blocks the twin nor reaches an answer, and the
    log quotes nothing of it unescaped. A trusting bus refuses the same claim without repeating
    the forged text."""
    from service.core.errors import InputError

    forged = {"pid": 1, "host": "evil\nINFO forged line", "http": "http://evil", "zid": "0"}
    host = ZenohBus(listen=[endpoint], connect=[], prefix="bearing")
    evil, token, owner = _squat(endpoint, "bearing/pump-9", forged)
    untrusting = ZenohBus(listen=[], connect=[endpoint], mode="client", prefix="bearing", trust_claims=False)
    trusting = ZenohBus(listen=[], connect=[endpoint], mode="client", prefix="bearing")
    try:
        assert support.wait_until(lambda: trusting._alive_elsewhere("bearing/pump-9"), WAIT_S)
        with pytest.raises(InputError) as err:
            trusting.attach_twin("pump-9", lambda: None, lambda p: {})
        message = err.value.errors[0].message
        assert err.value.status_code == 409 and "evil" not in message and "process 1 " not in message
        channel = untrusting.attach_twin("pump-9", lambda: None, lambda p: {})
        assert channel.prefix == "bearing/pump-9" and "pump-9" in untrusting.channels
        assert all("\n" not in r.getMessage() for r in caplog.records)
    finally:
        owner.undeclare()
        token.undeclare()
        evil.close()
        trusting.close()
        untrusting.close()
        host.close()


def test_prefixes_are_checked():
    from service.bus.zenoh_bus import check_prefix

    assert check_prefix("plant1/line2/motor7") == "plant1/line2/motor7"
    for bad in ("", "/a", "a/", "a//b", "a/*", "a/**", "a/$x", "a b", "/".join("x" * 9)):
        with pytest.raises(ValueError):
            check_prefix(bad)


def test_monitor_names_rows_and_forgets_gone_twins():
    from service.tools.monitor import TwinTable, twin_keys, twin_name

    assert twin_name("bearing/default/state") == "default"
    assert twin_name("plant1/line2/motor7/de/alive", "plant1/**") == "plant1/line2/motor7/de"
    assert twin_name("plant1/line2/motor7/de/state", "plant1/line2/motor7") == "de"
    assert twin_keys("plant1/**") == ("plant1/*/**/state", "plant1/*/**/alive")
    table = TwinTable("plant1/**", forget_gone_s=1.0)
    state = json.dumps({"balls": [], "seq": 1, "designation": "6208"}).encode()
    table.on_alive("plant1/l/a/alive", True)
    table.on_state("plant1/l/a/state", state)
    table.on_alive("plant1/l/a/alive", False)
    table.on_state("plant1/l/a/state", state)  # a late snapshot after the token went
    assert table.rows["plant1/l/a"]["alive"] is False and table.rows["plant1/l/a"]["messages"] == 1
    assert table.forget_gone(time.monotonic() + 0.5) == []
    assert table.forget_gone(time.monotonic() + 1.5) == ["plant1/l/a"]
    table.on_state("plant1/l/a/state", state)  # does not bring it back
    assert "plant1/l/a" not in table.rows
    table.on_alive("plant1/l/a/alive", True)  # a twin of that name started again
    assert table.rows["plant1/l/a"]["alive"] is True


def test_listen_conflict_is_a_clear_error(endpoint, bus):
    with pytest.raises(RuntimeError, match="cannot open"):
        ZenohBus(listen=[endpoint], connect=[])


@pytest.mark.parametrize(
    "bad", ["tcp/127.0.0.1:notaport", "127.0.0.1:7447", "tcp/127.0.0.1", "tcp/:7447", "tcp/127.0.0.1:70000", ""]
)
def test_malformed_endpoints_are_refused_up_front(bad):
    with pytest.raises(ValueError, match="not a zenoh endpoint"):
        make_config([], [bad])
    with pytest.raises(ValueError, match="not a zenoh endpoint"):
        ZenohBus(listen=[bad])


def test_endpoint_forms_that_are_accepted():
    make_config(
        ["tcp/127.0.0.1:0", "tcp/[::1]:7447"],
        ["tcp/localhost:7447", "udp/127.0.0.1:7447", "unixsock-stream/tmp/x.sock"],
    )


# ---- (e) monitor -----------------------------------------------------------------------------
def test_monitor_sees_twins_of_two_services(endpoint, twin, support):
    endpoint2 = support.free_endpoint()
    bus1 = ZenohBus(listen=[endpoint], connect=[])
    bus2 = ZenohBus(listen=[endpoint2], connect=[endpoint])  # a second service, joined to the first
    stop = threading.Event()
    try:
        base = twin.snapshot()
        names = ("m1", "m2", "m3")
        snaps = {name: base.model_copy(update={"bearing_id": name}) for name in names}
        channels = {
            name: (bus1 if name != "m3" else bus2).attach_twin(name, lambda n=name: snaps[n], lambda p: {})
            for name in names
        }

        def runner():  # the runners' job: publish at a fixed rate (20 Hz here)
            seq = 0
            while not stop.is_set():
                seq += 1
                for name in names:
                    snaps[name] = base.model_copy(update={"bearing_id": name, "seq": seq})
                    channels[name].publish(snaps[name])
                stop.wait(0.05)

        thread = threading.Thread(target=runner, daemon=True)
        thread.start()
        out = io.StringIO()
        t0 = time.monotonic()
        rows = run_monitor([endpoint], [], "bearing/*/state", duration_s=3.5, out=out)
        assert time.monotonic() - t0 < 8.0
    finally:
        stop.set()
        bus2.close()
        bus1.close()
    assert set(rows) == {"m1", "m2", "m3"}, rows.keys()
    for row in rows.values():
        assert row["designation"] == "6208"
        assert row["alive"] is True
        assert row["messages"] >= 1 and row["seq"] is not None
        assert row["min_lambda"] is None or row["min_lambda"] > 0
        assert sum(row["regimes"].values()) == 2 * len(base.balls)
        electrical = base.to_dict().get("electrical")
        assert row["discharge_risk"] == (electrical["discharge_risk"] if electrical else None)
        assert row["shaft_speed_rad_s"] == pytest.approx(500.0, rel=0.05)
        assert row["gaps"] == 0
    text = out.getvalue()
    assert "m1" in text and "m3" in text


def test_monitor_counts_gaps_marks_gone_and_reads_electrical(endpoint, twin, support):
    bus = ZenohBus(listen=[endpoint], connect=[])
    result: dict = {}
    try:
        channel = bus.attach_twin("g1", lambda: None, lambda p: {})
        pub = bus.session.declare_publisher("bearing/g1/state")
        base = twin.snapshot().to_dict()
        base["bearing_id"] = "g1"
        base["electrical"] = {"discharge_risk": 0.75}

        th = threading.Thread(
            target=lambda: result.update(run_monitor([endpoint], None, duration_s=3.0, out=io.StringIO())), daemon=True
        )
        th.start()
        # wait until the monitor's subscriber is routed to this publisher (NB: matching_status
        # is a MatchingStatus object, always truthy: read .matching), then send seq 1..10
        # without 4, 7, 8
        assert support.wait_until(lambda: pub.matching_status.matching, 8.0)
        for seq in (1, 2, 3, 5, 6, 9, 10):
            pub.put(json.dumps({**base, "seq": seq}))
        pub.put(b"garbage")
        time.sleep(0.5)
        channel.detach()
        pub.undeclare()
        th.join(10.0)
        assert not th.is_alive()
    finally:
        bus.close()
    row = result["g1"]
    assert row["seq"] == 10 and row["gaps"] == 2 and row["missing"] == 3
    assert row["discharge_risk"] == 0.75
    assert row["alive"] is False


def test_monitor_once_prints_one_table_and_returns(endpoint, twin):
    bus = ZenohBus(listen=[endpoint], connect=[])
    stop = threading.Event()
    try:
        snap = twin.snapshot().model_copy(update={"bearing_id": "o1"})
        channel = bus.attach_twin("o1", lambda: snap, lambda p: {})
        thread = threading.Thread(
            target=lambda: [channel.publish(snap) for _ in iter(lambda: stop.wait(0.05), True)], daemon=True
        )
        thread.start()
        out = io.StringIO()
        t0 = time.monotonic()
        rows = run_monitor([endpoint], [], once=True, duration_s=8.0, out=out)
        assert time.monotonic() - t0 < 6.0  # returned on the first twin, not at the deadline
    finally:
        stop.set()
        bus.close()
    assert list(rows) == ["o1"] and rows["o1"]["designation"] == "6208"
    assert "6208" in out.getvalue()


def test_monitor_command_registers_with_argparse():
    import argparse

    parser = argparse.ArgumentParser(prog="bearing-twin")
    sub = parser.add_subparsers(dest="command", required=True)
    add_monitor_command(sub)
    args = parser.parse_args(
        [
            "monitor",
            "--connect",
            "tcp/127.0.0.1:1",
            "--connect",
            "tcp/127.0.0.1:2",
            "--duration",
            "1",
            "bearing/x/state",
        ]
    )
    assert args.connect == ["tcp/127.0.0.1:1", "tcp/127.0.0.1:2"]
    assert args.keyexpr == "bearing/x/state" and args.duration == 1.0 and callable(args.func)
    args = parser.parse_args(["monitor"])
    assert args.keyexpr is None and args.prefix is None and not args.once  # {prefix}/*/state
    assert args.forget_after == 10.0
    bad = parser.parse_args(["monitor", "--connect", "tcp/127.0.0.1:notaport", "--duration", "0.2"])
    assert bad.func(bad) == 2


def test_ball_messages_are_made_only_for_a_subscriber(bus, client, twin, support):
    """The outbox follows each ball publisher's zenoh matching status and makes no ball message
    nobody subscribes to (service.bus.twin_outbox): without a subscriber every ball of every
    snapshot is counted unmatched; a subscriber to one ball gets that ball's messages and the
    other balls stay unmade."""
    snap = twin.snapshot()
    channel = bus.attach_twin("t1", lambda: snap, lambda p: {})
    balls = len(snap.balls)
    for _ in range(3):
        channel.publish(snap)
    assert support.wait_until(lambda: channel.published == 3, 5.0), channel.published
    assert channel.unmatched == 3 * (balls + 1)  # the balls' and the state's messages
    client.subscribe("bearing/t1/ball/2")
    sent = [3]

    def poke():
        sent[0] += 1
        channel.publish(snap)

    got = client.wait_for(lambda item: item[0] == "bearing/t1/ball/2", poke=poke, poke_every_s=0.05)
    assert loads(got[2])["index"] == 2
    assert support.wait_until(lambda: channel.published + channel.dropped == sent[0], 5.0)
    before = channel.unmatched
    channel.publish(snap)
    assert support.wait_until(lambda: channel.published + channel.dropped == sent[0] + 1, 5.0)
    assert channel.unmatched - before == balls - 1 + 1  # the other balls, and the state


def test_matching_follows_a_remote_subscriber(bus, client, support):
    """service.bus.twin_outbox.Matching: zenoh's matching listener keeps the flag the outbox
    reads in step with the publisher's own status as a subscriber of another session arrives
    and leaves, and with one that matched before the listener was declared."""
    pub = bus.session.declare_publisher("bearing/m1/ball/0")
    watch = Matching(pub)
    try:
        assert watch.matching is False and matched(pub) is False
        client.subscribe("bearing/m1/**")
        assert support.wait_until(lambda: watch.matching, WAIT_S)
        assert matched(pub)
        late = Matching(pub)  # declared while a subscriber matches
        assert support.wait_until(lambda: late.matching, WAIT_S)
        late.close()
        client.close()
        assert support.wait_until(lambda: not watch.matching, WAIT_S)
        assert not matched(pub)
    finally:
        watch.close()
        pub.undeclare()


# ---- (f) publish never blocks ----------------------------------------------------------------
class _Blocker:
    """A 'snapshot' whose state message goes out (`publish` puts it on the caller's thread) and
    whose ball messages block the publisher thread until released."""

    def __init__(self):
        self.entered = threading.Event()
        self.release = threading.Event()
        self.left = threading.Event()  # the publisher thread let go (released, or gave up after 10 s)

    def to_json(self):
        return "{}"

    @property
    def schema_(self):  # the first thing the publisher thread reads for the ball messages
        self.entered.set()
        self.release.wait(10.0)
        self.left.set()
        raise RuntimeError("not a real snapshot")  # must not kill the publisher thread


def test_publish_never_blocks_and_counts_drops(bus, client, twin, support):
    snap = twin.snapshot()
    channel = bus.attach_twin("t1", lambda: snap, lambda p: {}, queue_size=8)
    client.subscribe("bearing/t1/ball/0")  # a subscriber: the ball messages are queued for the outbox
    client.subscribe("bearing/t1/state")  # and the state message is made (and refused when garbage)
    ball = channel.outbox._ball_publisher(0)
    assert ball is not None and support.wait_until(lambda: channel.outbox._matched(ball), 5.0)
    assert support.wait_until(lambda: channel.outbox._state_matching.matching, 5.0)
    blocker = _Blocker()
    channel.publish(blocker)
    assert blocker.entered.wait(5.0)
    for _ in range(200):
        channel.publish(snap)
    assert not blocker.left.is_set()  # all 200 returned while the publisher thread was held
    assert channel.dropped == 200 - 8
    channel.publish(object())  # garbage is refused without raising: counted, not queued
    assert channel.dropped == 200 - 8 and channel.errors == 1
    blocker.release.set()
    # the thread survives the failure and drains the queue
    assert support.wait_until(lambda: channel.published == 8 and channel.errors == 2, 5.0), (
        channel.published,
        channel.errors,
    )
    client.wait_for(lambda item: item[0] == "bearing/t1/state", poke=lambda: channel.publish(snap))
    channel.detach()
    channel.publish(snap)  # after detach: a no-op, no exception


def test_messages_nobody_subscribes_to_are_not_queued(bus, twin, support):
    """service.bus.twin_outbox: without a subscriber to any state, ball, vibration or waveform
    key, a snapshot's messages and a waveform block are counted as unmatched on the caller's
    thread, not made and never queued, so the outbox's thread is not woken for them."""
    snap = twin.snapshot()
    channel = bus.attach_twin("t1", lambda: snap, lambda p: {}, queue_size=8)
    balls = len(snap.balls)
    for _ in range(20):
        channel.publish(snap)
    channel.publish_waveform("t1", [])
    assert channel.published == 20 and channel.dropped == 0
    assert channel.unmatched == 20 * (balls + 1) + 1
    assert channel.outbox.last_state(snap) is None  # no state message was made
    assert not channel.outbox._queue


def test_the_state_message_goes_out_on_the_callers_thread(bus, client, twin):
    """TwinChannel.publish puts the state message itself (the publish worker's thread), so it
    reaches a subscriber while the channel's own thread is held (here inside a snapshot's ball
    messages): no wait for that thread's wake-up between a snapshot and its state message."""
    snap = twin.snapshot()
    channel = bus.attach_twin("t1", lambda: snap, lambda p: {})
    client.subscribe("bearing/t1/state")
    blocker = _Blocker()
    channel.publish(blocker)
    assert blocker.entered.wait(5.0)  # the channel thread is held from now on
    try:
        got = []

        def state(item):
            got.append(loads(item[2]))
            return got[-1].get("seq") == snap.seq

        client.wait_for(state, poke=lambda: channel.publish(snap))
        assert got[-1] == json.loads(snap.to_json())
        assert not blocker.release.is_set() and channel.errors == 0  # the blocker is still held
    finally:
        blocker.release.set()


def test_a_burst_nobody_subscribes_to_queues_nothing_and_close_is_prompt(bus, twin):
    snaps = [twin.snapshot() for _ in range(5)]
    channel = bus.attach_twin("t1", lambda: snaps[-1], lambda p: {}, queue_size=64)
    for i in range(5000):
        channel.publish(snaps[i % 5])
    assert channel.dropped == 0 and channel.published == 5000  # nobody subscribes: nothing queued
    t = time.perf_counter()
    bus.close()
    assert time.perf_counter() - t < 5.0
    assert channel.closed
    assert channel.published + channel.dropped + channel.errors <= 5000


def _holding_setpoint_handler():
    """(on_setpoint, entered, release): a setpoint handler that holds the twin's control thread
    on the payload b"hold" until `release` is set (at most WAIT_S)."""
    entered, release = threading.Event(), threading.Event()

    def on_setpoint(payload: bytes) -> dict:
        if payload == b"hold":
            entered.set()
            release.wait(WAIT_S)
        return {"accepted": True}

    return on_setpoint, entered, release


def _hold(client, setpoints, entered) -> None:
    """Put b"hold" on `setpoints` until the control thread holds it (at most WAIT_S)."""
    deadline = time.monotonic() + WAIT_S
    while not entered.is_set() and time.monotonic() < deadline:
        client.drain()
        setpoints.put(b"hold")
        entered.wait(0.5)
    assert entered.is_set()


def test_a_full_setpoint_queue_refuses_with_429_never_drops(bus, client):
    """Zenoh setpoint results are never silently dropped. The twin's control thread is
    held inside the handler; 256 setpoints fill its queue (_CONTROL_QUEUE_SIZE) and each of the
    next 40 gets a refusal with status 429 and retry_after_s on the result key: one result for
    every setpoint sent, none lost."""
    from service.bus.zenoh_bus import _CONTROL_QUEUE_SIZE

    on_setpoint, entered, release = _holding_setpoint_handler()
    channel = bus.attach_twin("t1", lambda: None, on_setpoint)
    client.subscribe("bearing/t1/setpoint/result")
    pub = client.session.declare_publisher("bearing/t1/setpoint", congestion_control=zenoh.CongestionControl.BLOCK)
    client.wait_for(lambda item: True, poke=lambda: pub.put(b"warm"), poke_every_s=0.5)  # routes up
    _hold(client, pub, entered)
    time.sleep(0.5)
    client.drain()  # warm-up results (the held setpoint's comes later)
    over = 40
    for i in range(_CONTROL_QUEUE_SIZE + over):
        pub.put(f"n{i}".encode())
    deadline = time.monotonic() + WAIT_S
    while channel.setpoints_refused_busy < over and time.monotonic() < deadline:
        time.sleep(0.02)
    assert channel.setpoints_refused_busy == over
    release.set()
    results = []
    deadline = time.monotonic() + WAIT_S
    while len(results) < _CONTROL_QUEUE_SIZE + over + 1 and time.monotonic() < deadline:
        try:
            results.append(loads(client.inbox.get(timeout=0.2).payload))
        except queue.Empty:
            pass
    refused = [r for r in results if not r["accepted"]]
    assert len(results) == _CONTROL_QUEUE_SIZE + over + 1  # the held one, the queued, the refused
    assert len(refused) == over
    assert all(r["status"] == 429 and r["retry_after_s"] > 0 and "retry" in r["error"] for r in refused)
    pub.undeclare()


def test_a_full_queue_refuses_measured_windows_with_429_on_their_answer_key(bus, client):
    """Every write, not only setpoints, is answered when the control queue is full: with the
    control thread held inside a setpoint handler, 256 measured windows fill the queue
    (_CONTROL_QUEUE_SIZE) and each of the next 10 is refused with status 429 on
    `.../vibration/comparison`, none dropped unanswered."""
    from service.bus.zenoh_bus import _CONTROL_QUEUE_SIZE

    on_setpoint, entered, release = _holding_setpoint_handler()
    channel = bus.attach_twin("t2", lambda: None, on_setpoint, on_measured=lambda payload: {"accepted": True})
    client.subscribe("bearing/t2/vibration/comparison")
    setpoints = client.session.declare_publisher(
        "bearing/t2/setpoint", congestion_control=zenoh.CongestionControl.BLOCK
    )
    windows = client.session.declare_publisher(
        "bearing/t2/vibration/measured", congestion_control=zenoh.CongestionControl.BLOCK
    )
    client.wait_for(lambda item: True, poke=lambda: windows.put(b"warm"), poke_every_s=0.5)  # routes up
    _hold(client, setpoints, entered)
    time.sleep(0.5)
    client.drain()
    over = 10
    for i in range(_CONTROL_QUEUE_SIZE + over):
        windows.put(f"w{i}".encode())
    deadline = time.monotonic() + WAIT_S
    while channel.inbox.setpoints_refused_busy < over and time.monotonic() < deadline:
        time.sleep(0.02)
    release.set()
    results = []
    deadline = time.monotonic() + WAIT_S
    while len(results) < _CONTROL_QUEUE_SIZE + over and time.monotonic() < deadline:
        try:
            results.append(loads(client.inbox.get(timeout=0.2).payload))
        except queue.Empty:
            pass
    refused = [r for r in results if not r["accepted"]]
    assert len(results) == _CONTROL_QUEUE_SIZE + over  # every window answered
    assert len(refused) == over and all(r["status"] == 429 for r in refused)
    setpoints.undeclare()
    windows.undeclare()
