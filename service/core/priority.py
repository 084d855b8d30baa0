"""The stepping threads before everything else: the service's other threads run at a lower
scheduling priority (Linux thread nice values).

Why. Real time is the stepping threads' job (service.core.pool). On a small host the other
threads of the process (uvicorn's event loop answering a flood of requests, zenoh's runtime, the
rerun recorder, the OPC UA server, the HTTP worker threads) and other processes compete with
them for the same cores, and under the kernel's fair scheduler every runnable thread of equal
nice gets an equal share: a hostile HTTP flood at concurrency 32 took the default twin from
1.00 to 0.46 of real time on the 2-core VM. A real-time system puts its control loop above its
I/O. Here that is the nice value, which Linux keeps per thread: every thread of the process
except the stepping threads and the publish worker (their output is the product: snapshots,
waveform, alarms) gets nice +`io_thread_nice` (CFS weight 110 at nice 10 against 1024 at 0:
about 9 % of a contended core). Raising one's own nice needs no privilege. New threads appear
all the time (a twin's zenoh publisher, a recording's writer, asyncio's executor), so a sweep
every `sweep_s` renices the ones it has not seen yet. A thread inherits the nice of the thread
that creates it, and an unprivileged process cannot lower a nice value again, so the stepping
pool is started before the first sweep (TwinRegistry.open) and its threads are never reniced.

Not done: real-time scheduling classes (SCHED_FIFO / SCHED_RR) for the stepping threads. They
need CAP_SYS_NICE, and a FIFO thread that never sleeps (a twin behind the wall clock steps
without pause) would lock the other threads out of its core on a 2-core host.

Elsewhere than Linux (no per-thread nice) this is a no-op; `/health` says which.
"""

from __future__ import annotations

import logging
import os
import sys
import threading
import weakref
from collections.abc import Callable

log = logging.getLogger(__name__)

TASKS_DIR = "/proc/self/task"


def _process_nice() -> int:
    try:
        return os.getpriority(os.PRIO_PROCESS, os.getpid())
    except (OSError, AttributeError):
        return 0


BASE_NICE = _process_nice()   # the main thread's nice when the service was imported


def thread_nice(native_id: int) -> int | None:
    """The nice value of one thread of this process (Linux), None if it is gone or unknown."""
    try:
        return os.getpriority(os.PRIO_PROCESS, native_id)
    except (OSError, AttributeError):
        return None


def process_threads() -> list[int]:
    """The kernel thread ids of this process (Linux /proc; [] elsewhere)."""
    try:
        return [int(t) for t in os.listdir(TASKS_DIR)]
    except (OSError, ValueError):
        return []


class ThreadPriority:
    """Keeps every thread of the process but `keep()` at nice `io_nice` (module docstring).

    `keep` returns the native ids of the threads left alone (the stepping threads and the publish
    worker); `sweep()` renices the others once (returns how many it changed); `start()` sweeps now
    and then every `sweep_s` [s] in a daemon thread (itself reniced); `close()` stops it."""

    _live: weakref.WeakSet[ThreadPriority] = weakref.WeakSet()   # several services in one process (tests)

    def __init__(self, keep: Callable[[], set[int]], io_nice: int, sweep_s: float = 1.0):
        self.keep = keep
        self.io_nice = int(io_nice)
        self.sweep_s = float(sweep_s)
        self.supported = sys.platform.startswith("linux") and hasattr(os, "setpriority")
        self.reniced = 0                  # threads given io_nice so far
        self.errors = 0                   # setpriority refused (counted, never raised)
        self._seen: set[int] = set()
        self._kept: set[int] = set()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    @property
    def active(self) -> bool:
        return self.supported and self.io_nice > 0

    def sweep(self) -> int:
        """Renice the threads not kept and not seen before; returns the number changed."""
        if not self.active:
            return 0
        keep = self.keep()
        for tid in keep - self._kept:       # created by an already reniced thread (tests): back to
            self._kept.add(tid)             # the process's nice where permitted (root)
            current = thread_nice(tid)
            if current is not None and current > BASE_NICE:
                try:
                    os.setpriority(os.PRIO_PROCESS, tid, BASE_NICE)
                except OSError:
                    pass                    # unprivileged: it keeps the nice it inherited
        spared = set(keep)
        for other in list(ThreadPriority._live):     # another service's stepping threads
            if other is not self:
                spared |= other.keep()
        changed = 0
        tids = process_threads()
        for tid in tids:
            if tid in self._seen or tid in spared:
                continue
            self._seen.add(tid)
            current = thread_nice(tid)
            if current is None or current >= self.io_nice:
                continue
            try:
                os.setpriority(os.PRIO_PROCESS, tid, self.io_nice)
                changed += 1
            except OSError as exc:     # gone meanwhile, or not permitted
                self.errors += 1
                if self.errors <= 3:
                    log.debug("thread %d: nice %d refused: %s", tid, self.io_nice, exc)
        self._seen.intersection_update(tids)    # ids are reused after a thread ends
        self.reniced += changed
        return changed

    def start(self) -> ThreadPriority:
        if not self.active or self._thread is not None:
            return self
        ThreadPriority._live.add(self)
        self.sweep()
        self._thread = threading.Thread(target=self._run, name="thread-priority", daemon=True)
        self._thread.start()
        log.debug("stepping threads at nice %s, the service's other threads at nice %d",
                 sorted({thread_nice(t) for t in self.keep()} - {None}), self.io_nice)
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
        """For /health: whether it acts, the nice values, the counts."""
        return {"active": self.active, "io_thread_nice": self.io_nice if self.active else 0,
                "stepping_thread_nice": sorted({thread_nice(t) for t in self.keep()} - {None}),
                "threads_reniced": self.reniced, "errors": self.errors}
