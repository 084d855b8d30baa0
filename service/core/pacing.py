"""The pacing clock of a runner: frame deadlines, lateness, real-time factor, publishing schedule.

Real-time mode: the frame that ends at simulated time s (counted from the anchor) should end by
the wall-clock DEADLINE `anchor_wall + (s - anchor_sim)`; its successor may start then (its
RELEASE, `frame_done` returns it to the stepping pool, which waits). A frame is LATE (counted
in `overruns`, and in `late_fraction`) when it ends more than `lateness_s` (5 ms by default)
after its deadline, not when it ends a few microseconds after it: a twin running a frame or so
ahead of or behind the wall clock is real time to anyone watching it. A twin behind its
schedule is released at once and catches up; if it falls more than `resync_after_s` behind (a
stall, a cold JIT compile) the schedule is re-anchored (`resyncs`) instead of racing to catch
up. Fast mode never waits and is never late.

Lead (`lead_s`, one frame by default in the service): a frame is released that long BEFORE the
wall clock reaches its start, so the simulated clock runs up to `lead_s` ahead of the wall clock,
a buffer that absorbs a wait for the GIL or the CPU between frames (the Python between frames
needs the GIL, which the publish worker, zenoh, the recorder and HTTP hold in turn) instead of
turning it into a late frame. A setpoint still applies at the next frame boundary; what a viewer
sees is at most `lead_s` ahead of the wall clock. 0: frames start on the wall clock.

Real-time factor: simulated / wall time over a sliding window (`rtf_window_s`, 1 s).
Late fraction: late frames / frames over a sliding window of wall time (`late_window_s`, 10 s).

Publishing (choice): in real-time mode every 1/publish_rate_hz of WALL time (what a viewer or a
zenoh subscriber sees stays steady even if the twin falls behind), plus right after a frame that
applied a new setpoint (at most one such extra publication every `setpoint_publish_min_interval_s`:
a closer one waits for the next frame after that interval). The regular ticks do not hold a
setpoint's publication back: the state carrying a fresh setpoint goes out at the end of the
frame that applied it even right after a tick (holding it to the interval would delay one setpoint in
ten by a frame at 50 Hz). Such a publication stands for the period's tick: the next regular one
follows a period after it, so setpoints add no snapshots while they come slower than the publish
rate (each snapshot costs its build, its messages, its alarm evaluation and its recording rows),
and the gap between two publications never exceeds a period, but for one case: a frame that an
outside input (a setpoint or defects) cut short publishes nothing (the runner asks
`tick_may_wait`), since the next step applies the input and publishes the tick with it, a
fraction of a millisecond later. The state that carries the input then goes out without a
snapshot built before it, and the setpoint's latency has no extra build (a gap of at most two
periods: with the last publication older than that, the cut frame publishes). A frame cut with
no input waiting (the submitter's interrupt landed after the runner took the input, so it cuts
the very frame that applies it) publishes as due. In fast mode
every 1/publish_rate_hz of SIMULATED time (a scenario's samples sit on a regular grid of
simulated time however fast the machine is).
"""

from __future__ import annotations

import collections
import math
from collections.abc import Callable


class PacingClock:
    """Deadlines, lateness, real-time factor and publishing schedule of one runner (written by
    whichever stepping thread runs the twin's frame; read by any)."""

    def __init__(
        self,
        *,
        fast: bool,
        publish_period_s: float,
        clock: Callable[[], float],
        rtf_window_s: float = 1.0,
        resync_after_s: float = 0.25,
        setpoint_publish_min_interval_s: float = 0.002,
        lateness_s: float = 0.005,
        late_window_s: float = 10.0,
        lead_s: float = 0.0,
    ):
        if not (lateness_s >= 0.0 and math.isfinite(lateness_s)):
            raise ValueError(f"lateness_s = {lateness_s!r}: must be >= 0 [s]")
        if not (lead_s >= 0.0 and math.isfinite(lead_s)):
            raise ValueError(f"lead_s = {lead_s!r}: must be >= 0 [s]")
        self.lead_s = lead_s
        self.fast = fast
        self.publish_period_s = publish_period_s
        self.rtf_window_s = rtf_window_s
        self.resync_after_s = max(resync_after_s, lateness_s)
        self.setpoint_publish_min_interval_s = setpoint_publish_min_interval_s
        self.lateness_s = lateness_s
        self.late_window_s = late_window_s
        self.clock = clock
        self.overruns = 0  # frames that ended more than lateness_s after their deadline
        self.resyncs = 0
        self._rtf: float | None = None
        self._samples: collections.deque[tuple[float, float]] = collections.deque()
        self._late: collections.deque[tuple[float, bool]] = collections.deque()
        self._late_in_window = 0
        self._anchor_wall = self._anchor_sim = 0.0
        self._next_publish_wall = self._next_publish_sim = 0.0
        self._publish_soon = False
        self.last_publish_wall = -math.inf
        self.last_publish_sim = -math.inf
        self.last_setpoint_publish_wall = -math.inf  # the last publication asked by publish_soon

    @property
    def real_time_factor(self) -> float | None:
        return self._rtf

    @property
    def late_fraction(self) -> float | None:
        """Late frames / frames over the last `late_window_s` of wall time (None before any
        real-time frame)."""
        n = len(self._late)
        return self._late_in_window / n if n else None

    def start(self, sim_s: float, *, published: bool = False) -> None:
        """Anchor the schedule at the loop's start (`published`: a snapshot went out just now, the
        runner's initial one, and counts as the last publication's wall time)."""
        now = self.clock()
        self._anchor_wall, self._anchor_sim = now, sim_s
        if published:
            self.last_publish_wall = now
        self._next_publish_wall = now + self.publish_period_s
        self._next_publish_sim = sim_s + self.publish_period_s

    def reanchor(self, sim_s: float, at: float | None = None) -> None:
        """After idling or an error: deadlines count from now (or `at`)."""
        self._anchor_wall, self._anchor_sim = (self.clock() if at is None else at), sim_s

    def restart_sample_grid(self, sim_s: float) -> None:
        """Fast mode: the next sample one period after `sim_s` (a scenario started or ended)."""
        self._next_publish_sim = sim_s + self.publish_period_s

    def deadline(self, sim_s: float) -> float:
        """The wall-clock time at which the simulated clock should read `sim_s` [s]."""
        return self._anchor_wall + (sim_s - self._anchor_sim)

    def measure(self, now: float, sim_s: float) -> None:
        """A frame ended at wall time `now` with `sim_s` simulated: update the real-time factor."""
        samples = self._samples
        samples.append((now, sim_s))
        while len(samples) > 2 and now - samples[0][0] > self.rtf_window_s:
            samples.popleft()
        if len(samples) >= 2:
            dw = now - samples[0][0]
            if dw > 0:
                self._rtf = (sim_s - samples[0][1]) / dw

    def published(self, now: float, sim_s: float) -> None:
        """A snapshot was published at `now` / `sim_s`."""
        self.last_publish_wall, self.last_publish_sim = now, sim_s
        self._publish_soon = False

    def publish_due(self, now: float, sim_s: float, setpoint_changed: bool) -> bool:
        """Whether to publish after this frame (advances the schedule when it says yes)."""
        if self.fast:
            if sim_s >= self._next_publish_sim - 1e-9:
                self._next_publish_sim += self.publish_period_s
                if self._next_publish_sim <= sim_s:
                    self._next_publish_sim = sim_s + self.publish_period_s
                return True
            return False
        if setpoint_changed:
            self._publish_soon = True  # deferred (not dropped) if the last one was too recent
        if now >= self._next_publish_wall:
            self._next_publish_wall += self.publish_period_s
            if self._next_publish_wall <= now:
                self._next_publish_wall = now + self.publish_period_s
            return True
        if self._publish_soon and now - self.last_setpoint_publish_wall >= self.setpoint_publish_min_interval_s:
            self.last_setpoint_publish_wall = now
            self._next_publish_wall = now + self.publish_period_s  # it stands for this period's tick
            return True
        return False

    def tick_may_wait(self, now: float) -> bool:
        """Whether a publication due now may wait for the next frame: true while the last one is
        less than two periods old (real-time mode), so waiting never leaves a gap of more than
        two periods."""
        return not self.fast and now - self.last_publish_wall < 2.0 * self.publish_period_s

    def publish_soon(self) -> None:
        """Publish at the next frame (subject to the minimum interval)."""
        self._publish_soon = True

    def frame_done(self, now: float, sim_s: float) -> float:
        """A frame ended at `now` with the simulated clock at `sim_s`: count it late or not
        (real-time mode) and return when the next frame may start [wall-clock s]: its release
        (`lead_s` before the wall clock reaches `sim_s`), `now` itself when the twin is behind
        (and always in fast mode)."""
        if self.fast:
            return now
        behind = now - self.deadline(sim_s)
        late = behind > self.lateness_s
        if late:
            self.overruns += 1
        self._count_late(now, late)
        if behind > self.resync_after_s:
            self.resyncs += 1
            self._anchor_wall, self._anchor_sim = now, sim_s
            return now
        return max(now, self.deadline(sim_s) - self.lead_s)

    def _count_late(self, now: float, late: bool) -> None:
        w = self._late
        w.append((now, late))
        self._late_in_window += late
        while w and now - w[0][0] > self.late_window_s:
            _, was_late = w.popleft()
            self._late_in_window -= was_late
