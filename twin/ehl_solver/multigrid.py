"""The grids of the multigrid solver (used by twin.ehl_solver.solver): `GridLevel`, the arrays
and elastic operator of one uniform grid, and the transfers between a grid and the next coarser
one (full-weighting restriction, bilinear prolongation; Venner & Lubrecht, "Multilevel methods in
lubrication", Elsevier 2000).
"""

from __future__ import annotations

import numpy as np

from twin.ehl_solver import params as prm
from twin.ehl_solver.elastic import Deflection


class GridLevel:
    """Arrays and operators of one grid."""

    def __init__(self, n: int, domain, hz: prm.HertzScales, rx_m, ry_m, e_prime_pa):
        x0, x1, y0, y1 = domain
        self.n = n
        self.hx = (x1 - x0) / (n - 1)
        self.hy = (y1 - y0) / (n - 1)
        self.x = x0 + self.hx * np.arange(n)
        self.y = y0 + self.hy * np.arange(n)
        b = (rx_m / ry_m) * (hz.ay_m / hz.ax_m) ** 2
        self.gap = 0.5 * self.x[:, None] ** 2 + 0.5 * b * self.y[None, :] ** 2
        self.defl = Deflection(
            n,
            n,
            self.hx,
            self.hy,
            ax_m=hz.ax_m,
            ay_m=hz.ay_m,
            rx_m=rx_m,
            p_hertz_pa=hz.p_hertz_pa,
            e_prime_pa=e_prime_pa,
        )
        self.kc = self.defl.coef
        shape = (n, n)
        self.p = np.zeros(shape)
        self.f = np.zeros(shape)
        self.h = np.zeros(shape)
        self.eta = np.ones(shape)
        self.rho = np.ones(shape)
        self.eps = np.zeros(shape)
        self.dtheta = np.zeros(shape)
        self.r = np.zeros(shape)
        self.delta = np.zeros(shape)
        self.kind = np.zeros(shape, dtype=np.int8)
        self.band = np.zeros((n, 5))
        self.rhs = np.zeros(n)
        self.xw = np.zeros(n)
        self.load_target = 0.0
        self.area = self.hx * self.hy

    def load(self) -> float:
        return float(self.p.sum()) * self.area


def restrict_full_weighting(r: np.ndarray, out: np.ndarray) -> None:
    out[:] = 0.0
    c = r[2:-2:2, 2:-2:2]
    out[1:-1, 1:-1] = (
        4.0 * c
        + 2.0 * (r[1:-3:2, 2:-2:2] + r[3:-1:2, 2:-2:2] + r[2:-2:2, 1:-3:2] + r[2:-2:2, 3:-1:2])
        + r[1:-3:2, 1:-3:2]
        + r[3:-1:2, 1:-3:2]
        + r[1:-3:2, 3:-1:2]
        + r[3:-1:2, 3:-1:2]
    ) / 16.0


def prolong_bilinear(ec: np.ndarray, nf: int) -> np.ndarray:
    ef = np.zeros((nf, nf))
    ef[::2, ::2] = ec
    ef[1::2, ::2] = 0.5 * (ec[:-1, :] + ec[1:, :])
    ef[::2, 1::2] = 0.5 * (ec[:, :-1] + ec[:, 1:])
    ef[1::2, 1::2] = 0.25 * (ec[:-1, :-1] + ec[1:, :-1] + ec[:-1, 1:] + ec[1:, 1:])
    return ef
