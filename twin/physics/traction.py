"""Traction across the contact ellipse: rheology of the film, asperity friction and the geometry
of a ball rolling in a conforming groove.

A ball in a groove touches the raceway over an ellipse whose long (major) axis runs across the
groove. The contact surface is curved across the groove, so the surface speeds of ball and ring
differ along the major axis (Heathcote slip): in pure rolling two lines roll without slip and
the rest of the ellipse slides (Johnson, Contact Mechanics, 1985, section 8.4: the no-slip lines
lie at y = +-0.347 a under a Hertz pressure). The kernel (twin.kernels.traction) integrates the
traction of these laws over strips of the major axis; every law here is one function of scalars.

Traction of one element of the contact (boundary, mixed and full film):

    tau = Qa/Q mu(Lambda) p sgn_reg(s) + (1 - Qa/Q) min(tau_E(s, p), gamma p) sgn(s)

- asperity share Qa/Q(Lambda): seed 001 eq. A2 (twin.physics.rolling.asperity_load_share), with
  the boundary coefficient mu(Lambda) of seed 000 section 2.3 (twin.physics.friction);
- fluid share: Eyring's shear-thinning law tau_E = tau0 asinh(eta(p) s / (h tau0)) (Johnson and
  Tevaarwerk 1977, Proc. R. Soc. Lond. A 356, 215-236, the non-linear viscous regime of their
  model), bounded by the limiting shear stress tau_L = gamma p (Bair and Winer 1979,
  J. Lubr. Technol. 101, 258-265), with the Barus viscosity eta(p) = eta0 exp(alpha p).

SI units; slip s is the sliding speed ball minus ring [m/s]. Scalar numba functions, never NaN
for finite inputs.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from twin.jit import JIT

# Cap of the Barus exponent alpha p: beyond exp(200) the fluid sits at its limiting shear stress
# at any slip above 1e-60 m/s, so the cap changes nothing but keeps eta finite (alpha p reaches
# 420 at the spec's largest alpha and 4.2 GPa).
MAX_BARUS_EXPONENT = 200.0


@njit(**JIT)
def barus_viscosity_pa_s(eta0_pa_s, alpha_pa_inv, pressure_pa):
    """eta(p) = eta0 exp(alpha p) [Pa s] (Barus 1893; alpha is seed 000's xi), exponent capped at
    MAX_BARUS_EXPONENT."""
    return eta0_pa_s * math.exp(min(alpha_pa_inv * max(pressure_pa, 0.0), MAX_BARUS_EXPONENT))


@njit(**JIT)
def eyring_shear_stress_pa(slip_m_s, film_m, viscosity_pa_s, eyring_stress_pa):
    """tau = tau0 asinh(eta |s| / (h tau0)) [Pa], magnitude of the shear stress of a film of
    thickness h sheared at the sliding speed s (Johnson and Tevaarwerk 1977, non-linear viscous
    Eyring regime; the elastic term of their Maxwell model is negligible at steady slip).
    A film of zero thickness shears at any stress: returns inf for s != 0, 0 for s = 0."""
    s = abs(slip_m_s)
    if s == 0.0:
        return 0.0
    if film_m <= 0.0:
        return math.inf
    return eyring_stress_pa * math.asinh(viscosity_pa_s * s / (film_m * eyring_stress_pa))


@njit(**JIT)
def limiting_shear_stress_pa(pressure_pa, limiting_shear_coefficient):
    """tau_L = gamma p [Pa]: the largest shear stress a lubricant film transmits at the pressure p
    (Bair and Winer 1979: tau_L proportional to pressure; gamma = 0.05-0.08 for mineral oils)."""
    return limiting_shear_coefficient * max(pressure_pa, 0.0)


@njit(**JIT)
def fluid_shear_stress_pa(slip_m_s, film_m, viscosity_pa_s, pressure_pa, eyring_stress_pa, limiting_shear_coefficient):
    """Signed shear stress of the fluid film on the faster surface, along the slip [Pa]:
    sgn(s) min(tau_E, tau_L) (Eyring bounded by the limiting shear stress)."""
    tau = min(
        eyring_shear_stress_pa(slip_m_s, film_m, viscosity_pa_s, eyring_stress_pa),
        limiting_shear_stress_pa(pressure_pa, limiting_shear_coefficient),
    )
    return tau if slip_m_s > 0.0 else -tau


@njit(**JIT)
def eyring_saturation_slip_m_s(film_m, viscosity_pa_s, pressure_pa, eyring_stress_pa, limiting_shear_coefficient):
    """Sliding speed at which the Eyring stress reaches the limiting shear stress,
    s_L = (h tau0 / eta) sinh(gamma p / tau0) [m/s]: above it the film transmits gamma p."""
    if film_m <= 0.0 or viscosity_pa_s <= 0.0:
        return 0.0
    x = min(limiting_shear_coefficient * max(pressure_pa, 0.0) / eyring_stress_pa, MAX_BARUS_EXPONENT)
    return film_m * eyring_stress_pa / viscosity_pa_s * math.sinh(x)


@njit(**JIT)
def traction_capacity(asperity_share, asperity_mu, limiting_shear_coefficient):
    """Largest net traction coefficient of a contact, every element sliding one way [-]:
    Qa/Q mu(Lambda) + (1 - Qa/Q) gamma (the traction law above at large slip)."""
    return asperity_share * asperity_mu + (1.0 - asperity_share) * limiting_shear_coefficient


@njit(**JIT)
def deformed_surface_radius_m(ball_radius_m, groove_radius_m):
    """Radius of the contact surface across the groove, R_d = 2 Rb Rg / (Rb + Rg) [m]: between
    two bodies of the same elastic constants the pressure surface takes the mean curvature of
    ball and groove (Harris and Kotzalas, Essential Concepts of Bearing Technology, 5th ed.,
    2007, ch. 'Ball and raceway contact': r = 2 f D / (2 f + 1) with f = Rg / D)."""
    return 2.0 * ball_radius_m * groove_radius_m / (ball_radius_m + groove_radius_m)


def hertz_strip_table(n_strips: int) -> np.ndarray:
    """Exact integrals of the Hertz pressure over n equal strips of the major axis, t = y / a in
    [-1, 1] (p = p_h sqrt(1 - x^2/b^2 - y^2/a^2), so a strip carries dQ/dt = (3/4) Q (1 - t^2)).

    Returns an (n, 4) array, per strip: load-weighted mean of t, load-weighted mean of t^2, share
    of the load (sums to 1), mean pressure / p_h."""
    if n_strips < 1:
        raise ValueError(f"n_strips = {n_strips}: must be >= 1")
    edges = np.linspace(-1.0, 1.0, n_strips + 1)
    lo, hi = edges[:-1], edges[1:]

    load = (hi - hi**3 / 3) - (lo - lo**3 / 3)  # int (1 - t^2)
    first = (hi**2 / 2 - hi**4 / 4) - (lo**2 / 2 - lo**4 / 4)  # int t (1 - t^2)
    second = (hi**3 / 3 - hi**5 / 5) - (lo**3 / 3 - lo**5 / 5)  # int t^2 (1 - t^2)

    def half_disc(t):
        return 0.5 * (t * np.sqrt(np.clip(1.0 - t * t, 0.0, None)) + np.arcsin(np.clip(t, -1.0, 1.0)))

    area = half_disc(hi) - half_disc(lo)  # int sqrt(1 - t^2)
    share = 0.75 * load
    # mean pressure = share Q / (2 a b area), Q = (2 pi / 3) p_h a b
    mean_pressure = share * (2.0 * math.pi / 3.0) / (2.0 * area)
    return np.column_stack([first / load, second / load, share, mean_pressure])
