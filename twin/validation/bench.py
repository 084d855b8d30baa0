"""Engine benchmark: real-time factor of the full model (6208, 3000 N, 500 rad/s, dt = 1 us), with
everything on: tribology every 10 us, electrical RC every 100 us, and the electro-thermal coupling
of seed 003 (5 A shaft current, current and inlet shear heating fed back into the film every 10 ms).

Wall-clock figures belong here and in README, never in tests (machines are shared and noisy).
"""

from __future__ import annotations

import statistics
import time

from twin import catalog
from twin.engine import Twin
from twin.spec import BearingSpec
from twin.setpoint import Setpoint


def run_engine_benchmark(seconds: float = 0.2, repeats: int = 5, bearing: str = "6208",
                         radial_load_n: float = 3000.0, shaft_speed_rad_s: float = 500.0,
                         shaft_current_a: float = 5.0, shear_heating: bool = True) -> dict:
    """Best and median real-time factor (simulated s per wall s) over `repeats` runs."""
    spec = catalog.bearing(bearing)
    spec = BearingSpec.model_validate({**spec.model_dump(), "thermal": {**spec.thermal.model_dump(),
                                                                        "shear_heating": shear_heating}})
    twin = Twin(spec, setpoint=Setpoint(shaft_speed_rad_s=shaft_speed_rad_s, radial_load_n=radial_load_n,
                                        shaft_current_a=shaft_current_a))
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
        "shaft_current_a": shaft_current_a, "shear_heating": shear_heating, "time_step_s": dt, "simulated_seconds_per_repeat": seconds, "repeats": repeats,
        "real_time_factor": best, "real_time_factor_median": statistics.median(factors),
        "ns_per_step": dt / best * 1e9, "status": twin.status,
    }
