"""The limits of the OPC UA facade (service.opcua.guard) against a REAL service and asyncua's own
client on 127.0.0.1: the login backoff per client address (logged once per burst), the session
cap, the subscription cap per session with the publishing interval revised up, and the monitored
items a session may have by count and by notification rate. The limits are set small here so
that a few clients reach them. Every wait is bounded; the only time figures asserted are the
limits' own (a notification rate bounded by the configured one)."""

from __future__ import annotations

import asyncio
import logging
import time
from collections.abc import Awaitable

import pytest

asyncua = pytest.importorskip("asyncua")
from asyncua import Client, ua  # noqa: E402

from service.opcua.guard import GuardLimits, LoginThrottle  # noqa: E402
from service.opcua.layout import FOLDERS, NAMESPACE_URI, ROOT_FOLDER  # noqa: E402
from service.settings import ServiceSettings  # noqa: E402

TOKEN = "opc-guard-token-789"
WAIT_S = 60.0
PUBLISH_HZ = 20.0
LIMITS = dict(
    opcua_max_sessions=3,
    opcua_max_subscriptions_per_session=2,
    opcua_max_monitored_items_per_session=6,
    opcua_max_notifications_per_s=40.0,
    opcua_min_publishing_interval_ms=100.0,
    opcua_max_queue_size=4,
    opcua_login_free_failures=1,
    opcua_login_backoff_s=3.0,
    opcua_login_backoff_max_s=6.0,
)


@pytest.fixture(scope="module")
def server(support):
    settings = ServiceSettings(
        enable_zenoh=False,
        enable_recording=False,
        token=TOKEN,
        max_twins=1,
        publish_rate_hz=PUBLISH_HZ,
        opcua=f"opc.tcp://127.0.0.1:{support.free_port()}",
        opcua_security="none",
        **LIMITS,
    )
    with support.ThreadServer(settings, start_timeout_s=120.0, stop_timeout_s=30.0) as srv:
        yield srv


def run(coro: Awaitable, timeout: float = WAIT_S):
    return asyncio.run(asyncio.wait_for(coro, timeout))


def client(url: str, password: str | None = TOKEN) -> Client:
    c = Client(url, timeout=20, watchdog_intervall=10.0)
    if password is not None:
        c.set_user("operator")
        c.set_password(password)
    return c


async def refused(c: Client) -> int:
    with pytest.raises(ua.UaStatusCodeError) as err:
        await c.connect()
    c.disconnect_socket()
    return err.value.code


async def variables(c: Client, n: int) -> list:
    idx = await c.get_namespace_index(NAMESPACE_URI)
    twin = await c.nodes.objects.get_child([f"{idx}:{ROOT_FOLDER}", f"{idx}:default"])
    paths = [(folder, var.name) for folder, vars_ in FOLDERS.items() for var in vars_][:n]
    return [await twin.get_child([f"{idx}:{folder}", f"{idx}:{name}"]) for folder, name in paths]


def test_the_backoff_schedule_and_one_log_line_per_burst(caplog):
    """LoginThrottle alone, on a fake clock: `free` failures at once, then 1, 2, 4 s capped at the
    maximum; a success ends the burst with one summary; a quiet spell of the maximum ends it too."""
    now = [0.0]
    t = LoginThrottle(free_failures=2, backoff_s=1.0, backoff_max_s=4.0, clock=lambda: now[0])
    caplog.set_level(logging.WARNING, "service.opcua.guard")
    waits = []
    for _ in range(6):
        t.failed("10.0.0.7")
        waits.append(t.wait_s("10.0.0.7"))
    assert waits == [0.0, 1.0, 2.0, 4.0, 4.0, 4.0]
    assert t.wait_s("10.0.0.8") == 0.0  # per address
    t.refuse("10.0.0.7")
    now[0] = 3.0
    assert t.wait_s("10.0.0.7") == pytest.approx(1.0)
    t.succeeded("10.0.0.7")
    assert t.wait_s("10.0.0.7") == 0.0
    lines = [r.getMessage() for r in caplog.records]
    assert len(lines) == 2 and "failed login from 10.0.0.7" in lines[0]
    assert "6 failed login(s) from 10.0.0.7" in lines[1] and "1 more refused" in lines[1]
    t.failed("10.0.0.9")
    now[0] = 3.0 + 4.0
    t.sweep()
    assert len(caplog.records) == 4 and "1 failed login(s) from 10.0.0.9" in caplog.records[-1].getMessage()


def test_an_item_costs_what_it_may_send():
    limits = GuardLimits(publish_rate_hz=50.0)
    assert limits.item_rate_hz(1, 1000.0) == 1.0  # one latest value per publish
    assert limits.item_rate_hz(4, 1000.0) == 4.0  # up to a queue per publish
    assert limits.item_rate_hz(10, 50.0) == 50.0  # never more than the variable changes


def test_failed_logins_back_off_per_address_and_log_once(facade, server, caplog):
    """After one free failure the address waits 3 s: the next guesses and even the right password
    are refused without being tried until the backoff passed (an anonymous read-only session still
    opens); then it opens a session. One warning for the burst and one summary, no asyncua ERROR
    line per refusal."""
    caplog.set_level(logging.INFO)
    guard = facade.guard

    async def main():
        codes = [await refused(client(facade.url, password=f"guess-{i}")) for i in range(4)]
        in_backoff = await refused(client(facade.url))  # the token, during the backoff
        async with client(facade.url, password=None) as c:  # anonymous (read-only): not slowed
            await c.nodes.objects.read_browse_name()
        assert guard.logins.wait_s("127.0.0.1") > 0  # ... and it does not end the backoff
        await asyncio.sleep(guard.logins.wait_s("127.0.0.1") + 0.2)
        async with client(facade.url) as c:  # after it: accepted
            await c.nodes.objects.read_browse_name()
        return codes, in_backoff

    codes, in_backoff = run(main())
    assert codes == [ua.StatusCodes.BadUserAccessDenied] * 4 and in_backoff == ua.StatusCodes.BadUserAccessDenied
    figures = guard.figures()
    assert figures["failed_logins"] == 1 and figures["refused_in_backoff"] == 4
    mine = [r.getMessage() for r in caplog.records if r.name == "service.opcua.guard"]
    assert len(mine) == 2 and "1 failed login(s) from 127.0.0.1" in mine[1] and "4 more refused" in mine[1]
    assert not [r for r in caplog.records if r.levelno >= logging.ERROR and r.name.startswith("asyncua")]


def test_health_counts_what_the_limits_refused(facade, http):
    guard = http.get("/health").json()["opcua_guard"]
    assert set(guard) == {"sessions", "refused", "failed_logins", "refused_in_backoff", "addresses_in_backoff"}
    assert guard == {**facade.guard.figures(), "sessions": guard["sessions"]}


def test_sessions_are_capped(facade):
    async def main():
        clients = [client(facade.url) for _ in range(3)]
        for c in clients:
            await c.connect()
        try:
            code = await refused(client(facade.url))
        finally:
            await clients.pop().disconnect()
        async with client(facade.url) as c:  # one closed: room again
            await c.nodes.objects.read_browse_name()
        for c in clients:
            await c.disconnect()
        return code

    assert run(main()) == ua.StatusCodes.BadTooManySessions


class _Counter:
    def __init__(self):
        self.n = 0

    def datachange_notification(self, node, val, data):
        self.n += 1


def test_subscriptions_items_and_notifications_are_capped(facade):
    """2 subscriptions per session, a third refused; 1 ms asked, 100 ms granted; items beyond the
    session's notification budget (40/s at 10/s each: 4) refused one by one, and beyond its count
    (6) too; the notifications received stay within that budget."""

    async def main():
        async with client(facade.url) as c:
            counter = _Counter()
            sub = await c.create_subscription(1, counter)
            assert sub.parameters.RequestedPublishingInterval == 100.0  # as revised by the server
            other = await c.create_subscription(500, counter)
            with pytest.raises(ua.UaStatusCodeError) as err:
                await c.create_subscription(1000, counter)
            assert err.value.code == ua.StatusCodes.BadTooManySubscriptions
            nodes = await variables(c, 6)
            results = await sub.subscribe_data_change(nodes, queuesize=0)
            handles = [r for r in results if isinstance(r, int)]
            codes = [r.value for r in results if not isinstance(r, int)]
            assert len(handles) == 4 and codes == [ua.StatusCodes.BadTooManyMonitoredItems] * 2
            await asyncio.sleep(0.5)
            n0, t0 = counter.n, time.monotonic()
            await asyncio.sleep(3.0)
            rate = (counter.n - n0) / (time.monotonic() - t0)
            await sub.unsubscribe(handles[0])  # 3 items at 10/s left; at 500 ms an item costs 2/s
            again = await other.subscribe_data_change(nodes[:4], queuesize=1)
            assert [isinstance(r, int) for r in again] == [True, True, True, False]  # the 7th: over the count
            return rate

    rate = run(main())
    assert 0 < rate <= 40.0 * 1.2  # the budget; 20 % for the sleep's own jitter
