"""Per-pass timing of one step: gather, geometry, forces, tribology, traction, cage,
integration.

`twin.kernels.step.compute_accelerations` runs its passes inline in one compiled function, so a
profiler cannot split them. This harness times each pass on its own, on a copy of a settled
twin's state, each in its own compiled loop of `reps` calls (no Python between calls), in CPU
time of the calling thread (what the pass costs, not the waits for a core on a shared machine):

- geometry, forces: the kernel's own `raceway_geometry` and `raceway_forces` on the lanes padded
  to whole vectors as the step runs them (`layout.padded_lane_count`);
- tribology: the kernel's per-contact pass (copy of its loop) with the kernel's own
  `refresh_contact`, timed without refresh, with the tribology refresh and with the electrical
  refresh too (every refreshed contact gets its RC then: with `electrical_now` False the
  kernel still refreshes an RC that is 0); per step it costs the first plus the refreshes
  divided by their periods in steps (the model's tribology sub-rate, x ELECTRICAL_EVERY);
- traction: the kernel's own `apply_traction_moments` (every step) plus its `ellipse_traction`
  (the strip solve) divided by its period in steps (tribology sub-rate x P_TRACTION_EVERY);
- cage: the kernel's own `ball_loads_and_cage` (the per-ball force sums and the ball-cage
  contacts, on the velocities turned by the half step of the cage);
- gather: the kernel's own `gather_lanes` (the lanes filled from the ball and ring state, with
  the pad lanes);
- integration (the leapfrog kicks and drifts of `step_n` and the turn's cosine and sine): a copy
  of the kernel's inline loop.

The integration copy mirrors `twin/kernels/step.py` as of this writing; `total` is `step_n` itself, so the
sum of the passes against `total` shows how far the harness is from the real step (call
overheads and what LLVM fuses or hoists across passes).
"""

from __future__ import annotations

import math
import statistics
import time
from typing import Any

from numba import njit

from twin.jit import JIT, JIT_STEP
from twin.kernels.contacts import raceway_forces, raceway_geometry
from twin.kernels.layout import (
    C_LOAD,
    CW,
    E_SLIP,
    G_DELTA,
    G_LOAD,
    K_ORBIT,
    O_FX,
    O_TX,
    P_ALPHA_E,
    P_BALL_INERTIA,
    P_BALL_RADIUS,
    P_CAGE_INERTIA,
    P_DT,
    P_KT_RATIO,
    P_SUBSTEPS,
    P_TRACTION_EVERY,
    S_VISCOSITY,
    X_CAGE_ANGLE,
    X_CAGE_SPEED,
    X_CAGE_TORQUE,
    padded_lane_count,
)
from twin.kernels.step import ELECTRICAL_EVERY, _cos_sin, ball_loads_and_cage, gather_lanes, refresh_contact, step_n
from twin.kernels.structures import StateArrays
from twin.kernels.traction import apply_traction_moments, ellipse_traction

PASSES = ("gather", "geometry", "forces", "tribology", "traction", "cage", "integration")


@njit(**JIT_STEP)
def _gather(bx, bv, bw, rx, rv, scal, w, ct, st, reps):
    acc = 0.0
    for _ in range(reps):
        gather_lanes(scal, bx, bv, bw, rx, rv, w, ct, st)
        acc += w[K_ORBIT * CW]
    return acc


@njit(**JIT_STEP)
def _geometry(w, nc, reps):
    for _ in range(reps):
        raceway_geometry(w, nc)
    return w[G_DELTA * CW]


@njit(**JIT_STEP)
def _forces(w, nc, rb, dt, kt_ratio, alpha_e, reps):
    for _ in range(reps):
        raceway_forces(w, nc, rb, dt, kt_ratio, alpha_e)
    return w[O_FX * CW]


@njit(**JIT_STEP)
def _tribology(p, tr, sp, w, nc, tribology_now, electrical_now, reps):
    eta = sp[S_VISCOSITY]
    max_pen = 0.0
    for i in range(reps):
        stamp = (i + 1.0) * p[P_SUBSTEPS]  # a refresh every P_SUBSTEPS steps: the centring is timed too
        for c in range(nc):
            delta = w[G_DELTA * CW + c]
            if delta <= 0.0:
                continue
            if delta > max_pen:
                max_pen = delta
            q_el = w[G_LOAD * CW + c]
            w[C_LOAD * CW + c] = q_el
            if tribology_now:
                refresh_contact(p, tr, w, c, q_el, eta, electrical_now, stamp)
    return max_pen


@njit(**JIT_STEP)
def _traction_moments(w, nl, reps):
    for _ in range(reps):
        apply_traction_moments(w, nl)
    return w[O_TX * CW]


@njit(**JIT)
def _traction_solve(w, nc, p, eta, reps):
    # every solve from the same warm start (the last solution of the running twin), not from the
    # previous solve's own solution, which would converge at once
    start = w[E_SLIP * CW : E_SLIP * CW + nc].copy()
    for _ in range(reps):
        for c in range(nc):
            w[E_SLIP * CW + c] = start[c]
        ellipse_traction(w, nc, p, eta, p[P_KT_RATIO], p[P_BALL_INERTIA], p[P_DT])
    return w[O_TX * CW]


@njit(**JIT_STEP)
def _cage(p, scal, bx, bv, ba, balpha, w, cage_load, ct, st, reps):
    acc = 0.0
    for _ in range(reps):
        ring_fx, ring_fy, ring_fz, ring_tz, cage_tz = ball_loads_and_cage(
            p, scal, bx, bv, ba, balpha, w, cage_load, ct, st
        )
        acc += cage_tz + ring_tz + ring_fx + 1e-300 * (ring_fy + ring_fz)
    return acc


@njit(**JIT_STEP)
def _integration(p, scal, bx, bv, bw, ba, balpha, rx, rv, ra, reps):
    z = bx.shape[0]
    dt = p[P_DT]
    half = 0.5 * dt
    cage_inertia = p[P_CAGE_INERTIA]
    for _ in range(reps):
        for j in range(z):
            for k in range(3):
                bv[j, k] += dt * ba[j, k]
                bw[j, k] += dt * balpha[j, k]
                bx[j, k] += dt * bv[j, k]
        for k in range(3):
            rv[k] += dt * ra[k]
            rx[k] += dt * rv[k]
        scal[X_CAGE_SPEED] += dt * scal[X_CAGE_TORQUE] / cage_inertia
        scal[X_CAGE_ANGLE] += dt * scal[X_CAGE_SPEED]
        ct, st = _cos_sin(half * scal[X_CAGE_SPEED])  # the turn, applied as gather and cage read
        scal[X_CAGE_TORQUE] += 1e-300 * (ct + st)
    return bx[0, 0]


def _best_median_ns(fn, reps: int, repeats: int) -> tuple[float, float]:
    times = []
    for _ in range(repeats):  # CPU time of this thread: what the pass costs, not the waits for a core
        t0 = time.thread_time()
        fn(reps)
        times.append((time.thread_time() - t0) / reps * 1e9)
    return min(times), statistics.median(times)


def time_passes(twin, reps: int = 20000, repeats: int = 5) -> dict:
    """ns per step of each pass (best and median of `repeats` loops of `reps` calls) on copies of
    the twin's state, and of `step_n` itself (`total`); see the module docstring."""
    m, s = twin.model, twin.state
    p, tr, sp = m.params, m.angle_table, twin._setpoint_vector
    nc = 2 * m.ball_count
    nl = padded_lane_count(nc)
    substeps = int(p[P_SUBSTEPS])
    traction_steps = substeps * max(int(p[P_TRACTION_EVERY]), 1)

    def copies():
        return StateArrays(
            *(a.copy() for a in s.arrays())
        )  # scal, bx, bv, bw, ba, balpha, rx, rv, ra, w, cage_load, ...

    scal, bx, bv, bw, ba, balpha, rx, rv, ra, w, cage_load = copies()[:11]
    ct, st = math.cos(0.5 * p[P_DT] * scal[X_CAGE_SPEED]), math.sin(0.5 * p[P_DT] * scal[X_CAGE_SPEED])
    runs = {
        "gather": lambda n: _gather(bx, bv, bw, rx, rv, scal, w, ct, st, n),
        "geometry": lambda n: _geometry(w, nl, n),
        "forces": lambda n: _forces(w, nl, p[P_BALL_RADIUS], p[P_DT], p[P_KT_RATIO], p[P_ALPHA_E], n),
        "traction_moments": lambda n: _traction_moments(w, nl, n),
        "traction_solve": lambda n: _traction_solve(w, nc, p, sp[S_VISCOSITY], n),
        "tribology_no_refresh": lambda n: _tribology(p, tr, sp, w, nc, False, False, n),
        "tribology_refresh": lambda n: _tribology(p, tr, sp, w, nc, True, False, n),
        "tribology_refresh_electrical": lambda n: _tribology(p, tr, sp, w, nc, True, True, n),
        "cage": lambda n: _cage(p, scal, bx, bv, ba, balpha, w, cage_load, ct, st, n),
    }
    for fn in runs.values():  # compile
        fn(1)
    out: dict[str, Any] = {}
    for name, fn in runs.items():
        if name == "traction_solve":  # a solve costs ~100 steps: a hundredth of the calls, per call
            best, median = _best_median_ns(fn, max(reps // 100, 1), repeats)
        else:
            best, median = _best_median_ns(fn, reps, repeats)
        out[name] = {"best_ns": best, "median_ns": median}
    ig = copies()
    _integration(p, ig[0], ig[1], ig[2], ig[3], ig[4], ig[5], ig[6], ig[7], ig[8], 1)
    best, median = _best_median_ns(
        lambda n: _integration(p, ig[0], ig[1], ig[2], ig[3], ig[4], ig[5], ig[6], ig[7], ig[8], n), reps, repeats
    )
    out["integration"] = {"best_ns": best, "median_ns": median}
    # per step: the refreshes weighted by their periods in steps
    t0, t1, t2 = (out[k] for k in ("tribology_no_refresh", "tribology_refresh", "tribology_refresh_electrical"))
    out["tribology"] = {
        key: t0[key] + (t1[key] - t0[key]) / substeps + (t2[key] - t1[key]) / (substeps * ELECTRICAL_EVERY)
        for key in ("best_ns", "median_ns")
    }
    out["traction"] = {
        key: out["traction_moments"][key] + out["traction_solve"][key] / traction_steps
        for key in ("best_ns", "median_ns")
    }
    # the real step on a copy of the state
    full = copies()
    model_arrays = m.arrays()
    n_total = max(1000, reps // 10)
    step_n(model_arrays, full, sp, 10)
    best, median = _best_median_ns(lambda n: step_n(model_arrays, full, sp, n), n_total, repeats)
    out["total"] = {"best_ns": best, "median_ns": median}
    out["sum_of_passes"] = {key: sum(out[k][key] for k in PASSES) for key in ("best_ns", "median_ns")}
    out["tribology_steps_per_refresh"] = substeps
    out["electrical_steps_per_refresh"] = substeps * ELECTRICAL_EVERY
    out["traction_steps_per_solve"] = traction_steps
    return out
