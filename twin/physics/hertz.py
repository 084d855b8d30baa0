"""Hertz elliptic point contact: curvature, ellipticity, stiffness, contact ellipse.

Seed 000 eq. 2 with the reading of docs/physics.md (the printed 2 pi k G lost the 1/(1 - nu) factor):
Q = K delta^1.5, K = pi k E' sqrt(2 Ebar R / (9 Fbar^3)), R = Rx Ry / (Rx + Ry); k = a/b is the
ellipticity and Fbar = K(m), Ebar = E(m) the complete elliptic integrals of the first and second
kind of parameter m = 1 - 1/k^2. They are solved EXACTLY from the curvature ratio Ry/Rx
(`elliptic_constants`: the Hertz transcendental equation, Hamrock & Brewe 1983, "Simplified
solution for stresses and deformations", J. Lubr. Technol. 105, eqs. 6-8; Johnson, Contact
Mechanics, eq. 4.39) once per contact geometry, at model compile time (Python and scipy, never in
the hot loop). The kernels read the results from the compiled model.

The Brewe-Hamrock closed forms (Brewe & Hamrock 1977, NASA TM X-3452 / J. Lubr. Technol. 99;
Hamrock & Dowson, Ball Bearing Lubrication, 1981, ch. 5) stay as documented approximations:
k ~ (Ry/Rx)^(2/pi), Fbar ~ pi/2 + (pi/2 - 1) ln(Ry/Rx), Ebar ~ 1 + (pi/2 - 1) Rx/Ry (the first
kind is pi/2 for a circle; a reading with 1 + ... would make K 32 % too stiff for the 6208).
`tests/physics/test_hertz.py` bounds their error against the exact solution.

Ball-ball (cage element) contacts, eq. 3: Q = 4 G sqrt(Req) / (3 (1 - nu)) delta^1.5.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

from numba import njit
from scipy import optimize, special

from twin.jit import JIT

_Q = math.pi / 2.0 - 1.0


@njit(**JIT)
def effective_modulus_pa(youngs_modulus_pa, poisson_ratio):
    """E' = E / (1 - nu^2) for two bodies of the same material [Pa] (seed 000 eq. 6)."""
    return youngs_modulus_pa / (1.0 - poisson_ratio * poisson_ratio)


@njit(**JIT)
def shear_modulus_pa(youngs_modulus_pa, poisson_ratio):
    """G = E / (2 (1 + nu)) [Pa] (seed 000, below eq. 2)."""
    return youngs_modulus_pa / (2.0 * (1.0 + poisson_ratio))


@njit(**JIT)
def convex_radius_m(r1_m, r2_m):
    """Effective radius of two convex surfaces, R1 R2 / (R1 + R2) [m] (seed 000 eq. 2, Rx inner)."""
    return r1_m * r2_m / (r1_m + r2_m)


@njit(**JIT)
def concave_radius_m(r_ball_m, r_hollow_m):
    """Effective radius of a ball in a hollow, Rb Rh / (Rh - Rb) [m] (seed 000 eq. 2, Rx outer, Ry)."""
    return r_ball_m * r_hollow_m / (r_hollow_m - r_ball_m)


@njit(**JIT)
def curvature_sum_radius_m(rx_m, ry_m):
    """R = Rx Ry / (Rx + Ry) [m] (seed 000 eq. 2, R_curve)."""
    return rx_m * ry_m / (rx_m + ry_m)


# ---- exact solution (compile time) --------------------------------------------------------------


@dataclass(frozen=True)
class EllipticConstants:
    """Exact Hertz constants of one contact geometry.

    ellipticity: k = a/b >= 1 (a transverse, b along the rolling direction) [-];
    first_kind: Fbar = K(m) [-]; second_kind: Ebar = E(m) [-]; m = 1 - 1/k^2."""

    ellipticity: float
    first_kind: float
    second_kind: float


def _integrals(k: float) -> tuple[float, float]:
    """(K(m), E(m)) for m = 1 - 1/k^2; K through ellipkm1(1 - m) keeps its precision for long
    ellipses (m -> 1)."""
    m1 = 1.0 / (k * k)
    return float(special.ellipkm1(m1)), float(special.ellipe(1.0 - m1))


def _curvature_ratio_of(k: float) -> float:
    """Ry/Rx that yields the ellipticity k: the Hertz relation B/A = (k^2 E - K) / (K - E)
    (Johnson eq. 4.39 with e^2 = 1 - 1/k^2; Hamrock & Brewe 1983 eq. 6)."""
    big_k, big_e = _integrals(k)
    return (k * k * big_e - big_k) / (big_k - big_e)


@functools.lru_cache(maxsize=4096)
def elliptic_constants_of_ratio(curvature_ratio: float) -> EllipticConstants:
    """Exact k, Fbar, Ebar for the curvature ratio Ry/Rx >= 1 (the transcendental Hertz equation
    solved with brentq to 1e-14 in k). Ry/Rx = 1 is the circle: k = 1, Fbar = Ebar = pi/2."""
    ratio = float(curvature_ratio)
    if not (math.isfinite(ratio) and ratio >= 1.0):
        raise ValueError(f"curvature_ratio = {curvature_ratio!r}: must be finite and >= 1 (Ry >= Rx)")
    if ratio - 1.0 < 1e-6:  # a circle within 1e-6 (K differs from the circle's by < 1e-6)
        return EllipticConstants(1.0, 0.5 * math.pi, 0.5 * math.pi)
    # Ry/Rx grows monotonically with k and k < Ry/Rx: the root lies in (1 + 1e-7, ratio + 1]
    # (at k = 1 + 1e-7 the K - E difference still carries 9 significant digits)
    k = optimize.brentq(
        lambda kk: _curvature_ratio_of(kk) - ratio, 1.0 + 1e-7, ratio + 1.0, xtol=1e-14, rtol=1e-14, maxiter=200
    )
    big_k, big_e = _integrals(k)
    return EllipticConstants(float(k), big_k, big_e)


def elliptic_constants(rx_m: float, ry_m: float) -> EllipticConstants:
    """Exact Hertz constants for the rolling- and transverse-direction radii Rx <= Ry [m]
    (a along Ry, b along Rx). Raises ValueError naming the field for Rx > Ry or non-positive radii."""
    if not (rx_m > 0.0 and ry_m > 0.0 and math.isfinite(rx_m) and math.isfinite(ry_m)):
        raise ValueError(f"rx_m = {rx_m!r}, ry_m = {ry_m!r}: radii must be finite and > 0")
    if rx_m > ry_m * (1.0 + 1e-12):
        raise ValueError(f"rx_m = {rx_m:g} m > ry_m = {ry_m:g} m: the twin's contacts have Ry >= Rx")
    return elliptic_constants_of_ratio(max(ry_m / rx_m, 1.0))


# ---- Brewe-Hamrock approximations (documented, not used by the model) ---------------------------


@njit(**JIT)
def brewe_hamrock_ellipticity(rx_m, ry_m):
    """k ~ (Ry/Rx)^(2/pi) [-] (Brewe & Hamrock 1977; seed 000 eq. 2)."""
    return (ry_m / rx_m) ** (2.0 / math.pi)


@njit(**JIT)
def brewe_hamrock_first_kind(rx_m, ry_m):
    """Fbar ~ pi/2 + (pi/2 - 1) ln(Ry/Rx) [-] (Brewe & Hamrock 1977; the reading of docs/physics.md)."""
    return 0.5 * math.pi + _Q * math.log(ry_m / rx_m)


@njit(**JIT)
def brewe_hamrock_second_kind(rx_m, ry_m):
    """Ebar ~ 1 + (pi/2 - 1) Rx/Ry [-] (Brewe & Hamrock 1977; seed 000 eq. 2)."""
    return 1.0 + _Q * rx_m / ry_m


# ---- contact laws in terms of the constants -----------------------------------------------------


@njit(**JIT)
def stiffness_from_constants(k, fbar, ebar, r_m, effective_modulus_pa):
    """K = pi k E' sqrt(2 Ebar R / (9 Fbar^3)) [N/m^1.5] (seed 000 eq. 2, docs/physics.md)."""
    return math.pi * k * effective_modulus_pa * math.sqrt(2.0 * ebar * r_m / (9.0 * fbar**3))


@njit(**JIT)
def semi_major_from_constants(load_n, k, ebar, r_m, effective_modulus_pa):
    """a = (6 k^2 Ebar Q R / (pi E'))^(1/3) [m], transverse semi-axis (Hamrock & Brewe 1983)."""
    if load_n <= 0.0:
        return 0.0
    return (6.0 * k * k * ebar * load_n * r_m / (math.pi * effective_modulus_pa)) ** (1.0 / 3.0)


@njit(**JIT)
def semi_minor_from_constants(load_n, k, ebar, r_m, effective_modulus_pa):
    """b = (6 Ebar Q R / (pi k E'))^(1/3) [m], rolling-direction semi-axis (Hamrock & Brewe 1983)."""
    if load_n <= 0.0:
        return 0.0
    return (6.0 * ebar * load_n * r_m / (math.pi * k * effective_modulus_pa)) ** (1.0 / 3.0)


def raceway_stiffness_n_m15(rx_m, ry_m, effective_modulus_pa):
    """K [N/m^1.5] in Q = K delta^1.5 of a ball-raceway contact, exact constants (seed 000 eq. 2)."""
    c = elliptic_constants(rx_m, ry_m)
    return stiffness_from_constants(
        c.ellipticity, c.first_kind, c.second_kind, curvature_sum_radius_m(rx_m, ry_m), effective_modulus_pa
    )


def semi_major_axis_m(load_n, rx_m, ry_m, effective_modulus_pa):
    """a [m], transverse semi-axis of the Hertz ellipse, exact constants (Hamrock & Brewe 1983,
    the ref. [9] that seed 000 eq. 5 uses)."""
    c = elliptic_constants(rx_m, ry_m)
    return semi_major_from_constants(
        load_n, c.ellipticity, c.second_kind, curvature_sum_radius_m(rx_m, ry_m), effective_modulus_pa
    )


def semi_minor_axis_m(load_n, rx_m, ry_m, effective_modulus_pa):
    """b [m], rolling-direction semi-axis of the Hertz ellipse, exact constants."""
    c = elliptic_constants(rx_m, ry_m)
    return semi_minor_from_constants(
        load_n, c.ellipticity, c.second_kind, curvature_sum_radius_m(rx_m, ry_m), effective_modulus_pa
    )


def approach_m(load_n, rx_m, ry_m, effective_modulus_pa):
    """Mutual approach delta = (Q / K)^(2/3) [m] of the two bodies (seed 000 eq. 2 inverted)."""
    return (max(load_n, 0.0) / raceway_stiffness_n_m15(rx_m, ry_m, effective_modulus_pa)) ** (2.0 / 3.0)


@njit(**JIT)
def ball_ball_stiffness_n_m15(r1_m, r2_m, shear_modulus_pa, poisson_ratio):
    """K [N/m^1.5] for two spheres (ball-cage element), 4 G sqrt(Req) / (3 (1 - nu)) (seed 000 eq. 3)."""
    req = convex_radius_m(r1_m, r2_m)
    return 4.0 * shear_modulus_pa * math.sqrt(req) / (3.0 * (1.0 - poisson_ratio))


@njit(**JIT)
def max_pressure_pa(load_n, semi_major_m, semi_minor_m):
    """p_max = 3 Q / (2 pi a b) [Pa] (Hertz)."""
    if semi_major_m <= 0.0 or semi_minor_m <= 0.0:
        return 0.0
    return 1.5 * load_n / (math.pi * semi_major_m * semi_minor_m)
