"""Closed-form and quasi-static references used by the tests and the report.

Load distribution of a rigidly supported radial ball bearing (seed 000 Appendix A, after Harris
[45]): delta_psi = delta_r cos(psi) - Pd/2 (eq. A1), Q = K_eff delta^1.5 with the inner and
outer Hertz contacts in series, Stribeck's Qmax = Fr / (Z Jr(eps)) (eq. A3).
"""

from __future__ import annotations

import math

import numpy as np
from scipy import integrate, optimize

from twin.kernels import layout as L
from twin.model import BearingModel


def series_stiffness_n_m15(k_inner: float, k_outer: float) -> float:
    """K of the ball's two contacts in series: (Ki^-2/3 + Ko^-2/3)^-3/2 [N/m^1.5]."""
    return (k_inner ** (-2.0 / 3.0) + k_outer ** (-2.0 / 3.0)) ** -1.5


def load_parameter_epsilon(radial_shift_m: float, clearance_m: float) -> float:
    """eps = (1 - Pd / (2 delta_r)) / 2 (seed 000 Appendix A)."""
    return 0.5 * (1.0 - clearance_m / (2.0 * radial_shift_m))


def radial_integral(epsilon: float) -> float:
    """Jr(eps) = 1/(2 pi) int [1 - (1 - cos psi)/(2 eps)]^1.5 cos psi dpsi over the loaded zone
    (Harris; Jr(0.5) = 0.2288, seed 000 eq. A3)."""
    if epsilon >= 1.0:
        lim = math.pi
    else:
        lim = math.acos(max(-1.0, 1.0 - 2.0 * epsilon))

    def f(psi):
        return max(0.0, 1.0 - (1.0 - math.cos(psi)) / (2.0 * epsilon)) ** 1.5 * math.cos(psi)

    return integrate.quad(f, -lim, lim, limit=200)[0] / (2.0 * math.pi)


def stribeck_qmax_n(radial_load_n: float, ball_count: int, epsilon: float = 0.5) -> float:
    """Qmax = Fr / (Z Jr(eps)) (seed 000 eq. A3; 1457 N for the 6208 at 3000 N, Pd = 0)."""
    return radial_load_n / (ball_count * radial_integral(epsilon))


def radial_equilibrium(model: BearingModel, radial_load_n: float, azimuths_rad,
                       clearance_m: float | None = None) -> dict:
    """Hertz equilibrium of the inner ring for balls at the given azimuths (rigid rings, no
    centrifugal force): solves sum_j Q_j (cos psi_j, sin psi_j) = (Fr, 0) for the ring shift.

    Returns the shift (delta_x, delta_y) [m], radial shift along the load delta_r [m], ball loads
    [N], deflections [m], the load parameter eps and Qmax.
    """
    if clearance_m is None:
        clearance_m = model.spec.mounting.diametral_clearance_m
    psi = np.asarray(azimuths_rad, dtype=float)
    k = series_stiffness_n_m15(model.race_params[0, L.R_STIFFNESS], model.race_params[1, L.R_STIFFNESS])
    c, s = np.cos(psi), np.sin(psi)

    def loads(shift):
        defl = shift[0] * c + shift[1] * s - 0.5 * clearance_m
        return k * np.clip(defl, 0.0, None) ** 1.5, defl

    def residual(shift_um):
        q, _ = loads(shift_um * 1e-6)
        return [(q @ c - radial_load_n) / radial_load_n, (q @ s) / radial_load_n]

    guess = (radial_load_n / (model.ball_count * 0.2288 * k)) ** (2.0 / 3.0) + 0.5 * max(clearance_m, 0.0)
    sol = optimize.root(residual, [guess * 1e6, 0.0], method="hybr", options={"xtol": 1e-12})
    shift = sol.x * 1e-6
    q, defl = loads(shift)
    delta_r = float(math.hypot(*shift))
    return {
        "shift_m": shift, "radial_shift_m": delta_r, "ball_loads_n": q, "deflections_m": defl,
        "epsilon": load_parameter_epsilon(delta_r, clearance_m), "qmax_n": float(q.max()),
        "converged": bool(sol.success),
    }


def qmax_continuous_n(model: BearingModel, radial_load_n: float, clearance_m: float) -> tuple[float, float]:
    """(Qmax [N], eps) from the continuous Stribeck-Sjovall integral: solves
    Fr = Z K_eff delta_r^1.5 (1 - 1/(2 eps))^... in its integral form (Harris eq. 7.40 style)."""
    k = series_stiffness_n_m15(model.race_params[0, L.R_STIFFNESS], model.race_params[1, L.R_STIFFNESS])
    z = model.ball_count

    def fr_of(delta_r):
        eps = load_parameter_epsilon(delta_r, clearance_m)
        qmax = k * max(delta_r - 0.5 * clearance_m, 0.0) ** 1.5
        return qmax * z * radial_integral(eps) - radial_load_n

    lo = max(0.5 * clearance_m, 0.0) + 1e-12
    delta_r = optimize.brentq(fr_of, lo, 1e-3, xtol=1e-15)
    eps = load_parameter_epsilon(delta_r, clearance_m)
    return k * (delta_r - 0.5 * clearance_m) ** 1.5, eps
