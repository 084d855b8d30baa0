"""Seed 003 point-contact EHL solver (twin.ehl_solver): isothermal h_min against Hamrock-Dowson (seed
003 Fig. 1), the exit pressure spike (Fig. 5), h_c and h_min grid-independent within 2 % between the two finest
grids used, the film reduction against current (seed 003 Fig. 5) and the CLI contract.

Every test names the seed figure or equation it checks and its tolerance. Grids: 129 x 129 is
the solver default and 257 x 257 the validation / calibration grid (domain X in [-3, 1.5],
Y in [-2, 2]). Grid refinement compares the two finest grids used: 257 and 513 at the two low
speeds (0.832, 1.664 m/s, Moes M = 435 / 258), where the side lobes that carry h_min are not
resolved on 129 nodes; 129 and 257 at 2.5-4.2 m/s, where 129 already is within 1.5 %. 513 x 513
solves converge at every seed speed (11-19 s each here) but are run in CI at the two low speeds
only, where they matter (about 25 s together).

Criteria that are NOT met and stay strict xfails, with the evidence (see also the
docstring of twin/ehl_solver/solver.py):

- h_min within 8 % of Hamrock-Dowson (seed 003 Fig. 1) at 0.832-2.496 m/s (Moes M = 435-191):
  the grid-converged solver h_min lies 25-27 % (0.832 m/s) and 8-9 % (2.496 m/s) below HD. The
  converged value is bracketed by a first-order and a second-order upwind wedge scheme on
  129/257/513 nodes (0.832 m/s: 55.8/57.0/56.6 nm and 49.8/54.1/55.2 nm, the default hybrid
  scheme 52.3/54.7/55.3 nm; HD 75.7 nm),
  so it is not a resolution, scheme or domain artefact; h_c agrees with HD within 4 % at every
  speed. HD's h_min has a nearly fixed h_c/h_min = 1.76 (fitted on 34 cases over one decade of
  load), while numerical solutions give a ratio that grows with M (2.3 here at M = 435; 1 to
  over 3 in the literature, e.g. Sperka et al., Lubricants 6 (2018) 80). Seed 003 itself says
  the analytical model's accuracy "diminishes when the entrainment speed falls below 2.5 m/s".

Met with the 513 grid converged (the multigrid's smoother corrections: see the solver docstring): h_min
grid-independent within 2 % at 0.832 and 1.664 m/s between 257 and 513 nodes (1.1 % and 0.4 %;
from 129 to 257 it moves 4.6 % and 2.3 %: the side lobes at |Y| ~ 0.94 narrow as M grows).

Wall-clock figures are reported by the CLI (`bearing-twin ehl bench`) and the report, never
asserted here.
"""

from __future__ import annotations

import io
import json
import math
from contextlib import redirect_stdout
from itertools import pairwise

import numpy as np
import pytest

from twin.ehl_solver import film_reduction as calibration
from twin.ehl_solver import params as prm
from twin.ehl_solver import solve_point_contact
from twin.ehl_solver.elastic import Deflection
from twin.ehl_solver.multigrid import GridLevel
from twin.ehl_solver.solver import DEFAULT_DOMAIN

SPEEDS = prm.SEED_SPEEDS_M_S  # seed 003 Fig. 1: 0.832-4.16 m/s (10,000-50,000 rpm)
DEFAULT_SPEED = prm.DEFAULT_ENTRAINMENT_SPEED_M_S


def _spike_excess(res) -> tuple[float, float]:
    """(largest P - P_hertz downstream of the centre, its X) along y = 0, P in units of p_h: the
    second (exit) pressure spike of seed 003 Fig. 5, measured beyond the dry Hertz profile."""
    x, p, _ = res.centre_line()
    xs = x / res.hertz["ax_m"]
    ps = p / res.hertz["p_hertz_pa"]
    hertz = np.sqrt(np.clip(1.0 - xs**2, 0.0, None))
    down = xs > 0.0
    k = int(np.argmax(np.where(down, ps - hertz, -np.inf)))
    return float(ps[k] - hertz[k]), float(xs[k])


def _exit_local_maxima(res) -> list[float]:
    """X of the local pressure maxima along y = 0 in 0.5 < X < 1.1 (the exit region)."""
    x, p, _ = res.centre_line()
    xs = x / res.hertz["ax_m"]
    return [
        float(xs[k])
        for k in range(1, len(p) - 1)
        if 0.5 < xs[k] < 1.1 and p[k] >= p[k - 1] and p[k] > p[k + 1] and p[k] > 0.0
    ]


@pytest.fixture(scope="module")
def iso129():
    return {u: solve_point_contact(entrainment_speed_m_s=u, grid=129, thermal=False) for u in SPEEDS}


@pytest.fixture(scope="module")
def iso257():
    return {u: solve_point_contact(entrainment_speed_m_s=u, grid=257, thermal=False) for u in SPEEDS}


LOW_SPEEDS = (0.832, 1.664)  # Moes M = 435 / 258: h_min needs 513 nodes (see the module docstring)


@pytest.fixture(scope="module")
def iso513():
    """513 x 513 at the two low speeds only (CI time; the other speeds converge too, measured
    18-22 cycles, 15-19 s each, and move h_min by < 0.4 % from 257)."""
    return {u: solve_point_contact(entrainment_speed_m_s=u, grid=513, thermal=False) for u in LOW_SPEEDS}


def _two_finest(speed, iso129, iso257, iso513):
    """(coarser, finer) of the two finest grids used at this speed."""
    if speed in iso513:
        return iso257[speed], iso513[speed]
    return iso129[speed], iso257[speed]


CURRENTS = (0.0, 10.0, 20.0, 30.0)


@pytest.fixture(scope="module")
def with_current(iso257):
    """Thermal solves at the default speed on the calibration grid (257), eqs. 6 + 10."""
    return {
        i: solve_point_contact(entrainment_speed_m_s=DEFAULT_SPEED, grid=257, current_a=i, thermal=True)
        for i in CURRENTS
    }


# --- elasticity (seed 003 eq. 4, term d_e) -----------------------------------------------------


def test_fft_deflection_equals_the_direct_influence_sum():
    """eq. 4 d_e: the zero-padded FFT convolution is the influence-coefficient sum (to 1e-12)."""
    hz = prm.hertz_scales(prm.LOAD_N, prm.RX_M, prm.RY_M, prm.E_PRIME_PA)
    d = Deflection(
        17,
        17,
        0.375,
        0.375,
        ax_m=hz.ax_m,
        ay_m=hz.ay_m,
        rx_m=prm.RX_M,
        p_hertz_pa=hz.p_hertz_pa,
        e_prime_pa=prm.E_PRIME_PA,
    )
    rng = np.random.default_rng(3)
    p = rng.random((17, 17))
    assert np.max(np.abs(d(p) - d.direct(p))) < 1e-12 * np.max(np.abs(d.direct(p)))


def test_hertz_pressure_gives_the_hertz_approach():
    """eq. 4 with the Hertz pressure: gap + deflection is flat inside the contact and equals the
    Hertz approach (1 in units of a^2/R), the check of the influence coefficients (tol 1e-3)."""
    hz = prm.hertz_scales(prm.LOAD_N, prm.RX_M, prm.RY_M, prm.E_PRIME_PA)
    lv = GridLevel(129, DEFAULT_DOMAIN, hz, prm.RX_M, prm.RY_M, prm.E_PRIME_PA)
    p = prm.hertz_pressure(lv.x[:, None], lv.y[None, :])
    g = lv.gap + lv.defl(p)
    inside = (lv.x[:, None] ** 2 + lv.y[None, :] ** 2) < 0.9
    assert np.max(np.abs(g[inside] - 1.0)) < 1e-3
    assert p.sum() * lv.area == pytest.approx(2.0 * math.pi / 3.0, rel=2e-3)  # eq. 11, Hertz load


# --- isothermal validation (seed 003 Fig. 1) ----------------------------------------------------


def test_isothermal_solves_converge_to_the_seed_tolerances(iso129, iso257):
    """eqs. 13-14: pressure change < 1e-5, load error < 1e-2, every speed, 129 and 257 grids."""
    for res in list(iso129.values()) + list(iso257.values()):
        assert res.converged, res.message
        assert res.history["dp"][-1] < 1e-5
        assert res.history["load_error"][-1] < 1e-2
        assert res.iterations <= 60


def test_513_solves_converge_to_the_seed_tolerances(iso513):
    """eqs. 13-14 on 513 x 513 (0.832 and 1.664 m/s): the grid on which a multigrid without the
    smoother corrections stagnates near a pressure change of 7e-4 per cycle (measured: 13 and 16
    cycles)."""
    for u, res in iso513.items():
        assert res.converged, (u, res.message)
        assert res.history["dp"][-1] < 1e-5
        assert res.history["load_error"][-1] < 1e-2
        assert res.iterations <= 60


_HD_FAILS = (
    "not achieved, and not a numerical artefact: the grid-converged minimum film (side lobes) lies "
    "25-27 % (0.832 m/s, M = 435), ~16 % (1.664 m/s) and 8-9 % (2.496 m/s, M = 191) below "
    "Hamrock-Dowson; bracketed by first- and second-order upwind solutions on 129-513 nodes "
    "(0.832 m/s: 56.6 / 55.2 nm on 513 against HD 75.7 nm). HD's nearly fixed h_c/h_min = 1.76 "
    "does not hold at high Moes M (solver: 1.9-2.3); h_c agrees with HD within 4 %. Seed 003 notes "
    "the analytical model's accuracy diminishes below 2.5 m/s"
)


@pytest.mark.parametrize(
    "speed",
    [
        pytest.param(0.832, marks=pytest.mark.xfail(strict=True, reason=_HD_FAILS)),
        pytest.param(1.664, marks=pytest.mark.xfail(strict=True, reason=_HD_FAILS)),
        pytest.param(2.496, marks=pytest.mark.xfail(strict=True, reason=_HD_FAILS)),
        3.328,
        4.16,
    ],
)
def test_minimum_film_within_8_percent_of_hamrock_dowson(iso257, speed):
    """Seed 003 Fig. 1: isothermal h_min within 8 % of Hamrock-Dowson (257 x 257 grid).
    Holds at 3.33 and 4.16 m/s; at the lower speeds it does not (strict xfail, see reason).
    h_min is the global minimum of the film (the side lobes), which is what HD's h_min fits."""
    res = iso257[speed]
    assert res.h_min_m == pytest.approx(res.hamrock_dowson_h_min_m, rel=0.08)


@pytest.mark.parametrize("speed", SPEEDS)
def test_central_film_within_8_percent_of_hamrock_dowson(iso257, speed):
    """Seed 003 Fig. 1 companion: h_c within 8 % of the Hamrock-Dowson central film (257 x 257)."""
    res = iso257[speed]
    assert res.h_c_m == pytest.approx(res.hamrock_dowson_h_c_m, rel=0.08)


def test_minimum_film_rises_with_speed_and_lies_below_the_central_film(iso257):
    """Fig. 1: film grows with entrainment speed; the side-lobe minimum is below h_c."""
    h_min = [iso257[u].h_min_m for u in SPEEDS]
    assert all(b > a for a, b in pairwise(h_min))
    assert all(iso257[u].h_min_m < iso257[u].h_c_m for u in SPEEDS)


@pytest.mark.parametrize("speed", SPEEDS)
def test_isothermal_pressure_has_the_exit_spike(iso257, speed):
    """Seed 003 Fig. 5 (0 A curve): a second pressure maximum downstream of the centre: a local
    maximum of p along y = 0 between X = 0.5 and 1.1, above the dry Hertz profile by at least 5 %
    of p_h (257 x 257; on 129 x 129 the spike of the 2.5-4.2 m/s cases is only a shoulder)."""
    res = iso257[speed]
    excess, x_spike = _spike_excess(res)
    assert excess > 0.05
    assert 0.5 < x_spike < 1.1
    maxima = _exit_local_maxima(res)
    assert maxima and min(abs(m - x_spike) for m in maxima) < 0.05


def _nijenbanning_central_film(m_load: float, l_material: float) -> float:
    """Moes-Nijenbanning central film H_c = h_c/Rx (2U)^-1/2, circular contact (Nijenbanning,
    Venner, Moes, Wear 176 (1994) 217), fitted to Barus/incompressible numerical solutions."""
    h_ri = 145.0 * (1.0 + 0.796) ** (-15.0 / 7.0) * m_load**-2
    h_ei = 3.18 * 1.63 ** (-14.0 / 25.0) * m_load ** (-2.0 / 15.0)
    h_rp = 1.29 * 1.691 ** (-2.0 / 3.0) * l_material ** (2.0 / 3.0)
    h_ep = 1.48 * 1.63 ** (-7.0 / 20.0) * m_load ** (-1.0 / 12.0) * l_material**0.75
    s = 1.5 * (1.0 + math.exp(-1.2 * h_ei / h_ri))
    return (
        (h_ri**1.5 + (h_ei**-4 + 1.8**-4) ** (-3.0 / 8.0)) ** (2.0 * s / 3.0) + (h_rp**-8 + h_ep**-8) ** (-s / 8.0)
    ) ** (1.0 / s)


def test_solver_reproduces_the_moes_nijenbanning_central_film():
    """Solver check beyond the seed: with Barus viscosity and constant density (the rheology of
    the Moes-Nijenbanning formula) at M = 20, L = 10 the central film is within 5 % of the
    formula (measured +2 %, the same on 129 and 257 nodes)."""
    w = prm.LOAD_N / (prm.E_PRIME_PA * prm.RX_M**2)
    two_u = (w / 20.0) ** (4.0 / 3.0)
    speed = 0.5 * two_u * prm.E_PRIME_PA * prm.RX_M / 0.04
    alpha = 10.0 / two_u**0.25 / prm.E_PRIME_PA
    res = solve_point_contact(
        entrainment_speed_m_s=speed,
        alpha_pa_inv=alpha,
        eta0_pa_s=0.04,
        grid=129,
        thermal=False,
        rheology="barus_incompressible",
    )
    assert res.converged, res.message
    h_moes = res.h_c_m / (prm.RX_M * math.sqrt(two_u))
    assert h_moes == pytest.approx(_nijenbanning_central_film(20.0, 10.0), rel=0.05)


# --- grid refinement -------------------------------------------------------------------------


@pytest.mark.parametrize("speed", SPEEDS)
def test_grid_refinement_minimum_film(iso129, iso257, iso513, speed):
    """Grid refinement: h_min changes by < 2 % between the two finest grids used, seed 003
    Fig. 1 speeds: 257 -> 513 at 0.832 and 1.664 m/s (measured 1.1 % and 0.4 %; 129 -> 257 moves
    it 4.6 % and 2.3 % there, the side lobes being under-resolved on 129), 129 -> 257 above
    (measured 0.9-1.1 %)."""
    a, b = _two_finest(speed, iso129, iso257, iso513)
    assert abs(a.h_min_m / b.h_min_m - 1.0) < 0.02


def test_central_film_is_grid_converged_at_every_speed(iso129, iso257, iso513):
    """Grid refinement for h_c: < 2 % between the two finest grids used at every speed of
    Fig. 1 (measured < 0.5 % from 129 to 257 and < 0.2 % from 257 to 513: hybrid upwind wedge,
    second order in the inlet where h_c is formed)."""
    for u in SPEEDS:
        a, b = _two_finest(u, iso129, iso257, iso513)
        assert abs(a.h_c_m / b.h_c_m - 1.0) < 0.02
    for u in LOW_SPEEDS:  # and from the coarsest to the finest
        assert abs(iso129[u].h_c_m / iso513[u].h_c_m - 1.0) < 0.02


# --- current discharge (seed 003 eqs. 6-10, Figs. 2-5) ----------------------------------------


def test_current_heating_eq_10_scales_with_current_squared_over_speed():
    """eq. 10: T_obn proportional to I^2 R_b / f_s (to round-off)."""
    t1 = prm.current_temperature_rise_k(10.0, 2.0, 1e-3)
    assert prm.current_temperature_rise_k(20.0, 2.0, 1e-3) == pytest.approx(4.0 * t1, rel=1e-12)
    assert prm.current_temperature_rise_k(10.0, 4.0, 1e-3) == pytest.approx(0.5 * t1, rel=1e-12)
    assert prm.current_temperature_rise_k(10.0, 2.0, 2e-3) == pytest.approx(2.0 * t1, rel=1e-12)


def test_thermal_solves_converge(with_current):
    """eqs. 13-14 with the temperature of eqs. 6 + 10 coupled into eq. 3 (257 x 257)."""
    for i, res in with_current.items():
        assert res.converged, (i, res.message)
        assert res.history["dp"][-1] < 1e-5 and res.history["load_error"][-1] < 1e-2


def test_film_reduction_with_current_in_the_seed_band_and_rising(iso257, with_current):
    """Seed 003 Figs. 2 and 4: the minimum-film reduction against the isothermal film lies in the
    57.6-84.8 % band and rises with current. R_b is anchored so that 30 A gives 84.8 % (tol 0.005);
    20 A is a prediction and must lie inside the band; the reduction rises strictly with
    current from 0 to 30 A (at 0 A it is the shear heating of eq. 6 alone)."""
    iso = iso257[DEFAULT_SPEED]
    reduction = {i: 1.0 - r.h_min_m / iso.h_min_m for i, r in with_current.items()}
    assert reduction[30.0] == pytest.approx(0.848, abs=0.005)
    for i in (20.0,):
        assert 0.576 <= reduction[i] <= 0.848, (i, reduction[i])
    values = [reduction[i] for i in CURRENTS]
    assert all(b > a for a, b in pairwise(values)), values
    assert reduction[0.0] > 0.0  # shear heating alone already thins the film


def test_temperature_rise_grows_with_current(with_current):
    """Seed 003 Fig. 3: mean temperature rise of the contact increases with current."""
    rises = [with_current[i].temperature_rise_k for i in CURRENTS]
    assert all(b > a for a, b in pairwise(rises)), rises


def test_exit_spike_fades_as_current_rises(with_current):
    """Seed 003 Fig. 5: "with the increase in applied current, there is a tendency for the pressure
    spike to diminish and move towards the exit ... at 30 A the second pressure spike almost
    disappears". Measured as the spike's excess over the dry Hertz profile (257 x 257): up to 10 A
    it is unchanged within 5 % (little heating), from 10 A on it falls strictly, at 30 A it is
    below half the 0 A value, and it does not move upstream."""
    excess = {i: _spike_excess(with_current[i]) for i in CURRENTS}
    assert abs(excess[10.0][0] / excess[0.0][0] - 1.0) < 0.05
    falling = [excess[i][0] for i in CURRENTS if i >= 10.0]
    assert all(b < a for a, b in pairwise(falling)), excess
    assert excess[30.0][0] < 0.5 * excess[0.0][0]
    assert excess[30.0][1] >= excess[0.0][1]


# --- failure is reported, not hidden -----------------------------------------------------------


def test_non_convergence_is_reported_with_the_history():
    """A cycle cap far below what eqs. 13-14 need returns converged=False and the history."""
    res = solve_point_contact(grid=65, thermal=False, max_iter=2)
    assert res.converged is False
    assert res.iterations == 2 and len(res.history["dp"]) == 2
    assert "not converged" in res.message
    assert math.isnan(res.h_min_m) and math.isnan(res.h_c_m)  # no number that looks like an answer


def test_bad_grid_is_refused():
    """Input validation (no seed figure): the multigrid needs n = 2^k + 1 nodes; 100 is refused."""
    with pytest.raises(ValueError):
        solve_point_contact(grid=100)


# --- the calibration table shipped for the real-time loop -------------------------------------


def test_shipped_film_reduction_table_has_provenance_and_consistent_factors():
    """The table (generated by `bearing-twin ehl calibrate`) carries its inputs, grid, date and
    command; factors are in (0, 1] and fall with current at every speed; the 30 A entry at the
    default speed is the anchor (84.8 % reduction, tol 0.01)."""
    t = calibration.load_table()
    prov = t["provenance"]
    for key in ("generated_unix_s", "command", "grid", "inputs"):
        assert key in prov
    assert prov["inputs"]["bearing_resistance_ohm"] == pytest.approx(prm.DEFAULT_BEARING_RESISTANCE_OHM)
    currents, speeds, f = calibration.table_arrays("h_min", t)
    assert currents[0] == 0.0 and currents[-1] == 30.0
    assert speeds[0] == pytest.approx(0.832) and speeds[-1] == pytest.approx(4.16)
    assert np.all(np.isfinite(f)) and np.all(f > 0.0) and np.all(f <= 1.0)
    assert np.all(np.diff(f, axis=0) < 0.0)
    j = int(np.argmin(np.abs(speeds - DEFAULT_SPEED)))
    assert 1.0 - f[-1, j] == pytest.approx(0.848, abs=0.01)


def test_film_reduction_factor_interpolates_the_table():
    """The real-time form of the Figs. 2-4 table: bilinear interpolation reproduces the nodes
    (rel 1e-12), lies between neighbours, clamps outside the table, returns 1 for NaN input."""
    currents, speeds, f = calibration.table_arrays("h_min")
    assert calibration.film_reduction_factor(currents[2], speeds[1]) == pytest.approx(f[2, 1], rel=1e-12)
    mid = calibration.film_reduction_factor(0.5 * (currents[2] + currents[3]), speeds[1])
    assert min(f[2, 1], f[3, 1]) <= mid <= max(f[2, 1], f[3, 1])
    assert calibration.film_reduction_factor(100.0, 10.0) == pytest.approx(f[-1, -1], rel=1e-12)
    arr = calibration.film_reduction_factor(np.array([0.0, 30.0]), 2.496)
    assert arr.shape == (2,) and arr[0] > arr[1]
    assert calibration.interp_factor(currents, speeds, f, float("nan"), 1.0) == 1.0


# --- command line --------------------------------------------------------------------------------


def test_cli_solve_json_carries_the_required_fields():
    """The CLI contract: `bearing-twin ehl solve --json` (service/tools/ehl_cli.py, Appendix 2
    defaults, 65 x 65 grid) carries the required fields and inputs (exact keys, eta0 = 0.04)."""
    from service.tools.ehl_cli import main

    buf = io.StringIO()
    with redirect_stdout(buf):
        code = main(["ehl", "solve", "--grid", "65", "--json"])
    doc = json.loads(buf.getvalue())
    assert code == 0 and doc["converged"] is True
    for key in (
        "h_min_m",
        "h_c_m",
        "max_pressure_pa",
        "temperature_rise_k",
        "converged",
        "iterations",
        "hamrock_dowson_h_min_m",
    ):
        assert key in doc
    for key in ("eta0_pa_s", "alpha_pa_inv", "rx_m", "ry_m", "e_prime_pa", "load_n", "entrainment_speed_m_s"):
        assert key in doc["inputs"]
    assert doc["inputs"]["load_n"] == prm.LOAD_N and doc["inputs"]["eta0_pa_s"] == pytest.approx(0.04)


# --- report section (seed 003 Figs. 1 and 5) ------------------------------------------------------


def test_report_section_writes_the_figures_and_the_table(tmp_path):
    """service/reports/ehl.py write_ehl_section on a small grid (33 x 33, for speed): the three PNGs
    (centre line isothermal and with 0/10/20/30 A: seed 003 Fig. 5; film vs speed: Fig. 1) exist,
    are real images (PNG signature, > 10 kB) and the Markdown embeds them and names the figures."""
    from service.reports import ehl as report_ehl

    md = report_ehl.write_ehl_section(tmp_path, grid=33, progress=False)
    for name in (report_ehl.CENTRE_LINE_PNG, report_ehl.CURRENT_PNG, report_ehl.SPEED_PNG):
        path = tmp_path / name
        assert path.is_file() and path.stat().st_size > 10_000
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert f"]({name})" in md
    assert "Fig. 1" in md and "Fig. 5" in md
    assert "| 0.832 |" in md and "| 30 |" in md and "HD h_min" in md


@pytest.mark.parametrize(
    "argv, flag, says",
    [
        (["solve", "--base-temperature=-100"], "--base-temperature", "[-30, 150] degC"),
        (["solve", "--base-temperature", "nan"], "--base-temperature", "[-30, 150] degC"),
        (["solve", "--grid", "4097"], "--grid", "17, 33, 65, 129, 257, 513"),
        (["solve", "--grid", "x"], "--grid", "17, 33, 65, 129, 257, 513"),
        (["solve", "--load", "1e30"], "--load", "(0, 100000] N"),
        (["solve", "--current", "1e30"], "--current", "[0, 100] A"),
        (["solve", "--entrainment-speed", "0"], "--entrainment-speed", "(0, 100] m/s"),
        (["solve", "--max-iter", "0"], "--max-iter", "[1, 10000]"),
        (["bench", "--repeats", "0"], "--repeats", "[1, 1000]"),
    ],
)
def test_cli_refuses_bad_flags_naming_them_and_their_range(argv, flag, says, capsys):
    """`bearing-twin ehl ...`: a value outside the solver's domain ends with status 2 and a line
    naming the flag and its range, before any solve (a base temperature below Roelands' 138 K
    was a traceback, a 4097 grid a solve of hours)."""
    from service.tools.ehl_cli import main

    with pytest.raises(SystemExit) as exc:
        main(["ehl", *argv])
    err = capsys.readouterr().err
    assert exc.value.code == 2 and f"argument {flag}" in err and says in err and "Traceback" not in err
