"""Measures of the engine state that the frame loop, the couplings and the outputs read: the
balls' azimuths, the kinetic energy and the axial angular momentum of the balls and the cage,
the loaded inner contacts' mean entrainment speed and the loaded zone's ball count (K of seed 003
eq. 10).

Plain functions of a `BearingModel` and a `TwinState`: they read, never write. numpy, but for the
kinetic energy's sums, compiled: the frame loop takes it before and after each compiled call.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from twin.jit import JIT
from twin.kernels import layout as L
from twin.model import BearingModel
from twin.state import TwinState


def ball_azimuths_rad(state: TwinState) -> np.ndarray:
    """Ball centre angles about the outer ring's centre from the load line (+x), in (-pi, pi]
    [rad]."""
    x = state.ball_position_in_bearing_m
    return np.arctan2(x[:, 1], x[:, 0])


def axial_angular_momentum_n_m_s(model: BearingModel, state: TwinState) -> float:
    """Angular momentum of the balls and the cage about the bearing axis [N m s]: the balls'
    orbital m (x v_y - y v_x) and spin I omega_z, the cage's I_c omega_c."""
    p = model.params
    x, v = state.ball_position_in_bearing_m, state.ball_velocity_in_bearing_m_s
    orbital = p[L.P_BALL_MASS] * float(np.sum(x[:, 0] * v[:, 1] - x[:, 1] * v[:, 0]))
    spin = p[L.P_BALL_INERTIA] * float(np.sum(state.ball_angular_velocity_rad_s[:, 2]))
    return orbital + spin + p[L.P_CAGE_INERTIA] * float(state.scalars[L.X_CAGE_SPEED])


@njit(**JIT)
def _kinetic_energy_j(
    params: np.ndarray, velocity: np.ndarray, angular_velocity: np.ndarray, cage_speed: float
) -> float:
    """0.5 (m sum |v|^2 + I sum |omega|^2 + I_c omega_c^2) over the balls' (z, 3) velocities [J]:
    compiled, because the frame loop takes it twice per frame (before and after `step_n`)."""
    vv = 0.0
    ww = 0.0
    for j in range(velocity.shape[0]):
        for k in range(3):
            vv += velocity[j, k] * velocity[j, k]
            ww += angular_velocity[j, k] * angular_velocity[j, k]
    return 0.5 * (
        params[L.P_BALL_MASS] * vv + params[L.P_BALL_INERTIA] * ww + params[L.P_CAGE_INERTIA] * cage_speed * cage_speed
    )


def kinetic_energy_j(model: BearingModel, state: TwinState) -> float:
    """Kinetic energy of the balls (translation and rotation) and the cage [J]."""
    v = state.ball_velocity_in_bearing_m_s if model.housing_on else state.ball_velocity_m_s
    return float(
        _kinetic_energy_j(model.params, v, state.ball_angular_velocity_rad_s, float(state.scalars[L.X_CAGE_SPEED]))
    )


def mean_entrainment_speed_m_s(state: TwinState) -> float:
    """Mean entrainment speed of the loaded inner-race contacts (all inner contacts if none is
    loaded) [m/s]."""
    c = state.contacts
    u = c[L.C_ENTRAINMENT, 0::2]
    loaded = c[L.C_LOAD, 0::2] > 0.0
    return float(np.mean(np.abs(u[loaded] if loaded.any() else u)))


def loaded_zone_ball_count(model: BearingModel, state: TwinState) -> float:
    """Balls in the inner race's loaded zone (K of seed 003 eq. 10) as the zone's arc in ball
    pitches: the mean number of loaded balls over a ball pass. The count at an instant jumps by
    one whenever a ball crosses an edge of the zone, and sampled every 10 ms by the electro-thermal
    coupling it would make the heating a step function of the state (at 1700 rad/s and 20 A:
    6.5 or 8.1 K, 25 % apart, by when a sample fell). The edges are interpolated between
    neighbouring balls on their inner approach (G_DELTA, < 0: gap)."""
    z = model.ball_count
    delta = state.contacts[L.G_DELTA, 0::2]
    loaded = delta > 0.0
    if loaded.all() or not loaded.any():
        return float(z) if loaded.all() else 0.0
    az = ball_azimuths_rad(state)
    order = np.argsort(az)
    az, d = az[order], delta[order]
    arc = 0.0
    for j in range(z):
        k = (j + 1) % z
        gap = (az[k] - az[j]) % (2.0 * math.pi)
        if d[j] > 0.0 and d[k] > 0.0:
            arc += gap
        elif d[j] > 0.0 or d[k] > 0.0:  # one edge of the zone lies between the two balls
            inside = d[j] if d[j] > 0.0 else d[k]
            arc += gap * inside / (abs(d[j]) + abs(d[k]))
    return arc * z / (2.0 * math.pi)
