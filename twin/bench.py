"""Engine benchmark: real-time factor of the full model (6208, 3000 N, 500 rad/s, dt = 1 us).

Wall-clock figures belong here and in README, never in tests (machines are shared and noisy).
"""

from __future__ import annotations

import statistics
import time

from twin.engine import Twin
from twin.setpoint import Setpoint


def run_engine_benchmark(seconds: float = 0.2, repeats: int = 5, bearing: str = "6208",
                         radial_load_n: float = 3000.0, shaft_speed_rad_s: float = 500.0) -> dict:
    """Best and median real-time factor (simulated s per wall s) over `repeats` runs."""
    twin = Twin(bearing, setpoint=Setpoint(shaft_speed_rad_s=shaft_speed_rad_s, radial_load_n=radial_load_n))
    twin.advance(0.002)  # compile / warm caches
    factors = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        twin.advance(seconds)
        wall = time.perf_counter() - t0
        factors.append(seconds / wall)
    best = max(factors)
    dt = twin.model.dt_s
    return {
        "bearing": bearing, "radial_load_n": radial_load_n, "shaft_speed_rad_s": shaft_speed_rad_s,
        "time_step_s": dt, "simulated_seconds_per_repeat": seconds, "repeats": repeats,
        "real_time_factor": best, "real_time_factor_median": statistics.median(factors),
        "ns_per_step": dt / best * 1e9, "status": twin.status,
    }
