"""The stepping threads before everything else: they run at a higher scheduling priority than the
service's other threads and the host's other processes (Linux thread nice values).

Why. Real time is the stepping threads' job (service.core.pool). On a small host the other
threads of the process (uvicorn's event loop answering a flood of requests, zenoh's runtime, the
rerun recorder, the OPC UA server, the HTTP worker threads) and other processes compete with
them for the same cores, and under the kernel's fair scheduler every runnable thread of equal
nice gets an equal share, so a hostile HTTP flood takes real time from the twins (the `attack`
tool measures it; docs/operations.md). A real-time system puts its control loop above its I/O.
Here that is the nice value, which Linux keeps per thread:

- the stepping threads and the publish worker (their output is the product: snapshots, waveform,
  alarms) get nice `stepping_thread_nice` (-10: CFS weight 9548 against 1024 at nice 0, about
  90 % of a core contended with one other thread) where the process may raise a priority (root
  or CAP_SYS_NICE, e.g. systemd's `AmbientCapabilities=CAP_SYS_NICE`); elsewhere they keep the
  process's nice and `/health` says so. An attacker on the same host (the `attack` tool's own
  processes) or any other busy process then cannot take their core;
- every other thread of the process (the HTTP event loop, zenoh's runtime and callbacks, the
  recorder, the OPC UA server, the HTTP worker threads) gets nice `io_thread_nice` (-5: between
  the stepping threads and the host's other processes; CFS weight 3121). Two kinds are kept at
  `kept_nice`, the lower (higher-priority) of io_thread_nice and the process's nice: the HTTP
  event loop (`keep_thread`: /health answers in time) and zenoh's transmit threads
  (`EGRESS_THREAD_NAMES`: "tx-0", "tx-1", ... by their kernel name), which write the state
  messages to the links. With io_thread_nice set above the process's nice, that keeps them from
  waiting behind every other process (a tx thread behind the host's load delays every state
  message on its link: `bench-service` measures the put -> client latency). A tx thread is
  made when a link opens, by a zenoh thread already at io_thread_nice, so bringing it back to a
  lower nice needs the same privilege as raising the stepping threads (counted in
  `egress_priority_refused`). New threads appear all the time (a twin's zenoh publisher, a
  recording's writer, asyncio's executor), so a sweep every `sweep_s` renices the ones it has not
  seen yet. A thread inherits the nice of the thread that creates it, so the stepping pool is
  started before the first sweep
  (TwinRegistry.open).

Why the I/O threads are above the load and not below it. The stepping threads need the GIL for
the Python between frames, and whoever holds the GIL when they ask is an I/O thread (the event
loop, a zenoh callback, the zenoh publisher). A thread at a nice above the host's other
processes' (an attacker on the same host, like the `attack` tool's own processes, or any busy
process) gets a fraction of their CPU share (a tenth at nice 10 against 0): preempted while
holding the GIL, it keeps every stepping thread waiting for as long as the kernel leaves it off
the CPU (priority inversion; the GIL has no priority inheritance). `attack` measures the
real-time factor under a flood with each setting (docs/operations.md). The I/O work they can do
is bounded by the per-client budgets and the tarpit (service.api.middleware), so their priority
does not let a flood take more than the budgets allow; the stepping threads (-10, weight 9548)
still come first. Raising a priority needs root or CAP_SYS_NICE; without it these threads keep
the process's nice (counted in `errors`).

Not done: real-time scheduling classes (SCHED_FIFO / SCHED_RR) for the stepping threads. A FIFO
thread that never sleeps (a twin behind the wall clock steps without pause) would lock every
other thread out of its core on a 2-core host; a nice value only weights the fair share.

Elsewhere than Linux (no per-thread nice) this is a no-op; `/health` says which.
"""

from __future__ import annotations

import logging
import os
import re
import sys
import threading
import weakref
from collections.abc import Callable, Iterable
from typing import ClassVar

log = logging.getLogger(__name__)

TASKS_DIR = "/proc/self/task"

#: zenoh's transmit threads (the kernel names zenoh's runtime gives its "tx" pool), kept at
#: `ThreadPriority.kept_nice` (module docstring)
EGRESS_THREAD_NAMES = re.compile(r"^tx-\d+$")


def _process_nice() -> int:
    try:
        return os.getpriority(os.PRIO_PROCESS, os.getpid())
    except (OSError, AttributeError):
        return 0


BASE_NICE = _process_nice()  # the main thread's nice when the service was imported


def thread_nice(native_id: int) -> int | None:
    """The nice value of one thread of this process (Linux), None if it is gone or unknown."""
    try:
        return os.getpriority(os.PRIO_PROCESS, native_id)
    except (OSError, AttributeError):
        return None


def _nice_values(native_ids: Iterable[int]) -> list[int]:
    """The distinct known nice values of these threads, ascending."""
    return sorted({n for n in map(thread_nice, native_ids) if n is not None})


def thread_name(native_id: int) -> str | None:
    """The kernel name (comm) of one thread of this process (Linux), None if gone or unknown."""
    try:
        with open(f"{TASKS_DIR}/{native_id}/comm") as f:
            return f.read().strip()
    except OSError:
        return None


def process_threads() -> list[int]:
    """The kernel thread ids of this process (Linux /proc; [] elsewhere)."""
    try:
        return [int(t) for t in os.listdir(TASKS_DIR)]
    except (OSError, ValueError):
        return []


class ThreadPriority:
    """Stepping threads at `stepping_nice`, kept threads at `kept_nice`, every other thread of the
    process at `io_nice` (module docstring).

    `keep` returns the native ids of the stepping threads and the publish worker; `keep_thread`
    adds one kept at `kept_nice` (the event loop); threads whose kernel name matches `keep_names`
    (zenoh's transmit threads: EGRESS_THREAD_NAMES) are put at `kept_nice` too; `sweep()`
    renices the threads it has not seen (returns how many it changed); `start()` sweeps now and
    then every `sweep_s` [s] in a daemon thread (itself reniced); `close()` stops it."""

    _live: ClassVar[weakref.WeakSet[ThreadPriority]] = weakref.WeakSet()  # several services in one process (tests)

    def __init__(
        self,
        keep: Callable[[], set[int]],
        io_nice: int,
        stepping_nice: int = 0,
        sweep_s: float = 1.0,
        keep_names: re.Pattern | None = None,
    ):
        self.keep = keep
        self.keep_names = keep_names
        self.io_nice = int(io_nice)
        self.stepping_nice = int(stepping_nice)
        self.sweep_s = float(sweep_s)
        self.supported = sys.platform.startswith("linux") and hasattr(os, "setpriority")
        self.reniced = 0  # threads given io_nice so far
        self.errors = 0  # io_nice refused (counted, never raised)
        self.raise_refused = 0  # stepping_nice refused: no CAP_SYS_NICE (counted)
        self.egress_refused = 0  # a keep_names thread could not be brought back (no CAP_SYS_NICE)
        self._named: set[int] = set()  # threads kept by their name
        self._seen: set[int] = set()  # threads given io_nice (or found at it)
        self._placed: set[int] = set()  # stepping and kept threads already placed
        self._extra: set[int] = set()  # keep_thread
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    @property
    def active(self) -> bool:
        return self.supported and (self.io_nice != BASE_NICE or self.stepping_nice < BASE_NICE)

    @property
    def kept_nice(self) -> int:
        """The nice of a kept thread (the event loop): the process's, or io_nice when that is lower
        (a higher priority)."""
        return min(BASE_NICE, self.io_nice)

    def keep_thread(self, native_id: int) -> None:
        """Keep this thread at `kept_nice` (the HTTP event loop: /health answers in time)."""
        self._extra.add(native_id)
        self._seen.discard(native_id)
        self._placed.discard(native_id)
        if self.active:
            self._place(native_id, self.kept_nice)

    def _place(self, tid: int, nice: int) -> None:
        current = thread_nice(tid)
        if current is None or current == nice:
            return
        try:
            os.setpriority(os.PRIO_PROCESS, tid, nice)
        except OSError:  # a higher priority needs CAP_SYS_NICE: keeps its own
            self.raise_refused += 1

    def sweep(self) -> int:
        """Place the stepping and kept threads not placed yet; renice the other threads not seen
        before to io_nice; returns the number reniced."""
        if not self.active:
            return 0
        stepping = self.keep()
        for tid in stepping - self._placed:
            self._placed.add(tid)
            self._place(tid, self.stepping_nice)
        for tid in self._extra - self._placed:
            self._placed.add(tid)
            self._place(tid, self.kept_nice)
        spared = stepping | self._extra
        for other in list(ThreadPriority._live):  # another service's stepping threads
            if other is not self:
                spared |= other.keep() | other._extra
        changed = 0
        tids = process_threads()
        for tid in tids:
            if tid in self._seen or tid in spared:
                continue
            self._seen.add(tid)
            if self.keep_names is not None and self.keep_names.match(thread_name(tid) or ""):
                self._keep_named(tid)
                continue
            current = thread_nice(tid)
            if current is None or current == self.io_nice:
                continue
            try:
                os.setpriority(os.PRIO_PROCESS, tid, self.io_nice)
                changed += 1
            except OSError as exc:  # gone meanwhile, or not permitted
                self.errors += 1
                if self.errors <= 3:
                    log.debug("thread %d: nice %d refused: %s", tid, self.io_nice, exc)
        live = set(tids)
        self._seen &= live  # ids are reused after a thread ends
        self._placed &= live
        self._named &= live
        self.reniced += changed
        return changed

    def _keep_named(self, tid: int) -> None:
        """A thread matching keep_names: at `kept_nice` (it inherited its creator's nice)."""
        self._named.add(tid)
        current = thread_nice(tid)
        if current is None or current == self.kept_nice:
            return
        try:
            os.setpriority(os.PRIO_PROCESS, tid, self.kept_nice)
        except OSError:  # lowering a nice value needs CAP_SYS_NICE
            self.egress_refused += 1

    def start(self) -> ThreadPriority:
        if not self.active or self._thread is not None:
            return self
        ThreadPriority._live.add(self)
        self.sweep()
        self._thread = threading.Thread(target=self._run, name="thread-priority", daemon=True)
        self._thread.start()
        log.debug(
            "stepping threads at nice %s, the service's other threads at nice %d",
            _nice_values(self.keep()),
            self.io_nice,
        )
        return self

    def _run(self) -> None:
        while not self._stop.wait(self.sweep_s):
            try:
                self.sweep()
            except Exception:  # noqa: BLE001 - a priority sweep never stops the service
                self.errors += 1

    def close(self) -> None:
        ThreadPriority._live.discard(self)
        self._stop.set()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(2.0)

    def record(self) -> dict:
        """For /health: whether it acts, the nice values asked and found, the counts."""
        return {
            "active": self.active,
            "io_thread_nice": self.io_nice if self.active else 0,
            "stepping_thread_nice_asked": self.stepping_nice if self.active else BASE_NICE,
            "stepping_thread_nice": _nice_values(self.keep()),
            "threads_reniced": self.reniced,
            "errors": self.errors,
            "stepping_priority_refused": self.raise_refused,
            "egress_threads": _nice_values(self._named),
            "egress_priority_refused": self.egress_refused,
        }
