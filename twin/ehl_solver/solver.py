"""Steady isothermal / thermal point-contact EHL with current heating (seed 003), multigrid.

Numerical method
----------------
Dimensionless unknowns on a uniform n x n grid (n = 2^k + 1) over X = x/ax in [-3, 1.5],
Y = y/ay in [-2, 2] (ax, ay the dry Hertz semi-axes of the same load; a circle by default):
pressure P = p/p_h, film H = h Rx/ax^2 = H0 + X^2/2 + (Rx/Ry)(ay/ax)^2 Y^2/2 + D[P] (seed 003
eq. 4), D the elastic deflection by rectangle influence coefficients computed once per grid and
applied by FFT convolution (elastic.py), H0 the rigid gap set by the load balance (eq. 11).

Domain: at the Moes loads of seed 003 Fig. 1 (M = 130-435) the inlet pressure build-up starts
near X = -1.8 (P < 1e-3 p_h beyond X = -2.5 and |Y| = 2 on a [-4.5, 1.5] x [-3, 3] domain, whose
h_c differs by < 1.2 %). The smaller domain gives a 1.5x finer lateral spacing on the same grid,
and the lateral spacing is what the minimum film needs: the side lobes (|Y| ~ 0.9, the global
film minimum) narrow as M grows. On 257 nodes, refining Y alone raises
h_min at 0.832 m/s from 53.7 to 55.0 nm, refining X alone changes it by < 1 %.

The discrete Reynolds equation (seed 003 eq. 1, kernels.py; cavitation by P >= 0) is solved by
Full Approximation Storage multigrid (Venner & Lubrecht, "Multilevel methods in lubrication",
Elsevier 2000): Gauss-Seidel line relaxation where the Poiseuille terms dominate (omega 0.5),
Jacobi distributive line relaxation (zebra order, omega 0.25) in the Hertzian zone, its
pentadiagonal line model with the far film response lumped onto the band edges (kernels.relax_jd);
full-weighting restriction of residuals (zero in the cavitated zone), injection of pressures, bilinear prolongation of
the
corrections except within two nodes of the cavitation boundary (the exit spike, which coarse
grids cannot represent); every grid has its own influence coefficients (FAS: the coarse film is
that of the coarse pressure). V(2,1) cycles after a nested iteration from the coarsest grid (17 x
17, Hertz pressure and the Hamrock-Dowson central film as first guess). H0 is corrected after
every cycle by a damped dry-contact Newton step, dH0 = 0.6 (2/3) delta_H (w - F)/F.

The wedge term is a hybrid upwind scheme (kernels.wedge_weight): second-order upwind where
eps/hx^2 is large (the inlet, where the film is formed), first-order upwind where it vanishes
(Hertzian zone, exit spike).

Accuracy (isothermal, seed 003 Appendix 2). h_c changes by < 0.5 % from 129 to 257 nodes
and by < 0.2 % from 257 to 513 at every speed of Fig. 1 and agrees with Hamrock-Dowson (HD) within
4 %. h_min (the global film minimum, in the side lobes: what HD's h_min fits) changes from 129 to
257 nodes by about 1 % at 2.5-4.2 m/s but by 4.6 % at 0.832 and 2.3 % at 1.664 m/s (M = 435 /
258: the side lobes narrow as M grows); from 257 to 513 it changes by 1.1 / 0.4 / 0.3 / 0.3 /
0.4 % at 0.832-4.16 m/s, so the two finest grids used at the low speeds are 257 and 513 (513 h_min
55.3 / 101.9 / 144.6 / 184.6 / 222.4 nm). Its grid-converged value is bracketed by a first-order
(xi0 = -1) and a second-order (xi0 = 0) wedge scheme, which converge from different sides
(0.832 m/s, 129/257/513 nodes: 55.8/57.0/56.6 nm and 49.8/54.1/55.2 nm; 2.496 m/s:
150.6/148.5/147.1 and 140.2/144.0/144.8 nm): about 55-57 nm and 145-147 nm, i.e. 25-27 % and
8-9 % below HD (75.7 and 159.7 nm), while the 513-node h_min is 26.9, 15.9, 9.5, 5.0 and 1.6 %
below HD at 0.832-4.16 m/s (257: 27.7, 16.3, 9.8, 5.3, 2.0 %). So seed 003 Fig. 1's "within 8 %"
holds for h_min only from about 3 m/s up. The reason is HD's formula, not the discretisation: its
h_c/h_min is nearly fixed (1.76; 34 cases over one decade of load, Hamrock & Dowson 1977), while
converged numerical solutions give a ratio growing with the Moes load M (here 2.3 at M = 435, 1.8
at M = 130; 1 to over 3 in Sperka, Krupka, Hartl, Lubricants 6 (2018) 80; HD's h_min is found
inaccurate also by Wheeler et al., Friction 4 (2016) 369). Seed 003 itself notes the analytical
model's accuracy "diminishes when the entrainment speed falls below 2.5 m/s". HD's ellipticity is
k = a/b = 1 for the circle (k = 1.03 (Ry/Rx)^0.64 is HD's approximate fit; it would raise HD's
h_min by 2 %).

513 nodes. Two details of the smoother keep the multigrid converging there (without them the
pressure change stagnates at ~7e-4 per cycle at 0.832 m/s, ~1e-2 at 3.3-4.2 m/s); both are
invisible on 129/257 nodes because the Poiseuille coefficient eps/hx^2 of a given point grows 4x
per refinement:
(1) The Jacobi distributive line model lumps the tail of the distributed influence kernel Kt
beyond its two-node band onto the band's edges, so its row sum is exact (0). Truncated, the row
sum is (Kt(2) - Kt(3))/hx < 0, and for a change smooth along X and alternating from line to line,
whose only response is the lateral Poiseuille term, the line model has the wrong sign: local
Fourier analysis gives growth 1 + 4 omega xi (hx/hy)^2 / 0.01 per sweep for 0 < xi = eps/hx^2 <
~5e-3, the exit side of the Hertzian zone, which only on 513 nodes holds many nodes with xi in
that range; the pressure grows a line-to-line checkerboard (10 % of p_h at X = 0.8, 0.832 m/s).
The fixed point, i.e. the discrete solution, is the same either way.
(2) Gauss-Seidel lines use the film of the start of the sweep, i.e. they are Jacobi in the
elastic coupling between lines; just above the switch xi = 0.3 that amplifies smooth modes
(Fourier: 2.2 per sweep at omega 0.7, 1.5 at 0.5), and at 3.3-4.2 m/s the nodes at the lateral
edge of the Hertzian zone flip between the two smoothers in a residual limit cycle near
dp ~ 2e-4. omega_gs = 0.5 removes it (xi_lim = 1 does too, at 30 % more cycles).
Measured (isothermal, 2 shared cores): 513 converges at 0.832 / 1.664 / 2.496 / 3.328 / 4.16 m/s
in 13 / 16 / 20 / 18 / 22 cycles, 11 / 14 / 17 / 15 / 19 s; 257 in 14-20 cycles, 3-4 s; 129 in
20-26 cycles, ~1 s. With or without the two details the 129 and 257 results agree within 0.05 %
(the discretisation is the same, only the path to it).

Thermal case: the temperature field of eq. 6 (local h and p) + eq. 10 (current, uniform) is
recomputed on the finest grid before every cycle (under-relaxed by 1/2) and enters Roelands
(eq. 3) and Dowson-Higginson (eq. 2); coarser grids see it by injection. The coupled problem is
converged as a whole.

Convergence (seed 003 eqs. 13-14): relative pressure change per cycle sum|P^k - P^k-1| / sum P^k
< tol_p, load error |w - F| / F < tol_load and, in the thermal case, a temperature change below
0.05 K. The cycle cap max_iter, non-finite values, a load error above 100 %, a pressure at the
safety cap (20 p_h), a negative film or nodes where eq. 6 has no solution return converged=False
with the history and a message instead of a number that looks like an answer.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from twin.ehl_solver import kernels as K
from twin.ehl_solver import params as prm
from twin.ehl_solver.multigrid import GridLevel, prolong_bilinear, restrict_full_weighting
from twin.ehl_solver.result import EHLResult
from twin.physics.thermal import ROELANDS_LN_ETA_INF, ROELANDS_PRESSURE_PA_INV, ROELANDS_T_K

DEFAULT_DOMAIN = (-3.0, 1.5, -2.0, 2.0)  # X = x/ax, Y = y/ay (see the module docstring)
TEMPERATURE_CAP_K = 1000.0
TEMPERATURE_TOL_K = 0.05  # thermal case: max change of the temperature field in the last cycle
STAGNATION_WINDOW = 30  # cycles without progress before giving up (see _stagnated)


@dataclass
class _Settings:
    xi_lim: float = 0.3
    omega_gs: float = 0.5  # 0.7 stagnated on 513 nodes (see the module docstring)
    omega_jd: float = 0.25
    nu1: int = 2
    nu2: int = 1
    coarse_sweeps: int = 8
    gamma: int = 1  # 1: V-cycle, 2: W-cycle
    h0_gain: float = 0.1  # nested iteration, coarsest grid: H0 += gain delta_H err per sweep
    h0_gain_finest: float = 0.6  # after each cycle: fraction of the dry-contact Newton step
    xi0: float = 1.0  # wedge blending, kernels.wedge_weight (-1: first-order upwind)
    omega_t: float = 0.5  # under-relaxation of the temperature field (finest grid)
    zebra: bool = True  # Jacobi distributive lines in two passes (even, odd)
    max_step: float = 0.2  # largest pressure change per node and sweep (units of p_hertz)
    cgc_margin: int = 2  # no coarse-grid correction within this many nodes of P = 0


class _Solver:
    def __init__(
        self,
        n_fine: int,
        n_coarse: int,
        domain,
        hz,
        *,
        rx_m,
        ry_m,
        e_prime_pa,
        lam,
        ln_eta0,
        z,
        s0,
        theta_i_k,
        dt_rel,
        settings: _Settings,
    ):
        self.levels: list[GridLevel] = []
        n = n_fine
        while True:
            self.levels.append(GridLevel(n, domain, hz, rx_m, ry_m, e_prime_pa))
            if n <= n_coarse or (n - 1) % 2 or n < 9:
                break
            n = (n - 1) // 2 + 1
        self.hz = hz
        self.kappa2 = (hz.ax_m / hz.ay_m) ** 2
        self.lam, self.ln_eta0, self.z, self.s0 = lam, ln_eta0, z, s0
        self.theta_i_k, self.dt_rel = theta_i_k, dt_rel
        self.barus_alpha = 0.0
        self.incompressible = False
        self.h0 = 0.0
        self.h_approach = hz.approach_m * rx_m / hz.ax_m**2
        self.s = settings
        self.bad = 0
        self.zero_pivots = 0

    # -- film and fields -------------------------------------------------------------------
    def film(self, lv: GridLevel) -> None:
        lv.h[:] = self.h0 + lv.gap + lv.defl(lv.p)

    def fields(self, lv: GridLevel) -> None:
        self.bad += K.update_fields(
            lv.p,
            lv.h,
            lv.dtheta,
            lv.eta,
            lv.rho,
            lv.eps,
            self.hz.p_hertz_pa,
            self.lam,
            self.ln_eta0,
            self.z,
            self.s0,
            self.theta_i_k,
            self.dt_rel,
            self.barus_alpha,
            self.incompressible,
        )

    def operator(self, lv: GridLevel) -> float:
        """Film, fields and residual r = f - L(P); returns sum |r| over nodes with P > 0."""
        self.film(lv)
        self.fields(lv)
        return K.residual(lv.p, lv.h, lv.rho, lv.eps, lv.f, lv.hx, lv.hy, self.kappa2, self.s.xi0, lv.r)

    def relax(self, lv: GridLevel, sweeps: int, load_balance: bool) -> None:
        s = self.s
        for _ in range(sweeps):
            self.film(lv)
            self.fields(lv)
            K.classify(lv.p, lv.eps, lv.hx, s.xi_lim, lv.kind)
            self.zero_pivots += K.relax_gs(
                lv.p,
                lv.h,
                lv.rho,
                lv.eps,
                lv.f,
                lv.hx,
                lv.hy,
                self.kappa2,
                lv.kc,
                lv.kind,
                s.xi0,
                s.omega_gs,
                s.max_step,
                lv.band,
                lv.rhs,
                lv.xw,
            )
            for parity in (0, 1) if s.zebra else (-1,):
                self.film(lv)
                self.fields(lv)
                K.classify(lv.p, lv.eps, lv.hx, s.xi_lim, lv.kind)
                self.zero_pivots += K.relax_jd(
                    lv.p,
                    lv.h,
                    lv.rho,
                    lv.eps,
                    lv.f,
                    lv.hx,
                    lv.hy,
                    self.kappa2,
                    lv.kc,
                    lv.kind,
                    s.xi0,
                    s.omega_jd,
                    s.max_step,
                    lv.band,
                    lv.rhs,
                    lv.xw,
                    lv.delta,
                    parity,
                )
            if load_balance:
                err = (lv.load() - lv.load_target) / lv.load_target
                self.h0 += s.h0_gain * self.h_approach * err

    # -- multigrid ---------------------------------------------------------------------------
    def cycle(self, k: int) -> None:
        lv = self.levels[k]
        if k == len(self.levels) - 1:
            self.relax(lv, self.s.coarse_sweeps, load_balance=False)
            return
        self.relax(lv, self.s.nu1, load_balance=False)
        self.operator(lv)
        lv.r[lv.p <= 0.0] = 0.0
        cv = self.levels[k + 1]
        cv.p[:] = lv.p[::2, ::2]
        cv.dtheta[:] = lv.dtheta[::2, ::2]
        restrict_full_weighting(lv.r, cv.r)
        restricted = cv.r.copy()
        cv.f[:] = 0.0
        self.operator(cv)  # cv.r = 0 - L_c(P_c)
        cv.f[:] = restricted - cv.r
        cv.f[0, :] = cv.f[-1, :] = cv.f[:, 0] = cv.f[:, -1] = 0.0
        cv.load_target = lv.load_target - lv.load() + cv.load()
        p_old = cv.p.copy()
        for _ in range(self.s.gamma):
            self.cycle(k + 1)
        corr = prolong_bilinear(cv.p - p_old, lv.n)
        mask = _away_from_cavitation(lv.p, self.s.cgc_margin)
        lv.p[mask] += corr[mask]
        np.maximum(lv.p, 0.0, out=lv.p)
        self.relax(lv, self.s.nu2, load_balance=False)


def _away_from_cavitation(p: np.ndarray, margin: int) -> np.ndarray:
    """Nodes with P > 0 and no cavitated (P = 0) node within `margin` nodes in x or y: where
    the coarse-grid correction is applied. Next to the cavitation boundary (the exit spike) the
    coarse grid cannot represent the solution and its correction would start a two-cycle; the
    relaxation alone converges those few nodes."""
    ok = p > 0.0
    if margin <= 0:
        return ok
    out = ok.copy()
    for s in range(1, margin + 1):
        out[s:, :] &= ok[:-s, :]
        out[:-s, :] &= ok[s:, :]
        out[:, s:] &= ok[:, :-s]
        out[:, :-s] &= ok[:, s:]
    return out


def _validate_grid(n: int) -> None:
    if n < 9 or (n - 1) & (n - 2) != 0:
        raise ValueError(f"grid must be 2^k + 1 with k >= 3 (9, 17, 33, 65, 129, 257, ...), got {n}")


def solve_point_contact(
    load_n: float = prm.LOAD_N,
    entrainment_speed_m_s: float = prm.DEFAULT_ENTRAINMENT_SPEED_M_S,
    *,
    rx_m: float = prm.RX_M,
    ry_m: float = prm.RY_M,
    e_prime_pa: float = prm.E_PRIME_PA,
    eta0_pa_s: float | None = None,
    alpha_pa_inv: float = prm.ALPHA_PA_INV,
    current_a: float = 0.0,
    base_temperature_c: float = prm.BASE_TEMPERATURE_C,
    bearing_resistance_ohm: float = prm.DEFAULT_BEARING_RESISTANCE_OHM,
    thermal: bool | None = None,
    beta_k_inv: float | None = None,
    grid: int = 129,
    domain=DEFAULT_DOMAIN,
    tol_p: float = 1e-5,
    tol_load: float = 1e-2,
    max_iter: int = 200,
    coarsest_grid: int = 17,
    rheology: str = "roelands",
    settings: dict | None = None,
) -> EHLResult:
    """Steady point-contact EHL (seed 003): pressure and film maps, h_c, h_min, temperature rise.

    Defaults are seed 003 Appendix 2 (see params.py). eta0_pa_s=None takes the project's seed-000
    oil at base_temperature_c (0.04 Pa s at 40 degC). thermal=None means thermal when
    current_a > 0 or when explicitly asked; thermal=False is the isothermal solution (eq. 6 and
    eq. 10 off, seed 003 Fig. 1), thermal=True adds shear heating (eq. 6) and the current heating
    (eq. 10) to the Roelands temperature. max_iter caps the multigrid cycles on the finest grid.
    """
    t_start = time.perf_counter()
    _validate_grid(grid)
    _validate_grid(coarsest_grid)
    if not (
        load_n > 0
        and entrainment_speed_m_s > 0
        and rx_m > 0
        and ry_m > 0
        and e_prime_pa > 0
        and alpha_pa_inv > 0
        and current_a >= 0
        and math.isfinite(current_a)
    ):
        raise ValueError("load, speed, radii, modulus and alpha must be > 0 and current >= 0")
    if thermal is None:
        thermal = current_a > 0.0
    theta_i_k = base_temperature_c + 273.15
    if not (math.isfinite(theta_i_k) and theta_i_k > 200.0):
        raise ValueError("base temperature must be above -73 degC (Roelands' (T - 138 K) term)")
    if eta0_pa_s is None:
        eta0_pa_s = prm.oil_viscosity_pa_s(base_temperature_c)
    if beta_k_inv is None:
        beta_k_inv = prm.oil_temperature_viscosity_coefficient(base_temperature_c)
    hz = prm.hertz_scales(load_n, rx_m, ry_m, e_prime_pa)
    ln_eta0 = math.log(eta0_pa_s)
    if ln_eta0 + ROELANDS_LN_ETA_INF <= 0.0:
        raise ValueError("Roelands needs eta0 > exp(-9.67) Pa s = 6.3e-5 Pa s")
    z = alpha_pa_inv / (ROELANDS_PRESSURE_PA_INV * (ln_eta0 + ROELANDS_LN_ETA_INF))
    s0 = beta_k_inv * (theta_i_k - ROELANDS_T_K) / (ln_eta0 + ROELANDS_LN_ETA_INF)
    lam = 12.0 * eta0_pa_s * entrainment_speed_m_s * rx_m**2 / (hz.ax_m**3 * hz.p_hertz_pa)
    dt_rel = prm.DENSITY_TEMPERATURE_KG_M3_K / prm.OIL_DENSITY_KG_M3
    h_scale = hz.ax_m**2 / rx_m  # h [m] = H h_scale
    current_rise = (
        prm.current_temperature_rise_k(current_a, entrainment_speed_m_s, bearing_resistance_ohm) if thermal else 0.0
    )
    hd_min, hd_c = prm.hamrock_dowson_film_m(
        load_n,
        entrainment_speed_m_s,
        rx_m=rx_m,
        ry_m=ry_m,
        e_prime_pa=e_prime_pa,
        eta0_pa_s=eta0_pa_s,
        alpha_pa_inv=alpha_pa_inv,
    )
    st = _Settings(**(settings or {}))
    solver = _Solver(
        grid,
        coarsest_grid,
        domain,
        hz,
        rx_m=rx_m,
        ry_m=ry_m,
        e_prime_pa=e_prime_pa,
        lam=lam,
        ln_eta0=ln_eta0,
        z=z,
        s0=s0,
        theta_i_k=theta_i_k,
        dt_rel=dt_rel,
        settings=st,
    )
    if rheology == "barus_incompressible":
        solver.barus_alpha = alpha_pa_inv
        solver.incompressible = True
    elif rheology != "roelands":
        raise ValueError("rheology must be 'roelands' (seed 003) or 'barus_incompressible'")
    levels = solver.levels
    target = load_n / (hz.p_hertz_pa * hz.ax_m * hz.ay_m)
    inputs = {
        "load_n": load_n,
        "entrainment_speed_m_s": entrainment_speed_m_s,
        "rx_m": rx_m,
        "ry_m": ry_m,
        "e_prime_pa": e_prime_pa,
        "eta0_pa_s": eta0_pa_s,
        "alpha_pa_inv": alpha_pa_inv,
        "current_a": current_a,
        "base_temperature_c": base_temperature_c,
        "bearing_resistance_ohm": bearing_resistance_ohm,
        "thermal": bool(thermal),
        "beta_k_inv": beta_k_inv,
        "grid": grid,
        "domain_hertz_radii": list(domain),
        "rheology": rheology,
        "tol_p": tol_p,
        "tol_load": tol_load,
        "max_iter": max_iter,
        "coarsest_grid": levels[-1].n,
        "thermal_expansion_per_k": prm.THERMAL_EXPANSION_PER_K,
        "oil_conductivity_w_m_k": prm.OIL_CONDUCTIVITY_W_M_K,
        "density_temperature_rel_per_k": dt_rel,
        "shaft_frequency_hz": prm.shaft_frequency_hz(entrainment_speed_m_s),
    }
    hertz = {"ax_m": hz.ax_m, "ay_m": hz.ay_m, "p_hertz_pa": hz.p_hertz_pa, "approach_m": hz.approach_m}

    t_work = np.zeros((grid, grid))

    def temperature(lv: GridLevel) -> tuple[int, float]:
        """Coarser grids: the uniform current rise (eq. 10) only. Finest grid: eq. 6 + eq. 10 from
        the current P and H, under-relaxed (omega_t) into lv.dtheta. Returns (#capped nodes,
        max |change| of dtheta [K])."""
        if not thermal:
            lv.dtheta[:] = 0.0
            return 0, 0.0
        if lv is not levels[0]:
            lv.dtheta[:] = current_rise
            return 0, 0.0
        capped = K.temperature_field(
            lv.p,
            lv.h,
            t_work,
            hz.p_hertz_pa,
            h_scale,
            entrainment_speed_m_s,
            theta_i_k,
            prm.THERMAL_EXPANSION_PER_K,
            hz.ax_m,
            eta0_pa_s,
            prm.OIL_CONDUCTIVITY_W_M_K,
            current_rise,
            TEMPERATURE_CAP_K,
        )
        change = t_work - lv.dtheta
        lv.dtheta += st.omega_t * change
        return capped, float(np.abs(change).max())

    # first guess: Hertz pressure on the coarsest grid, H0 from the Hamrock-Dowson central film
    coarse = levels[-1]
    coarse.p[:] = prm.hertz_pressure(coarse.x[:, None], coarse.y[None, :])
    solver.h0 = 0.0
    solver.film(coarse)
    ic, jc = int(np.argmin(np.abs(coarse.x))), int(np.argmin(np.abs(coarse.y)))
    solver.h0 = hd_c / h_scale - coarse.h[ic, jc]

    history: dict[str, list[float]] = {
        "dp": [],
        "load_error": [],
        "residual": [],
        "h0": [],
        "h_c_m": [],
        "h_min_m": [],
        "level_n": [],
        "capped_temperature_nodes": [],
        "temperature_change_k": [],
    }
    message = ""
    converged = False
    iterations = 0
    # nested iteration: a few cycles per grid from the coarsest up, then converge on the finest
    for k in range(len(levels) - 1, -1, -1):
        lv = levels[k]
        lv.f[:] = 0.0
        lv.load_target = target
        if k < len(levels) - 1:
            lv.p[:] = prolong_bilinear(levels[k + 1].p, lv.n)
        lv.dtheta[:] = current_rise
        finest = k == 0
        n_cycles = max_iter if finest else 4
        p_prev = lv.p.copy()
        for it in range(n_cycles):
            solver.film(lv)
            capped, t_change = temperature(lv)
            if k == len(levels) - 1:
                solver.relax(lv, st.coarse_sweeps, load_balance=True)
            else:
                solver.cycle(k)
            if k < len(levels) - 1:
                err = (lv.load() - target) / target
                solver.h0 += st.h0_gain_finest * (2.0 / 3.0) * solver.h_approach * err
            solver.film(lv)
            psum = float(lv.p.sum())
            dp = float(np.abs(lv.p - p_prev).sum()) / psum if psum > 0 else float("inf")
            p_prev[:] = lv.p
            load_err = abs(lv.load() - target) / target
            if finest:
                iterations = it + 1
                solver.fields(lv)
                K.residual(lv.p, lv.h, lv.rho, lv.eps, lv.f, lv.hx, lv.hy, solver.kappa2, st.xi0, lv.r)
                res = (
                    K.natural_residual(lv.p, lv.h, lv.rho, lv.eps, lv.r, lv.hx, lv.hy, solver.kappa2, lv.kc, st.xi0)
                    / psum
                )
                history["dp"].append(dp)
                history["load_error"].append(load_err)
                history["residual"].append(res)
                history["h0"].append(solver.h0)
                history["h_c_m"].append(_centre_value(lv) * h_scale)
                history["h_min_m"].append(float(lv.h[1:-1, 1:-1].min()) * h_scale)
                history["level_n"].append(lv.n)
                history["capped_temperature_nodes"].append(int(capped))
                history["temperature_change_k"].append(t_change)
                if not (math.isfinite(dp) and math.isfinite(solver.h0)) or solver.bad:
                    message = "non-finite values (diverged)"
                    break
                if load_err > 1.0 or float(lv.p.max()) >= K.P_CAP:
                    message = "diverged (load error > 100 % or pressure at the safety cap)"
                    break
                if dp < tol_p and load_err < tol_load and t_change < TEMPERATURE_TOL_K:
                    converged = True
                    break
                if _stagnated(history["dp"], tol_p):
                    message = (
                        f"stagnated: pressure change per cycle stays near {dp:.1e} "
                        f"(tolerance {tol_p:.0e}) over the last {STAGNATION_WINDOW} cycles"
                    )
                    break
            if not math.isfinite(psum) or solver.bad:
                message = "non-finite values (diverged)"
                break
        if message:
            break
    fine = levels[0]
    solver.film(fine)
    if thermal:
        temperature(fine)
    if not converged and not message:
        message = f"not converged within max_iter={max_iter} cycles"
    if converged and float(fine.h[1:-1, 1:-1].min()) <= 0.0:
        converged = False
        message = "negative film (penetration): no EHL solution on this grid"
    if converged and history["capped_temperature_nodes"] and history["capped_temperature_nodes"][-1]:
        converged = False
        message = "eq. 6 has no solution at some nodes (conduction cannot carry the heat): capped"
    if solver.zero_pivots:
        message = (message + "; " if message else "") + f"{solver.zero_pivots} zero pivots in line relaxation"
    p_pa = fine.p * hz.p_hertz_pa
    h_m = fine.h * h_scale
    inside = (fine.x[:, None] ** 2 + fine.y[None, :] ** 2) <= 1.0
    mean_rise = float(fine.dtheta[inside].mean()) if thermal else 0.0
    h_c, h_min, p_max = _centre_value(fine) * h_scale, float(h_m[1:-1, 1:-1].min()), float(p_pa.max())
    if not converged:  # no number that looks like an answer; the maps stay for diagnosis
        h_c = h_min = p_max = mean_rise = float("nan")
    return EHLResult(
        pressure_pa=p_pa,
        film_m=h_m,
        temperature_rise_map_k=fine.dtheta.copy(),
        x_m=fine.x * hz.ax_m,
        y_m=fine.y * hz.ay_m,
        h_c_m=h_c,
        h_min_m=h_min,
        max_pressure_pa=p_max,
        temperature_rise_k=mean_rise,
        current_temperature_rise_k=current_rise,
        converged=converged,
        iterations=iterations,
        history=history,
        inputs=inputs,
        hertz=hertz,
        hamrock_dowson_h_min_m=hd_min,
        hamrock_dowson_h_c_m=hd_c,
        message=message,
        wall_time_s=time.perf_counter() - t_start,
    )


def _stagnated(dps: list, tol_p: float) -> bool:
    """No progress: after STAGNATION_WINDOW cycles the best pressure change of the last window is
    not a tenth below the best before it, and still 10x above the tolerance."""
    w = STAGNATION_WINDOW
    if len(dps) < 2 * w:
        return False
    recent = min(dps[-w:])
    before = min(dps[:-w])
    return recent > 10.0 * tol_p and recent > 0.9 * before


def _centre_value(lv: GridLevel) -> float:
    """H at X = Y = 0 by bilinear interpolation."""
    fx = (0.0 - lv.x[0]) / lv.hx
    fy = (0.0 - lv.y[0]) / lv.hy
    i, j = math.floor(fx), math.floor(fy)
    i = min(max(i, 0), lv.n - 2)
    j = min(max(j, 0), lv.n - 2)
    tx, ty = fx - i, fy - j
    h = lv.h
    return float(
        (1 - tx) * (1 - ty) * h[i, j]
        + tx * (1 - ty) * h[i + 1, j]
        + (1 - tx) * ty * h[i, j + 1]
        + tx * ty * h[i + 1, j + 1]
    )
