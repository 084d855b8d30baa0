"""Closed-form and quasi-static references used by the tests and the report.

Load distribution of a rigidly supported radial ball bearing (seed 000 Appendix A, after Harris
[45]): delta_psi = delta_r cos(psi) - Pd/2 (eq. A1), Q = K_eff delta^1.5 with the inner and
outer Hertz contacts in series, Stribeck's Qmax = Fr / (Z Jr(eps)) (eq. A3).

Jones' quasi-static solution for combined radial and axial load (and clearance or preload) of
angular-contact and deep-groove ball bearings, with the centrifugal force of the balls and the
exact Hertz constants at each contact's own angle (`jones_equilibrium`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import integrate, optimize

from twin import model as model_lib
from twin.kernels import layout as L
from twin.model import BearingModel


def series_stiffness_n_m15(k_inner: float, k_outer: float) -> float:
    """K of the ball's two contacts in series: (Ki^-2/3 + Ko^-2/3)^-3/2 [N/m^1.5]."""
    return (k_inner ** (-2.0 / 3.0) + k_outer ** (-2.0 / 3.0)) ** -1.5


def load_parameter_epsilon(radial_shift_m: float, clearance_m: float) -> float:
    """eps = (1 - Pd / (2 delta_r)) / 2 (seed 000 Appendix A)."""
    return 0.5 * (1.0 - clearance_m / (2.0 * radial_shift_m))


def radial_integral(epsilon: float) -> float:
    """Jr(eps) = 1/(2 pi) int [1 - (1 - cos psi)/(2 eps)]^1.5 cos psi dpsi over the loaded zone
    (Harris; Jr(0.5) = 0.2288, seed 000 eq. A3)."""
    if epsilon >= 1.0:
        lim = math.pi
    else:
        lim = math.acos(max(-1.0, 1.0 - 2.0 * epsilon))

    def f(psi):
        return max(0.0, 1.0 - (1.0 - math.cos(psi)) / (2.0 * epsilon)) ** 1.5 * math.cos(psi)

    return integrate.quad(f, -lim, lim, limit=200)[0] / (2.0 * math.pi)


def stribeck_qmax_n(radial_load_n: float, ball_count: int, epsilon: float = 0.5) -> float:
    """Qmax = Fr / (Z Jr(eps)) (seed 000 eq. A3; 1457 N for the 6208 at 3000 N, Pd = 0)."""
    return radial_load_n / (ball_count * radial_integral(epsilon))


def radial_equilibrium(
    model: BearingModel, radial_load_n: float, azimuths_rad, clearance_m: float | None = None
) -> dict:
    """Hertz equilibrium of the inner ring for balls at the given azimuths (rigid rings, no
    centrifugal force): solves sum_j Q_j (cos psi_j, sin psi_j) = (Fr, 0) for the ring shift.

    Returns the shift (delta_x, delta_y) [m], radial shift along the load delta_r [m], ball loads
    [N], deflections [m], the load parameter eps and Qmax.
    """
    if clearance_m is None:
        clearance_m = model.spec.mounting.diametral_clearance_m
    psi = np.asarray(azimuths_rad, dtype=float)
    k = series_stiffness_n_m15(model.race_params[0, L.R_STIFFNESS], model.race_params[1, L.R_STIFFNESS])
    c, s = np.cos(psi), np.sin(psi)

    def loads(shift):
        defl = shift[0] * c + shift[1] * s - 0.5 * clearance_m
        return k * np.clip(defl, 0.0, None) ** 1.5, defl

    def residual(shift_um):
        q, _ = loads(shift_um * 1e-6)
        return [(q @ c - radial_load_n) / radial_load_n, (q @ s) / radial_load_n]

    guess = (radial_load_n / (model.ball_count * 0.2288 * k)) ** (2.0 / 3.0) + 0.5 * max(clearance_m, 0.0)
    sol = optimize.root(residual, [guess * 1e6, 0.0], method="hybr", options={"xtol": 1e-12})
    shift = sol.x * 1e-6
    q, defl = loads(shift)
    delta_r = float(math.hypot(*shift))
    return {
        "shift_m": shift,
        "radial_shift_m": delta_r,
        "ball_loads_n": q,
        "deflections_m": defl,
        "epsilon": load_parameter_epsilon(delta_r, clearance_m),
        "qmax_n": float(q.max()),
        "converged": bool(sol.success),
    }


@dataclass(frozen=True)
class JonesSolution:
    """Quasi-static equilibrium of the inner ring and every ball (Jones 1960; Harris & Kotzalas,
    Rolling Bearing Analysis, 5th ed., vol. 2, ch. 3 "Distribution of internal loading in high
    speed bearings", and vol. 1 ch. 7-8 for the static case).

    ring_displacement_m: inner-ring shift (x along Fr, y, z along Fa) [m]; azimuths_rad: ball
    azimuths [rad]; inner_load_n / outer_load_n [N]; inner_angle_rad / outer_angle_rad: contact
    angles, the angle between the contact normal and the radial plane, positive in the bearing's
    nominal sense [rad]; ball_axial_m / ball_radial_m: ball-centre positions (z, distance from the
    axis) [m]; centrifugal_force_n [N]; gyroscopic_moment_n_m: each ball's M_g under outer raceway
    control [N m] (zeros without it); epsilon: the load parameter (1 + delta_a tan(alpha0) /
    delta_r) / 2 of seed 004 section 3.1 (Harris) with the nominal angle alpha0 [-]; converged."""

    ring_displacement_m: np.ndarray
    azimuths_rad: np.ndarray
    inner_load_n: np.ndarray
    outer_load_n: np.ndarray
    inner_angle_rad: np.ndarray
    outer_angle_rad: np.ndarray
    ball_axial_m: np.ndarray
    ball_radial_m: np.ndarray
    centrifugal_force_n: float
    epsilon: float
    converged: bool
    gyroscopic_moment_n_m: np.ndarray | None = None

    @property
    def qmax_n(self) -> float:
        """Largest inner-contact load [N]."""
        return float(self.inner_load_n.max())


class _Geometry:
    """Groove-curvature centres of one bearing in a ball's (z, rho) plane and the exact Hertz
    stiffness of each race at any contact angle (twin.model.contact_constants)."""

    def __init__(self, model: BearingModel):
        race = model.race_params
        self.model = model
        self.rb = model.ball_radius_m
        self.inner_centre = np.array([race[0, L.R_GROOVE_CENTRE_Z], race[0, L.R_GROOVE_CENTRE_RADIUS]])
        self.outer_centre = np.array([race[1, L.R_GROOVE_CENTRE_Z], race[1, L.R_GROOVE_CENTRE_RADIUS]])
        self.inner_free = race[0, L.R_GROOVE_RADIUS] - self.rb
        self.outer_free = race[1, L.R_GROOVE_RADIUS] - self.rb
        self.e_prime = float(model.params[L.P_E_PRIME])

    def stiffness(self, race: int, sin_alpha: float) -> float:
        """Exact Hertz K [N/m^1.5] of race `race` at |sin(alpha)|."""
        return model_lib.contact_constants(self.model.spec, race == 0, min(abs(sin_alpha), 0.999), self.e_prime)[
            "stiffness_n_m15"
        ]


def outer_control_kinematics(
    ball_rho_m: float, ball_radius_m: float, inner_normal, outer_normal, shaft_speed_rad_s: float
) -> tuple[float, float, float]:
    """(omega_rho, omega_z, omega_m) [rad/s] of a ball under outer raceway control (Jones 1960;
    Harris and Kotzalas, Advanced Concepts of Bearing Technology, 5th ed. 2007, ch. 2, "Ball
    bearings: kinematics"): the ball rolls without sliding at the centres of both contacts and does
    not spin at the outer one, the inner ring turning at `shaft_speed_rad_s`, the outer fixed.

    `inner_normal` and `outer_normal` are the (z, rho) unit vectors of `_ball_forces` (ball ->
    inner groove centre, outer groove centre -> ball), so the contact points lie at -R n_i and
    +R n_o from the ball's centre at radius `ball_rho_m`. Written in the frame that turns with the
    ball's orbit omega_m, the three conditions are linear in the ball's angular velocity
    (omega_rho, 0, omega_z) relative to that frame and in omega_m: with c the contact point's
    direction and r = rho + R c_rho its distance from the axis,
    R (omega_z c_rho - omega_rho c_z) = (Omega_ring - omega_m) r at each contact, and
    omega_rho c_rho + (omega_z + omega_m) c_z = 0 at the outer. omega_rho is the ball's absolute
    angular velocity along e_rho, omega_R sin(beta) in Harris' notation (beta: the pitch of the
    spin axis; tan beta = sin(alpha_o) / (cos(alpha_o) + D / d_m) at the pitch radius)."""
    ci_z, ci_r = -float(inner_normal[0]), -float(inner_normal[1])
    co_z, co_r = float(outer_normal[0]), float(outer_normal[1])
    r_ci = ball_rho_m + ball_radius_m * ci_r
    r_co = ball_rho_m + ball_radius_m * co_r
    a = np.array(
        [
            [-ball_radius_m * ci_z, ball_radius_m * ci_r, r_ci],
            [-ball_radius_m * co_z, ball_radius_m * co_r, r_co],
            [co_r, co_z, co_z],
        ]
    )
    w_rho, w_z, w_m = np.linalg.solve(a, np.array([shaft_speed_rad_s * r_ci, 0.0, 0.0]))
    return float(w_rho), float(w_z), float(w_m)


def gyroscopic_moment_n_m(ball_inertia_kg_m2: float, omega_rho_rad_s: float, omega_m_rad_s: float) -> float:
    """M_g = J omega_m omega_R sin(beta) = J omega_m omega_rho [N m] (Harris and Kotzalas vol. 2
    ch. 3): the moment about e_phi that turns the ball's angular momentum J omega with its orbit
    (dH/dt = omega_m e_z x J omega), to be supplied by contact friction."""
    return ball_inertia_kg_m2 * omega_m_rad_s * omega_rho_rad_s


def _ball_forces(geo: _Geometry, ball: np.ndarray, inner_centre: np.ndarray, m_omega2: float, gyro=None):
    """Net force on a ball at `ball` (z, rho) [N], its two contacts (Q [N], unit normal), the
    gyroscopic moment it carries [N m] and the friction force its inner contact puts on the inner
    ring [N] (z, rho); m_omega2 = m omega_c^2 [N/m] makes the centrifugal force m omega_c^2 rho.

    `gyro` = (J [kg m^2], shaft speed [rad/s], traction limit gamma [-]): the moment M_g of outer
    raceway control (`outer_control_kinematics`, `gyroscopic_moment_n_m`) is held by friction
    forces tangent to the contacts in the ball's (z, rho) plane, whose moments about the centre add
    to M_g e_phi: at the outer contact up to gamma Q_o (Jones' outer raceway control, Harris'
    lambda_o = 2), the remainder at the inner contact up to gamma Q_i; beyond both the ball pivots
    and both contacts slide at the limit. A ball the inner race does not touch is not driven and
    carries none."""
    to_inner = inner_centre - ball
    d_i = float(np.hypot(*to_inner))
    n_i = to_inner / d_i  # ball -> inner groove centre
    from_outer = ball - geo.outer_centre
    d_o = float(np.hypot(*from_outer))
    n_o = from_outer / d_o  # outer groove centre -> ball
    delta_i = d_i - geo.inner_free
    delta_o = d_o - geo.outer_free
    q_i = geo.stiffness(0, n_i[0]) * delta_i**1.5 if delta_i > 0.0 else 0.0
    q_o = geo.stiffness(1, n_o[0]) * delta_o**1.5 if delta_o > 0.0 else 0.0
    force = q_i * n_i - q_o * n_o + np.array([0.0, m_omega2 * ball[1]])
    m_g = 0.0
    on_ring = np.zeros(2)
    if gyro is not None and q_i > 0.0 and q_o > 0.0:
        inertia, shaft_speed, traction = gyro
        w_rho, _, w_m = outer_control_kinematics(float(ball[1]), geo.rb, n_i, n_o, shaft_speed)
        m_g = gyroscopic_moment_n_m(inertia, w_rho, w_m)
        need = abs(m_g) / geo.rb  # the friction whose moment R F is |M_g| [N]
        f_o = min(need, traction * q_o)
        f_i = min(need - f_o, traction * q_i)
        sign = math.copysign(1.0, m_g)
        # e_phi x c for the contact direction c from the centre (-n_i inner, +n_o outer), in
        # (z, rho): the tangent whose moment R c x t is +e_phi
        t_o = np.array([-n_o[1], n_o[0]])
        t_i = np.array([n_i[1], -n_i[0]])
        inner_friction = sign * f_i * t_i
        force = force + sign * f_o * t_o + inner_friction
        on_ring = -inner_friction
    return force, q_i, n_i, q_o, n_o, m_g, on_ring


def _solve_ball(geo: _Geometry, inner_centre: np.ndarray, m_omega2: float, scale: float, gyro=None):
    """Equilibrium position (z, rho) of one ball between the displaced inner groove centre and
    the fixed outer one: Qi n_i - Qo n_o + Fc e_rho (+ the friction that holds the gyroscopic
    moment, `gyro`) = 0 (Harris vol. 2 ch. 3). A ball that the inner race does not reach rests in
    the bottom of the outer groove. With `gyro` the solve continues from the equilibrium without
    it, so the ball stays on the branch that grows out of the frictionless one (the friction
    vanishes where the inner contact opens, so a search from afar can stop on that edge)."""
    k_o0 = geo.stiffness(1, 0.0)
    fc = m_omega2 * (geo.outer_centre[1] + geo.outer_free)
    rest = geo.outer_centre + np.array([0.0, geo.outer_free + (fc / k_o0) ** (2.0 / 3.0)])
    if np.hypot(*(inner_centre - rest)) <= geo.inner_free:
        return rest
    if gyro is not None:
        guess = _solve_ball(geo, inner_centre, m_omega2, scale)
    else:
        axis = inner_centre - geo.outer_centre
        span = float(np.hypot(*axis))
        overlap = max(span - geo.inner_free - geo.outer_free, 0.0)
        guess = geo.outer_centre + axis / span * (geo.outer_free + 0.5 * overlap)

    def residual(x_um):
        return _ball_forces(geo, x_um * 1e-6, inner_centre, m_omega2, gyro)[0] / scale

    sol = optimize.root(residual, guess * 1e6, method="hybr", options={"xtol": 1e-13})
    if np.max(np.abs(residual(sol.x))) > 1e-10:
        sol = optimize.root(residual, sol.x, method="lm", options={"xtol": 1e-15, "ftol": 1e-15})
    return sol.x * 1e-6


def jones_equilibrium(
    model: BearingModel,
    radial_load_n: float,
    axial_load_n: float,
    shaft_speed_rad_s: float = 0.0,
    azimuths_rad=None,
    centrifugal: bool = True,
    initial_displacement_m=None,
    gyroscopic: bool = False,
    traction_limit: float | None = None,
) -> JonesSolution:
    """Jones' quasi-static solution (Jones 1960, "A general theory for elastically constrained
    ball and radial roller bearings under arbitrary load and speed conditions", J. Basic Eng. 82;
    Harris & Kotzalas vol. 2 ch. 3) for the model's bearing: rigid rings, the inner ring displaced
    (delta_x, delta_y, delta_z) without tilt (as in the twin), each ball in equilibrium between its
    inner and outer contacts and its centrifugal force m omega_c^2 rho (omega_c the cage speed of
    the rolling kinematics), each contact Q = K(alpha) delta^1.5 with the EXACT Hertz constants of
    its own contact angle, and with `gyroscopic` (Jones-Harris) the gyroscopic moment of outer
    raceway control held by contact friction up to `traction_limit` x Q (`_ball_forces`; by default the lubricant's
    limiting shear coefficient, the largest traction its film carries; inf: Jones' unlimited
    outer raceway control); no other friction. The centrifugal force uses the cage speed of the
    rolling kinematics for every ball (the cage holds the balls to one orbit speed); the gyroscopic
    moment each ball's own outer-control orbit and spin. Works for deep-groove bearings too
    (nominal angle 0, with clearance or preload through the model's mounting; their spin axis
    lies along the bearing's, so they carry no gyroscopic moment). Without `gyroscopic` (the
    default) no friction at all: Jones' solution with centrifugal force. The gyroscopic friction
    acts mostly through the lightly loaded balls, which cannot hold the moment and slide at the
    traction limit, all of it here in the ball's (z, rho) plane (docs/physics.md, Limits: the 7208
    at speed).

    azimuths_rad: the balls' azimuths (default evenly spaced from 0); radial load along +x,
    axial load along +z on the inner ring [N]."""
    z = model.ball_count
    psi = np.asarray(azimuths_rad, dtype=float) if azimuths_rad is not None else 2.0 * math.pi * np.arange(z) / z
    geo = _Geometry(model)
    mass = float(model.params[L.P_BALL_MASS])
    omega_c = model.cage_speed_rad_s(shaft_speed_rad_s) if centrifugal else 0.0
    scale = max(abs(radial_load_n), abs(axial_load_n), 1.0)
    c, s = np.cos(psi), np.sin(psi)

    m_omega2 = mass * omega_c**2
    traction = model.spec.lubricant.limiting_shear_coefficient if traction_limit is None else traction_limit
    gyro = None
    if gyroscopic and shaft_speed_rad_s != 0.0:
        if initial_displacement_m is None:  # continue from the frictionless solution (see _solve_ball)
            initial_displacement_m = jones_equilibrium(
                model, radial_load_n, axial_load_n, shaft_speed_rad_s, psi, centrifugal, gyroscopic=False
            ).ring_displacement_m
        gyro = (0.4 * mass * model.ball_radius_m**2, shaft_speed_rad_s, traction)  # J = m D^2 / 10

    def solve_balls(shift):
        out = []
        for j in range(z):
            centre = geo.inner_centre + np.array([shift[2], shift[0] * c[j] + shift[1] * s[j]])
            out.append((centre, _solve_ball(geo, centre, m_omega2, scale, gyro)))
        return out

    def ring_residual(shift_um):
        shift = shift_um * 1e-6
        force = np.array([radial_load_n, 0.0, axial_load_n])
        for j, (centre, ball) in enumerate(solve_balls(shift)):
            _, q_i, n_i, _, _, _, friction = _ball_forces(geo, ball, centre, m_omega2, gyro)
            radial = q_i * n_i[1] - friction[1]
            force[0] -= radial * c[j]
            force[1] -= radial * s[j]
            force[2] -= q_i * n_i[0] - friction[0]
        return force / scale

    if initial_displacement_m is None:
        k_eff = series_stiffness_n_m15(
            geo.stiffness(0, math.sin(model.contact_angle_rad)), geo.stiffness(1, math.sin(model.contact_angle_rad))
        )
        sa, ca = math.sin(model.contact_angle_rad), math.cos(model.contact_angle_rad)
        pd = model.spec.mounting.diametral_clearance_m
        dr = (max(radial_load_n, 1.0) / (z * 0.2288 * k_eff)) ** (2 / 3) / max(ca, 0.2) + 0.5 * max(pd, 0.0)
        da = (axial_load_n / (z * k_eff * sa)) ** (2 / 3) / sa if (sa > 0.05 and axial_load_n > 0) else 0.0
        initial_displacement_m = np.array([dr, 0.0, da])
    x0 = np.asarray(initial_displacement_m, dtype=float) * 1e6
    sol = optimize.root(ring_residual, x0, method="hybr", options={"xtol": 1e-12})
    if np.max(np.abs(ring_residual(sol.x))) > 1e-9:
        sol = optimize.root(ring_residual, sol.x, method="lm", options={"xtol": 1e-15, "ftol": 1e-15})
    converged = bool(np.max(np.abs(ring_residual(sol.x))) <= 1e-8)
    shift = sol.x * 1e-6
    q_in, q_out, a_in, a_out, zb, rho, m_g = (np.zeros(z) for _ in range(7))
    for j, (centre, ball) in enumerate(solve_balls(shift)):
        _, q_i, n_i, q_o, n_o, m_g[j], _ = _ball_forces(geo, ball, centre, m_omega2, gyro)
        q_in[j], q_out[j] = q_i, q_o
        a_in[j] = math.atan2(n_i[0], n_i[1])
        a_out[j] = math.atan2(n_o[0], n_o[1])
        zb[j], rho[j] = ball
    delta_r = float(math.hypot(shift[0], shift[1]))
    tan_a = math.tan(model.contact_angle_rad)
    eps = 0.5 * (1.0 + shift[2] * tan_a / delta_r) if delta_r > 0.0 else math.inf
    return JonesSolution(
        ring_displacement_m=shift,
        azimuths_rad=psi,
        inner_load_n=q_in,
        outer_load_n=q_out,
        inner_angle_rad=a_in,
        outer_angle_rad=a_out,
        ball_axial_m=zb,
        ball_radial_m=rho,
        centrifugal_force_n=float(m_omega2 * model.pitch_radius_m),
        epsilon=eps,
        converged=converged,
        gyroscopic_moment_n_m=m_g,
    )
