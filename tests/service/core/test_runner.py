"""TwinRunner: frames run by a stepping pool (its own, of one thread, here), mailbox latest-wins,
setpoints between frames, pacing, fast mode, stop/join, scenarios in the stepping thread, errors
counted, snapshots built off the stepping thread. Real Twin, bounded waits; no wall-clock speed
threshold (the machines are shared and noisy): pacing is checked as "never ahead of the wall clock"
on the real runner and exactly on a fake clock (tests/service/core/test_pool.py)."""

from __future__ import annotations

import json
import threading
import time

import pytest

from service.core.admission import AdmissionGate
from service.core.errors import InputError
from service.core.intake import SetpointIntake
from service.core.runner import TwinRunner
from service.core.scenario_files import scenario_from_dict
from service.core.scenarios import ScenarioError
from twin.engine import Twin

WAIT_S = 30.0


class ListSink:
    """A SnapshotSink that keeps everything (tests only)."""

    def __init__(self):
        self.snapshots = []
        self.threads = set()
        self.dropped = 0
        self._lock = threading.Lock()

    def publish(self, snapshot):
        with self._lock:
            self.snapshots.append(snapshot)
            self.threads.add(threading.current_thread().name)

    def close(self):
        pass

    def wait_for(self, predicate, timeout=WAIT_S):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            with self._lock:
                for s in self.snapshots:
                    if predicate(s):
                        return s
            time.sleep(0.01)
        return None


def wait_until(predicate, timeout=WAIT_S, interval=0.01):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(interval)
    return predicate()


@pytest.fixture
def twin():
    tw = Twin("6208", bearing_id="t")
    tw.advance(0.001)  # compiled and warm
    return tw


@pytest.fixture
def make_runner():
    runners = []

    def make(twin, **kw):
        r = TwinRunner(twin, **kw)
        runners.append(r)
        return r

    yield make
    for r in runners:
        assert r.stop(timeout=10.0)


def test_mailbox_latest_wins_and_merges_in_order(twin, make_runner):
    sink = ListSink()
    runner = make_runner(twin, fast=True, sinks=[sink])
    runner.submit(radial_load_n=4000.0)
    runner.submit(shaft_speed_rad_s=300.0)
    target = runner.submit({"radial_load_n": 5000.0, "oil_temperature_c": 60.0})
    # merged in order, latest wins per field; nothing applied yet (no frame has run)
    assert (target.radial_load_n, target.shaft_speed_rad_s, target.oil_temperature_c) == (5000.0, 300.0, 60.0)
    assert twin.setpoint.radial_load_n == 3000.0
    runner.start()
    first = sink.snapshots[0]
    assert first.setpoint.radial_load_n == 3000.0  # published before the first frame
    assert wait_until(lambda: runner.frames >= 3)
    assert runner.setpoints_applied == 1  # three updates, one application
    assert runner.setpoints_accepted == 3
    sp = twin.setpoint
    assert (sp.radial_load_n, sp.shaft_speed_rad_s, sp.oil_temperature_c) == (5000.0, 300.0, 60.0)


def test_setpoint_validation_names_field_and_range(twin, make_runner):
    runner = make_runner(twin, fast=True)
    with pytest.raises(InputError) as exc:
        runner.submit(shaft_speed_rad_s=5000.0)  # above the 6208's limit, below the schema's 1e4
    err = exc.value.errors[0]
    assert err.field == "shaft_speed_rad_s"
    low, high = err.allowed
    assert low == 0.0 and 2000.0 < high < 2100.0
    with pytest.raises(InputError) as exc:
        runner.submit({"radial_load_n": -1.0})
    assert exc.value.errors[0].field == "radial_load_n"
    with pytest.raises(InputError) as exc:
        runner.submit({"radial_load": 1.0})
    assert exc.value.errors[0].field == "radial_load"
    # a refused update changes nothing
    assert runner.target_setpoint == twin.setpoint


def test_zenoh_setpoint_handler_never_raises(twin, make_runner):
    runner = make_runner(twin, fast=True)
    intake = SetpointIntake(twin.bearing_id, AdmissionGate(), runner)
    ok = intake(b'{"radial_load_n": 2500}')
    assert ok["accepted"] is True and ok["setpoint"]["radial_load_n"] == 2500.0
    for payload, field in (
        (b'{"radial_load_n": NaN}', "radial_load_n"),
        (b'{"shaft_speed_rad_s": 1e9}', "shaft_speed_rad_s"),
        (b'{"axial_load_n": "x"}', "axial_load_n"),
        (b"not json", None),
        (b"[1, 2]", None),
        (b"\xff\xfe", None),
    ):
        res = intake(payload)
        assert res["accepted"] is False, payload
        json.dumps(res, allow_nan=False)  # the refusal itself is valid JSON
        if field is not None:
            assert field in res["error"]
    assert runner.target_setpoint.radial_load_n == 2500.0


def test_setpoints_only_change_between_frames(twin, make_runner):
    """The runner thread is the only writer and never changes the setpoint during a frame."""
    violations, writers = [], set()
    advance, set_setpoint = twin.advance, twin.set_setpoint

    def checked_advance(*a, **kw):
        before = twin.setpoint
        advance(*a, **kw)
        if twin.setpoint is not before:
            violations.append(twin.time_s)

    def recorded_set_setpoint(*a, **kw):
        writers.add(threading.current_thread().name)
        return set_setpoint(*a, **kw)

    twin.advance, twin.set_setpoint = checked_advance, recorded_set_setpoint
    runner = make_runner(twin, fast=True).start()
    stop = threading.Event()

    def hammer():
        i = 0
        while not stop.is_set():
            runner.submit(radial_load_n=2000.0 + (i % 50) * 10.0)
            i += 1
            time.sleep(0.0005)

    threads = [threading.Thread(target=hammer) for _ in range(2)]
    for t in threads:
        t.start()
    assert wait_until(lambda: runner.setpoints_applied >= 20)
    stop.set()
    for t in threads:
        t.join(5.0)
    assert not violations
    assert writers == set(runner.stepping_threads)  # the stepping thread, never the submitters


class _TimedSink(ListSink):
    """Keeps each snapshot with the wall time it arrived."""

    def __init__(self):
        super().__init__()
        self.arrivals = []

    def publish(self, snapshot):
        with self._lock:
            self.arrivals.append((time.perf_counter(), snapshot))
        super().publish(snapshot)


def test_real_time_pacing(twin, make_runner):
    """Paced to the wall clock: never ahead of it by more than the frame that may run early.
    How far behind depends on this shared machine's load (the pool's behaviour under load is
    tests/service/core/test_pool.py's, with a fake clock), so only progress is asserted here."""
    sink = ListSink()
    runner = make_runner(twin, publish_rate_hz=50.0, sinks=[sink])
    t0 = time.perf_counter()
    runner.start()
    assert wait_until(lambda: runner.frames >= 50 and runner.published >= 3)  # progress (bounded wait)
    assert runner.stop(timeout=10.0)
    wall = time.perf_counter() - t0
    sim = runner.sim_elapsed_s
    assert 0.0 < sim <= wall + 2 * runner.frame_s
    assert runner.real_time_factor is not None and runner.real_time_factor > 0.0
    assert runner.overruns <= runner.frames
    lf = runner.late_fraction
    assert lf is not None and 0.0 <= lf <= 1.0
    # published on the wall clock at about 50 Hz (+ the initial one), never faster
    assert 1 <= runner.published <= 50 * wall + 5
    rtfs = [s.real_time_factor for s in sink.snapshots[1:]]
    assert rtfs and all(r is not None for r in rtfs)
    assert all(s.late_fraction is not None for s in sink.snapshots[1:])
    seqs = [s.seq for s in sink.snapshots]
    assert seqs == sorted(seqs) and len(set(seqs)) == len(seqs)


class _FakeClock:
    """A monotonic clock that only moves when told to (frame work) or when the pacing sleeps."""

    def __init__(self):
        self.t = 100.0
        self.slept = 0.0

    def __call__(self):
        return self.t

    def wait(self, seconds):  # threading.Event.wait as the pacing uses it
        assert seconds >= 0.0
        self.t += seconds
        self.slept += seconds
        return False


def test_fast_mode_publishes_on_simulated_time(twin, make_runner):
    sink = ListSink()
    runner = make_runner(twin, fast=True, publish_rate_hz=200.0, sinks=[sink]).start()
    assert wait_until(lambda: runner.sim_elapsed_s >= 0.05)
    assert runner.stop(timeout=10.0)
    assert runner.overruns == 0 and runner.resyncs == 0
    # one snapshot at start + one per 5 ms of simulated time
    expected = 1 + round(runner.sim_elapsed_s / 0.005)
    assert abs(len(sink.snapshots) - expected) <= 1
    times = [s.time_s for s in sink.snapshots[1:]]
    gaps = [b - a for a, b in zip(times, times[1:])]
    assert all(abs(g - 0.005) < 1e-6 for g in gaps)


def test_stop_joins_and_is_idempotent(twin, make_runner):
    runner = make_runner(twin).start()
    assert wait_until(lambda: runner.frames >= 2)
    t0 = time.monotonic()
    assert runner.stop(timeout=5.0)
    assert time.monotonic() - t0 < 5.0
    assert not runner.running
    frames = runner.frames
    time.sleep(0.05)
    assert runner.frames == frames
    assert runner.stop(timeout=1.0)


def test_setpoint_timing_records_first_reflecting_snapshot(twin, make_runner):
    sink = ListSink()
    runner = make_runner(twin, publish_rate_hz=20.0, sinks=[sink]).start()
    assert wait_until(lambda: runner.frames >= 5)
    runner.submit(radial_load_n=4321.0)
    assert wait_until(lambda: runner.setpoint_latencies())
    (timing,) = runner.setpoint_latencies()
    assert timing.latency_s is not None and timing.latency_s >= 0.0
    by_seq = {s.seq: s for s in sink.snapshots}
    assert by_seq[timing.seq].setpoint.radial_load_n == 4321.0
    assert by_seq[timing.seq - 1].setpoint.radial_load_n == 3000.0
    # published at once, not at the next 50 ms publishing tick
    assert timing.published_wall_s - timing.applied_wall_s < 0.05 + 10 * runner.frame_s


def _scenario(**kw):
    data = {
        "name": "t",
        "duration_s": 0.03,
        "sample_every_s": 0.001,
        "initial": {"radial_load_n": 2000.0},
        "steps": [
            {"at_s": 0.005, "set": {"oil_temperature_c": 60.0}},
            {"at_s": 0.01, "ramp": {"radial_load_n": 4000.0}, "over_s": 0.01},
        ],
    }
    data.update(kw)
    return scenario_from_dict(data)


def test_scenario_runs_in_the_runner_thread(twin, make_runner):
    sink = ListSink()
    runner = make_runner(twin, fast=True, publish_rate_hz=1000.0, sinks=[sink], idle_without_scenario=True).start(
        publish_initial=False
    )
    writers = set()
    set_setpoint = twin.set_setpoint

    def recorded(*a, **kw):
        writers.add(threading.current_thread().name)
        return set_setpoint(*a, **kw)

    twin.set_setpoint = recorded
    handle, replaced = runner.start_scenario(_scenario().resolved_runs()[0])
    assert replaced is None
    assert handle.wait(WAIT_S)
    assert handle.state == "done" and handle.progress == 1.0
    assert writers == set(runner.stepping_threads)
    # the snapshots are built and handed to the sinks by the publish worker, not the stepping thread
    assert sink.threads == {runner._pool.publisher.thread_name}
    t0 = sink.snapshots[0].time_s
    by_t = {round(s.time_s - t0, 6): s.setpoint for s in sink.snapshots}
    assert by_t[0.0].radial_load_n == 2000.0
    assert by_t[0.004].oil_temperature_c == 40.0 and by_t[0.006].oil_temperature_c == 60.0
    assert by_t[0.010].radial_load_n == pytest.approx(2000.0)
    # a snapshot at t shows the setpoint in force during the frame that ended at t, i.e. the
    # ramp's value at t - frame_s: 2000 + 2000 * (0.014 - 0.010) / 0.010
    assert by_t[0.015].radial_load_n == pytest.approx(2800.0)
    assert by_t[0.025].radial_load_n == 4000.0
    assert max(by_t) == pytest.approx(0.03)  # last sample at the end
    # idle afterwards: no frames without a scenario
    frames = runner.frames
    time.sleep(0.1)
    assert runner.frames == frames


def test_scenario_replaced_and_cancelled(twin, make_runner):
    runner = make_runner(twin, fast=True).start()
    long = _scenario(duration_s=60.0, steps=[]).resolved_runs()[0]
    first, _ = runner.start_scenario(long)
    assert wait_until(lambda: first.state == "running")
    second, replaced = runner.start_scenario(long)
    assert replaced is first
    assert first.wait(WAIT_S) and first.state == "cancelled"
    assert wait_until(lambda: second.state == "running")
    assert runner.cancel_scenario() is second
    assert second.wait(WAIT_S) and second.state == "cancelled"
    assert runner.running


def test_scenario_restart_warm_starts_at_the_initial_setpoint(twin, make_runner):
    runner = make_runner(twin, fast=True).start()
    assert wait_until(lambda: runner.sim_elapsed_s >= 0.005)
    before = twin.time_s
    run = _scenario(initial={"radial_load_n": 1000.0, "shaft_speed_rad_s": 200.0}, steps=[]).resolved_runs()[0]
    handle, _ = runner.start_scenario(run, restart=True)
    assert handle.wait(WAIT_S) and handle.state == "done"
    assert twin.setpoint.radial_load_n == 1000.0
    assert twin.time_s > before  # time went on through the restart
    assert runner.latest.shaft_speed_rad_s == pytest.approx(200.0)  # started there, not ramped


def test_scenario_outside_the_bearing_limits_is_refused(twin, make_runner):
    runner = make_runner(twin, fast=True)
    bad = _scenario(steps=[{"at_s": 0.0, "set": {"shaft_speed_rad_s": 5000.0}}]).resolved_runs()[0]
    with pytest.raises(ScenarioError) as exc:
        runner.start_scenario(bad)
    assert exc.value.field.endswith("steps[0].set.shaft_speed_rad_s")
    assert exc.value.allowed[1] < 5000.0


def test_loop_exception_is_counted_shown_and_survived(twin, make_runner):
    advance = twin.advance
    calls = {"n": 0}

    def flaky(*a, **kw):
        calls["n"] += 1
        if calls["n"] == 3:
            raise RuntimeError("injected failure")
        return advance(*a, **kw)

    twin.advance = flaky
    sink = ListSink()
    runner = make_runner(twin, fast=True, publish_rate_hz=1000.0, sinks=[sink]).start()
    assert wait_until(lambda: runner.frames >= 10)
    assert runner.errors == 1 and runner.running and not runner.failed
    assert "injected failure" in runner.latest.status
    assert "injected failure" in runner.stats()["status"]
    times = [s.time_s for s in sink.snapshots]
    assert times == sorted(times)  # the warm restart keeps the simulated clock


def test_repeated_exceptions_stop_the_runner_with_a_status(twin, make_runner):
    def broken(*a, **kw):
        raise RuntimeError("always")

    twin.advance = broken
    runner = make_runner(twin, fast=True, max_consecutive_errors=3).start()
    assert wait_until(lambda: not runner.running)
    assert runner.failed and runner.errors == 3
    assert runner.latest.status.startswith("failed")


def test_a_setpoint_ends_the_frame_in_progress(twin, make_runner):
    """Real time, frames of 2 s of simulated time (seconds of wall time): a setpoint submitted
    while one runs ends it at its next step (Twin.interrupt_frame), so the setpoint frame that
    applies it starts off the grid of whole frames, and the first snapshot carrying it is not
    held back to the end of the long frame. Counted in steps, no wall-clock threshold."""
    from twin.kernels import layout as L

    sink = ListSink()
    t_init = twin.time_s
    runner = make_runner(twin, frame_s=2.0, setpoint_frame_s=0.001, sinks=[sink]).start()
    step0 = int(twin.state.scalars[L.X_STEP])
    assert wait_until(lambda: int(twin.state.scalars[L.X_STEP]) > step0 + 10, interval=0.001)
    runner.submit(radial_load_n=4321.0)
    snap = sink.wait_for(lambda s: s.setpoint.radial_load_n == 4321.0)
    assert snap is not None
    dt = twin.model.dt_s
    cut_steps = round((snap.time_s - runner.setpoint_frame_steps * dt - t_init) / dt)
    assert cut_steps % runner.frame_steps != 0  # the frame was cut short
    assert snap.time_s < t_init + runner.frame_s  # within the first long frame
    assert runner.stop(timeout=10.0)  # stop interrupts the frame as well
    assert runner.sim_elapsed_s == pytest.approx(twin.time_s - t_init, abs=0.5 * dt)


def test_a_frame_cut_for_a_setpoint_publishes_nothing_before_it(twin, make_runner):
    """Real time, a 10 Hz tick due when a setpoint ends the first frame (2 s of simulated time) 110
    ms after the initial snapshot: the tick due at the cut waits for the setpoint's frame
    (service.core.pacing, "Publishing"): no snapshot is built at the cut with the old setpoint,
    and the next snapshot carries the new one. Counted in steps, no wall-clock threshold."""
    from twin.kernels import layout as L

    sink = ListSink()
    runner = make_runner(twin, publish_rate_hz=10.0, frame_s=2.0, setpoint_frame_s=0.001, sinks=[sink])
    runner.start()
    started = time.perf_counter()  # after the runner's clock started its schedule
    assert len(sink.snapshots) == 1  # the initial snapshot
    step0 = int(twin.state.scalars[L.X_STEP])
    # past the first tick (100 ms after the initial snapshot), within two periods of it (200 ms)
    assert wait_until(lambda: time.perf_counter() - started > 0.11, interval=0.001)
    assert runner.frames == 0 and int(twin.state.scalars[L.X_STEP]) > step0  # the 2 s frame still runs
    before = len(sink.snapshots)
    runner.submit(radial_load_n=4321.0)
    snap = sink.wait_for(lambda s: s.setpoint.radial_load_n == 4321.0)
    assert snap is not None
    after = sink.snapshots[before:]
    assert after[0] is snap  # nothing published between the setpoint and the state that carries it
    dt = twin.model.dt_s
    cut_s = snap.time_s - runner.setpoint_frame_steps * dt
    assert all(abs(s.time_s - cut_s) > 0.5 * dt for s in sink.snapshots)  # no snapshot at the cut
    assert runner.stop(timeout=10.0)


def test_an_interrupt_landing_after_its_setpoint_was_taken_does_not_hold_the_setpoint_back(twin, make_runner):
    """The race of `TwinRunner.submit` against the stepping thread: the setpoint is offered, the
    stepping thread takes it, and only then does the submitter's interrupt land, cutting the very
    frame that applies it with nothing left waiting. That frame publishes the setpoint at once
    (no tick for 1000 s here: held back, it would not be published at all). Counted in
    publications and steps, not in wall time."""
    sink = ListSink()
    runner = make_runner(twin, publish_rate_hz=0.001, frame_s=0.005, setpoint_frame_s=0.001, sinks=[sink]).start()
    assert wait_until(lambda: runner.frames >= 3)
    take = runner.mailbox.take

    def take_then_interrupt():
        pending, timings = take()
        if timings:
            twin.interrupt_frame()  # the submitter's interrupt, after the take
        return pending, timings

    runner.mailbox.take = take_then_interrupt
    runner.submit(radial_load_n=4321.0)
    snap = sink.wait_for(lambda s: s.setpoint.radial_load_n == 4321.0, timeout=10.0)
    assert snap is not None  # published by the cut frame that applied it
    assert snap.seq == sink.snapshots[0].seq + 1
    (timing,) = runner.setpoint_latencies()
    assert timing.seq == snap.seq
    assert runner.stop(timeout=10.0)


def test_a_setpoint_is_published_at_the_end_of_the_frame_that_applied_it(twin, make_runner):
    """No 50 Hz tick involved (one tick every 1000 s here): the state carrying a setpoint is
    published because its frame applied it, once, right after that frame (counted in
    publications and in steps of simulated time, not in wall time)."""
    sink = ListSink()
    runner = make_runner(twin, publish_rate_hz=0.001, frame_s=0.005, setpoint_frame_s=0.001, sinks=[sink]).start()
    assert wait_until(lambda: runner.frames >= 5)
    assert runner.published == 1  # the initial snapshot only
    runner.submit(radial_load_n=4321.0)
    snap = sink.wait_for(lambda s: s.setpoint.radial_load_n == 4321.0)
    assert snap is not None and snap.seq == sink.snapshots[0].seq + 1
    assert wait_until(lambda: runner.frames >= 20)
    assert runner.published == 2  # no other publication since
    (timing,) = runner.setpoint_latencies()
    assert timing.seq == snap.seq and timing.published_wall_s >= timing.applied_wall_s


def test_a_setpoint_snapshot_is_delivered_by_the_stepping_thread_in_order(twin, make_runner):
    """Real time: every snapshot, the one that carries an outside setpoint and the 200 Hz ones,
    is built and handed to the sinks on the stepping thread that ran its frame (no hop to the
    publish worker, service.core.publishing), with gapless increasing seq numbers."""
    sink = ListSink()
    runner = make_runner(twin, publish_rate_hz=200.0, frame_s=0.005, sinks=[sink]).start()
    assert wait_until(lambda: runner.published >= 5)
    for k in range(5):
        runner.submit(radial_load_n=4000.0 + k)
        assert sink.wait_for(lambda s, k=k: s.setpoint.radial_load_n == 4000.0 + k) is not None
    assert wait_until(lambda: len(runner.setpoint_latencies()) == 5)
    assert runner.stop(timeout=10.0)
    seqs = [s.seq for s in sink.snapshots]
    assert seqs == list(range(seqs[0], seqs[0] + len(seqs)))
    assert sink.threads <= set(runner.stepping_threads) | {"MainThread"}  # MainThread: before the start
    assert runner._pool.publisher.thread_name not in sink.threads
    for timing in runner.setpoint_latencies():
        stages = timing.stages_s()
        assert stages is not None and set(stages) == {"admission", "apply", "step", "build", "publish"}
        assert all(v >= 0.0 for v in stages.values())
        assert sum(stages.values()) == pytest.approx(timing.latency_s, abs=1e-9)
    latency = runner.stats()["setpoint_latency_ms"]
    assert latency["count"] == 5
    assert set(latency) == {"admission", "apply", "step", "build", "publish", "total", "count"}
    assert latency["total"]["p50"] <= latency["total"]["p99"] <= latency["total"]["max"]


def test_fast_mode_snapshots_are_built_on_the_publish_worker_without_a_gap(twin, make_runner):
    """Fast mode: the stepping thread hands a frozen copy to the pool's publish worker, which
    builds and delivers every sample of the grid, in order (service.core.publishing)."""
    sink = ListSink()
    runner = make_runner(twin, fast=True, publish_rate_hz=1000.0, sinks=[sink]).start()
    assert wait_until(lambda: runner.published >= 30)
    assert runner.stop(timeout=10.0)
    seqs = [s.seq for s in sink.snapshots]
    assert seqs == list(range(seqs[0], seqs[0] + len(seqs)))
    assert runner._pool.publisher.thread_name in sink.threads
    assert not sink.threads & set(runner.stepping_threads)
    times = [s.time_s for s in sink.snapshots[1:]]
    assert all(b > a for a, b in zip(times, times[1:]))


def test_setpoint_timing_stages_start_at_the_requests_arrival():
    """With the request's arrival known, the latency counts from it and the `http` stage comes
    first; the stages add up to the latency. Without it, from the submission."""
    from service.core.mailbox import SetpointTiming

    t = SetpointTiming(accepted_wall_s=10.0003, submitted_wall_s=10.0002, received_wall_s=10.0)
    t.applied_wall_s, t.captured_wall_s, t.built_wall_s, t.published_wall_s = 10.0005, 10.0010, 10.0012, 10.0013
    stages = t.stages_s()
    assert list(stages) == ["http", "admission", "apply", "step", "build", "publish"]
    assert stages["http"] == pytest.approx(2e-4) and stages["admission"] == pytest.approx(1e-4)
    assert sum(stages.values()) == pytest.approx(t.latency_s) == pytest.approx(1.3e-3)
    t.received_wall_s = None
    assert "http" not in t.stages_s() and t.latency_s == pytest.approx(1.1e-3)
