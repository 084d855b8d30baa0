"""`bearing-twin bench-service --twins N`: one real small run (2 twins, 2 s, zenoh and recording
on, a served subprocess on loopback ports) whose JSON carries the keys the README documents. The
figures themselves depend on the machine and are never asserted."""

from __future__ import annotations

import json

import pytest

from loadtest.benchmark import overhead_over_run, run_service_benchmark, twin_plan


def test_twin_plan_cycles_the_designations():
    plan = twin_plan(5)
    assert [(d, sp.get("shaft_current_a")) for _, d, sp in plan] == [
        ("6208", None),
        ("6205", None),
        ("7208", None),
        ("6208", 5.0),
        ("6208", None),
    ]
    assert len({i for i, _, _ in plan}) == 5
    alike = twin_plan(3, alike=True)  # --twins auto: the kind the capacity formula counts
    assert [(i, d, sp.get("shaft_current_a")) for i, d, sp in alike] == [
        ("b1-6208", "6208", None),
        ("b2-6208", "6208", None),
        ("b3-6208", "6208", None),
    ]


def test_bench_service_two_twins_reports_per_twin_figures():
    r = run_service_benchmark(twins=2, seconds=2.0, rate_hz=10.0, force=True, settle_s=0.5)
    json.dumps(r, allow_nan=False)
    assert r["zenoh"] is True and r["recording"] is True and r["admission"] == "off"
    assert r["refused"] == []
    assert [(t["id"], t["designation"]) for t in r["twins"]] == [("b1-6208", "6208"), ("b2-6205", "6205")]
    for t in r["twins"]:
        assert {"id", "designation", "real_time_factor_median", "late_fraction", "frames", "cost"} <= set(t)
        assert t["frames"] > 0 and 0.0 <= t["late_fraction"] <= 1.0
        assert t["real_time_factor_median"] > 0.0
    assert "client_latency_ms_p99" in r and r["setpoints"] > 0
    assert r["capacity"]["stepping_threads"] >= 1 and r["recording_rows"] > 0
    run = r["overhead_over_run"]
    assert run is not None and run["window_s"] > 0 and run["engine_cpu_s_per_s"] > 0
    assert run["twin_overhead_cpu_s_per_s"] >= run["publish_worker_cpu_s_per_s"] >= 0.0


def test_overhead_over_the_run_is_the_totals_difference_over_the_wall_time():
    """From the cumulative totals of /health capacity.service_overhead at the start and the end
    of a 10 s measurement: each role's difference / 10 s, the twin overhead per twin and over the
    engines' CPU; None when the service gives no totals (an older service)."""
    before = {
        "engine_cpu_s_total": 1.0,
        "twin_overhead_cpu_s_total": 0.5,
        "publish_worker_cpu_s_total": 0.2,
        "http_cpu_s_total": 0.1,
    }
    after = {
        "engine_cpu_s_total": 6.0,
        "twin_overhead_cpu_s_total": 2.0,
        "publish_worker_cpu_s_total": 0.7,
        "http_cpu_s_total": 0.4,
    }
    run = overhead_over_run(before, after, 10.0, 2)
    expected = {
        "engine_cpu_s_per_s": 0.5,
        "publish_worker_cpu_s_per_s": 0.05,
        "http_cpu_s_per_s": 0.03,
        "twin_overhead_cpu_s_per_s": 0.15,
        "twin_overhead_per_twin_cpu_s_per_s": 0.075,
        "twin_overhead_fraction": 0.3,
    }
    for key, value in expected.items():
        assert run[key] == pytest.approx(value, abs=1e-12), key
    assert overhead_over_run({}, after, 10.0, 2) is None


def test_free_ports_are_distinct_and_free():
    """The load tools' ports for one service (HTTP, zenoh, OPC UA) are asked for together, so
    they are never the same port (asked one at a time, the kernel can hand a released ephemeral
    port out again: the service's HTTP and zenoh then collided, 'address already in use')."""
    import socket

    from loadtest.ports import free_ports

    given: list[int] = []
    for _ in range(50):
        ports = free_ports(3)
        assert len(set(ports)) == 3
        with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
            s.bind(("127.0.0.1", ports[0]))  # free again once returned
        given += ports
    assert len(set(given)) == len(given)  # never handed out twice in one process


def test_free_port_never_repeats_within_a_process():
    """The tests' one-port asks (`loadtest.ports.free_port`, used by every test that starts a
    server) never hand a port out twice in one process, whatever the kernel recycles."""
    from loadtest.ports import free_port

    ports = [free_port() for _ in range(200)]
    assert len(set(ports)) == 200
