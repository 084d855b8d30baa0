"""Warm start: quasi-static equilibrium of the inner ring and every ball (normal Hertz contacts,
applied loads, centrifugal force of the orbit) with rolling kinematics, so a new twin is in
steady state within a few milliseconds of simulated time instead of hundreds."""

from __future__ import annotations

import math

import numpy as np
from scipy import optimize

from twin.kernels import layout as L
from twin.kernels.contacts import groove_penetration
from twin.model import BearingModel
from twin.state import TwinState

_REG_SPRING_N_M = 1e3  # keeps floating (unloaded) balls and the free axial mode well posed


def _equilibrium_residual(x_um, model: BearingModel, azimuths, fr, fa, cage_speed):
    p, race = model.params, model.race_params
    rb, m = p[L.P_BALL_RADIUS], p[L.P_BALL_MASS]
    z = model.ball_count
    x = x_um * 1e-6
    ring = x[:3]
    res = np.zeros(3 + 2 * z)
    ring_force = np.array([fr, 0.0, fa]) - _REG_SPRING_N_M * ring * np.array([0.0, 0.0, 1.0])
    for j in range(z):
        rho = model.pitch_radius_m + x[3 + 2 * j]
        zb = x[4 + 2 * j]
        c, s = math.cos(azimuths[j]), math.sin(azimuths[j])
        ball = np.array([rho * c, rho * s, zb])
        fball = np.zeros(3)
        for r, centre in ((0, ring), (1, np.zeros(3))):
            rel = ball - centre
            delta, nx, ny, nz = groove_penetration(rel[0], rel[1], rel[2], race[r, L.R_GROOVE_CENTRE_RADIUS],
                                                   race[r, L.R_GROOVE_CENTRE_Z], race[r, L.R_GROOVE_RADIUS], rb)
            if delta > 0.0:
                q = race[r, L.R_STIFFNESS] * delta ** 1.5
                f = -q * np.array([nx, ny, nz])
                fball += f
                if r == 0:
                    ring_force -= f
        fball[0] += m * cage_speed ** 2 * rho * c
        fball[1] += m * cage_speed ** 2 * rho * s
        fball -= _REG_SPRING_N_M * np.array([x[3 + 2 * j] * c, x[3 + 2 * j] * s, zb])
        res[3 + 2 * j] = fball[0] * c + fball[1] * s
        res[4 + 2 * j] = fball[2]
    res[:3] = ring_force
    return res


def solve_equilibrium(model: BearingModel, azimuths, radial_load_n, axial_load_n, cage_speed_rad_s):
    """Ring shift [m] (3,), ball radial offsets from the pitch circle [m] and axial positions [m]."""
    z = model.ball_count
    x0 = np.zeros(3 + 2 * z)
    sol = optimize.root(_equilibrium_residual, x0, args=(model, azimuths, radial_load_n, axial_load_n,
                                                        cage_speed_rad_s),
                        method="hybr", options={"xtol": 1e-13, "maxfev": 20000})
    if not sol.success:
        sol = optimize.root(_equilibrium_residual, sol.x, args=(model, azimuths, radial_load_n,
                                                               axial_load_n, cage_speed_rad_s),
                            method="lm", options={"xtol": 1e-14, "maxiter": 20000})
    x = sol.x * 1e-6
    return x[:3], x[3::2], x[4::2], bool(sol.success)


def warm_start(model: BearingModel, state: TwinState, shaft_speed_rad_s: float, radial_load_n: float,
               axial_load_n: float, cage_angle_rad: float = 0.0) -> bool:
    """Fill `state` with the quasi-static equilibrium and rolling kinematics; returns whether the
    equilibrium solver converged."""
    z = model.ball_count
    cage_speed = model.cage_speed_rad_s(shaft_speed_rad_s)
    azimuths = cage_angle_rad + 2.0 * math.pi * np.arange(z) / z
    ring, d_rho, zb, ok = solve_equilibrium(model, azimuths, radial_load_n, axial_load_n, cage_speed)
    rb = model.ball_radius_m
    alpha = model.contact_angle_rad
    state.scalars[:] = 0.0
    state.scalars[L.X_SHAFT_SPEED] = shaft_speed_rad_s
    state.scalars[L.X_CAGE_ANGLE] = cage_angle_rad
    state.scalars[L.X_CAGE_SPEED] = cage_speed
    state.ring_position_m[:] = ring
    state.ring_velocity_m_s[:] = 0.0
    state.tangential_spring_m[:] = 0.0
    state.contacts[:] = 0.0
    state.contacts[L.C_LAMBDA] = -1.0
    for j in range(z):
        c, s = math.cos(azimuths[j]), math.sin(azimuths[j])
        rho = model.pitch_radius_m + d_rho[j]
        state.ball_position_m[j] = (rho * c, rho * s, zb[j])
        e_t = np.array([-s, c, 0.0])
        speed = cage_speed * rho
        state.ball_velocity_m_s[j] = speed * e_t
        # no slip at the outer contact: omega_b = -(V / Rb) (n_o x e_t), n_o the outer normal
        n_o = np.array([math.cos(alpha) * c, math.cos(alpha) * s, math.sin(alpha)])
        state.ball_angular_velocity_rad_s[j] = -(speed / rb) * np.cross(n_o, e_t)
    return ok
