"""Film-reduction factor for the real-time loop, calibrated with the thermal EHL solver (seed 003).

factor(I, u) = h_min(current I, shear + current heating) / h_min(isothermal)   (same speed u)

is what the twin's in-loop film formula (Hamrock-Dowson / Masjedi-Khonsari at the oil
temperature, an isothermal law) is multiplied by to account for the heating of seed 003 eqs.
6-10. `generate_table` runs the solver over currents 0-30 A and the speeds of seed 003 Fig. 1
(0.832-4.16 m/s) at the Appendix 2 inputs and writes `film_reduction_table.json` with its
provenance (inputs, grid, date, command); `film_reduction_factor` interpolates it (bilinear,
pure numpy), `table_arrays` + `interp_factor` give the numba-friendly form.

The one free parameter, the equivalent bearing resistance R_b of eq. 10, is anchored by
`anchor_bearing_resistance`: 84.8 % minimum-film reduction at 30 A and the default speed (the
top of the 57.6-84.8 % band of seed 003 Fig. 2; Fig. 5: 30 A is the largest current). Every other
entry of the table is a consequence of eqs. 3, 6 and 10, not a fit.

Cells where the solver does not converge (films of a few nanometres at low speed and high
current, beyond what the grid resolves) are filled by a temperature-viscosity extrapolation and
flagged `extrapolated`: ln f(I, u) = ln f(0, u) + c(u) ln g(T_obn), g the Hamrock-Dowson film
ratio (eta(T)/eta0)^0.68 (alpha*(T)/alpha)^0.49 of Roelands at ambient pressure and c(u) fitted
on the converged cells of the same speed.

Regenerate: `bearing-twin ehl calibrate` (or `python -m twin.ehl_solver.film_reduction`).
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import sys
import time
from functools import lru_cache
from pathlib import Path

import numpy as np
from numba import njit

from twin.ehl_solver import params as prm
from twin.ehl_solver.solver import solve_point_contact
from twin.jit import JIT
from twin.physics.thermal import hamrock_dowson_temperature_film_ratio

TABLE_PATH = Path(__file__).with_name("film_reduction_table.json")
SCHEMA = "bearing-twin/ehl-film-reduction/1"
DEFAULT_CURRENTS_A = (0.0, 5.0, 10.0, 15.0, 20.0, 25.0, 30.0)
DEFAULT_SPEEDS_M_S = prm.SEED_SPEEDS_M_S
CALIBRATION_GRID = 257
SEED_REDUCTION_BAND = (0.576, 0.848)  # seed 003 Fig. 2, reduction of the minimum film
ANCHOR_CURRENT_A = 30.0


def _solve(
    current_a: float,
    speed: float,
    *,
    thermal: bool,
    grid: int,
    bearing_resistance_ohm: float,
    load_n: float,
    base_temperature_c: float,
    max_iter: int = 200,
):
    return solve_point_contact(
        load_n,
        speed,
        current_a=current_a,
        thermal=thermal,
        grid=grid,
        bearing_resistance_ohm=bearing_resistance_ohm,
        base_temperature_c=base_temperature_c,
        max_iter=max_iter,
    )


def anchor_bearing_resistance(
    *,
    target_reduction: float = SEED_REDUCTION_BAND[1],
    current_a: float = ANCHOR_CURRENT_A,
    entrainment_speed_m_s: float = prm.DEFAULT_ENTRAINMENT_SPEED_M_S,
    grid: int = CALIBRATION_GRID,
    r0_ohm: float = 2.5e-4,
    r1_ohm: float = 3.0e-4,
    rel_tol: float = 0.005,
    max_steps: int = 8,
    load_n: float = prm.LOAD_N,
    base_temperature_c: float = prm.BASE_TEMPERATURE_C,
    log=None,
) -> dict:
    """R_b [ohm] such that h_min(current) / h_min(isothermal) = 1 - target_reduction, by a secant
    iteration on ln(factor) against ln(R_b). Returns {"bearing_resistance_ohm", "factor", steps}."""
    iso = _solve(
        0.0,
        entrainment_speed_m_s,
        thermal=False,
        grid=grid,
        bearing_resistance_ohm=0.0,
        load_n=load_n,
        base_temperature_c=base_temperature_c,
    )
    if not iso.converged:
        raise RuntimeError(f"isothermal reference did not converge: {iso.message}")
    target = 1.0 - target_reduction
    steps = []

    def factor(r_ohm: float) -> float:
        res = _solve(
            current_a,
            entrainment_speed_m_s,
            thermal=True,
            grid=grid,
            bearing_resistance_ohm=r_ohm,
            load_n=load_n,
            base_temperature_c=base_temperature_c,
        )
        f = res.h_min_m / iso.h_min_m if res.converged else float("nan")
        steps.append({"bearing_resistance_ohm": r_ohm, "factor": f, "converged": res.converged})
        if log:
            log(f"  R_b = {r_ohm:.4e} ohm -> h_min factor {f:.4f} ({res.message or 'converged'})")
        return f

    x0, x1 = math.log(r0_ohm), math.log(r1_ohm)
    f0, f1 = factor(r0_ohm), factor(r1_ohm)
    for _ in range(max_steps):
        if not (f0 > 0 and f1 > 0):
            raise RuntimeError(f"anchor solve did not converge: {steps}")
        if abs(f1 / target - 1.0) < rel_tol:
            break
        g0, g1 = math.log(f0 / target), math.log(f1 / target)
        if g1 == g0:
            break
        x2 = x1 - g1 * (x1 - x0) / (g1 - g0)
        x0, f0 = x1, f1
        x1 = x2
        f1 = factor(math.exp(x1))
    return {
        "bearing_resistance_ohm": math.exp(x1),
        "factor": f1,
        "target_factor": target,
        "current_a": current_a,
        "entrainment_speed_m_s": entrainment_speed_m_s,
        "grid": grid,
        "isothermal_h_min_m": iso.h_min_m,
        "steps": steps,
    }


def hd_temperature_film_ratio(
    temperature_rise_k: float,
    base_temperature_c: float = prm.BASE_TEMPERATURE_C,
    eta0_pa_s: float | None = None,
    beta_k_inv: float | None = None,
) -> float:
    """g(T) = (eta(T)/eta0)^0.68 (alpha*(T)/alpha)^0.49 of a uniform inlet temperature rise
    (twin.physics.thermal.hamrock_dowson_temperature_film_ratio, Roelands' eq. 3 at ambient
    pressure) for the solver's oil at base_temperature_c unless eta0 / beta are given."""
    if eta0_pa_s is None:
        eta0_pa_s = prm.oil_viscosity_pa_s(base_temperature_c)
    if beta_k_inv is None:
        beta_k_inv = prm.oil_temperature_viscosity_coefficient(base_temperature_c)
    return hamrock_dowson_temperature_film_ratio(temperature_rise_k, eta0_pa_s, base_temperature_c + 273.15, beta_k_inv)


def generate_table(
    currents_a=DEFAULT_CURRENTS_A,
    speeds_m_s=DEFAULT_SPEEDS_M_S,
    *,
    grid: int = CALIBRATION_GRID,
    bearing_resistance_ohm: float | None = None,
    load_n: float = prm.LOAD_N,
    base_temperature_c: float = prm.BASE_TEMPERATURE_C,
    anchor: dict | None = None,
    command: str | None = None,
    log=None,
) -> dict:
    """Solve the grid of (current, speed) cases and return the table (JSON-ready dict).

    bearing_resistance_ohm=None uses params.DEFAULT_BEARING_RESISTANCE_OHM."""
    if bearing_resistance_ohm is None:
        bearing_resistance_ohm = prm.DEFAULT_BEARING_RESISTANCE_OHM
    currents = [float(c) for c in currents_a]
    speeds = [float(u) for u in speeds_m_s]
    nc, ns = len(currents), len(speeds)
    f_min = np.full((nc, ns), np.nan)
    f_c = np.full((nc, ns), np.nan)
    t_mean = np.full((nc, ns), np.nan)
    t_cur = np.zeros((nc, ns))
    conv = np.zeros((nc, ns), dtype=bool)
    iters = np.zeros((nc, ns), dtype=int)
    iso_min, iso_c, hd_min = [], [], []
    for s_idx, u in enumerate(speeds):
        iso = _solve(
            0.0,
            u,
            thermal=False,
            grid=grid,
            bearing_resistance_ohm=bearing_resistance_ohm,
            load_n=load_n,
            base_temperature_c=base_temperature_c,
        )
        if not iso.converged:
            raise RuntimeError(f"isothermal reference at {u} m/s did not converge: {iso.message}")
        iso_min.append(iso.h_min_m)
        iso_c.append(iso.h_c_m)
        hd_min.append(iso.hamrock_dowson_h_min_m)
        for c_idx, cur in enumerate(currents):
            res = _solve(
                cur,
                u,
                thermal=True,
                grid=grid,
                bearing_resistance_ohm=bearing_resistance_ohm,
                load_n=load_n,
                base_temperature_c=base_temperature_c,
            )
            t_cur[c_idx, s_idx] = res.current_temperature_rise_k
            iters[c_idx, s_idx] = res.iterations
            conv[c_idx, s_idx] = res.converged
            if res.converged:
                f_min[c_idx, s_idx] = res.h_min_m / iso.h_min_m
                f_c[c_idx, s_idx] = res.h_c_m / iso.h_c_m
                t_mean[c_idx, s_idx] = res.temperature_rise_k
            if log:
                log(
                    f"  u = {u:.3f} m/s, I = {cur:4.1f} A: h_min factor {f_min[c_idx, s_idx]:.4f}, "
                    f"h_c factor {f_c[c_idx, s_idx]:.4f}, mean rise {t_mean[c_idx, s_idx]:.1f} K, "
                    f"eq. 10 rise {t_cur[c_idx, s_idx]:.1f} K, {res.iterations} cycles, "
                    f"{res.message or 'converged'}"
                )
    extrapolated = ~conv
    fits = {}
    for s_idx in range(ns):
        for name, arr in (("h_min", f_min), ("h_c", f_c)):
            fits[(name, s_idx)] = _fill_speed(arr[:, s_idx], t_cur[:, s_idx], conv[:, s_idx], base_temperature_c)
    table = {
        "schema": SCHEMA,
        "description": (
            "film-reduction factor h(current, shear + current heating) / h(isothermal) at the same "
            "entrainment speed, point contact of seed 003 Appendix 2; rows = currents, "
            "columns = speeds"
        ),
        "currents_a": currents,
        "entrainment_speeds_m_s": speeds,
        "h_min_factor": _rows(f_min),
        "h_c_factor": _rows(f_c),
        "mean_temperature_rise_k": _rows(t_mean),
        "current_temperature_rise_k": _rows(t_cur),
        "converged": conv.tolist(),
        "extrapolated": extrapolated.tolist(),
        "iterations": iters.tolist(),
        "extrapolation_exponent_c": {
            "h_min": [fits[("h_min", s)] for s in range(ns)],
            "h_c": [fits[("h_c", s)] for s in range(ns)],
        },
        "isothermal_h_min_m": iso_min,
        "isothermal_h_c_m": iso_c,
        "hamrock_dowson_h_min_m": hd_min,
        "provenance": {
            "generated_unix_s": int(time.time()),
            "command": command or "python -m twin.ehl_solver.film_reduction",
            "solver": "twin.ehl_solver.solve_point_contact (FAS multigrid, seed 003 eqs. 1-11)",
            "grid": grid,
            "python": sys.version.split()[0],
            "numpy": np.__version__,
            "platform": platform.platform(),
            "inputs": {
                "load_n": load_n,
                "rx_m": prm.RX_M,
                "ry_m": prm.RY_M,
                "e_prime_pa": prm.E_PRIME_PA,
                "alpha_pa_inv": prm.ALPHA_PA_INV,
                "base_temperature_c": base_temperature_c,
                "eta0_pa_s": prm.oil_viscosity_pa_s(base_temperature_c),
                "beta_k_inv": prm.oil_temperature_viscosity_coefficient(base_temperature_c),
                "bearing_resistance_ohm": bearing_resistance_ohm,
                "slip_band_depth_m": prm.SLIP_BAND_DEPTH_M,
                "pitch_diameter_m": prm.PITCH_DIAMETER_M,
                "ball_diameter_m": prm.BALL_DIAMETER_M,
                "contact_angle_rad": prm.CONTACT_ANGLE_RAD,
                "balls_in_loaded_zone": prm.BALLS_IN_LOADED_ZONE,
                "thermal_expansion_per_k": prm.THERMAL_EXPANSION_PER_K,
                "oil_conductivity_w_m_k": prm.OIL_CONDUCTIVITY_W_M_K,
            },
            "bearing_resistance_anchor": anchor,
            "seed": "003_a699b754428c6d28 (Hamdan, Lee, Ng 2025), Appendix 2, eqs. 1-11, Figs. 1-5",
        },
    }
    return table


def _rows(a: np.ndarray) -> list:
    return [[None if not np.isfinite(v) else float(v) for v in row] for row in a]


def _fill_speed(
    factors: np.ndarray, t_current: np.ndarray, converged: np.ndarray, base_temperature_c: float
) -> float | None:
    """Fill non-converged cells of one speed in place (see the module docstring); returns c(u)."""
    ok = converged & np.isfinite(factors)
    if not ok.any() or not ok[0]:
        return None
    ln_f0 = math.log(factors[0])
    xs = np.array([math.log(hd_temperature_film_ratio(t, base_temperature_c)) for t in t_current])
    ys = np.log(np.where(ok, factors, np.nan)) - ln_f0
    sel = ok & (xs < 0.0)
    c = float(np.sum(xs[sel] * ys[sel]) / np.sum(xs[sel] ** 2)) if sel.any() else 1.0
    for i in np.nonzero(~ok)[0]:
        factors[i] = math.exp(ln_f0 + c * xs[i])
    return c


def write_table(table: dict, path: Path | str = TABLE_PATH) -> Path:
    path = Path(path)
    path.write_text(json.dumps(table, indent=1) + "\n")
    load_table.cache_clear()
    return path


@lru_cache(maxsize=4)
def load_table(path: str | None = None) -> dict:
    """The shipped table (or the one at `path`)."""
    return json.loads(Path(path or TABLE_PATH).read_text())


def table_arrays(which: str = "h_min", table: dict | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(currents [A], speeds [m/s], factors[current, speed]) as float64 arrays for interp_factor."""
    t = table or load_table()
    key = {"h_min": "h_min_factor", "h_c": "h_c_factor"}[which]
    f = np.array([[np.nan if v is None else v for v in row] for row in t[key]], dtype=np.float64)
    return (np.asarray(t["currents_a"], dtype=np.float64), np.asarray(t["entrainment_speeds_m_s"], dtype=np.float64), f)


@njit(**JIT)
def interp_factor(currents, speeds, factors, current_a, speed_m_s):
    """Bilinear interpolation of factors[current, speed]; inputs outside the table are clamped to
    its edges (current beyond 30 A: the 30 A value, i.e. not extrapolated). Non-negative current
    magnitude is used. Returns 1.0 for a non-finite input (no reduction known)."""
    if not (math.isfinite(current_a) and math.isfinite(speed_m_s)):
        return 1.0
    c = abs(current_a)
    ic = _bracket(currents, c)
    iu = _bracket(speeds, speed_m_s)
    tc = _frac(currents, ic, c)
    tu = _frac(speeds, iu, speed_m_s)
    f00 = factors[ic, iu]
    f10 = factors[ic + 1, iu]
    f01 = factors[ic, iu + 1]
    f11 = factors[ic + 1, iu + 1]
    return (1.0 - tc) * (1.0 - tu) * f00 + tc * (1.0 - tu) * f10 + (1.0 - tc) * tu * f01 + tc * tu * f11


@njit(**JIT)
def _bracket(grid, v):
    n = grid.shape[0]
    if v <= grid[0]:
        return 0
    if v >= grid[n - 1]:
        return n - 2
    i = 0
    while grid[i + 1] < v:
        i += 1
    return i


@njit(**JIT)
def _frac(grid, i, v):
    t = (v - grid[i]) / (grid[i + 1] - grid[i])
    if t < 0.0:
        return 0.0
    if t > 1.0:
        return 1.0
    return t


def film_reduction_factor(current_a, entrainment_speed_m_s, *, which: str = "h_min", table: dict | None = None):
    """h(current, heated) / h(isothermal) from the shipped table, bilinear in (current, speed),
    clamped to the table's range (0-30 A, 0.832-4.16 m/s). Scalars or arrays (broadcast)."""
    currents, speeds, factors = table_arrays(which, table)
    c = np.asarray(current_a, dtype=np.float64)
    u = np.asarray(entrainment_speed_m_s, dtype=np.float64)
    cb, ub = np.broadcast_arrays(c, u)
    out = np.empty(cb.shape)
    for idx in np.ndindex(cb.shape):
        out[idx] = interp_factor(currents, speeds, factors, float(cb[idx]), float(ub[idx]))
    return float(out) if out.shape == () else out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description="generate the seed-003 film-reduction table")
    parser.add_argument("--out", default=str(TABLE_PATH), help="output JSON path")
    parser.add_argument("--grid", type=int, default=CALIBRATION_GRID)
    parser.add_argument(
        "--anchor", action="store_true", help="re-anchor R_b (84.8 %% at 30 A, default speed) before the table"
    )
    args = parser.parse_args(argv)
    return run_calibration(
        args.out,
        grid=args.grid,
        anchor=args.anchor,
        command="python -m twin.ehl_solver.film_reduction " + " ".join(argv or sys.argv[1:]),
    )


def run_calibration(
    out, *, grid: int = CALIBRATION_GRID, anchor: bool = False, command: str | None = None, log=print
) -> int:
    """Anchor R_b (optional) and write the table; prints progress through `log`."""
    anchor_info = None
    r_b = prm.DEFAULT_BEARING_RESISTANCE_OHM
    if anchor:
        log("anchoring the bearing resistance (seed 003 Fig. 2: 84.8 % at 30 A)")
        anchor_info = anchor_bearing_resistance(grid=grid, log=log)
        r_b = anchor_info["bearing_resistance_ohm"]
        log(f"R_b = {r_b:.5e} ohm")
    else:
        anchor_info = {
            "bearing_resistance_ohm": r_b,
            "note": "params.DEFAULT_BEARING_RESISTANCE_OHM (anchored with `bearing-twin ehl calibrate --anchor`)",
        }
    log(f"solving {len(DEFAULT_CURRENTS_A)} currents x {len(DEFAULT_SPEEDS_M_S)} speeds on {grid} x {grid}")
    table = generate_table(grid=grid, bearing_resistance_ohm=r_b, anchor=anchor_info, command=command, log=log)
    path = write_table(table, out)
    log(f"table written to {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
