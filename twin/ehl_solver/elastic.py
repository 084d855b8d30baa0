"""Elastic deflection of the two half-spaces by influence coefficients applied with the FFT.

d(x, y) = (2 / (pi E')) int int p(x', y') / r dx' dy'   (seed 003 eq. 4, term d_e; E' of
Hamrock-Dowson, E' = E / (1 - nu^2) for two equal bodies). The pressure is piecewise constant on
rectangles of the grid (hx ax by hy ay, centred on the nodes); the deflection of a uniform unit
pressure on a rectangle has the closed form of Johnson (Contact Mechanics, eq. 3.25), so the
influence coefficients are exact for that pressure model. They depend only on the node offsets,
so the sum over all patches is a 2-D convolution: the kernel is computed ONCE per grid, its FFT
cached, and each deflection costs one zero-padded real FFT pair (cyclic convolution of length
>= 2n - 1 equals the linear one on the n x n grid).
"""

from __future__ import annotations

import numpy as np
import scipy.fft as sfft


def _antiderivative(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """F(u, v) with d2F/du dv = 1 / sqrt(u^2 + v^2): u asinh(v/|u|) + v asinh(u/|v|) (0/0 -> 0)."""
    au, av = np.abs(u), np.abs(v)
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = np.where(au > 0.0, u * np.arcsinh(v / np.where(au > 0.0, au, 1.0)), 0.0)
        t2 = np.where(av > 0.0, v * np.arcsinh(u / np.where(av > 0.0, av, 1.0)), 0.0)
    return t1 + t2


def rectangle_influence(dx: np.ndarray, dy: np.ndarray, half_x: float, half_y: float) -> np.ndarray:
    """int int over [-half_x, half_x] x [-half_y, half_y] of 1 / r, seen from offset (dx, dy) [m]."""
    return (
        _antiderivative(dx + half_x, dy + half_y)
        - _antiderivative(dx - half_x, dy + half_y)
        - _antiderivative(dx + half_x, dy - half_y)
        + _antiderivative(dx - half_x, dy - half_y)
    )


class Deflection:
    """Dimensionless deflection D = h_el Rx / ax^2 of a dimensionless pressure P = p / p_h on an
    nx x ny grid with spacings hx (units of ax) and hy (units of ay).

    `coef[m, l]` is dD at node offset (m, l) per unit P on one patch (symmetric in sign of m, l).
    """

    def __init__(
        self,
        nx: int,
        ny: int,
        hx: float,
        hy: float,
        *,
        ax_m: float,
        ay_m: float,
        rx_m: float,
        p_hertz_pa: float,
        e_prime_pa: float,
    ):
        self.nx, self.ny = nx, ny
        mx = np.arange(nx, dtype=float) * hx * ax_m
        my = np.arange(ny, dtype=float) * hy * ay_m
        raw = rectangle_influence(mx[:, None], my[None, :], 0.5 * hx * ax_m, 0.5 * hy * ay_m)
        scale = 2.0 * p_hertz_pa * rx_m / (np.pi * e_prime_pa * ax_m * ax_m)
        self.coef = np.ascontiguousarray(raw * scale)
        self.fx = sfft.next_fast_len(2 * nx - 1, real=True)
        self.fy = sfft.next_fast_len(2 * ny - 1, real=True)
        wrap = np.zeros((self.fx, self.fy))
        wrap[:nx, :ny] = self.coef
        wrap[self.fx - nx + 1 :, :ny] = self.coef[:0:-1, :]
        wrap[:nx, self.fy - ny + 1 :] = self.coef[:, :0:-1]
        wrap[self.fx - nx + 1 :, self.fy - ny + 1 :] = self.coef[:0:-1, :0:-1]
        self._kernel_hat = sfft.rfft2(wrap)
        self._pad = np.zeros((self.fx, self.fy))

    def __call__(self, p: np.ndarray) -> np.ndarray:
        """D on the grid for pressure P (same shape)."""
        self._pad[: self.nx, : self.ny] = p
        out = sfft.irfft2(sfft.rfft2(self._pad) * self._kernel_hat, s=(self.fx, self.fy))
        return np.ascontiguousarray(out[: self.nx, : self.ny])

    def direct(self, p: np.ndarray) -> np.ndarray:
        """The same sum by brute force (O(n^4)); for tests on small grids."""
        out = np.zeros_like(p)
        for i in range(self.nx):
            for j in range(self.ny):
                di = np.abs(np.arange(self.nx) - i)
                dj = np.abs(np.arange(self.ny) - j)
                out[i, j] = np.sum(self.coef[di[:, None], dj[None, :]] * p)
        return out
