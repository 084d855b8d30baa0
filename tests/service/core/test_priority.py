"""service.core.priority: the stepping threads before the service's I/O threads (Linux per-thread
nice values, read back from the kernel with getpriority on each thread id).

Each check runs in a fresh Python process (`_run`): renicing is one-way for an unprivileged
process, and the functional tests run with BEARING_TWIN_IO_THREAD_NICE=0 (tests/conftest.py), so
the pytest process's own threads must keep their priority."""

from __future__ import annotations

import os
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from service.core.priority import BASE_NICE, ThreadPriority, process_threads, thread_nice

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="per-thread nice is Linux's")


def _now_and_restored() -> tuple[int, int]:
    """(this thread's nice now, the nice a kept thread created now ends with): an earlier test
    in this process may have reniced this thread already; a thread inherits its creator's nice,
    and only root may lower it back to the process's."""
    now = thread_nice(threading.get_native_id())
    return now, (BASE_NICE if os.geteuid() == 0 else now)


class _Parked:
    """A thread that waits until released, with its kernel id."""

    def __init__(self, spawn_child: bool = False):
        self.release = threading.Event()
        self.ready = threading.Event()
        self.child: _Parked | None = None
        self._spawn_child = spawn_child
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()
        assert self.ready.wait(10.0)

    def _run(self) -> None:
        self.release.wait(0.0)
        self.ready.set()
        self.release.wait(30.0)
        if self._spawn_child:
            self.child = _Parked()

    @property
    def tid(self) -> int:
        return self.thread.native_id


def check_every_thread_but_the_kept_ones_gets_the_io_nice_and_new_threads_are_swept():
    now, restored = _now_and_restored()
    io = now + 3
    kept, other = _Parked(), _Parked(spawn_child=True)
    prio = ThreadPriority(lambda: {kept.tid}, io_nice=io, sweep_s=3600.0)
    try:
        assert prio.sweep() >= 1
        assert thread_nice(other.tid) == io
        assert thread_nice(threading.get_native_id()) == io  # this (main) thread too
        assert thread_nice(kept.tid) == restored
        assert prio.sweep() == 0  # each thread once
        # a thread created by a reniced thread inherits its nice (Linux clone semantics)
        other.release.set()
        other.thread.join(10.0)
        assert other.child is not None and thread_nice(other.child.tid) == io
        record = prio.record()
        assert record["active"] and record["io_thread_nice"] == io
        assert record["stepping_thread_nice"] == [restored] and record["errors"] == 0
        assert set(process_threads()) >= {kept.tid, threading.get_native_id()}
    finally:
        kept.release.set()
        if other.child is not None:
            other.child.release.set()


def _named(name: str) -> _Parked:
    """A parked thread whose kernel name (comm) is `name`, like zenoh's transmit threads."""
    t = _Parked()
    with open(f"/proc/self/task/{t.tid}/comm", "w") as f:
        f.write(name)
    return t


def check_zenohs_transmit_threads_keep_the_process_nice():
    """EGRESS_THREAD_NAMES: a thread named like zenoh's transmit threads ("tx-0") stays at (or,
    with the privilege, is brought back to) the process's nice when the sweep gives every other
    thread the I/O nice; a receive thread ("rx-0") is not spared."""
    from service.core.priority import EGRESS_THREAD_NAMES

    now, restored = _now_and_restored()
    io = now + 3
    tx, rx = _named("tx-0"), _named("rx-0")
    prio = ThreadPriority(lambda: set(), io_nice=io, sweep_s=3600.0, keep_names=EGRESS_THREAD_NAMES)
    try:
        prio.sweep()
        assert thread_nice(rx.tid) == io
        assert thread_nice(tx.tid) == restored
        assert prio.record()["egress_threads"] == [restored]
        refused = prio.egress_refused
        # created by a reniced thread it inherits the I/O nice; only the privilege brings it back
        late = _named("tx-1")
        assert thread_nice(late.tid) == io
        prio.sweep()
        assert thread_nice(late.tid) == (restored if os.geteuid() == 0 else io)
        assert prio.egress_refused == refused + (0 if os.geteuid() == 0 else 1)
        late.release.set()
    finally:
        tx.release.set()
        rx.release.set()


def check_io_nice_zero_changes_nothing():
    t = _Parked()
    before = thread_nice(t.tid)
    prio = ThreadPriority(lambda: set(), io_nice=0)
    try:
        assert not prio.active and prio.sweep() == 0 and thread_nice(t.tid) == before
        assert prio.record()["io_thread_nice"] == 0
    finally:
        t.release.set()


def check_a_service_keeps_its_stepping_threads_above_its_other_threads():
    """TwinRegistry.open with the default settings: the pool's stepping threads and publish worker
    at `stepping_thread_nice` (-10), every other thread at `io_thread_nice` (-5: above the load,
    since those threads hold the GIL the stepping threads wait for), both granted to root only;
    /health carries the record."""
    from service.core.registry import TwinRegistry
    from service.settings import ServiceSettings

    now, _ = _now_and_restored()
    io, asked = ServiceSettings().runner.io_thread_nice, ServiceSettings().runner.stepping_thread_nice
    assert io == -5 and asked == -10 and now == BASE_NICE == 0
    raised = asked if os.geteuid() == 0 else now  # a higher priority needs root / CAP_SYS_NICE
    io_got = io if os.geteuid() == 0 else now
    settings = ServiceSettings(enable_zenoh=False, enable_recording=False, start_twin=False, stepping_threads=2)
    reg = TwinRegistry(settings).open()
    try:
        stepping = reg.pool.native_ids()
        assert len(stepping) == 3  # 2 stepping + the publish worker
        for tid in stepping:
            assert thread_nice(tid) == raised
        assert thread_nice(threading.get_native_id()) == io_got
        others = [t for t in process_threads() if t not in stepping]
        assert others and all(thread_nice(t) == io_got for t in others if thread_nice(t) is not None)
        reg.priority.keep_thread(threading.get_native_id())  # the event loop's thread
        assert reg.priority.kept_nice == io and thread_nice(threading.get_native_id()) == io_got
        health = reg.health()["thread_priority"]
        assert health["active"] and health["io_thread_nice"] == io and health["stepping_thread_nice_asked"] == asked
        assert health["stepping_thread_nice"] == [raised]
        assert health["stepping_priority_refused"] == (0 if os.geteuid() == 0 else len(stepping))
    finally:
        reg.close()


def check_a_negative_io_nice_raises_the_io_threads_and_the_event_loop_with_them():
    """io_thread_nice -5 (root): every thread but the stepping ones at -5, the kept thread (the
    event loop) too (kept_nice = min(process nice, io_nice)); unprivileged: refused and counted."""
    from service.core.registry import TwinRegistry
    from service.settings import ServiceSettings

    reg = TwinRegistry(
        ServiceSettings(
            enable_zenoh=False, enable_recording=False, start_twin=False, stepping_threads=1, io_thread_nice=-5
        )
    ).open()
    try:
        stepping = reg.pool.native_ids()
        reg.priority.keep_thread(threading.get_native_id())
        assert reg.priority.kept_nice == -5
        others = [t for t in process_threads() if t not in stepping]
        if os.geteuid() == 0:
            assert all(thread_nice(t) == -5 for t in others if thread_nice(t) is not None)
            assert all(thread_nice(t) == -10 for t in stepping)
            assert reg.priority.errors == 0
        else:
            assert reg.priority.errors > 0
    finally:
        reg.close()


def check_an_open_service_freezes_its_start_up_heap():
    """service.core.heap.freeze_heap at TwinRegistry.open (default gc_freeze): the objects alive
    then are out of the collector's generations (gc.get_freeze_count), objects made later are not."""
    import gc

    from service.core.registry import TwinRegistry
    from service.settings import ServiceSettings

    assert gc.get_freeze_count() == 0
    reg = TwinRegistry(
        ServiceSettings(enable_zenoh=False, enable_recording=False, start_twin=False, gc_freeze=False)
    ).open()
    reg.close()
    assert gc.get_freeze_count() == 0
    reg = TwinRegistry(ServiceSettings(enable_zenoh=False, enable_recording=False, start_twin=False)).open()
    try:
        frozen = gc.get_freeze_count()
        assert frozen > 10_000  # the imported modules at least
        later = [[i] for i in range(1000)]
        assert gc.get_freeze_count() == frozen and gc.is_tracked(later[0])
    finally:
        reg.close()


def _run(check: str) -> None:
    env = {
        k: v
        for k, v in os.environ.items()
        if k not in ("BEARING_TWIN_IO_THREAD_NICE", "BEARING_TWIN_STEPPING_THREAD_NICE", "BEARING_TWIN_GC_FREEZE")
    }
    root = str(Path(__file__).resolve().parents[3])
    env["PYTHONPATH"] = os.pathsep.join([root, *filter(None, [env.get("PYTHONPATH")])])
    code = f"import runpy; runpy.run_path({str(Path(__file__))!r})[{check!r}]()"
    res = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr[-3000:]


def test_every_thread_but_the_kept_ones_gets_the_io_nice_and_new_threads_are_swept():
    _run("check_every_thread_but_the_kept_ones_gets_the_io_nice_and_new_threads_are_swept")


def test_zenohs_transmit_threads_keep_the_process_nice():
    _run("check_zenohs_transmit_threads_keep_the_process_nice")


def test_io_nice_zero_changes_nothing():
    _run("check_io_nice_zero_changes_nothing")


def test_a_service_keeps_its_stepping_threads_above_its_other_threads():
    _run("check_a_service_keeps_its_stepping_threads_above_its_other_threads")


def test_a_negative_io_nice_raises_the_io_threads_and_the_event_loop_with_them():
    _run("check_a_negative_io_nice_raises_the_io_threads_and_the_event_loop_with_them")


def test_an_open_service_freezes_its_start_up_heap():
    _run("check_an_open_service_freezes_its_start_up_heap")
