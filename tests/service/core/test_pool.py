"""The stepping pool (service.core.pool), the lateness accounting (service.core.pacing) and the
admission by measured capacity (service.core.capacity, the registry's 503).

The scheduler's ordering and accounting are checked with a fake clock and fake twins (a discrete
event simulation of the pool's rule: a free stepping thread takes the released job with the
earliest deadline); the threaded pool with fake jobs and bounded waits; the admission with given
costs. No wall-clock threshold anywhere."""

from __future__ import annotations

import heapq
import math
import threading
import time

import pytest

from loadtest.attack_watchers import ADMISSION_REFUSAL
from service.core.capacity import (
    OVERHEAD_GOAL,
    Capacity,
    CpuMeter,
    ServiceOverheadMeter,
    TwinCost,
    calibrate,
    expected_engine_cost,
    mean_engine_cost,
)
from service.core.errors import InputError
from service.core.pacing import PacingClock
from service.core.pool import EdfQueue, Job, Schedule, SteppingPool

WAIT_S = 30.0


class _Named:
    def __init__(self, name):
        self.name = name


def _job(name):
    return Job(_Named(name))


# ---- EdfQueue: the ordering ----------------------------------------------------------------------
def test_released_job_with_the_earliest_deadline_goes_first():
    q = EdfQueue()
    a, b, c, d = (_job(n) for n in "abcd")
    q.put(a, Schedule(release=0.000, deadline=0.010))
    q.put(b, Schedule(release=0.000, deadline=0.006))
    q.put(c, Schedule(release=0.004, deadline=0.005))  # earliest deadline, not yet released
    q.put(d, Schedule(release=0.000))  # no deadline (fast mode): after the others
    assert q.take(0.001) is b
    assert q.take(0.001) is a
    assert q.take(0.001) is d
    assert q.take(0.001) is None
    assert q.next_release() == pytest.approx(0.004)
    assert q.take(0.004) is c
    assert q.next_release() is None


def test_jobs_without_deadline_go_round_robin():
    q = EdfQueue()
    jobs = [_job(n) for n in "abc"]
    for j in jobs:
        q.put(j, Schedule(0.0))
    order = []
    for _ in range(9):
        j = q.take(1.0)
        order.append(j.task.name)
        q.put(j, Schedule(1.0))  # back at the end of the line
    assert "".join(order) == "abcabcabc"


def test_wake_releases_a_waiting_job_now_and_stale_entries_are_ignored():
    q = EdfQueue()
    a, b = _job("a"), _job("b")
    q.put(a, Schedule(release=0.050, deadline=0.055))
    q.put(b, Schedule(release=0.010, deadline=0.015))
    assert q.take(0.001) is None
    assert q.wake(a, 0.001)  # a setpoint arrived: released now, deadline kept
    assert not q.wake(a, 0.001)  # already released
    assert q.take(0.001) is a
    assert not q.wake(a, 0.002)  # running: nothing to release
    q.put(a, Schedule(release=0.020, deadline=0.025))
    assert q.take(0.012) is b
    assert q.take(0.012) is None  # a's old entry (release 0.050) is stale, its new one waits
    assert q.next_release() == pytest.approx(0.020)
    q.remove(a)
    assert q.take(1.0) is None and q.next_release() is None


# ---- the pool's rule with a fake clock and fake twins ---------------------------------------------
class FakeTwin:
    """A twin whose frame of `frame_s` simulated seconds costs `cost_s` wall seconds, paced by the
    real PacingClock on the simulation's clock."""

    def __init__(self, name, frame_s, cost_s, clock, lateness_s=0.005):
        self.name, self.frame_s, self.cost_s = name, frame_s, cost_s
        self.sim_s = 0.0
        self.pacing = PacingClock(fast=False, publish_period_s=0.02, clock=clock, lateness_s=lateness_s)
        self.pacing.start(0.0)
        self.frames = 0

    def run(self, now):
        """One frame started at `now`: (its end, the schedule of the next)."""
        end = now + self.cost_s
        self.sim_s += self.frame_s
        self.frames += 1
        self.pacing.measure(end, self.sim_s)
        release = self.pacing.frame_done(end, self.sim_s)
        return end, Schedule(release, release + self.frame_s)


def simulate(twins, workers, until, joins=()):
    """Discrete event simulation of `workers` stepping threads under the pool's rule; `joins`:
    (wall time, twin) added to the pool then (a twin created while the others run)."""
    clock = {"now": 0.0}
    q = EdfQueue()
    for t in twins:
        q.put(Job(t), Schedule(0.0, t.frame_s))
    joins = sorted(joins, key=lambda jt: jt[0])
    running = []  # heap of (end, n, job, schedule)
    n = 0
    now = 0.0
    while now < until:
        clock["now"] = now
        while joins and joins[0][0] <= now:
            t_join, t = joins.pop(0)
            t.pacing.start(t_join)
            q.put(Job(t), Schedule(t_join, t_join + t.frame_s))
        while running and running[0][0] <= now:
            _, _, job, sched = heapq.heappop(running)
            q.put(job, sched)
        while len(running) < workers:
            job = q.take(now)
            if job is None:
                break
            end, sched = job.task.run(now)
            n += 1
            heapq.heappush(running, (end, n, job, sched))
        nexts = [running[0][0]] if running else []
        if joins:
            nexts.append(joins[0][0])
        nr = q.next_release()
        if nr is not None and len(running) < workers:
            nexts.append(max(nr, now))
        now = min(nexts)
    return twins


def _fake_twins(costs, frame_s=0.005):
    clock = {"now": 0.0}
    return [FakeTwin(f"t{i}", frame_s, c, lambda: clock["now"]) for i, c in enumerate(costs)]


def test_twins_within_capacity_are_never_late():
    # 4 twins of 0.8 of a core each (4 ms of work per 5 ms frame) on 4 threads; 3 twins of 0.6 on 2
    for costs, workers in (([0.004] * 4, 4), ([0.003] * 3, 2)):
        twins = simulate(_fake_twins(costs), workers, until=2.0)
        for t in twins:
            assert t.pacing.overruns == 0 and t.pacing.late_fraction == 0.0
            assert t.sim_s == pytest.approx(2.0, abs=2 * t.frame_s)  # real time: no more, no less
            assert t.pacing.real_time_factor == pytest.approx(1.0, abs=0.01)


def test_overloaded_twins_fall_behind_together():
    # 3 twins of 0.8 of a core on 2 threads: 2.4 cores of work on 2. Earliest deadline first keeps
    # them level (the one furthest behind goes next): each runs at 2 / 2.4 of real time, none starves.
    twins = simulate(_fake_twins([0.004] * 3), 2, until=3.0)
    sims = [t.sim_s for t in twins]
    assert max(sims) - min(sims) <= 0.005 + 1e-12  # within one frame of each other
    for t in twins:
        assert t.sim_s / 3.0 == pytest.approx(2.0 / 2.4, abs=0.02)
        assert t.pacing.late_fraction > 0.5  # and they say so
    # a twin alone on a thread beside them would have been on time: the pool, not the twin, is full


def test_a_twin_added_to_an_overloaded_pool_gets_its_share():
    # 3 twins of 0.8 of a core on 2 threads, each behind the wall clock; a 4th joins at 1 s. Its
    # first deadline (join + one frame) is later than theirs (in the past, up to the pacing's
    # resync_after_s), so by deadline alone it would wait until they re-anchor. A released job is
    # queued by max(deadline, release time): late jobs share round robin, the newcomer included.
    # 4 x 0.8 = 3.2 cores of work on 2: each should run at 2 / 3.2 = 0.625 of real time.
    twins = _fake_twins([0.004] * 3)
    late = _fake_twins([0.004])[0]
    late.name = "late"
    simulate(twins, 2, until=3.0, joins=[(1.0, late)])
    assert late.frames > 0
    assert late.sim_s / 2.0 == pytest.approx(2.0 / 3.2, abs=0.05)  # its share from its first second on
    for t in twins:  # and theirs after it joined
        assert t.sim_s == pytest.approx(1.0 * 2.0 / 2.4 + 2.0 * 2.0 / 3.2, abs=0.05)


def test_lateness_counts_frames_ending_beyond_it_not_every_microsecond():
    clock = {"now": 0.0}
    p = PacingClock(fast=False, publish_period_s=0.02, clock=lambda: clock["now"], lateness_s=0.005, late_window_s=10.0)
    p.start(0.0)
    assert p.late_fraction is None
    # frames of 5 ms ending 1 us, 4.9 ms and 6 ms after their deadline
    assert p.frame_done(0.005 + 1e-6, 0.005) == pytest.approx(0.005 + 1e-6)  # behind: next at once
    p.frame_done(0.010 + 0.0049, 0.010)
    assert p.overruns == 0 and p.late_fraction == 0.0
    p.frame_done(0.015 + 0.006, 0.015)
    assert p.overruns == 1 and p.late_fraction == pytest.approx(1 / 3)
    # ahead of the wall clock: the next frame is released at the deadline
    assert p.frame_done(0.017, 0.020) == pytest.approx(0.020)
    assert p.late_fraction == pytest.approx(1 / 4)
    # the window forgets frames older than 10 s of wall time
    p.reanchor(0.020, at=20.0)
    p.frame_done(20.005, 0.025)
    assert p.late_fraction == 0.0 and p.overruns == 1
    # more than resync_after_s behind: re-anchored, counted
    p.frame_done(20.5, 0.030)
    assert p.resyncs == 1 and p.frame_done(20.5, 0.030) == pytest.approx(20.5)


def test_a_lead_releases_frames_before_the_wall_clock_and_absorbs_a_stall():
    """service.core.pacing lead_s: the next frame is released lead_s before the wall clock reaches
    its start, so a 5 ms frame that took 3.4 ms and then waited 8 ms (a GIL or CPU stall) ends
    within the lateness instead of 8 - 1.6 = 6.4 ms behind."""
    for lead, late in ((0.0, 1), (0.005, 0)):
        clock = {"now": 0.0}
        p = PacingClock(
            fast=False, publish_period_s=0.02, clock=lambda c=clock: c["now"], lateness_s=0.005, lead_s=lead
        )
        p.start(0.0)
        release = p.frame_done(0.0034, 0.005)  # 5 ms of simulated time in 3.4 ms
        assert release == pytest.approx(max(0.0034, 0.005 - lead))  # never before now
        p.frame_done(release + 0.0034 + 0.008, 0.010)  # the next frame, started at its release, stalls 8 ms
        assert p.overruns == late, lead
    with pytest.raises(ValueError, match="lead_s"):
        PacingClock(fast=False, publish_period_s=0.02, clock=lambda: 0.0, lead_s=-1.0)


def test_a_setpoint_is_published_at_the_end_of_its_frame_even_right_after_a_tick():
    """service.core.pacing: the state carrying a fresh setpoint goes out at the end of the frame
    that applied it, not one frame later because a regular 50 Hz tick went out less than
    setpoint_publish_min_interval_s before; that interval still spaces the setpoint
    publications themselves (a closer one is deferred, not dropped); a setpoint's publication
    stands for the period's tick: the next tick is one period after it."""
    p = PacingClock(fast=False, publish_period_s=0.02, clock=lambda: 0.0, setpoint_publish_min_interval_s=0.002)
    p.start(0.0)
    assert not p.publish_due(0.019, 0.019, False)
    assert p.publish_due(0.020, 0.020, False)  # the tick
    p.published(0.020, 0.020)
    assert p.publish_due(0.0205, 0.0205, True)  # a setpoint frame 0.5 ms after it: at once
    p.published(0.0205, 0.0205)
    assert not p.publish_due(0.021, 0.021, True)  # another, 0.5 ms later: deferred
    assert not p.publish_due(0.022, 0.022, False)
    assert p.publish_due(0.0226, 0.0226, False)  # ... to the first frame 2 ms after the last
    p.published(0.0226, 0.0226)
    assert not p.publish_due(0.030, 0.030, False)
    assert not p.publish_due(0.0425, 0.0425, False)  # no tick 20 ms after the tick at 0.020 ...
    assert p.publish_due(0.0426, 0.0426, False)  # ... but 20 ms after the setpoint's publication
    p.published(0.0426, 0.0426)
    assert not p.publish_due(0.0625, 0.0625, False)
    assert p.publish_due(0.0626, 0.0626, False)  # and on that grid from then on


def test_a_tick_waits_for_an_input_frame_at_most_two_periods_after_the_last_publication():
    """service.core.pacing ("Publishing"): the tick due at the end of a frame an outside input cut
    short may wait for the input's frame while the last publication (the initial snapshot at
    the start counts) is less than two periods old; never in fast mode."""
    now = {"t": 0.0}
    p = PacingClock(fast=False, publish_period_s=0.02, clock=lambda: now["t"])
    p.start(0.0, published=True)
    assert p.tick_may_wait(0.0399) and not p.tick_may_wait(0.0401)
    p.published(0.05, 0.05)
    assert p.tick_may_wait(0.0899) and not p.tick_may_wait(0.0901)
    unpublished = PacingClock(fast=False, publish_period_s=0.02, clock=lambda: 0.0)
    unpublished.start(0.0)
    assert not unpublished.tick_may_wait(0.001)  # nothing published yet: the tick goes out
    fast = PacingClock(fast=True, publish_period_s=0.02, clock=lambda: 0.0)
    fast.start(0.0, published=True)
    assert not fast.tick_may_wait(0.0)


def test_frames_as_long_as_the_publish_period_publish_every_frame_in_any_phase():
    """service.core.pacing: 20 ms frames (the service's default) and 50 Hz publishing. Frames
    that end just before their tick (0.1 ms, with a jitter of +-0.05 ms) publish every frame but
    the first: the tick a frame misses is taken by the next frame, and the grid stays a tick
    behind instead of losing every other publication."""
    p = PacingClock(fast=False, publish_period_s=0.02, clock=lambda: 0.0)
    p.start(0.0)
    published = 0
    for k in range(1, 51):
        end = 0.02 * k - 0.0001 + (0.00005 if k % 2 else -0.00005)
        if p.publish_due(end, end, False):
            p.published(end, end)
            published += 1
    assert published == 49


def test_fast_mode_is_never_late():
    p = PacingClock(fast=True, publish_period_s=0.02, clock=lambda: 0.0)
    p.start(0.0)
    assert p.frame_done(100.0, 0.005) == 100.0
    assert p.overruns == 0 and p.late_fraction is None


# ---- the threaded pool with fake jobs --------------------------------------------------------------
class CountingJob:
    """A fast-mode job that records which threads run it and whether two ever overlap."""

    def __init__(self, name, limit):
        self.name, self.limit = name, limit
        self.steps = 0
        self.threads = set()
        self.inside = 0
        self.overlaps = 0
        self.left = threading.Event()
        self._lock = threading.Lock()

    def step(self, now):
        with self._lock:
            self.inside += 1
            self.overlaps += self.inside > 1
        self.threads.add(threading.current_thread().name)
        time.sleep(0.0002)
        with self._lock:
            self.inside -= 1
        self.steps += 1
        return None if self.steps >= self.limit else Schedule(now)

    def left_pool(self):
        self.left.set()


def test_pool_runs_each_job_on_one_thread_at_a_time():
    pool = SteppingPool(2, name="t-pool").start()
    try:
        jobs = [CountingJob(f"j{i}", 200) for i in range(3)]
        handles = [pool.add(j) for j in jobs]
        for j, h in zip(jobs, handles):
            assert j.left.wait(WAIT_S) and h.done.wait(WAIT_S)
            assert j.steps == 200 and j.overlaps == 0
            assert j.threads <= set(pool.thread_names)
    finally:
        assert pool.close(timeout=10.0)


class LateJob:
    """Real time, always behind the wall clock: released again at once, its deadline past."""

    def __init__(self, name):
        self.name = name
        self.steps = 0

    def step(self, now):
        self.steps += 1
        time.sleep(0.0005)
        return Schedule(now - 1.0, now - 0.5)

    def left_pool(self):
        pass


def test_a_twin_added_to_a_pool_of_late_twins_runs():
    # Every twin of an overloaded pool is released at once with a deadline in the past (up to the
    # pacing's resync_after_s). A job added then is due at its release; with no deadline it came
    # after all of them and never ran its first frame (found with bench-service --twins 4 --force:
    # the 4th twin ran 0 frames in 20 s, the 3rd none in its first 15 s).
    pool = SteppingPool(1, name="t-late").start()
    hogs = [LateJob(f"hog{i}") for i in range(2)]
    newcomer = CountingJob("new", 1)  # its first frame, then it leaves
    try:
        for h in hogs:
            pool.add(h)
        deadline = time.monotonic() + WAIT_S
        while sum(h.steps for h in hogs) < 20 and time.monotonic() < deadline:
            time.sleep(0.001)
        handle = pool.add(newcomer)
        assert newcomer.left.wait(WAIT_S) and handle.done.wait(WAIT_S)
        assert newcomer.steps == 1
    finally:
        for h in hogs:
            h.step = lambda now: None  # leave the pool at their next frame
        assert pool.close(timeout=10.0)


class SleepyJob:
    """Real time: released again only in an hour, unless woken."""

    name = "sleepy"

    def __init__(self):
        self.steps = 0
        self.stepped = threading.Event()

    def step(self, now):
        self.steps += 1
        self.stepped.set()
        return Schedule(now + 3600.0, now + 3600.005)

    def left_pool(self):
        pass


def test_wake_releases_a_job_waiting_for_its_release():
    pool = SteppingPool(1, name="t-wake").start()
    try:
        job = SleepyJob()
        handle = pool.add(job)
        assert job.stepped.wait(WAIT_S)
        deadline = time.monotonic() + WAIT_S
        while handle.state != "waiting" and time.monotonic() < deadline:
            time.sleep(0.001)
        job.stepped.clear()
        pool.wake(handle)
        assert job.stepped.wait(WAIT_S) and job.steps == 2
    finally:
        assert pool.close(timeout=10.0)


class PacedJob:
    """Real time: a frame every `period_s` from its first, `frames` of them, then it leaves; notes
    how late each frame started after its release."""

    def __init__(self, name, period_s, frames):
        self.name, self.period_s, self.frames = name, period_s, frames
        self.steps = 0
        self.t0: float | None = None
        self.lateness: list[float] = []
        self.left = threading.Event()

    def step(self, now):
        if self.t0 is None:
            self.t0 = now
        self.lateness.append(now - (self.t0 + self.steps * self.period_s))
        self.steps += 1
        if self.steps >= self.frames:
            return None
        release = self.t0 + self.steps * self.period_s
        return Schedule(release, release + self.period_s)

    def left_pool(self):
        self.left.set()


class CountingCondition(threading.Condition):
    """A condition that counts the returns from `wait` (a stepping thread's wake-ups)."""

    def __init__(self):
        super().__init__()
        self.wakeups = 0

    def wait(self, timeout=None):
        try:
            return super().wait(timeout)
        finally:
            self.wakeups += 1


def test_idle_stepping_threads_sleep_while_one_job_is_paced():
    # One free thread at a time times the next release: with one twin the other stepping threads
    # sleep (each wake-up of an idle thread costs about 0.1 ms of CPU on the 2-core VMs). When every
    # free thread timed it, three threads woke at every frame.
    pool = SteppingPool(3, name="t-idle")
    cond = pool._cond = CountingCondition()
    job = PacedJob("paced", 0.005, 40)
    try:
        pool.add(job)
        assert job.left.wait(WAIT_S)
        assert job.steps == 40
        assert cond.wakeups <= 40 + 10  # one per frame, and the start
    finally:
        assert pool.close(timeout=10.0)


def test_a_setpoint_wakes_one_stepping_thread():
    # An urgent wake (an outside setpoint) releases the job at once; one free thread takes it, the
    # others sleep on. When every free thread was woken, each setpoint cost two more wake-ups.
    pool = SteppingPool(3, name="t-wake-one")
    cond = pool._cond = CountingCondition()
    job = SleepyJob()
    try:
        handle = pool.add(job)
        assert job.stepped.wait(WAIT_S)
        woken = 0
        for _ in range(20):
            deadline = time.monotonic() + WAIT_S
            while handle.state != "waiting" and time.monotonic() < deadline:
                time.sleep(0.001)
            job.stepped.clear()
            before = cond.wakeups
            pool.wake(handle, urgent=True)
            assert job.stepped.wait(WAIT_S)
            time.sleep(0.002)  # any other thread woken by it has returned from its wait by now
            woken += cond.wakeups - before
        assert job.steps == 21
        assert woken <= 20 + 4
    finally:
        assert pool.close(timeout=10.0)


def test_a_paced_job_stays_timed_when_the_job_timed_before_it_leaves():
    # The fast job's frames come first, so its release is the one a free thread times; the slow
    # job's frames are timed once the fast one has left (else it would wait for a wake-up that never
    # comes), and every job runs every frame, none before its release.
    pool = SteppingPool(2, name="t-handover")
    jobs = [PacedJob("fast", 0.002, 15), PacedJob("mid", 0.007, 10), PacedJob("slow", 0.03, 8)]
    try:
        for j in jobs:
            pool.add(j)
        for j in jobs:
            assert j.left.wait(WAIT_S), j.name
            assert j.steps == j.frames
            assert min(j.lateness) >= -1e-3  # never started before its release (timer resolution)
    finally:
        assert pool.close(timeout=10.0)


# ---- capacity: the rule ----------------------------------------------------------------------------
def test_cpu_meter_reports_the_last_closed_window():
    m = CpuMeter(window=1.0)
    m.add(0.3, 0.5)
    assert m.rate is None
    m.add(0.5, 0.5)
    assert m.rate == pytest.approx(0.8)
    m.add(0.2, 1.0)
    assert m.rate == pytest.approx(0.2) and m.cpu_s == pytest.approx(1.0)


def test_capacity_rule():
    cap = Capacity(stepping_threads=2, core_fraction=0.85, cores=2)
    assert cap.budget_cpu_s_per_s == pytest.approx(1.7)
    small = TwinCost(0.3, 0.05)
    assert cap.check(small, []).admitted
    assert cap.check(small, [small] * 3).admitted  # 1.4 of 1.7
    full = cap.check(small, [small] * 4)  # 1.75 > 1.7
    assert not full.admitted and "no capacity left" in full.reason and "1.400 of 1.700" in full.reason
    big = cap.check(TwinCost(0.9, 0.05), [])  # one core's share is 0.85
    assert not big.admitted and "cannot run the twin in real time" in big.reason
    assert cap.estimate_max_twins(small, running=1, used_cpu_s_per_s=0.35) == 1 + 3
    # more threads than cores buy nothing; fewer threads than cores limit the budget
    assert Capacity(8, 0.85, cores=2).budget_cpu_s_per_s == pytest.approx(1.7)
    assert Capacity(1, 0.85, cores=2).budget_cpu_s_per_s == pytest.approx(0.85)
    # the service's reserve comes off the budget, never below one twin's share
    reserved = Capacity(2, 0.85, cores=2, reserve_cores=0.5)
    assert reserved.budget_cpu_s_per_s == pytest.approx(1.2)
    twin = TwinCost(0.68, 0.06)  # a default 6208 on this VM: 0.74
    assert reserved.check(twin, []).admitted
    second = reserved.check(twin, [twin])  # 1.48 > 1.2
    assert not second.admitted and "less 0.5 reserved for the service" in second.reason
    assert Capacity(1, 0.85, cores=1, reserve_cores=0.5).budget_cpu_s_per_s == pytest.approx(0.85)
    with pytest.raises(ValueError, match="reserve_cores"):
        Capacity(2, 0.85, reserve_cores=-1.0)


def test_capacity_formula_states_the_figures_it_counts_with():
    cap = Capacity(2, 0.85, cores=2, reserve_cores=0.5)  # budget 2 x 0.85 - 0.5 = 1.2
    assert "no twin calibrated yet" in cap.formula(None, 0, 0.0)
    twin = TwinCost(0.25, 0.03)  # c = 0.28: floor((1.2 - 0.28) / 0.28) = 3
    text = cap.formula(twin, 1, 0.28)
    assert cap.estimate_max_twins(twin, 1, 0.28) == 4
    assert "= 1.200 CPU s/s" in text
    assert "c = engine 0.250 (calibrated) + snapshots 0.030 (no service overhead measured yet)" in text
    assert "(no service overhead measured yet) = 0.280" in text
    assert text.endswith("1 running + floor((1.200 - 0.280 in use) / 0.280) = 4")
    assert twin.publish_fraction == pytest.approx(0.12)


def test_capacity_counts_the_measured_service_overhead_per_twin():
    """service.core.capacity: once the service's overhead per twin is measured (ThreadCpuMeter),
    each twin's need is its engine plus that share (its calibrated snapshots when larger), in the
    check, the count and the formula."""
    cap = Capacity(2, 0.85, cores=2, reserve_cores=0.5)  # budget 1.2
    twin = TwinCost(0.27, 0.02)
    assert cap.estimate_max_twins(twin, 0, 0.0) == 4  # c = 0.29
    assert cap.need(twin, 0.09) == pytest.approx(0.36)
    assert cap.need(twin, 0.01) == pytest.approx(0.29)  # the snapshots' cost is the floor
    assert cap.used([twin, twin], 0.09) == pytest.approx(0.72)
    assert cap.estimate_max_twins(twin, 0, 0.0, 0.09) == 3  # floor(1.2 / 0.36)
    assert cap.estimate_max_twins(twin, 2, 0.72, 0.09) == 3  # 2 + floor(0.48 / 0.36)
    text = cap.formula(twin, 2, 0.72, 0.09)
    assert "c = engine 0.270 (calibrated) + service 0.090 (measured per twin" in text
    assert "(measured per twin; its snapshots alone 0.020) = 0.360" in text
    assert text.endswith("2 running + floor((1.200 - 0.720 in use) / 0.360) = 3")
    verdict = cap.check(twin, [twin, twin, twin], 0.09)  # 1.08 + 0.36 > 1.2
    assert not verdict.admitted and "service 0.090" in verdict.reason
    assert cap.check(twin, [twin, twin, twin]).admitted  # 0.87 + 0.29: the snapshots alone fit


def test_service_overhead_is_the_process_cpu_beside_the_engines():
    wall, cpu = [0.0], [0.0]
    meter = ServiceOverheadMeter(1.0, clock=lambda: wall[0], cpu_clock=lambda: cpu[0])
    assert meter.sample(0.0, 2) is None  # the first mark
    wall[0], cpu[0] = 0.5, 0.3
    assert meter.sample(0.25, 2) is None  # the window is not closed yet
    wall[0], cpu[0] = 2.0, 1.1  # 0.55 CPU s/s, engines 0.5
    out = meter.sample(1.0, 2)
    assert out["process_cpu_s_per_s"] == pytest.approx(0.55) and out["engine_cpu_s_per_s"] == pytest.approx(0.5)
    assert out["overhead_cpu_s_per_s"] == pytest.approx(0.05)
    assert out["overhead_per_twin_cpu_s_per_s"] == pytest.approx(0.025)
    assert out["overhead_fraction"] == pytest.approx(0.10) and out["goal_fraction"] == OVERHEAD_GOAL
    wall[0] = 2.5
    assert meter.sample(1.2, 2) is out  # kept until the next window closes
    assert meter.sample(0.1, 1) is out  # a twin left: a new mark, no negative figure


def test_calibration_measures_thread_cpu_per_simulated_second():
    from twin.engine import Twin

    twin = Twin("6205", bearing_id="cal")
    seq = twin.seq
    ticks = iter([0.0, 0.012, 1.0, 1.011, 2.0, 2.0005])  # two halves of 10 ms, one snapshot
    cost = calibrate(twin, sim_s=0.02, frame_steps=1000, publish_rate_hz=50.0, cpu_clock=lambda: next(ticks))
    assert cost.engine_cpu_s_per_sim_s == pytest.approx(0.011 / 0.01)  # the cheaper half
    assert cost.publish_cpu_s_per_s == pytest.approx(0.0005 * 50.0)
    assert twin.time_s == pytest.approx(0.021)  # warm-up frame + 20 ms
    assert twin.seq == seq  # nothing published


# ---- the registry: 503 with the reason, the configured twin over capacity --------------------------
def _open_registry_on_two_cores():
    """A registry with measured admission, no start twin, zenoh and recording off, two stepping
    threads on two cores (whatever runs the test) at core_fraction 0.85 and no reserve: a budget
    of 1.7 CPU s/s, so the tests' arithmetic is the rule's alone."""
    from service.core.registry import TwinRegistry
    from service.settings import ServiceSettings

    settings = ServiceSettings(
        enable_zenoh=False,
        enable_recording=False,
        admission="measured",
        stepping_threads=2,
        capacity_core_fraction=0.85,
        start_twin=False,
        capacity_reserve_cores=0.0,
    )
    reg = TwinRegistry(settings)
    reg.capacity.cores = 2
    return reg.open()


def test_registry_refuses_a_twin_beyond_the_measured_capacity(monkeypatch):
    import service.core.registry as registry_module
    from service.core.runner import TwinRunner

    costs = iter([TwinCost(0.6, 0.05), TwinCost(0.6, 0.05), TwinCost(0.9, 0.05), TwinCost(0.6, 0.05)])
    monkeypatch.setattr(registry_module, "calibrate", lambda twin, **kw: next(costs))
    # the running twins' costs as calibrated (not as this machine's speed would measure them)
    monkeypatch.setattr(TwinRunner, "cost", property(lambda self: self.calibration))
    reg = _open_registry_on_two_cores()
    try:
        reg.create_twin(id="a", designation="6205")  # 0.65 of 1.7
        reg.create_twin(id="b", designation="6205")  # 1.3 of 1.7
        with pytest.raises(InputError) as exc:  # 0.95 > one core's 0.85
            reg.create_twin(id="c", designation="6205")
        assert exc.value.status_code == 503
        err = exc.value.errors[0]
        assert "refused" in err.message and "cannot run the twin in real time" in err.message
        assert ADMISSION_REFUSAL in err.message  # the attack counts it as the admission's refusal
        assert "0.950" in err.message and "0.850" in err.message
        assert [e.id for e in reg.entries()] == ["a", "b"]
        with pytest.raises(InputError) as exc:  # 1.3 + 0.65 > 1.7
            reg.create_twin(id="d", designation="6205")
        assert exc.value.status_code == 503 and "no capacity left" in exc.value.errors[0].message
        assert ADMISSION_REFUSAL in exc.value.errors[0].message
        cap = reg.health()["capacity"]
        assert cap["admission"] == "measured" and cap["budget_cpu_s_per_s"] == pytest.approx(1.7)
        assert cap["used_cpu_s_per_s"] == pytest.approx(1.3)
        assert {t["id"] for t in reg.health()["twins"]} == {"a", "b"}
    finally:
        reg.close()


def test_configured_twin_starts_over_capacity_and_says_so(monkeypatch):
    import service.core.registry as registry_module
    from service.core.registry import TwinRegistry
    from service.settings import ServiceSettings

    monkeypatch.setattr(registry_module, "calibrate", lambda twin, **kw: TwinCost(1.5, 0.05))
    settings = ServiceSettings(
        enable_zenoh=False, enable_recording=False, admission="measured", bearing="6205", stepping_threads=1
    )
    reg = TwinRegistry(settings).open()
    try:
        assert [e.id for e in reg.entries()] == ["default"]
        cap = reg.health()["capacity"]
        assert "cannot run the twin in real time" in cap["over_capacity"]
        assert cap["max_twins"] == 1
        reg.delete_twin("default")
        assert reg.health()["capacity"]["over_capacity"] is None
    finally:
        reg.close()


def test_health_counts_the_measured_service_overhead_in_the_capacity(monkeypatch):
    """service.core.registry + capacity: once a window of the thread CPU meter has closed, /health
    gives the service overhead per twin, counts it in what the running twin uses, and the formula
    states it and ends with max_twins. The calibration says snapshots cost nothing and the engine
    0.1 CPU s/s (monkeypatched), so any measured overhead is the larger share."""
    import service.core.registry as registry_module
    from service.core.registry import TwinRegistry
    from service.core.runner import TwinRunner
    from service.settings import ServiceSettings

    monkeypatch.setattr(registry_module, "calibrate", lambda twin, **kw: TwinCost(0.1, 0.0))
    monkeypatch.setattr(TwinRunner, "cost", property(lambda self: self.calibration))
    settings = ServiceSettings(enable_zenoh=False, enable_recording=False, admission="measured", bearing="6208")
    reg = TwinRegistry(settings).open()
    try:
        reg.health()  # the first mark
        deadline = time.monotonic() + 10.0
        cap = reg.health()["capacity"]
        while cap["service_overhead_per_twin_cpu_s_per_s"] is None and time.monotonic() < deadline:
            time.sleep(0.3)
            cap = reg.health()["capacity"]
        per_twin = cap["service_overhead_per_twin_cpu_s_per_s"]
        assert per_twin is not None and per_twin > 0.0
        assert cap["used_cpu_s_per_s"] == pytest.approx(0.1 + per_twin)
        assert f"service {per_twin:.3f} (measured per twin; its snapshots alone 0.000)" in cap["formula"]
        assert cap["formula"].endswith(f"= {cap['max_twins']}")
    finally:
        reg.close()


def test_expected_engine_cost_is_the_calibration_or_what_twins_alike_measure():
    """service.core.capacity.expected_engine_cost of mean_engine_cost: the larger of the lone
    calibration and the mean measured cost of the running twins alike (the calibration alone with
    none measured; non-positive or non-finite measurements left out)."""
    assert expected_engine_cost(0.28, mean_engine_cost([0.42, 0.46])) == pytest.approx(0.44)
    assert expected_engine_cost(0.28, mean_engine_cost([])) == 0.28
    assert expected_engine_cost(0.40, mean_engine_cost([0.30])) == 0.40  # a calibration above what runs counts as it is
    assert expected_engine_cost(0.28, mean_engine_cost([math.nan, 0.0, 0.42])) == pytest.approx(0.42)
    assert TwinCost(0.28, 0.02).with_engine(0.42) == TwinCost(0.42, 0.02)


def test_a_twin_alike_a_running_one_counts_at_what_that_one_measures(monkeypatch):
    """service.core.registry: a running 6205 whose engine measures 0.45 CPU s per simulated s
    against its calibration's 0.3 makes another 6205 count at 0.45, in max_twins and the
    formula; at 0.9 measured, a 6205 whose lone cost (0.35 CPU s/s) fits one core's 0.85 is
    refused (0.95), while a twin of another kind still counts at its own calibration. Measured
    rates are set on the runner's meter, not measured, so the arithmetic holds on any machine."""
    from types import SimpleNamespace

    import service.core.registry as registry_module

    monkeypatch.setattr(registry_module, "calibrate", lambda twin, **kw: TwinCost(0.3, 0.05))
    reg = _open_registry_on_two_cores()
    try:
        reg.create_twin(id="a", designation="6205")
        cap = reg.health()["capacity"]
        assert cap["alike_engine_cpu_s_per_sim_s"] is None  # nothing measured yet: the calibration counts
        meter = SimpleNamespace(rate=0.45, cpu_s=0.0, add=lambda cpu_s, work: None)
        reg.get("a").runner.engine_cpu = meter
        cap = reg.health()["capacity"]
        assert cap["alike_engine_cpu_s_per_sim_s"] == pytest.approx(0.45)
        # c = 0.45 + 0.05 = 0.5; in use 0.45 + 0.05 = 0.5: 1 + floor((1.7 - 0.5) / 0.5) = 3
        assert cap["max_twins"] == 3
        assert "engine max(calibrated 0.300, running alike 0.450)" in cap["formula"]
        assert "= 0.500 CPU s/s" in cap["formula"]
        meter.rate = 0.9
        with pytest.raises(InputError) as exc:
            reg.create_twin(id="b", designation="6205")
        assert exc.value.status_code == 503 and "0.950" in exc.value.errors[0].message
        reg.create_twin(id="c", designation="6208")  # unlike: 0.35 of what is left (1.7 - 0.95)
        assert [e.id for e in reg.entries()] == ["a", "c"]
    finally:
        reg.close()


def test_max_twins_unset_means_the_capacity_decides():
    from service.settings import ServiceSettings

    assert ServiceSettings().runner.max_twins is None and ServiceSettings().runner.twin_limit == 256
    assert ServiceSettings(max_twins=3).runner.twin_limit == 3
    assert math.isclose(ServiceSettings().runner.frame_s, 0.02) and ServiceSettings().runner.lateness_s == 0.005


def test_an_urgent_wake_puts_the_frame_before_the_released_frames_of_the_others():
    """Earliest deadline first: a setpoint's frame (woken urgently) is taken before the frames of
    twins that only keep their pace, whether its job waited for its release or was released."""
    q = EdfQueue()
    a, b, c = _job("a"), _job("b"), _job("c")
    q.put(a, Schedule(release=0.050, deadline=0.055))
    q.put(b, Schedule(release=0.000, deadline=0.004))
    q.put(c, Schedule(release=0.000, deadline=0.006))
    assert q.wake(a, 0.002, deadline=0.002)  # waiting: released now, due now
    assert q.take(0.002) is a
    q.put(a, Schedule(release=0.000, deadline=0.010))
    assert q.take(0.003) is b  # a is released but due last
    assert q.wake(a, 0.003, deadline=0.003)  # moved up the released jobs
    assert not q.wake(a, 0.003, deadline=0.003)  # already due now
    assert q.take(0.003) is a
    assert q.take(0.003) is c


def test_an_urgent_wake_of_a_running_job_gives_its_next_frame_the_deadline_now():
    pool = SteppingPool(1, clock=lambda: 1.0)
    job = Job(task=None)
    job.state = "running"
    pool.wake(job, urgent=True)
    assert job.wake_pending and job.wake_deadline == 1.0
