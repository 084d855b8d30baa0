"""The race profiles and ball sizes of `twin.vibration.surface` in the kernel: `write_profile_params`
puts the profile tables and the ball radius offsets into the model vector (twin.kernels.layout
P_PROFILE_*, P_BALL_SIZE); `profile_drops` reads each lane's height where its ball is (on the inner
ring: turned with the shaft) and adds it, with the ball's offset, to the lane's extra clearance
(`twin.kernels.vibration.apply_clearances`)."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from twin.jit import JIT
from twin.kernels.layout import (
    CW,
    G_DEFECT_DROP,
    K_PX,
    K_PY,
    P_BALL_SIZE,
    P_PROFILE_INNER,
    P_PROFILE_OUTER,
    PROFILE_POINTS,
)
from twin.vibration.surface import SurfaceProfile, ball_radius_offsets_m, race_profile_m

JIT_INLINE = dict(JIT, inline="always")

_INV_TWO_PI = 1.0 / (2.0 * math.pi)


def write_profile_params(p: np.ndarray, profile: SurfaceProfile, geometry) -> None:
    """The profile tables and the ball radius offsets into the model vector p (P_PROFILE_*,
    P_BALL_SIZE); all zero when the profile is off."""
    p[P_BALL_SIZE : P_PROFILE_OUTER + PROFILE_POINTS] = 0.0
    if not profile.enabled:
        return
    rng = np.random.default_rng(profile.seed)
    p[P_PROFILE_INNER : P_PROFILE_INNER + PROFILE_POINTS] = race_profile_m(
        profile.race_profile_rms_m, geometry.inner_raceway_radius_m, profile.shortest_wavelength_m, rng
    )
    p[P_PROFILE_OUTER : P_PROFILE_OUTER + PROFILE_POINTS] = race_profile_m(
        profile.race_profile_rms_m, geometry.outer_raceway_radius_m, profile.shortest_wavelength_m, rng
    )
    z = geometry.ball_count
    p[P_BALL_SIZE : P_BALL_SIZE + z] = ball_radius_offsets_m(profile.ball_diameter_spread_m, z, rng)


# Abramowitz & Stegun 4.4.49: atan x = x (1 + sum a_2k x^2k), 0 <= x <= 1, |error| <= 2e-8 rad
_ATAN_COEFFS = (
    -0.3333314528,
    0.1999355085,
    -0.1420889944,
    0.1065626393,
    -0.0752896400,
    0.0429096138,
    -0.0161657367,
    0.0028662257,
)
_A2, _A4, _A6, _A8, _A10, _A12, _A14, _A16 = _ATAN_COEFFS


_HALF_PI = 0.5 * math.pi
_TINY_M = 1e-300  # keeps the octant's ratio finite at the origin (where the azimuth is 0)
_TABLE_MASK = PROFILE_POINTS - 1
if PROFILE_POINTS & _TABLE_MASK:
    raise ValueError(f"PROFILE_POINTS = {PROFILE_POINTS}: the table's wrap-around by bit mask needs a power of two")
_POINTS_PER_RAD = PROFILE_POINTS * _INV_TWO_PI


@njit(**JIT_INLINE)
def azimuth_rad(y, x):
    """atan2(y, x) [rad] in [-pi, pi] to 2e-8 rad (Abramowitz & Stegun 4.4.49 on the octant, then
    the reflections, as selects: no branch for the lanes to mispredict): the profile's table has
    4096 points (1.5e-3 rad apart), so the error moves the read point by 1e-5 of a step, at a
    third of libm's cost per lane. 0 at the origin."""
    ax = abs(x)
    ay = abs(y)
    t = min(ax, ay) / max(max(ax, ay), _TINY_M)
    t2 = t * t
    a = t * (
        1.0 + t2 * (_A2 + t2 * (_A4 + t2 * (_A6 + t2 * (_A8 + t2 * (_A10 + t2 * (_A12 + t2 * (_A14 + t2 * _A16)))))))
    )
    a = _HALF_PI - a if ay > ax else a
    a = math.pi - a if x < 0.0 else a
    return -a if y < 0.0 else a


@njit(**JIT_INLINE)
def _table_height_m(p, base, u):
    """Height [m] of the table at p[base:base + PROFILE_POINTS] at table coordinate u >= 0
    (points; periodic by the bit mask), linearly interpolated."""
    i = int(u)
    f = u - i
    lo = p[base + (i & _TABLE_MASK)]
    return lo + f * (p[base + ((i + 1) & _TABLE_MASK)] - lo)


@njit(**JIT_INLINE)
def profile_height_m(p, base, angle_rad):
    """Height [m] of the profile table at p[base:base + PROFILE_POINTS] at `angle_rad` (any
    real angle; periodic), linearly interpolated. A tiny negative angle wraps to u =
    PROFILE_POINTS exactly, which the bit mask of `_table_height_m` reads as point 0."""
    u = angle_rad * _POINTS_PER_RAD
    return _table_height_m(p, base, u - math.floor(u / PROFILE_POINTS) * PROFILE_POINTS)


@njit(**JIT_INLINE)
def profile_drops(w, nc, p, shaft_angle):
    """Take each lane's race-profile height and its ball's radius offset [m] off its extra clearance
    G_DEFECT_DROP (module docstring; lane c = 2 j + r, r = 0 inner race, turned with the shaft
    angle [rad], r = 1 outer race). One azimuth per ball, its outer lane's; the inner lane's is
    that plus the small angle between the two lanes' centres (the ball seen from the inner and
    the outer ring's centre, which differ by the rings' displacement: asin of their cross
    product, taken as the sine, ~1e-3 rad, so the error is below 1e-9 rad)."""
    turns = shaft_angle * _INV_TWO_PI
    shaft_u = (turns - math.floor(turns)) * PROFILE_POINTS  # [0, PROFILE_POINTS)
    for j in range(nc >> 1):
        co = 2 * j + 1
        ci = 2 * j
        xo = w[K_PX * CW + co]
        yo = w[K_PY * CW + co]
        xi = w[K_PX * CW + ci]
        yi = w[K_PY * CW + ci]
        outer_rad = azimuth_rad(yo, xo)
        between_rad = (xo * yi - yo * xi) / max(math.sqrt((xo * xo + yo * yo) * (xi * xi + yi * yi)), _TINY_M)
        size = p[P_BALL_SIZE + j]
        # table coordinates shifted by 2 PROFILE_POINTS: >= 0 for every azimuth in [-pi, pi]
        u_outer = outer_rad * _POINTS_PER_RAD + 2.0 * PROFILE_POINTS
        u_inner = (outer_rad + between_rad) * _POINTS_PER_RAD - shaft_u + 2.0 * PROFILE_POINTS
        w[G_DEFECT_DROP * CW + co] -= _table_height_m(p, P_PROFILE_OUTER, u_outer) + size
        w[G_DEFECT_DROP * CW + ci] -= _table_height_m(p, P_PROFILE_INNER, u_inner) + size
