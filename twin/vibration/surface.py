"""The excitation a healthy bearing has: the races' profiles and the spread of the ball sizes.

A real raceway is not a circle: its waviness and roughness, seen by a rolling ball, are a
displacement excitation of the contact (Sawalhi & Randall 2008, "Simulating gear and bearing
interactions in the presence of faults, Part II", MSSP 22(8) 1952-1966: the extended (rough
surface) race faults are a random profile added to the contact deflection; Harsha 2006,
"Nonlinear dynamic analysis of rolling element bearings due to cage run-out and number of balls",
J. Sound Vib. 289, and Wardle 1988, Proc. IMechE C 202, waviness as a Fourier series of the race
profile over the circumference). Here each race carries one random profile over its
circumference,

    h(theta) = sum_{n = 2}^{n_max} a cos(n theta + phi_n),   phi_n uniform in [0, 2 pi),

a flat spectrum of equal amplitudes a over the orders n = 2 (the lowest waviness, ovality)
to n_max = 2 pi R / lambda_min (R the raceway radius, lambda_min the shortest wavelength the
contact follows: shorter ones are averaged out over the Hertz contact, whose length 2b along the
rolling direction is 0.2-0.4 mm in the CWRU bearing at its load), scaled to the RMS asked for;
order 1 (an eccentricity) is left out, as it moves the ring rather than loading the balls. The
balls' own diameters spread (ISO 3290-1: the lot diameter variation V_DwL of grade G10 balls is
0.5 um): each ball has a constant radius offset, which modulates the load distribution at the
cage frequency.

The slip of the cage is not an input: the balls and the cage are free bodies of the DEM, so the
cage's speed (and every ball's lag behind its pocket) follows from the traction and the load
zone, and the profile is read where each ball actually is.

Kernel side (`profile_drops`): every contact lane takes the height of its race's profile at the
ball's azimuth (on the inner ring: the azimuth less the shaft angle) by linear interpolation in a
PROFILE_POINTS table held in the model vector (twin.kernels.layout P_PROFILE_*), plus the ball's
radius offset; the sum closes the contact (a negative extra clearance), and
`twin.kernels.vibration.apply_clearances` takes it off the deflection with the defects' drops.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from pydantic import BaseModel, ConfigDict, Field

from twin.jit import JIT
from twin.kernels.layout import (
    CW, G_DEFECT_DROP, K_PX, K_PY, P_BALL_SIZE, P_PROFILE_INNER, P_PROFILE_OUTER, PROFILE_POINTS,
)

JIT_INLINE = dict(JIT, inline="always")

_FROZEN = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False)

_INV_TWO_PI = 1.0 / (2.0 * math.pi)


class SurfaceProfile(BaseModel):
    """Race profiles and ball-size spread exciting the contacts (module docstring). Off by default:
    the catalog's bearings keep seed 000's perfect geometry; `CWRU-DE` switches it on."""

    model_config = _FROZEN

    enabled: bool = Field(
        default=False, description="Race profiles and ball-size spread excite the contacts (twin.vibration.surface).")
    race_profile_rms_m: float = Field(
        default=0.05e-6, ge=0.0, le=5e-6,
        description="RMS of each race's profile over the orders 2 .. n_max [m] (waviness and the roughness the "
        "contact follows; superfinished raceways: a few hundredths of a micrometre to ~0.1 um).")
    shortest_wavelength_m: float = Field(
        default=0.3e-3, ge=20e-6, le=0.01,
        description="Shortest wavelength of the profile [m]: about the Hertz contact length 2b, over which the "
        "contact averages shorter ones out.")
    ball_diameter_spread_m: float = Field(
        default=0.125e-6, ge=0.0, le=5e-6,
        description="Standard deviation of the balls' diameters [m] (ISO 3290-1 grade G10: lot diameter "
        "variation 0.5 um, taken as 4 standard deviations).")
    seed: int = Field(default=0, ge=0, le=2 ** 32 - 1,
                      description="Seed of the profiles' random phases and the ball sizes (numpy).")


def race_profile_m(rms_m: float, raceway_radius_m: float, shortest_wavelength_m: float,
                   rng: np.random.Generator, points: int = PROFILE_POINTS) -> np.ndarray:
    """Heights [m] of one race's profile at `points` equally spaced angles (module docstring): equal
    amplitudes of random phase over the orders 2 .. n_max = 2 pi R / lambda_min (at most
    points / 4, so that linear interpolation resolves the shortest wave), RMS `rms_m`."""
    n_max = int(min(2.0 * math.pi * raceway_radius_m / shortest_wavelength_m, points // 4))
    if n_max < 2 or rms_m == 0.0:
        return np.zeros(points)
    spectrum = np.zeros(points // 2 + 1, dtype=complex)
    orders = np.arange(2, n_max + 1)
    spectrum[orders] = np.exp(1j * rng.uniform(0.0, 2.0 * math.pi, orders.size))
    h = np.fft.irfft(spectrum, n=points)
    return h * (rms_m / math.sqrt(float(np.mean(h * h))))


def ball_radius_offsets_m(spread_m: float, ball_count: int, rng: np.random.Generator) -> np.ndarray:
    """Radius offset [m] of each ball: half a normal diameter deviation of standard deviation
    `spread_m`, less the set's mean (the nominal diameter stays the set's mean)."""
    d = rng.normal(0.0, spread_m, ball_count) if spread_m > 0.0 else np.zeros(ball_count)
    return 0.5 * (d - d.mean())


def write_profile_params(p: np.ndarray, profile: SurfaceProfile, geometry) -> None:
    """The profile tables and the ball radius offsets into the model vector p (P_PROFILE_*,
    P_BALL_SIZE); all zero when the profile is off."""
    p[P_BALL_SIZE:P_PROFILE_OUTER + PROFILE_POINTS] = 0.0
    if not profile.enabled:
        return
    rng = np.random.default_rng(profile.seed)
    p[P_PROFILE_INNER:P_PROFILE_INNER + PROFILE_POINTS] = race_profile_m(
        profile.race_profile_rms_m, geometry.inner_raceway_radius_m, profile.shortest_wavelength_m, rng)
    p[P_PROFILE_OUTER:P_PROFILE_OUTER + PROFILE_POINTS] = race_profile_m(
        profile.race_profile_rms_m, geometry.outer_raceway_radius_m, profile.shortest_wavelength_m, rng)
    z = geometry.ball_count
    p[P_BALL_SIZE:P_BALL_SIZE + z] = ball_radius_offsets_m(profile.ball_diameter_spread_m, z, rng)


# Abramowitz & Stegun 4.4.49: atan x = x (1 + sum a_2k x^2k), 0 <= x <= 1, |error| <= 2e-8 rad
_ATAN_COEFFS = (-0.3333314528, 0.1999355085, -0.1420889944, 0.1065626393,
                -0.0752896400, 0.0429096138, -0.0161657367, 0.0028662257)
_A2, _A4, _A6, _A8, _A10, _A12, _A14, _A16 = _ATAN_COEFFS


@njit(**JIT_INLINE)
def azimuth_rad(y, x):
    """atan2(y, x) [rad] in [-pi, pi] to 2e-8 rad (Abramowitz & Stegun 4.4.49 on the octant, then
    the reflections): the profile's table has 4096 points (1.5e-3 rad apart), so the error moves the
    read point by 1e-5 of a step, at a third of libm's cost per lane."""
    ax = abs(x)
    ay = abs(y)
    if ax == 0.0 and ay == 0.0:
        return 0.0
    swap = ay > ax
    t = ax / ay if swap else ay / ax
    t2 = t * t
    a = t * (1.0 + t2 * (_A2 + t2 * (_A4 + t2 * (_A6 + t2 * (_A8 + t2 * (_A10 + t2 * (_A12 + t2 * (
        _A14 + t2 * _A16))))))))
    if swap:
        a = 0.5 * math.pi - a
    if x < 0.0:
        a = math.pi - a
    return -a if y < 0.0 else a


@njit(**JIT_INLINE)
def profile_height_m(p, base, angle_rad):
    """Height [m] of the profile table at p[base:base + PROFILE_POINTS] at `angle_rad` (any
    real angle; periodic), linearly interpolated."""
    u = angle_rad * _INV_TWO_PI * PROFILE_POINTS
    u -= math.floor(u / PROFILE_POINTS) * PROFILE_POINTS
    i = int(u)
    if i >= PROFILE_POINTS:  # a tiny negative angle wraps to u = PROFILE_POINTS exactly: that is point 0
        i = 0
        u = 0.0
    f = u - i
    i1 = i + 1 if i + 1 < PROFILE_POINTS else 0
    return p[base + i] + f * (p[base + i1] - p[base + i])


@njit(**JIT_INLINE)
def profile_drops(w, nc, p, shaft_angle):
    """Take each lane's race-profile height and its ball's radius offset [m] off its extra clearance
    G_DEFECT_DROP (module docstring; lane c = 2 j + r, r = 0 inner race, turned with the shaft
    angle [rad], r = 1 outer race)."""
    for c in range(nc):
        theta = azimuth_rad(w[K_PY * CW + c], w[K_PX * CW + c])
        if c & 1:
            h = profile_height_m(p, P_PROFILE_OUTER, theta)
        else:
            h = profile_height_m(p, P_PROFILE_INNER, theta - shaft_angle)
        w[G_DEFECT_DROP * CW + c] -= h + p[P_BALL_SIZE + (c >> 1)]
