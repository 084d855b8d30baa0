"""The time step from the physics: the critical step of the explicit scheme (seed 000
eq. 10), `time_step_s = "auto"`, the sub-rates as periods, and the convergence study."""

import json
import math
import subprocess
import sys

import numpy as np
import pytest
from pydantic import ValidationError

from twin import catalog, timestep
from twin.engine import Twin
from twin.kernels import layout as L
from twin.model import make_model
from twin.spec import ModelOptions
from twin.validation import timestep_study


def _leapfrog_stability_limit(zeta: float) -> float:
    """omega dt at which the engine's scheme (leapfrog kicks, the damping force on the half-step
    velocity) stops being stable for x'' = -x - 2 zeta x', by bisection on its amplification
    matrix: an independent check of the formula."""

    def stable(h):
        m = np.zeros((3, 3))
        for i in range(3):
            x, vh, a = np.eye(3)[i]
            vh2 = vh + h * a
            x2 = x + h * vh2
            m[:, i] = [x2, vh2, -x2 - 2.0 * zeta * vh2]
        return np.max(np.abs(np.linalg.eigvals(m))) <= 1.0 + 1e-12

    lo, hi = 0.0, 4.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if stable(mid) else (lo, mid)
    return lo


@pytest.mark.parametrize("zeta", [0.0, 0.1, 0.48, 1.0])
def test_critical_step_is_the_schemes_stability_limit(zeta):
    # Belytschko et al. section 6.2: dt_crit = 2 / omega (sqrt(1 + zeta^2) - zeta)
    omega = 3.0e5
    dt = timestep.central_difference_critical_step_s(omega, zeta)
    assert omega * dt == pytest.approx(_leapfrog_stability_limit(zeta), rel=1e-6)


def test_hertz_tangent_stiffness_is_dq_ddelta():
    # seed 000 eq. 2: Q = K delta^1.5 -> dQ/d(delta) = 1.5 K^(2/3) Q^(1/3)
    big_k, delta = 4.3e10, 30e-6
    q = big_k * delta**1.5
    h = 1e-10
    slope = (big_k * (delta + h) ** 1.5 - big_k * (delta - h) ** 1.5) / (2 * h)
    assert timestep.hertz_tangent_stiffness_n_m(big_k, q) == pytest.approx(slope, rel=1e-6)


@pytest.mark.parametrize("designation", ["6208", "6205", "7208"])
def test_elements_read_from_the_compiled_model(designation):
    # the ball's normal mode: both Hertz contacts at the static capacity on the ball mass (the
    # inner ring, 60x heavier, lowers it by ~1 %); stiffness and load from the model arrays
    model = make_model(catalog.bearing(designation))
    est = model.time_step
    p, race = model.params, model.race_params
    k = sum(timestep.hertz_tangent_stiffness_n_m(race[r, L.R_STIFFNESS], est.static_load_n) for r in range(2))
    normal = est.elements[0]
    assert normal.omega_rad_s == pytest.approx(math.sqrt(k / p[L.P_BALL_MASS]), rel=0.02)
    # its damping: C_hyst = 1.5 alpha_e Q per contact (seed 000 eq. 4), both contacts
    assert normal.damping_ratio == pytest.approx(
        2 * 1.5 * p[L.P_ALPHA_E] * est.static_load_n / (2 * math.sqrt(k * p[L.P_BALL_MASS])), rel=0.03
    )
    # the static capacity: the ball load at which the model's Hertz pressure reaches 4.2 GPa
    a = race[:, L.R_SEMI_MAJOR_COEF] * est.static_load_n ** (1 / 3)
    b = race[:, L.R_SEMI_MINOR_COEF] * est.static_load_n ** (1 / 3)
    assert np.max(1.5 * est.static_load_n / (np.pi * a * b)) == pytest.approx(4.2e9, rel=1e-9)
    assert est.critical_step_s == min(e.critical_step_s for e in est.elements)
    # auto: 0.8 x critical, rounded down to a divisor of the 1 ms frame
    dt = model.dt_s
    n = 1e-3 / dt
    assert n == pytest.approx(round(n), abs=1e-6)
    target = timestep.SAFETY_FACTOR * est.critical_step_s
    assert target * (1 - dt / 1e-3) < dt <= target


def test_auto_is_the_default_and_explicit_steps_still_work():
    assert ModelOptions().time_step_s == "auto"
    twin = Twin("6208")
    assert twin.model.dt_s == twin.model.time_step.auto_time_step_s
    assert 2e-6 < twin.model.dt_s < 5e-6
    assert Twin("6208", options=ModelOptions(time_step_s=1e-6)).model.dt_s == 1e-6
    assert ModelOptions(time_step_s=" AUTO ").time_step_s == "auto"
    assert ModelOptions(time_step_s="2e-6").time_step_s == 2e-6


@pytest.mark.parametrize("value", ["fast", -1e-6, 0.0, 1e-3, float("nan"), float("inf"), True, None])
def test_bad_time_step_refused_with_field_and_range(value):
    with pytest.raises(ValidationError) as err:
        ModelOptions(time_step_s=value)
    text = str(err.value)
    assert "time_step_s" in text and "auto" in text and "[1e-08, 2e-05]" in text


@pytest.mark.parametrize("dt", [1e-6, "auto", 4e-6])
def test_tribology_sub_rate_is_a_period(dt):
    model = make_model(catalog.bearing("6208"), ModelOptions(time_step_s=dt))
    steps = int(model.params[L.P_SUBSTEPS])
    period = ModelOptions().tribology_period_s  # twin.validation.subrate_study
    assert abs(steps * model.dt_s - period) <= 0.5 * model.dt_s  # to the nearest step
    if dt == 1e-6:
        assert steps == round(period / 1e-6)  # exact at the seed's step


def test_auto_step_is_a_stability_bound_not_a_loose_one():
    # at the static capacity (the largest radial load accepted) and 10 rad/s: the auto step runs,
    # 1.2 x the critical step diverges (the kernel reports it)
    for row in timestep_study.stability_study(["6208", "7208"]):
        assert row["auto_stable"], row
        assert not row["unstable_stable"], row


def _run_cli(*args, timeout=900):
    return subprocess.run([sys.executable, "-m", "service.cli", *args], capture_output=True, text=True, timeout=timeout)


def test_quick_timestep_study_within_tolerances_at_auto():
    # the auto step changes no output beyond its tolerance: outputs averaged over whole cage
    # revolutions at the auto step agree with 1 us within 0.5 % (loads, films, Lambda, mu, speeds)
    # and 2 % (torque, electrical values)
    res = _run_cli("timestep-study", "--quick", "--json")
    assert res.returncode == 0, res.stderr
    result = json.loads(res.stdout, parse_constant=lambda c: pytest.fail(f"non-finite {c}"))
    tol = result["tolerances"]
    assert tol["ball_load"] == 0.005 and tol["lambda"] == 0.005 and tol["friction_torque"] == 0.02
    assert tol["impedance"] == 0.02 and tol["capacitance"] == 0.02
    auto = [r for r in result["cases"] if r["step"] == "auto"]
    assert {r["id"] for r in auto} >= {"6208-serve", "7208-preload", "6208-5A"}
    for r in auto:
        assert r["status"] == "ok" and r["restarts"] == 0, r["id"]
        assert r["time_step_s"] > 1.9e-6, r["id"]  # auto is the faster step, not 1 us
        for q, limit in tol.items():
            dev = r["deviation"][q]
            assert dev is None or dev <= limit, (r["id"], q, dev)
        # the impedance is always defined; the capacitance only where the network is capacitive
        # (the snapshot publishes null otherwise), so it may be null here
        for q in ("ball_load", "lambda", "h_min", "mu", "cage_speed", "friction_torque", "impedance"):
            assert r["deviation"][q] is not None, (r["id"], q)
    assert result["all_within_tolerance_at_auto"] is True
    assert result["stability_as_expected"] is True


def test_simulate_dt_auto_number_or_refused():
    res = _run_cli("simulate", "--duration", "0.002", "--dt", "auto", "--json")
    assert res.returncode == 0, res.stderr
    assert json.loads(res.stdout)["time_s"] == pytest.approx(0.002, abs=5e-6)
    res = _run_cli("simulate", "--duration", "0.002", "--dt", "2e-6", "--json")
    assert res.returncode == 0, res.stderr
    assert json.loads(res.stdout)["time_s"] == pytest.approx(0.002, abs=1e-12)
    res = _run_cli("simulate", "--duration", "0.001", "--dt", "1e-3")
    assert res.returncode == 2 and "time_step_s" in res.stderr and "Traceback" not in res.stderr
    res = _run_cli("simulate", "--duration", "0.001", "--dt", "fast")
    assert res.returncode == 2 and "--dt" in res.stderr and "Traceback" not in res.stderr


def test_bench_json_keys_positive_and_finite():
    # no wall-clock threshold: the keys are there and every figure is a positive finite number
    res = _run_cli("bench", "--json", "--seconds", "0.01")
    assert res.returncode == 0, res.stderr
    r = json.loads(res.stdout, parse_constant=lambda c: pytest.fail(f"non-finite {c}"))
    for key in (
        "real_time_factor",
        "real_time_factor_median",
        "time_step_s",
        "ns_per_step",
        "real_time_factor_1us",
        "real_time_factor_1us_median",
        "ns_per_step_1us",
        "cpu_real_time_factor",
        "cpu_real_time_factor_1us",
    ):
        assert math.isfinite(r[key]) and r[key] > 0, key
    assert r["repeats"] >= 5 and r["time_step_s"] > 1e-6
    assert {c["id"] for c in r["cases"]} == {
        "ev-5A-heating",
        "7208-combined",
        "6208-1700rad-7.5kN",
        "vibration-healthy",
        "vibration-outer-spall",
        "vibration-healthy-profile",
        "vibration-cwru-de",
        "ev-6200-20krpm",
    }
    # seed 003's EV case: the 6200 at 20 000 rpm; the auto step (twin.timestep) is about 1.3 us there
    ev = next(c for c in r["cases"] if c["id"] == "ev-6200-20krpm")
    assert ev["designation"] == "6200" and ev["shaft_speed_rad_s"] == pytest.approx(20000.0 * math.pi / 30.0)
    assert 1.1e-6 <= ev["default_step"]["time_step_s"] <= 1.5e-6
    assert r["passes_ev"]["ns_per_step_for_real_time"] == pytest.approx(ev["default_step"]["time_step_s"] * 1e9)
    for c in r["cases"]:
        for step in ("default_step", "step_1us"):
            for key in ("real_time_factor", "real_time_factor_median", "ns_per_step", "time_step_s"):
                assert math.isfinite(c[step][key]) and c[step][key] > 0, (c["id"], step, key)
            if c["id"].startswith("vibration"):  # housing on: the real-time factor includes the indicators' share
                assert c[step]["housing"] and c[step]["indicator_window_s"] > 0 and c[step]["status"] == "ok"
                assert c[step]["real_time_factor"] < c[step]["real_time_factor_kernel"]
            assert c[step]["repeats"] >= 5 and c[step]["status"] == "ok"
    for name in ("gather", "geometry", "forces", "tribology", "cage", "integration", "total"):
        for key in ("best_ns", "median_ns"):
            for passes in ("passes", "passes_ev"):
                assert math.isfinite(r[passes][name][key]) and r[passes][name][key] > 0, (passes, name, key)
    res = _run_cli("bench", "--json", "--seconds", "0.01", "--repeats", "3")
    assert res.returncode == 2 and "error: --repeats: repeats = 3: must be in [5, 100]" in res.stderr
    res = _run_cli("bench", "--json", "--seconds", "1e9")  # would run for years: refused with the range
    assert res.returncode == 2 and "error: --seconds: seconds = 1000000000.0: must be in (0, 60] s" in res.stderr
