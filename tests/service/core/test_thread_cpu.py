"""The service overhead by the job of its threads (service.core.thread_cpu)."""

from __future__ import annotations

import threading
import time

import pytest

from service.core.thread_cpu import ROLES, ThreadCpuMeter, thread_cpu_by_role, thread_role


@pytest.mark.parametrize(
    ("name", "role"),
    [
        ("step-0", "stepping"),
        ("step-publish", "publish_worker"),
        ("twin-b1-0", "stepping"),
        ("twin-b1-publish", "publish_worker"),
        ("zenoh-pub-b1", "zenoh_outbox"),
        ("zenoh-ctl-b1", "zenoh_inbox"),
        ("Thread-3 (pyo3-closure)", "zenoh_inbox"),
        ("alarms", "alarms"),
        ("rerun-recorder", "recording"),
        ("MainThread", "http"),
        ("AnyIO worker thread", "http"),
        ("opcua", "opcua"),
        ("thread-priority", "other"),
    ],
)
def test_threads_are_given_their_role_by_name(name, role):
    assert thread_role(name) == role


def test_rates_per_role_with_the_engines_taken_from_the_stepping_threads():
    """Two samples 2 s apart: each role's CPU difference / 2 s; the stepping threads' rate less
    the engines' (0.5 of their 0.6 CPU s/s); twin overhead = every role but http and opcua."""
    now = [0.0]
    totals = [dict.fromkeys(ROLES, 0.0)]
    meter = ThreadCpuMeter(1.0, clock=lambda: now[0], sample=lambda: dict(totals[0]))
    first = meter.sample(0.0, 2)  # no window yet: the totals only
    assert "twin_overhead_fraction" not in first and first["engine_cpu_s_total"] == 0.0
    now[0] = 2.0
    totals[0] = {
        **dict.fromkeys(ROLES, 0.0),
        "stepping": 1.2,
        "publish_worker": 0.1,
        "recording": 0.04,
        "http": 0.3,
        "opcua": 0.1,
        "native": 0.02,
    }
    out = meter.sample(1.0, 2)
    assert out["stepping_cpu_s_per_s"] == pytest.approx(0.6 - 0.5, abs=1e-12)
    assert out["publish_worker_cpu_s_per_s"] == pytest.approx(0.05, abs=1e-12)
    assert out["http_cpu_s_per_s"] == pytest.approx(0.15, abs=1e-12)
    assert out["twin_overhead_cpu_s_per_s"] == pytest.approx(0.1 + 0.05 + 0.02 + 0.01, abs=1e-12)
    assert out["twin_overhead_per_twin_cpu_s_per_s"] == pytest.approx(0.09, abs=1e-12)
    assert out["twin_overhead_fraction"] == pytest.approx(0.18 / 0.5, abs=1e-12)
    assert out["stepping_cpu_s_total"] == pytest.approx(1.2 - 1.0, abs=1e-12)
    assert out["twin_overhead_cpu_s_total"] == pytest.approx(0.2 + 0.1 + 0.04 + 0.02, abs=1e-12)
    now[0] = 2.5  # a window shorter than 1 s keeps the last rates
    again = meter.sample(1.1, 2)
    assert again["twin_overhead_fraction"] == out["twin_overhead_fraction"]
    assert again["stepping_cpu_s_total"] == pytest.approx(1.2 - 1.1, abs=1e-12)


def test_a_busy_python_thread_is_counted_under_its_role():
    """A thread named like the publish worker that spins for 0.2 s of CPU shows at least that
    much more under publish_worker (its own CPU clock), and the roles add up to no more than the
    process's CPU."""
    before = thread_cpu_by_role()
    if not before:
        pytest.skip("no per-thread CPU clock on this platform")

    def spin():
        c0 = time.thread_time()
        while time.thread_time() - c0 < 0.2:
            pass
        done.wait(5.0)

    done = threading.Event()
    t = threading.Thread(target=spin, name="step-publish")
    t.start()
    time.sleep(0.05)
    deadline = time.monotonic() + 10.0
    while thread_cpu_by_role()["publish_worker"] - before["publish_worker"] < 0.2 and time.monotonic() < deadline:
        time.sleep(0.01)
    after = thread_cpu_by_role()
    done.set()
    t.join()
    assert after["publish_worker"] - before["publish_worker"] >= 0.2
    assert sum(after.values()) <= time.process_time() + 1e-3


@pytest.mark.skipif(not hasattr(time, "pthread_getcpuclockid"), reason="no per-thread CPU clocks here")
def test_the_clock_by_kernel_id_is_the_threads_own_and_an_ended_thread_has_none():
    """thread_cpu_clock(native id) is the clock pthread_getcpuclockid gives for the same thread;
    for a thread that has ended the kernel refuses the clock (OSError), which the sampler skips."""
    from service.core.thread_cpu import thread_cpu_clock

    me = threading.current_thread()
    assert thread_cpu_clock(me.native_id) == time.pthread_getcpuclockid(me.ident)
    t = threading.Thread(target=lambda: None)
    t.start()
    t.join()  # returns as the thread finishes in Python; the kernel thread ends just after

    def gone() -> bool:
        try:
            time.clock_gettime(thread_cpu_clock(t.native_id))
        except OSError:
            return True
        return False

    deadline = time.monotonic() + 5.0
    while not gone() and time.monotonic() < deadline:
        time.sleep(0.01)
    assert gone()
