"""The OPC UA facade (service.opcua) against a REAL service: uvicorn + the twins + an asyncua server
on 127.0.0.1 (free ports), browsed, read and written with asyncua's own client. A bearer token is
set: it is the OPC UA password. These tests run on the None security policy, asked for
explicitly (with a token the default offers only signed and encrypted endpoints: see
test_opcua_security.py). Every wait is bounded; no wall-clock figure is asserted except the
contract's own "within one publish period", counted in publications (seq)."""

from __future__ import annotations

import asyncio
import json
import math
from collections.abc import Awaitable

import pytest

asyncua = pytest.importorskip("asyncua")
from asyncua import Client, ua  # noqa: E402

from service.opcua.layout import (  # noqa: E402
    FOLDERS,
    LAST_RESULT,
    MEASURED_TEMPERATURE,
    NAMESPACE_URI,
    ROOT_FOLDER,
)
from service.settings import ServiceSettings  # noqa: E402
from twin.setpoint import NAMES as SETPOINT_NAMES  # noqa: E402

TOKEN = "opc-token-123"
WAIT_S = 60.0
PUBLISH_HZ = 20.0


@pytest.fixture(scope="module")
def server(support):
    settings = ServiceSettings(
        enable_zenoh=False,
        enable_recording=False,
        token=TOKEN,
        max_twins=3,
        publish_rate_hz=PUBLISH_HZ,
        opcua=f"opc.tcp://127.0.0.1:{support.free_port()}",
        opcua_security="none",
    )
    with support.ThreadServer(settings, start_timeout_s=120.0, stop_timeout_s=30.0) as srv:
        yield srv


@pytest.fixture(scope="module")
def url(facade):
    return facade.url


def run(coro: Awaitable, timeout: float = WAIT_S):
    return asyncio.run(asyncio.wait_for(coro, timeout))


def client(url: str, password: str | None = TOKEN) -> Client:
    # asyncua's client drops a connection whose server-state probe takes over watchdog_intervall
    # (1 s by default): far too tight on a shared test machine where building a twin holds the GIL
    c = Client(url, timeout=20, watchdog_intervall=10.0)
    if password is not None:
        c.set_user("operator")
        c.set_password(password)
    return c


async def twin_node(c: Client, bearing_id: str = "default"):
    idx = await c.get_namespace_index(NAMESPACE_URI)
    return idx, await c.nodes.objects.get_child([f"{idx}:{ROOT_FOLDER}", f"{idx}:{bearing_id}"])


async def read(c: Client, *path: str, bearing_id: str = "default"):
    idx, twin = await twin_node(c, bearing_id)
    node = await twin.get_child([f"{idx}:{p}" for p in path])
    return await node.read_value()


def test_browse_the_namespace_folders_and_setpoint(url):
    async def main():
        async with client(url, password=None) as c:
            assert NAMESPACE_URI in await c.get_namespace_array()
            idx, twin = await twin_node(c)
            folders = [(await n.read_browse_name()) for n in await twin.get_children()]
            assert all(q.NamespaceIndex == idx for q in folders)
            assert [q.Name for q in folders] == ["Identification", *FOLDERS, "Setpoint", MEASURED_TEMPERATURE]
            setpoint = await twin.get_child(f"{idx}:Setpoint")
            names = [(await n.read_browse_name()).Name for n in await setpoint.get_children()]
            assert names == [*SETPOINT_NAMES, LAST_RESULT]
            assert await read(c, "Identification", "designation") == "6208"
            assert await read(c, "Identification", "ball_count") == 9
            assert await read(c, "Identification", "static_load_rating_n") > 0.0
            node = await twin.get_child([f"{idx}:Setpoint", f"{idx}:radial_load_n"])
            assert ua.AccessLevel.CurrentWrite in await node.get_access_level()
            eu = await (await node.get_child(f"{idx}:EURange")).read_value()
            return eu

    eu = run(main())
    # the bearing's own range: the 6208's radial-load limit of the compiled model (static capacity,
    # 4.2 GPa with the exact Hertz constants)
    from twin import catalog
    from twin.model import make_model

    limit = make_model(catalog.bearing("6208")).max_radial_load_n
    assert (eu.Low, eu.High) == (0.0, pytest.approx(limit, rel=1e-9))


def test_state_is_within_one_publish_period_of_http(url, http):
    """The facade copies each new snapshot within half a publish period: an OPC UA read made right
    after an HTTP read sees that snapshot or the one before it (seq counts publications)."""

    async def main():
        async with client(url, password=None) as c:
            idx, twin = await twin_node(c)
            seq_node = await twin.get_child([f"{idx}:OperatingConditions", f"{idx}:seq"])
            time_node = await twin.get_child([f"{idx}:OperatingConditions", f"{idx}:time_s"])
            pairs = []
            for _ in range(10):
                h = (await asyncio.to_thread(http.get, "/v1/bearings/default/state")).json()
                seq, time_s = await c.read_values([seq_node, time_node])  # one Read: one snapshot
                pairs.append((h["seq"], h["time_s"], seq, time_s))
                await asyncio.sleep(0.5 / PUBLISH_HZ)
            return pairs

    pairs = run(main())
    for seq_http, time_http, seq_opc, time_opc in pairs:
        assert seq_opc >= seq_http - 1, pairs
        if seq_opc == seq_http:
            assert time_opc == time_http


def test_authenticated_write_goes_the_http_way(url, http, support):
    async def main():
        async with client(url) as c:
            idx, twin = await twin_node(c)
            node = await twin.get_child([f"{idx}:Setpoint", f"{idx}:radial_load_n"])
            await node.write_value(3500.0)
            last = json.loads(await read(c, "Setpoint", LAST_RESULT))
            return last, await node.read_value()

    last, value = run(main())
    assert last["accepted"] is True and last["status"] == "Good" and last["setpoint"]["radial_load_n"] == 3500.0
    assert value == 3500.0
    assert http.get("/v1/bearings/default").json()["setpoint"]["radial_load_n"] == 3500.0
    # the runner applies it at its next frame: the snapshot's setpoint in force follows
    support.wait_for(
        lambda: http.get("/v1/bearings/default/state").json()["setpoint"]["radial_load_n"],
        lambda v: v == 3500.0,
        timeout=WAIT_S,
    )

    async def in_force():
        async with client(url, password=None) as c:
            for _ in range(200):
                if await read(c, "OperatingConditions", "radial_load_n") == 3500.0:
                    return True
                await asyncio.sleep(0.05)
            return False

    assert run(in_force())


def test_out_of_range_write_is_refused_with_bad_out_of_range_and_a_message_naming_the_field(url, http):
    low, high = http.get("/v1/bearings/default").json()["limits"]["radial_load_n"]
    before = http.get("/v1/bearings/default").json()["setpoint"]["radial_load_n"]
    answer = http.put("/v1/bearings/default/setpoint", json={"radial_load_n": 1e7})
    assert answer.status_code == 422
    http_message = answer.json()["detail"][0]["message"]

    async def main():
        async with client(url) as c:
            idx, twin = await twin_node(c)
            node = await twin.get_child([f"{idx}:Setpoint", f"{idx}:radial_load_n"])
            results = {}
            for label, variant in (
                ("too_large", ua.Variant(1e7, ua.VariantType.Double)),
                ("nan", ua.Variant(math.nan, ua.VariantType.Double)),
                ("text", ua.Variant("3000", ua.VariantType.String)),
                ("bool", ua.Variant(True, ua.VariantType.Boolean)),
            ):
                with pytest.raises(ua.UaStatusCodeError) as err:
                    await node.write_value(variant)
                results[label] = (err.value.code, json.loads(await read(c, "Setpoint", LAST_RESULT)))
            return results, await node.read_value()

    results, value = run(main())
    code, last = results["too_large"]
    assert code == ua.StatusCodes.BadOutOfRange
    assert last == {
        "accepted": False,
        "status": "BadOutOfRange",
        "field": "radial_load_n",
        "error": f"radial_load_n: {http_message}",
    }
    assert f"[{low:g}, {high:g}] N for bearing 6208" in last["error"]  # the bearing's own range
    assert results["nan"][0] == ua.StatusCodes.BadOutOfRange
    assert results["text"][0] == ua.StatusCodes.BadTypeMismatch and "String" in results["text"][1]["error"]
    assert results["bool"][0] == ua.StatusCodes.BadTypeMismatch
    assert value == before
    assert http.get("/v1/bearings/default").json()["setpoint"]["radial_load_n"] == before


def test_measured_temperature_write_goes_the_http_way(url, http, support):
    """A write to MeasuredTemperature/outer_ring_c is the measurement of PUT .../temperature
    (service.core.measured_temperature): taken into the snapshot's thermal block, and outside
    [-60, 400] degC refused with BadOutOfRange and the words naming the field and its range."""

    async def main():
        async with client(url) as c:
            idx, twin = await twin_node(c)
            node = await twin.get_child([f"{idx}:{MEASURED_TEMPERATURE}", f"{idx}:outer_ring_c"])
            eu = await (await node.get_child(f"{idx}:EURange")).read_value()
            await node.write_value(46.5)
            good = json.loads(await read(c, MEASURED_TEMPERATURE, LAST_RESULT))
            with pytest.raises(ua.UaStatusCodeError) as err:
                await node.write_value(900.0)
            bad = json.loads(await read(c, MEASURED_TEMPERATURE, LAST_RESULT))
            return eu, good, err.value.code, bad

    eu, good, code, bad = run(main())
    assert (eu.Low, eu.High) == (-60.0, 400.0)
    assert good == {
        "accepted": True,
        "status": "Good",
        "field": "outer_ring_c",
        "node": "outer_ring",
        "temperature_c": 46.5,
    }
    assert code == ua.StatusCodes.BadOutOfRange
    assert bad["accepted"] is False and bad["field"] == "outer_ring_c" and "[-60, 400] degC" in bad["error"], bad
    thermal = support.wait_for(
        lambda: http.get("/v1/bearings/default/state").json()["thermal"],
        lambda t: t["measured_c"] == 46.5,
        timeout=WAIT_S,
    )
    assert thermal["measured_node"] == "outer_ring"

    async def shown():  # the variable reads the measurement the twin took (its snapshot)
        async with client(url, password=None) as c:
            for _ in range(200):
                try:  # BadNoValue until the facade's next update copies the snapshot
                    if await read(c, MEASURED_TEMPERATURE, "outer_ring_c") == 46.5:
                        return True
                except ua.UaStatusCodeError as err:
                    assert err.code == ua.StatusCodes.BadNoValue, err
                await asyncio.sleep(0.05)
            return False

    assert run(shown())


def test_anonymous_write_is_refused_when_a_token_is_set(url, http, server):
    gate = server.service.gate
    unauthorized = gate.unauthorized
    before = http.get("/v1/bearings/default").json()["setpoint"]["shaft_speed_rad_s"]

    async def main():
        async with client(url, password=None) as c:
            assert await read(c, "Identification", "designation") == "6208"  # reads are open
            idx, twin = await twin_node(c)
            node = await twin.get_child([f"{idx}:Setpoint", f"{idx}:shaft_speed_rad_s"])
            with pytest.raises(ua.UaStatusCodeError) as err:
                await node.write_value(100.0)
            return err.value.code, json.loads(await read(c, "Setpoint", LAST_RESULT))

    code, last = run(main())
    assert code == ua.StatusCodes.BadUserAccessDenied
    assert last["status"] == "BadUserAccessDenied" and "token" in last["error"]
    assert gate.unauthorized == unauthorized + 1
    assert http.get("/v1/bearings/default").json()["setpoint"]["shaft_speed_rad_s"] == before


def test_a_wrong_password_refuses_the_session(url, server):
    unauthorized = server.service.gate.unauthorized

    async def main():
        c = client(url, password="not-the-token")
        with pytest.raises(ua.UaStatusCodeError) as err:
            await c.connect()
        c.disconnect_socket()  # (connect already dropped it; idempotent)
        return err.value.code

    assert run(main()) == ua.StatusCodes.BadUserAccessDenied
    assert server.service.gate.unauthorized == unauthorized + 1


def test_twins_created_and_deleted_at_runtime_appear_and_disappear(url, http):
    created = http.post("/v1/bearings", json={"id": "pump-2", "designation": "6208"})
    assert created.status_code == 201, created.text

    async def names(c: Client) -> list[str]:
        idx = await c.get_namespace_index(NAMESPACE_URI)
        root = await c.nodes.objects.get_child(f"{idx}:{ROOT_FOLDER}")
        out = []
        for n in await root.get_children():
            try:  # a twin deleted between the browse and the read is gone
                out.append((await n.read_browse_name()).Name)
            except ua.uaerrors.BadNodeIdUnknown:
                pass
        return out

    async def until(c: Client, predicate) -> list[str]:
        for _ in range(400):
            got = await names(c)
            if predicate(got):
                return got
            await asyncio.sleep(0.05)
        raise AssertionError(f"twins seen: {got}")

    async def appear():
        async with client(url) as c:
            got = await until(c, lambda n: "pump-2" in n)
            await asyncio.to_thread(lambda: http.delete("/v1/bearings/pump-2").raise_for_status())
            gone = await until(c, lambda n: "pump-2" not in n)
            return got, gone

    got, gone = run(appear())
    assert sorted(got) == ["default", "pump-2"] and gone == ["default"]
