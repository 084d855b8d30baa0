"""Engine benchmark: the twin `serve` runs by default, at its default step and at 1 us,
further cases, and the per-pass timing of the step.

- `real_time_factor`, `time_step_s`: the twin `bearing-twin serve` starts (6208, 3000 N,
  500 rad/s, 40 degC, no current) at its default step (`time_step_s = "auto"`, `twin.timestep`);
  `real_time_factor_1us`: the same twin at the seed's 1 us;
- `cases`: the electro-thermal coupling on (5 A shaft current, current and inlet shear heating fed
  back into the film every 10 ms), the 7208 under Fr = Fa = 3000 N, the 6208 at 1700 rad/s and
  7500 N, the 6208 with its outer ring on the housing (housing DOFs, in-kernel
  accelerometer decimation, the sample drain every frame) healthy and with a 0.5 mm outer-race
  spall (defect drops), and healthy with the race profiles and ball sizes on (twin.vibration.surface);
  the CWRU rig's drive end (`CWRU-DE`: housing, rotor and race profiles) at 1797 rpm;
  each at its default step and at 1 us (snapped to 1 / (20 x 51.2 kHz) with
  the housing on). With the housing on, the indicators of a window (Python, once per
  `Accelerometer.window_s`) are timed apart (`indicator_window_s`, best of `repeats`) and
  `real_time_factor` includes their share, `real_time_factor_kernel` does not; and seed 003's EV
  case (`EV_20K`: the 6200 at 20 000 rpm, 200 N, 10 A with current and shear heating, as
  `twin.validation.studies.ev_operating_point` runs it for Figs. 8 and 10), whose auto step is the
  shortest of all;
- every figure: best and median real-time factor (simulated s per wall s) of `repeats` (>= 5)
  runs of `seconds` simulated seconds each, and ns per step; `cpu_real_time_factor`: simulated s
  per CPU s of the stepping thread (what the twin would run at with a core to itself: on a
  shared, loaded machine the wall-clock figure also counts the time the thread waited for a core);
- `passes`: ns per step (CPU time of the thread) of gather, geometry, forces, tribology,
  traction, cage and integration (`twin.validation.step_timing`, a harness that times each pass
  alone), at the default step; `passes_ev`: the same for the EV case, with what its step would
  have to cost for real time (`ns_per_step_for_real_time` = its auto step).

Wall-clock figures belong here and in benchmarks/results/ (`bench --save`), never in tests (machines are
shared and noisy).
"""

from __future__ import annotations

import math
import os
import statistics
import time
from dataclasses import asdict, dataclass
from typing import Any, Literal

import numpy as np

from twin import catalog
from twin.accelerometer import window_indicators
from twin.engine import Twin
from twin.setpoint import Setpoint
from twin.spec import BearingSpec, ModelOptions
from twin.validation.step_timing import time_passes
from twin.validation.studies import EV_BEARING, EV_RADIAL_LOAD_N
from twin.validation.vibration_simulation import defect_for

MIN_REPEATS = 5
MAX_REPEATS = 100
MAX_SECONDS = 60.0  # simulated time per repeat and case, at most [s]


@dataclass(frozen=True)
class BenchCase:
    """One benchmarked operating point (SI)."""

    id: str
    designation: str = "6208"
    shaft_speed_rad_s: float = 500.0
    radial_load_n: float = 3000.0
    axial_load_n: float = 0.0
    shaft_current_a: float = 0.0
    shear_heating: bool | None = None  # inlet shear heating (None: the spec's default, on)
    housing: bool | None = None  # outer ring on the housing (None: the spec's default, off)
    defect: str | None = None  # local defect of twin.validation.vibration_simulation.defect_for (outer, inner, ball)
    surface_profile: bool = False  # race profiles and ball sizes exciting the contacts (twin.vibration.surface)


SERVE_DEFAULT = BenchCase("serve-default")  # Twin("6208")'s default setpoint, what `serve` runs
CASES: tuple[BenchCase, ...] = (
    BenchCase("ev-5A-heating", shaft_current_a=5.0, shear_heating=True),
    BenchCase("7208-combined", designation="7208", axial_load_n=3000.0),
    BenchCase("6208-1700rad-7.5kN", shaft_speed_rad_s=1700.0, radial_load_n=7500.0),
    BenchCase("vibration-healthy", housing=True),
    BenchCase("vibration-outer-spall", housing=True, defect="outer"),
    BenchCase("vibration-healthy-profile", housing=True, surface_profile=True),
    # the CWRU rig as `python -m twin.validation.cwru` runs it: housing, rotor, race profiles
    BenchCase(
        "vibration-cwru-de",
        designation="CWRU-DE",
        shaft_speed_rad_s=1797.0 * math.pi / 30.0,
        radial_load_n=catalog.CWRU_RADIAL_LOAD_N,
        surface_profile=True,
    ),
)
EV_20K = BenchCase(
    "ev-6200-20krpm",
    designation=EV_BEARING,
    shaft_speed_rad_s=20000.0 * math.pi / 30.0,
    radial_load_n=EV_RADIAL_LOAD_N,
    shaft_current_a=10.0,
    shear_heating=True,
)
CASES = (*CASES, EV_20K)


def _twin(case: BenchCase, time_step_s: float | Literal["auto"]) -> Twin:
    spec = catalog.bearing(case.designation)
    if case.shear_heating is not None and case.shear_heating != spec.thermal.shear_heating:
        spec = BearingSpec.model_validate(
            {**spec.model_dump(), "thermal": {**spec.thermal.model_dump(), "shear_heating": case.shear_heating}}
        )
    if case.housing is not None and case.housing != spec.housing.enabled:
        spec = BearingSpec.model_validate(
            {**spec.model_dump(), "housing": {**spec.housing.model_dump(), "enabled": case.housing}}
        )
    if case.surface_profile != spec.surface_profile.enabled:
        spec = BearingSpec.model_validate(
            {
                **spec.model_dump(),
                "surface_profile": {**spec.surface_profile.model_dump(), "enabled": case.surface_profile},
            }
        )
    twin = Twin(
        spec,
        options=ModelOptions(time_step_s=time_step_s),
        setpoint=Setpoint(
            shaft_speed_rad_s=case.shaft_speed_rad_s,
            radial_load_n=case.radial_load_n,
            axial_load_n=case.axial_load_n,
            shaft_current_a=case.shaft_current_a,
        ),
    )
    if case.defect is not None:
        twin.set_defects([defect_for(case.defect, spec.geometry)])
    return twin


def measure(
    case: BenchCase, time_step_s: float | Literal["auto"] = "auto", seconds: float = 0.2, repeats: int = MIN_REPEATS
) -> dict:
    """Best and median real-time factor and ns per step of `repeats` runs of `seconds`; with the
    outer ring on the housing the indicators of one window are timed apart and their share per
    simulated second added (module docstring)."""
    twin = _twin(case, time_step_s)
    twin.advance(0.002)  # compile / warm caches
    factors, cpu_factors = [], []
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.thread_time()
        twin.advance(seconds)
        factors.append(seconds / (time.perf_counter() - t0))
        cpu_factors.append(seconds / max(time.thread_time() - c0, 1e-9))
    dt = twin.model.dt_s
    best, median = max(factors), statistics.median(factors)
    out: dict[str, Any] = {
        "time_step_s": dt,
        "real_time_factor": best,
        "real_time_factor_median": median,
        "ns_per_step": dt / best * 1e9,
        "ns_per_step_median": dt / median * 1e9,
        "cpu_real_time_factor": max(cpu_factors),
        "cpu_real_time_factor_median": statistics.median(cpu_factors),
        "repeats": repeats,
        "housing": twin.model.housing_on,
        "defects": len(twin.defects),
        "status": twin.status,
    }
    if twin.model.housing_on:
        reader = twin._sensor
        assert reader is not None  # the housing's accelerometer
        window = np.random.default_rng(0).standard_normal(reader.window_samples)
        costs, cpu_costs = [], []
        for _ in range(repeats):
            t0, c0 = time.perf_counter(), time.thread_time()
            window_indicators(twin.model, window, case.shaft_speed_rad_s, twin.state, twin.time_s)
            costs.append(time.perf_counter() - t0)
            cpu_costs.append(time.thread_time() - c0)
        share = min(costs) / reader.window_s  # wall s per simulated s
        cpu_share = min(cpu_costs) / reader.window_s
        out.update(
            {
                "indicator_window_s": min(costs),
                "window_s": reader.window_s,
                "real_time_factor_kernel": best,
                "real_time_factor_kernel_median": median,
                "real_time_factor": 1.0 / (1.0 / best + share),
                "real_time_factor_median": 1.0 / (1.0 / median + share),
                "cpu_real_time_factor": 1.0 / (1.0 / out["cpu_real_time_factor"] + cpu_share),
                "cpu_real_time_factor_median": 1.0 / (1.0 / out["cpu_real_time_factor_median"] + cpu_share),
            }
        )
        out["ns_per_step"] = dt / out["real_time_factor"] * 1e9
        out["ns_per_step_median"] = dt / out["real_time_factor_median"] * 1e9
    return out


def run_engine_benchmark(
    seconds: float = 0.2, repeats: int = MIN_REPEATS, *, cases: bool = True, passes: bool = True
) -> dict:
    """The benchmark (module docstring). `cases` / `passes`: include those parts."""
    if not MIN_REPEATS <= repeats <= MAX_REPEATS:
        raise ValueError(f"repeats = {repeats}: must be in [{MIN_REPEATS}, {MAX_REPEATS}]")
    if not (math.isfinite(seconds) and 0.0 < seconds <= MAX_SECONDS):
        raise ValueError(f"seconds = {seconds!r}: must be in (0, {MAX_SECONDS:g}] s of simulated time per repeat")
    load_before = os.getloadavg()
    auto = measure(SERVE_DEFAULT, "auto", seconds, repeats)
    one = measure(SERVE_DEFAULT, 1e-6, seconds, repeats)
    result = {
        **asdict(SERVE_DEFAULT),
        "bearing": SERVE_DEFAULT.designation,
        "simulated_seconds_per_repeat": seconds,
        "repeats": repeats,
        "time_step_s": auto["time_step_s"],
        "real_time_factor": auto["real_time_factor"],
        "real_time_factor_median": auto["real_time_factor_median"],
        "ns_per_step": auto["ns_per_step"],
        "ns_per_step_median": auto["ns_per_step_median"],
        "status": auto["status"],
        "real_time_factor_1us": one["real_time_factor"],
        "real_time_factor_1us_median": one["real_time_factor_median"],
        "ns_per_step_1us": one["ns_per_step"],
        "ns_per_step_1us_median": one["ns_per_step_median"],
        "cpu_real_time_factor": auto["cpu_real_time_factor"],
        "cpu_real_time_factor_median": auto["cpu_real_time_factor_median"],
        "cpu_real_time_factor_1us": one["cpu_real_time_factor"],
        "cpu_real_time_factor_1us_median": one["cpu_real_time_factor_median"],
    }
    if cases:
        result["cases"] = [
            {
                **asdict(c),
                "default_step": measure(c, "auto", seconds, repeats),
                "step_1us": measure(c, 1e-6, seconds, repeats),
            }
            for c in CASES
        ]
    if passes:
        twin = _twin(SERVE_DEFAULT, "auto")
        twin.advance(0.005)
        result["passes"] = time_passes(twin, repeats=repeats)
        result["passes_ev"] = ev_passes(repeats)
    result["load_average_1min"] = [load_before[0], os.getloadavg()[0]]  # before, after
    result["cpu_count"] = os.cpu_count()
    return result


def ev_passes(repeats: int = MIN_REPEATS) -> dict:
    """The step of the EV case pass by pass (`step_timing.time_passes`), with the cost per step
    that real time allows (its auto step) [ns]."""
    twin = _twin(EV_20K, "auto")
    twin.advance(0.005)
    return {
        **time_passes(twin, repeats=repeats),
        "time_step_s": twin.model.dt_s,
        "ns_per_step_for_real_time": twin.model.dt_s * 1e9,
    }


def summary_text(result: dict) -> str:
    """The benchmark as a few lines of text (what `bearing-twin bench` prints without --json)."""

    def fig(r: dict, key: str = "") -> str:
        return (
            f"real-time factor {r[f'real_time_factor{key}']:.2f} best / {r[f'real_time_factor{key}_median']:.2f} "
            f"median, {r[f'ns_per_step{key}']:.0f} ns per step"
        )

    lines = [
        f"{result['bearing']} at {result['radial_load_n']:.0f} N, {result['shaft_speed_rad_s']:.0f} rad/s, "
        f"best and median of {result['repeats']} x {result['simulated_seconds_per_repeat']:g} s:",
        f"  default step dt = {result['time_step_s'] * 1e6:.3f} us: {fig(result)}",
        f"  dt = 1 us: {fig(result, '_1us')}",
        f"  per CPU second of the stepping thread: {result['cpu_real_time_factor']:.2f} (default step), "
        f"{result['cpu_real_time_factor_1us']:.2f} (1 us)",
    ]
    for c in result.get("cases", []):
        d, o = c["default_step"], c["step_1us"]
        lines.append(f"  {c['id']}: dt = {d['time_step_s'] * 1e6:.3f} us: {fig(d)}; 1 us: {fig(o)}")
    for key, what in (("passes", ""), ("passes_ev", f" of {EV_20K.id}")):
        p = result.get(key)
        if p:
            parts = ", ".join(
                f"{k} {p[k]['best_ns']:.0f}"
                for k in ("gather", "geometry", "forces", "tribology", "traction", "cage", "integration")
            )
            budget = (
                f"; real time needs <= {p['ns_per_step_for_real_time']:.0f}" if "ns_per_step_for_real_time" in p else ""
            )
            lines.append(
                f"  per pass{what}, ns per step (best): {parts}; sum {p['sum_of_passes']['best_ns']:.0f}, "
                f"step_n {p['total']['best_ns']:.0f}{budget}"
            )
    lines.append(
        f"  load average (1 min) before / after: {result['load_average_1min'][0]:.2f} / "
        f"{result['load_average_1min'][1]:.2f}"
    )
    return "\n".join(lines)
