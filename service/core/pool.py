"""The stepping pool: a few threads advance every twin of a service frame by frame, earliest
deadline first, and one publishing thread turns what they captured into snapshots.

Why. One thread per twin makes N twins fight for the GIL and the cores: each thread needs the
GIL between its frames, and the more threads there are the longer each waits for it behind the
others, the zenoh, rerun and HTTP threads. The engine's `step_n` releases the GIL
(`@njit(nogil=True)`), so a frame of a twin runs in parallel with anything else; what needs the
GIL is the Python between frames (mailbox, scenario, pacing: tens of microseconds) and building
snapshots (about 0.2 ms each right after the frame). So: as many stepping threads as cores
(`workers`), each running one frame of one twin at a time; frames long enough (20 ms of simulated
time by default in the service) that the Python and the thread wake-up between them are a small
share. In real time the stepping thread builds the frame's snapshot itself (a hand-off to
another thread costs more than the build, service.core.publishing); in fast mode the snapshots
are built and delivered by one `PublishWorker` thread while the twins step on.

Scheduling (earliest deadline first, `EdfQueue`). Each twin is a job with a RELEASE time (wall
clock: when its next frame may start; in real time, the wall-clock time its simulated clock has
reached) and a DEADLINE (when that frame should have ended: release + frame length). A free
stepping thread takes, among the released jobs, the one with the earliest deadline, runs ONE
frame of it (`Steppable.step(now)`, which returns the next `Schedule`, or None when the twin
stops), puts it back and takes the next. A twin behind the wall clock has the earliest deadline,
so twins that cannot all keep up fall behind together rather than one starving. Jobs without a
deadline (fast mode) run round robin after every released real-time job. A job is held by at
most one thread at a time: its twin's state has one writer at any moment (which thread that is
may change from frame to frame). `wake(job)` releases a waiting job now (a setpoint arrived, a
scenario started, the twin is asked to stop); `wake(job, urgent=True)` also gives the frame it
releases the deadline "now", so it goes before the released frames of twins that only keep their
pace (an outside setpoint: with three twins on two stepping threads its wait for a thread, the
`apply` stage of the setpoint latency, is otherwise up to a frame of each other twin).

Wake-ups. A thread that puts a job back is free at once and itself waits for the earliest
release (or takes a released job), so putting back wakes nobody; a thread that takes a job
while other jobs wait wakes one free thread, which takes over the timer of the next release.
Every waiting job so has a free thread timing it whenever one is free, and the free threads do
not all wake at every frame: one free thread at a time waits with a timeout, for the earliest
release (`_timer`), the others until they are notified (with one twin and two stepping threads,
the idle one sleeps until a second job arrives; two timed waiters for one release cost two
wake-ups per frame, about 0.1 ms of CPU each on the 2-core VMs). A thread whose put-back job is
released before the timed release times it as well. `add` and `wake` wake one free thread (it
takes the released job, or times the next release; the thread it takes a job from hands the
timing on as above); `close` wakes every thread.

The queue is plain data (no threads, no clock): the tests drive it with a fake clock.
"""

from __future__ import annotations

import heapq
import itertools
import logging
import math
import queue
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol

log = logging.getLogger(__name__)

__all__ = ["EdfQueue", "Job", "PublishWorker", "Schedule", "Steppable", "SteppingPool"]


@dataclass(frozen=True)
class Schedule:
    """When a job's next frame may start (`release`) and should end (`deadline`) [wall-clock s];
    `deadline = inf`: no deadline (fast mode, idle polling)."""

    release: float
    deadline: float = math.inf


class Steppable(Protocol):
    """What the pool runs: one frame per `step` call."""

    @property
    def name(self) -> str: ...

    def step(self, now: float) -> Schedule | None:
        """Run one frame (or one idle poll); return when to run next, None to leave the pool."""

    def left_pool(self) -> None:
        """Called once, from the stepping thread, after `step` returned None (or raised)."""


@dataclass(eq=False)
class Job:
    """One twin in the pool (see the module docstring)."""

    task: Steppable
    release: float = 0.0
    deadline: float = math.inf
    state: str = "waiting"  # waiting | ready | running | done
    gen: int = 0  # heap entries of older generations are stale
    wake_pending: bool = False  # woken while running: release at once when put back
    wake_deadline: float = math.inf  # woken urgently while running: the deadline of its next frame
    frames: int = 0  # steps run (for the tests and the accounting)
    done: threading.Event = field(default_factory=threading.Event)

    @property
    def name(self) -> str:
        return getattr(self.task, "name", repr(self.task))


class EdfQueue:
    """Jobs waiting for their release time (a heap by release) and released jobs (a heap by
    deadline, then by arrival: equal deadlines go round robin). No threads, no clock."""

    def __init__(self) -> None:
        self._waiting: list[tuple[float, int, int, Job]] = []
        self._ready: list[tuple[float, int, int, Job]] = []
        self._order = itertools.count()
        self.jobs: set[Job] = set()

    def __len__(self) -> int:
        return len(self.jobs)

    def put(self, job: Job, schedule: Schedule) -> None:
        """(Re)schedule a job that no thread is running."""
        job.gen += 1
        job.release, job.deadline = schedule.release, schedule.deadline
        job.state = "waiting"
        self.jobs.add(job)
        heapq.heappush(self._waiting, (job.release, next(self._order), job.gen, job))

    def remove(self, job: Job) -> None:
        job.gen += 1
        job.state = "done"
        self.jobs.discard(job)

    def wake(self, job: Job, now: float, deadline: float = math.inf) -> bool:
        """Release a waiting job now, its deadline brought forward to `deadline` when that is
        earlier (a released job not yet taken is moved up the same way). Returns whether it was
        released or moved up."""
        if job.state == "waiting" and job.release > now:
            self.put(job, Schedule(now, min(job.deadline, deadline)))
            return True
        if job.state in ("waiting", "ready") and deadline < job.deadline:
            self.put(job, Schedule(min(job.release, now), deadline))
            return True
        return False

    def _release_due(self, now: float) -> None:
        w = self._waiting
        while w and w[0][0] <= now:
            _, _, gen, job = heapq.heappop(w)
            if gen == job.gen and job.state == "waiting":
                job.state = "ready"
                heapq.heappush(self._ready, (job.deadline, next(self._order), job.gen, job))

    def take(self, now: float) -> Job | None:
        """The released job with the earliest deadline (now running), or None."""
        self._release_due(now)
        r = self._ready
        while r:
            _, _, gen, job = heapq.heappop(r)
            if gen == job.gen and job.state == "ready":
                job.state = "running"
                return job
        return None

    def next_release(self) -> float | None:
        """The earliest release time of a waiting job (None: none waits)."""
        w = self._waiting
        while w and (w[0][2] != w[0][3].gen or w[0][3].state != "waiting"):
            heapq.heappop(w)
        if self._ready:
            return -math.inf
        return w[0][0] if w else None


class PublishWorker:
    """One thread that runs, in order, what the stepping threads hand it (building snapshots and
    calling the sinks). FIFO: the snapshots of one twin keep their order."""

    def __init__(self, name: str = "publish"):
        self.name = name
        self._queue: queue.SimpleQueue[Callable[[], object] | None] = queue.SimpleQueue()
        self._thread: threading.Thread | None = None
        self._lock = threading.Lock()
        self._closed = False

    @property
    def alive(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    @property
    def thread_name(self) -> str | None:
        return self._thread.name if self._thread is not None else None

    @property
    def native_id(self) -> int | None:
        """Kernel thread id of the worker thread (None before it starts)."""
        return self._thread.native_id if self._thread is not None else None

    def start(self) -> None:
        with self._lock:
            if self._thread is None and not self._closed:
                self._thread = threading.Thread(target=self._run, name=self.name, daemon=True)
                self._thread.start()

    def submit(self, fn: Callable[[], object]) -> bool:
        """Queue `fn`; False (not queued) when the worker is not running: run it yourself."""
        if not self.alive or self._closed:
            return False
        self._queue.put(fn)
        return True

    def close(self, timeout: float = 5.0) -> bool:
        """Run what is queued, then stop. Returns whether the thread ended within the timeout."""
        with self._lock:
            self._closed = True
            thread = self._thread
        if thread is None:
            return True
        self._queue.put(None)
        thread.join(timeout)
        return not thread.is_alive()

    def _run(self) -> None:
        while True:
            fn = self._queue.get()
            if fn is None:
                return
            try:
                fn()
            except Exception:
                log.exception("publish worker: a task failed")


class SteppingPool:
    """`workers` stepping threads running `Steppable` jobs earliest deadline first, plus one
    `PublishWorker` (see the module docstring). Thread-safe; `start` / `close` idempotent."""

    def __init__(self, workers: int = 1, *, name: str = "step", clock: Callable[[], float] = time.perf_counter):
        if workers < 1:
            raise ValueError(f"workers = {workers!r}: at least 1 stepping thread")
        self.workers = int(workers)
        self.name = name
        self.clock = clock
        self.publisher = PublishWorker(name=f"{name}-publish")
        self._queue = EdfQueue()
        self._cond = threading.Condition()
        self._timer: tuple[float, int] | None = None  # (release, thread) a free thread waits for
        self._threads: list[threading.Thread] = []
        self._started = False
        self._closing = False

    @property
    def thread_names(self) -> list[str]:
        return [t.name for t in self._threads]

    def native_ids(self) -> set[int]:
        """Kernel thread ids of the stepping threads and the publish worker (started ones)."""
        ids = [t.native_id for t in self._threads] + [self.publisher.native_id]
        return {i for i in ids if i is not None}

    def start(self) -> SteppingPool:
        with self._cond:
            if self._started or self._closing:
                return self
            self._started = True
            self.publisher.start()
            for i in range(self.workers):
                t = threading.Thread(target=self._work, name=f"{self.name}-{i}", daemon=True)
                self._threads.append(t)
                t.start()
        return self

    def add(self, task: Steppable, release: float | None = None) -> Job:
        """Schedule a job (released now unless `release` is given); starts the pool if needed.
        Its first step is due at its release: without a deadline it would come after every
        released real-time job, so in an overloaded pool, whose twins are always released,
        a twin created later would never run its first frame."""
        self.start()
        job = Job(task)
        with self._cond:
            if self._closing:
                raise RuntimeError("the stepping pool is closed")
            at = self.clock() if release is None else release
            self._queue.put(job, Schedule(at, at))
            self._cond.notify()  # one free thread takes it or times it
        return job

    def wake(self, job: Job | None, *, urgent: bool = False) -> None:
        """Release a waiting job now; a running one is released as soon as it is put back.
        `urgent`: the frame it releases is due now (earliest deadline first: before the frames
        of the twins that only keep their pace)."""
        if job is None:
            return
        with self._cond:
            now = self.clock()
            if job.state == "running":
                job.wake_pending = True
                if urgent:
                    job.wake_deadline = min(job.wake_deadline, now)
            elif self._queue.wake(job, now, now if urgent else math.inf):
                self._cond.notify()  # one free thread takes it

    def close(self, timeout: float = 5.0) -> bool:
        """Stop the stepping threads (jobs still in the pool are dropped without `left_pool`;
        stop the twins first), then the publish worker after what it holds."""
        with self._cond:
            self._closing = True
            self._cond.notify_all()
            threads = list(self._threads)
        deadline = time.monotonic() + timeout
        ok = True
        for t in threads:
            t.join(max(0.0, deadline - time.monotonic()))
            ok = ok and not t.is_alive()
        return self.publisher.close(max(0.1, deadline - time.monotonic())) and ok

    def _work(self) -> None:
        cond, q = self._cond, self._queue
        me = threading.get_ident()
        while True:
            with cond:
                while True:
                    if self._closing:
                        return
                    now = self.clock()
                    job = q.take(now)
                    if job is not None:
                        job.wake_pending, job.wake_deadline = False, math.inf
                        if q.next_release() is not None:
                            cond.notify()  # another job waits: one free thread takes over its timer
                        break
                    nxt = q.next_release()
                    timer = self._timer
                    if nxt is not None and (timer is None or nxt < timer[0]):
                        self._timer = (nxt, me)  # this thread times the next release
                        cond.wait(max(0.0, nxt - now))
                    else:  # nothing to time, or another free thread times it already
                        cond.wait()
                    if self._timer is not None and self._timer[1] == me:
                        self._timer = None
            schedule: Schedule | None = None
            try:
                schedule = job.task.step(self.clock())
            except Exception:
                log.exception("stepping pool: job %s failed and leaves the pool", job.name)
            job.frames += 1
            with cond:
                if schedule is None:
                    q.remove(job)
                else:
                    if job.wake_pending:
                        schedule = Schedule(
                            min(schedule.release, self.clock()), min(schedule.deadline, job.wake_deadline)
                        )
                        job.wake_pending, job.wake_deadline = False, math.inf
                    q.put(job, schedule)  # this thread is free again and times it: no wake-up
            if schedule is None:
                try:
                    job.task.left_pool()
                except Exception:
                    log.exception("stepping pool: %s left the pool with an error", job.name)
                job.done.set()
