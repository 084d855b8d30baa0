"""The pacing clock of a runner: frame deadlines, real-time factor, publishing schedule.

Real-time mode: frame k ends at the deadline `anchor + k * frame_s` on the monotonic clock; a
frame that finishes after its deadline is an overrun (counted), the loop then does not sleep and
catches up on the following frames. If it falls more than `resync_after_s` behind (a stall, a
cold JIT compile) the schedule is re-anchored (`resyncs`) instead of racing to catch up. Fast
mode never sleeps.

Real-time factor: simulated / wall time over a sliding window (`rtf_window_s`, 1 s).

Publishing (choice): in real-time mode every 1/publish_rate_hz of WALL time (what a viewer or a
zenoh subscriber sees stays steady even if the twin falls behind), plus right after a frame that
applied a new setpoint (at most every `setpoint_publish_min_interval_s`; a closer one waits for
the next frame after that interval); in fast mode every 1/publish_rate_hz of SIMULATED time (a
scenario's samples sit on a regular grid of simulated time however fast the machine is).
"""

from __future__ import annotations

import collections
import math
import threading
from collections.abc import Callable


class PacingClock:
    """Deadlines, real-time factor and publishing schedule of one runner (runner thread only)."""

    def __init__(self, *, fast: bool, publish_period_s: float, clock: Callable[[], float],
                 rtf_window_s: float = 1.0, resync_after_s: float = 0.25,
                 setpoint_publish_min_interval_s: float = 0.002):
        self.fast = fast
        self.publish_period_s = publish_period_s
        self.rtf_window_s = rtf_window_s
        self.resync_after_s = resync_after_s
        self.setpoint_publish_min_interval_s = setpoint_publish_min_interval_s
        self.clock = clock
        self.overruns = 0
        self.resyncs = 0
        self._rtf: float | None = None
        self._samples: collections.deque[tuple[float, float]] = collections.deque()
        self._anchor_wall = self._anchor_sim = 0.0
        self._next_publish_wall = self._next_publish_sim = 0.0
        self._publish_soon = False
        self.last_publish_wall = -math.inf
        self.last_publish_sim = -math.inf

    @property
    def real_time_factor(self) -> float | None:
        return self._rtf

    def start(self, sim_s: float) -> None:
        """Anchor the schedule at the loop's start."""
        now = self.clock()
        self._anchor_wall, self._anchor_sim = now, sim_s
        self._next_publish_wall = now + self.publish_period_s
        self._next_publish_sim = sim_s + self.publish_period_s

    def reanchor(self, sim_s: float) -> None:
        """After idling or an error: deadlines count from now."""
        self._anchor_wall, self._anchor_sim = self.clock(), sim_s

    def restart_sample_grid(self, sim_s: float) -> None:
        """Fast mode: the next sample one period after `sim_s` (a scenario started or ended)."""
        self._next_publish_sim = sim_s + self.publish_period_s

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
            self._publish_soon = True   # deferred (not dropped) if the last one was too recent
        if now >= self._next_publish_wall:
            self._next_publish_wall += self.publish_period_s
            if self._next_publish_wall <= now:
                self._next_publish_wall = now + self.publish_period_s
            return True
        return self._publish_soon and now - self.last_publish_wall >= self.setpoint_publish_min_interval_s

    def publish_soon(self) -> None:
        """Publish at the next frame (subject to the minimum interval)."""
        self._publish_soon = True

    def wait_for_deadline(self, now: float, sim_s: float, stop: threading.Event) -> None:
        """Real-time mode: sleep until the frame's deadline (or count an overrun, re-anchoring
        when far behind). Fast mode: return at once."""
        if self.fast:
            return
        late = now - (self._anchor_wall + (sim_s - self._anchor_sim))
        if late > 0.0:
            self.overruns += 1
            if late > self.resync_after_s:
                self.resyncs += 1
                self._anchor_wall, self._anchor_sim = now, sim_s
        else:
            stop.wait(-late)
