"""Warm start: quasi-static equilibrium of the inner ring and every ball (normal Hertz contacts,
applied loads, centrifugal force of the orbit) with rolling kinematics, so a new twin is in
steady state within a few milliseconds of simulated time instead of hundreds. Each contact's
Hertz stiffness is taken at its own contact angle from the model's angle table, as the kernel
does, and written to the contact lanes, so the first step starts from the same equilibrium."""

from __future__ import annotations

import math

import numpy as np
from scipy import optimize

from twin.kernels import layout as L
from twin.kernels.contacts import groove_penetration
from twin.model import BearingModel
from twin.state import TwinState
from twin.vibration.housing import housing_equilibrium

_REG_SPRING_N_M = 1e3  # keeps floating (unloaded) balls and the free axial mode well posed
_ORIGIN = np.zeros(3)  # the outer ring's centre (fixed) [m]


def race_contacts(model: BearingModel, ring_m, ball_m) -> tuple[tuple[float, float, float, float, float], ...]:
    """A ball's two raceway contacts, the ball's centre at `ball_m` and the inner ring's at
    `ring_m` [m] (the outer ring's at the origin): per race (0 inner, 1 outer) the penetration
    delta [m] (<= 0: no contact), the contact normal's unit components (nx, ny, nz) and the
    Hertz stiffness K [N/m^1.5] at the contact's own angle (`BearingModel.stiffness_at`, as
    the kernel interpolates it); the contact load is K delta^1.5 (seed 000 eq. 2)."""
    race, rb = model.race_params, model.ball_radius_m
    contacts = []
    for r, centre in ((0, ring_m), (1, _ORIGIN)):
        delta, nx, ny, nz = groove_penetration(
            ball_m[0] - centre[0],
            ball_m[1] - centre[1],
            ball_m[2] - centre[2],
            race[r, L.R_GROOVE_CENTRE_RADIUS],
            race[r, L.R_GROOVE_CENTRE_Z],
            race[r, L.R_GROOVE_RADIUS],
            rb,
        )
        contacts.append((delta, nx, ny, nz, model.stiffness_at(r, nz)))
    return tuple(contacts)


def _equilibrium_residual(x_um, model: BearingModel, azimuths, fr, fa, cage_speed):
    m = model.params[L.P_BALL_MASS]
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
        for r, (delta, nx, ny, nz, k) in enumerate(race_contacts(model, ring, ball)):
            if delta > 0.0:
                q = k * delta**1.5
                f = -q * np.array([nx, ny, nz])
                fball += f
                if r == 0:
                    ring_force -= f
        fball[0] += m * cage_speed**2 * rho * c
        fball[1] += m * cage_speed**2 * rho * s
        fball -= _REG_SPRING_N_M * np.array([x[3 + 2 * j] * c, x[3 + 2 * j] * s, zb])
        res[3 + 2 * j] = fball[0] * c + fball[1] * s
        res[4 + 2 * j] = fball[2]
    res[:3] = ring_force
    return res


def _initial_guess_um(model: BearingModel, azimuths, fr, fa) -> np.ndarray:
    """Ring shift and ball offsets from the rigid-ring Hertz estimate (Stribeck's Qmax for the
    radial part, an even share for the axial part), so that the solver does not start at the
    zero-penetration point where every contact stiffness vanishes."""
    z = model.ball_count
    race = model.race_params
    ki, ko = race[0, L.R_STIFFNESS], race[1, L.R_STIFFNESS]
    k_eff = (ki ** (-2 / 3) + ko ** (-2 / 3)) ** -1.5
    outer_share = ko ** (-2 / 3) / (ki ** (-2 / 3) + ko ** (-2 / 3))
    alpha = model.contact_angle_rad
    pd = model.spec.mounting.diametral_clearance_m
    qmax = max(fr, 1.0) / (z * 0.2288)
    delta_r = (qmax / k_eff) ** (2 / 3) / max(math.cos(alpha), 0.2) + 0.5 * max(pd, 0.0)
    delta_a = 0.0
    if alpha > 0.0 and fa > 0.0:
        delta_a = (fa / (z * k_eff * math.sin(alpha))) ** (2 / 3) / math.sin(alpha)
    x = np.zeros(3 + 2 * z)
    x[0], x[2] = delta_r, delta_a
    for j in range(z):
        total = delta_r * math.cos(azimuths[j]) * math.cos(alpha) + delta_a * math.sin(alpha) - 0.5 * pd
        d_out = outer_share * max(total, 0.0)
        x[3 + 2 * j] = d_out * math.cos(alpha) + 0.5 * pd
        x[4 + 2 * j] = d_out * math.sin(alpha)
    return x * 1e6


def solve_equilibrium(model: BearingModel, azimuths, radial_load_n, axial_load_n, cage_speed_rad_s):
    """Ring shift [m] (3,), ball radial offsets from the pitch circle [m], ball axial positions
    [m], and whether the residual forces are below 1e-6 of the load."""
    args = (model, azimuths, radial_load_n, axial_load_n, cage_speed_rad_s)
    x0 = _initial_guess_um(model, azimuths, radial_load_n, axial_load_n)
    scale = max(radial_load_n, abs(axial_load_n), 1.0)
    sol = optimize.root(_equilibrium_residual, x0, args=args, method="hybr", options={"xtol": 1e-13, "maxfev": 20000})
    if np.max(np.abs(_equilibrium_residual(sol.x, *args))) > 1e-6 * scale:
        sol = optimize.root(
            _equilibrium_residual,
            sol.x,
            args=args,
            method="lm",
            options={"xtol": 1e-15, "ftol": 1e-15, "maxiter": 20000},
        )
    ok = bool(np.max(np.abs(_equilibrium_residual(sol.x, *args))) <= 1e-6 * scale)
    x = sol.x * 1e-6
    return x[:3], x[3::2], x[4::2], ok


def warm_start(
    model: BearingModel,
    state: TwinState,
    shaft_speed_rad_s: float,
    radial_load_n: float,
    axial_load_n: float,
    cage_angle_rad: float = 0.0,
) -> bool:
    """Fill `state` with the quasi-static equilibrium and rolling kinematics; returns whether the
    equilibrium solver converged."""
    z = model.ball_count
    cage_speed = model.cage_speed_rad_s(shaft_speed_rad_s)
    azimuths = cage_angle_rad + 2.0 * math.pi * np.arange(z) / z
    ring, d_rho, zb, ok = solve_equilibrium(model, azimuths, radial_load_n, axial_load_n, cage_speed)
    rb = model.ball_radius_m
    state.scalars[:] = 0.0
    state.scalars[L.X_SHAFT_SPEED] = shaft_speed_rad_s
    state.scalars[L.X_CAGE_ANGLE] = cage_angle_rad
    state.scalars[L.X_CAGE_SPEED] = cage_speed
    state.ring_position_m[:] = ring
    state.ring_velocity_m_s[:] = 0.0
    state.clear_contacts()
    rows = state.lanes.reshape(L.N_ROWS, L.CW)
    for j in range(z):
        c, s = math.cos(azimuths[j]), math.sin(azimuths[j])
        rho = model.pitch_radius_m + d_rho[j]
        ball = np.array([rho * c, rho * s, zb[j]])
        state.ball_position_m[j] = ball
        normals = []
        for r, (_, nx, ny, nz, k) in enumerate(race_contacts(model, ring, ball)):
            rows[L.M_STIFFNESS, 2 * j + r] = k
            normals.append(np.array([nx, ny, nz]))
        e_t = np.array([-s, c, 0.0])
        speed = cage_speed * rho
        state.ball_velocity_m_s[j] = speed * e_t
        # no slip at the outer contact: omega_b = -(V / Rb) (n_o x e_t), n_o the outer normal at
        # the equilibrium position (the contact angle the ball actually has)
        state.ball_angular_velocity_rad_s[j] = -(speed / rb) * np.cross(normals[1], e_t)
    return ok


def place_on_housing(model: BearingModel, state: TwinState, radial_load_n: float, axial_load_n: float) -> None:
    """Warm start on the housing: the outer ring at the static equilibrium of its support under
    the whole load (at the quasi-static equilibrium the balls pass the applied loads to the outer
    ring; their centrifugal forces cancel over the ring), the balls and the inner ring moved with
    it; the decimator and the sample ring restart (twin.vibration.housing.housing_equilibrium)."""
    s = state
    housing_equilibrium(
        model.housing_params,
        radial_load_n,
        0.0,
        axial_load_n,
        s.housing_displacement_m,
        s.housing_velocity_m_s,
        s.housing_acceleration_m_s2,
    )
    shift = s.housing_displacement_m[:3]
    s.ball_position_m += shift
    s.ring_position_m += shift
    s.decimator_state[:] = 0.0
    s.sample_ring_state[:] = 0.0
