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

Kernel side (`twin.kernels.profile.profile_drops`): every contact lane takes the height of its race's profile at the
ball's azimuth (on the inner ring: the azimuth less the shaft angle) by linear interpolation in a
PROFILE_POINTS table held in the model vector (twin.kernels.layout P_PROFILE_*), plus the ball's
radius offset; the sum closes the contact (a negative extra clearance), and
`twin.kernels.vibration.apply_clearances` takes it off the deflection with the defects' drops.
"""

from __future__ import annotations

import math

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

_FROZEN = ConfigDict(frozen=True, extra="forbid", strict=True, allow_inf_nan=False)

PROFILE_POINTS = 4096  # points of a race profile over its circumference (the kernel's table length)


class SurfaceProfile(BaseModel):
    """Race profiles and ball-size spread exciting the contacts (module docstring). Off by default:
    the catalog's bearings keep seed 000's perfect geometry; `CWRU-DE` switches it on."""

    model_config = _FROZEN

    enabled: bool = Field(
        default=False, description="Race profiles and ball-size spread excite the contacts (twin.vibration.surface)."
    )
    race_profile_rms_m: float = Field(
        default=0.05e-6,
        ge=0.0,
        le=5e-6,
        description="RMS of each race's profile over the orders 2 .. n_max [m] (waviness and the roughness the "
        "contact follows; superfinished raceways: a few hundredths of a micrometre to ~0.1 um).",
    )
    shortest_wavelength_m: float = Field(
        default=0.3e-3,
        ge=20e-6,
        le=0.01,
        description="Shortest wavelength of the profile [m]: about the Hertz contact length 2b, over which the "
        "contact averages shorter ones out.",
    )
    ball_diameter_spread_m: float = Field(
        default=0.125e-6,
        ge=0.0,
        le=5e-6,
        description="Standard deviation of the balls' diameters [m] (ISO 3290-1 grade G10: lot diameter "
        "variation 0.5 um, taken as 4 standard deviations).",
    )
    seed: int = Field(
        default=0, ge=0, le=2**32 - 1, description="Seed of the profiles' random phases and the ball sizes (numpy)."
    )


def race_profile_m(
    rms_m: float,
    raceway_radius_m: float,
    shortest_wavelength_m: float,
    rng: np.random.Generator,
    points: int = PROFILE_POINTS,
) -> np.ndarray:
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
