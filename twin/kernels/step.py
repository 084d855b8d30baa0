"""The hot loop: `step_n` integrates the bearing for n steps of velocity-Verlet (seed 000 eq. 10).

One module for one kernel: the functions before `step_n` are its stages, inlined into it
(`inline="always"`) and compiled with it as one unit, and a sixth of the lines imports the lane indices.

One compiled call per frame, no allocation, no Python objects, no array passed to another
function inside the loop; problems are reported through the returned status code
(`twin.kernels.layout.STATUS_*`), never raised.
"""

import math

from numba import njit

from twin.jit import JIT, JIT_STEP
from twin.kernels.contacts import cage_contact, raceway_forces, raceway_geometry
from twin.kernels.layout import (
    A_STIFFNESS,
    A_TRIBOLOGY,
    ANGLE_INV_STEP,
    ANGLE_MAX_SIN,
    ANGLE_POINTS,
    C_CAPACITANCE,
    C_ENTRAINMENT,
    C_FLUID_DAMPING,
    C_H_C,
    C_H_MIN,
    C_LAMBDA,
    C_LOAD,
    C_MU,
    C_REGIME,
    C_RESISTANCE,
    C_ROLLING_FORCE,
    C_ROLLING_PER_SPEED,
    C_SEMI_MAJOR,
    C_SEMI_MINOR,
    C_SPIN_MOMENT,
    C_SRR,
    C_TANGENT_DAMPING,
    C_XI_DECAY,
    CW,
    FRICTION_ELLIPSE,
    G_DELTA,
    G_LOAD,
    G_NX,
    G_NY,
    G_NZ,
    G_SQRT_DELTA,
    H_LOAD,
    H_SIN_ANGLE,
    H_SPEED,
    H_STAMP,
    K_BX,
    K_BY,
    K_ORBIT,
    K_OVX,
    K_OVY,
    K_OVZ,
    K_PX,
    K_PY,
    K_PZ,
    K_SPIN,
    K_VX,
    K_VY,
    K_VZ,
    K_WX,
    K_WY,
    K_WZ,
    LANE_BLOCK,
    M_GROOVE_CLEARANCE,
    M_STIFFNESS,
    N_CACHED,
    O_EX,
    O_EY,
    O_EZ,
    O_FX,
    O_FY,
    O_FZ,
    O_NORMAL_RATE,
    O_RING_TZ,
    O_SX,
    O_SY,
    O_SZ,
    O_TX,
    O_TY,
    O_TZ,
    P_ALPHA_E,
    P_ASPERITY_RESISTANCE,
    P_BALL_INERTIA,
    P_BALL_MASS,
    P_BALL_RADIUS,
    P_BALL_REDUCED_TANGENT_MASS,
    P_CAGE_CONTACT_DISTANCE,
    P_CAGE_INERTIA,
    P_CAGE_RADIUS,
    P_CAGE_REDUCED_MASS,
    P_CAGE_STEP_COS,
    P_CAGE_STEP_SIN,
    P_CAGE_STIFFNESS,
    P_CENTRED_REFRESH,
    P_CT_RATIO,
    P_DT,
    P_FRICTION_MODEL,
    P_GAP_LIMIT,
    P_GAP_LIMIT_OUTER,
    P_KT_RATIO,
    P_LIMITING_SHEAR,
    P_LN_ROUGHNESS,
    P_MAX_PENETRATION,
    P_OIL_PERMITTIVITY,
    P_OIL_RESISTIVITY,
    P_PROFILE_ON,
    P_RAMP,
    P_RING_MASS,
    P_ROLLING,
    P_ROUGHNESS,
    P_SUBSTEPS,
    P_TRACTION_EVERY,
    P_VIB,
    S_AXIAL_LOAD,
    S_RADIAL_LOAD,
    S_SHAFT_SPEED,
    S_STOP,
    S_VISCOSITY,
    STATUS_NOT_FINITE,
    STATUS_OK,
    STATUS_PENETRATION,
    V_DECIMATION_RATIO,
    V_HOUSING_ON,
    X_CAGE_ANGLE,
    X_CAGE_SPEED,
    X_CAGE_TORQUE,
    X_DEFECT_COUNT,
    X_DRIVE_TORQUE,
    X_MAX_PENETRATION,
    X_SHAFT_ANGLE,
    X_SHAFT_SPEED,
    X_STEP,
    X_TIME,
    X_TORQUE_COUNT,
    X_TORQUE_SUM,
)
from twin.kernels.traction import apply_traction_moments, ellipse_traction, limiting_traction_coefficient_share
from twin.kernels.tribology import T_RX, T_RY, contact_electrical, contact_tribology
from twin.kernels.vibration import (
    apply_clearances,
    defect_table,
    has_ball_defect,
    integrate_orientations,
    orientations,
    outer_ring_force,
    shift_frame,
)
from twin.physics.rolling import asperity_load_share_ln
from twin.vibration.housing import housing_accelerations, housing_close, housing_kick_drift
from twin.vibration.signal import sensor_push_direct

# Below this entrainment speed [m/s] the rolling resistance (applied as (F_R / u) times the
# entrainment vector) turns into a bounded viscous drag, F_R / 0.01 N s/m at most, instead of a
# force of fixed size along an undefined direction; dividing by the actual u there would make a
# damper stiff enough to destabilise the explicit integration (at 1 rad/s).
ROLLING_REGULARISATION_SPEED = 0.01

# Linearising the fully sliding Coulomb traction mu p v/|v| of a spinning Hertz ellipse about pure
# spin (relative spin w_s) gives a force -(mu Q / (|w_s| sqrt(a b))) M v for a small extra slip v,
# with M = 3 pi / 8 for a circle and 1.18-1.38 across the major axis for k = 1..15 (0.4-1.2 along
# the minor axis): the twin uses one M (tests/physics/test_spin_creep.py integrates it).
SPIN_CREEP_FACTOR = 1.3

# The contacts' parallel RC is refreshed every ELECTRICAL_EVERY tribology refreshes (200 us at
# the default 40 us, twin.validation.subrate_study): it only feeds the network evaluated between
# frames (1 ms) and the 10 ms electro-thermal coupling, and a refresh every 10 us costs ~90 ns
# per step (10 % of the budget). A contact that has just closed gets its RC at once.
ELECTRICAL_EVERY = 5

SMALL_ANGLE = 1e-2  # [rad] below it `_cos_sin` takes the series


@njit(inline="always", **JIT)
def _at_angle(table, r, i, f, col):
    """Column `col` of race r's contact-angle table, linear between rows i and i + 1 (weight f).
    Inlined at numba level: 18 calls per contact refresh would otherwise each pass the table."""
    lo = table[r, i, col]
    return lo + f * (table[r, i + 1, col] - lo)


@njit(inline="always", **JIT)
def _cos_sin(x):
    """(cos x, sin x); for |x| <= SMALL_ANGLE their Taylor series to x^7, exact to the last bit
    there (the next terms are below 3e-21), without the library call: the step's half turn of
    the cage is ~3e-4 rad at the auto step (a sincos call costs ~2 % of the step)."""
    if abs(x) <= SMALL_ANGLE:
        x2 = x * x
        c = 1.0 - x2 * (0.5 - x2 * (1.0 / 24.0 - x2 * (1.0 / 720.0)))
        s = x * (1.0 - x2 * (1.0 / 6.0 - x2 * (1.0 / 120.0 - x2 * (1.0 / 5040.0))))
        return c, s
    return math.cos(x), math.sin(x)


@njit(inline="always", **JIT)
def _minmod(a, b):
    """The smaller of two slopes of one sign, 0 when their signs differ (a slope limiter)."""
    if a * b <= 0.0:
        return 0.0
    return a if abs(a) < abs(b) else b


@njit(inline="always", **JIT)
def centred_inputs(p, w, c, q_el, u_now, s_now, stamp):
    """The tribology refresh's inputs CENTRED on the period they are held for.

    A refresh at step k holds its values for the P_SUBSTEPS = N steps k .. k + N - 1 while the ball
    rolls on, so values computed from the inputs at step k lag by (N - 1) / 2 steps on average:
    an error FIRST order in the period (Lambda 0.30 % at 20 us on the 7208 at 1700 rad/s). This
    evaluates the load q_el [N], the entrainment speed u [m/s] and |sin(contact angle)| [-] at the
    middle of the coming period instead, x_k + (N - 1) / 2 x' with x' a slope per step: the held
    values then carry the mean over the period to within the curvature of x, SECOND order in the
    period.

    The slope x' of the load and of the angle is limited (minmod, as in MUSCL schemes): the
    smaller of the secant from the contact's previous refresh j, (x_k - x_j) / (k - j) (lanes
    H_*), and the rate of this step (the load's 1.5 Q / delta d(delta)/dt from the force pass's
    O_NORMAL_RATE; the angle's d n_z / dt = (v_z - n_z d(delta)/dt) / (groove clearance + delta)),
    0 where they disagree in sign. Without it the secant carried the steep fall of the load at the
    end of the loaded zone past the kink where the load levels off at the centrifugal load
    (the 7208 at 1700 rad/s, 40 us: +0.8 % on Lambda in that bin, the lag's -1.2 % overshot),
    and the rate alone follows the contact's vibration. The speed u, smooth and without a rate
    at hand, takes the secant.
    The lanes H_* take this refresh's own inputs (not extrapolated) and its stamp (1 + k).

    No extrapolation (the inputs as they are) with p[P_CENTRED_REFRESH] = 0, when the contact has
    just closed (H_STAMP = 0: no previous refresh; its refresh holds until the next regular one,
    fewer than N steps), for `evaluate` (stamp 0, and none from it) or when the previous refresh is
    not 1 .. 2N steps back (a restart, a restored state). Clamps: the load and
    the speed stay within [1/2, 2] x their current values (the extrapolation of a jump -- a ball
    over a spall edge, an impact -- is bounded by the jump itself: it is at most a factor 2 on a
    film that goes as Q^-0.073, and it holds for one period; a setpoint step moves the ring over
    many periods, i.e. the load moves smoothly and is extrapolated as such), |sin| within the
    angle table [0, sin 60 deg]. Returns (q, u, |sin alpha|)."""
    prev = w[H_STAMP * CW + c]
    q_prev = w[H_LOAD * CW + c]
    u_prev = w[H_SPEED * CW + c]
    s_prev = w[H_SIN_ANGLE * CW + c]
    w[H_STAMP * CW + c] = stamp
    w[H_LOAD * CW + c] = q_el
    w[H_SPEED * CW + c] = u_now
    w[H_SIN_ANGLE * CW + c] = s_now
    n = p[P_SUBSTEPS]
    d = stamp - prev
    if prev <= 0.0 or not (0.0 < d <= 2.0 * n) or p[P_CENTRED_REFRESH] == 0.0:
        return q_el, u_now, s_now
    lag = 0.5 * (n - 1.0)  # steps from this one to the middle of the held period
    dt = p[P_DT]
    delta = w[G_DELTA * CW + c]
    rate = w[O_NORMAL_RATE * CW + c]  # d(delta)/dt [m/s]
    nz = w[G_NZ * CW + c]
    q_rate = 1.5 * q_el / delta * rate * dt if delta > 0.0 else 0.0
    nz_rate = ((w[K_VZ * CW + c] - w[K_OVZ * CW + c]) - nz * rate) / (w[M_GROOVE_CLEARANCE * CW + c] + delta) * dt
    s_rate = nz_rate if nz >= 0.0 else -nz_rate
    inv_d = 1.0 / d
    q = q_el + lag * _minmod((q_el - q_prev) * inv_d, q_rate)
    q = min(max(q, 0.5 * q_el), 2.0 * q_el)
    u = min(max(u_now + lag * (u_now - u_prev) * inv_d, 0.5 * u_now), 2.0 * u_now)
    s = min(max(s_now + lag * _minmod((s_now - s_prev) * inv_d, s_rate), 0.0), ANGLE_MAX_SIN)
    return q, u, s


@njit(inline="always", **JIT_STEP)
def refresh_contact(p, tr, w, c, q_now, eta, electrical_now, stamp):
    """Tribology refresh of loaded contact c (load q_now [N], viscosity eta [Pa s]) at the step
    stamped `stamp` (1 + the step index): its Hertz stiffness (lane M_STIFFNESS, read by the next
    geometry pass) and film constants at its contact angle from the model's angle table `tr`
    (`twin.model.make_angle_table`, linear in |sin alpha| = |n_z|), then `contact_tribology`
    (seed 000 eqs. 5-7, Table 2, seed 001 eqs. 1-5, 9, 11), the limiting friction coefficient,
    the tangential damping and spring relaxation, the slide-to-roll ratio and, when
    `electrical_now` (or the contact has just closed), its parallel RC (`contact_electrical`).
    Writes the contact's C_* lanes.

    Centred: the load, the entrainment speed and the contact angle are those of the
    middle of the period the values are held for (`centred_inputs`, second order in the period),
    not those of this step.

    With the ellipse friction the asperity share (seed 001 eq. A2) takes ln Lambda = ln h_min -
    ln sigma from the film's own logarithm (`contact_tribology`'s last output), not another
    logarithm."""
    friction_model = int(p[P_FRICTION_MODEL])
    r = c & 1
    ex = w[O_EX * CW + c]
    ey = w[O_EY * CW + c]
    ez = w[O_EZ * CW + c]
    u2 = ex * ex + ey * ey + ez * ez
    q_el, u, sin_a = centred_inputs(p, w, c, q_now, math.sqrt(u2), min(abs(w[G_NZ * CW + c]), ANGLE_MAX_SIN), stamp)
    # Hertz and film constants at the contact's (centred) angle (angle table row i, i + 1)
    xa = sin_a * ANGLE_INV_STEP
    ia = min(int(xa), ANGLE_POINTS - 2)
    fa = xa - ia
    w[M_STIFFNESS * CW + c] = _at_angle(tr, r, ia, fa, A_STIFFNESS)
    t = A_TRIBOLOGY
    tri = contact_tribology(
        q_el,
        u,
        eta,
        p[P_ROUGHNESS],
        _at_angle(tr, r, ia, fa, t),
        _at_angle(tr, r, ia, fa, t + 1),
        _at_angle(tr, r, ia, fa, t + 2),
        _at_angle(tr, r, ia, fa, t + 3),
        _at_angle(tr, r, ia, fa, t + 4),
        _at_angle(tr, r, ia, fa, t + 5),
        _at_angle(tr, r, ia, fa, t + 6),
        _at_angle(tr, r, ia, fa, t + 7),
        _at_angle(tr, r, ia, fa, t + 8),
        _at_angle(tr, r, ia, fa, t + 9),
        _at_angle(tr, r, ia, fa, t + 10),
        _at_angle(tr, r, ia, fa, t + 11),
        _at_angle(tr, r, ia, fa, t + 12),
        _at_angle(tr, r, ia, fa, t + 13),
        _at_angle(tr, r, ia, fa, t + 14),
        friction_model,
        p[P_ROLLING] != 0.0,
    )
    w[C_H_MIN * CW + c] = tri[0]
    w[C_H_C * CW + c] = tri[1]
    w[C_LAMBDA * CW + c] = tri[2]
    w[C_REGIME * CW + c] = tri[3]
    # the contact's limiting friction coefficient: the Coulomb law's mu, or with the ellipse
    # friction its traction capacity over Q (not the effective |F_t| / Q it publishes)
    if friction_model == FRICTION_ELLIPSE:
        share = asperity_load_share_ln(tri[2], tri[10] - p[P_LN_ROUGHNESS])
        mu_lim = limiting_traction_coefficient_share(tri[2], share, p[P_LIMITING_SHEAR])
    else:
        mu_lim = tri[4]
    w[C_MU * CW + c] = mu_lim
    w[C_SEMI_MAJOR * CW + c] = tri[5]
    w[C_SEMI_MINOR * CW + c] = tri[6]
    w[C_FLUID_DAMPING * CW + c] = tri[7]
    w[C_ROLLING_FORCE * CW + c] = tri[8]
    w[C_ROLLING_PER_SPEED * CW + c] = tri[8] / max(u, ROLLING_REGULARISATION_SPEED)
    w[C_SPIN_MOMENT * CW + c] = tri[9]
    kt = p[P_KT_RATIO] * 1.5 * w[M_STIFFNESS * CW + c] * w[G_SQRT_DELTA * CW + c]
    w[C_TANGENT_DAMPING * CW + c] = p[P_CT_RATIO] * 2.0 * math.sqrt(kt * p[P_BALL_REDUCED_TANGENT_MASS])
    w[C_ENTRAINMENT * CW + c] = u
    # tangential spring relaxation (contacts.raceway_forces): by rolling over L = sqrt(a b)
    # and by the spin sliding of the contact, kt |w_spin| sqrt(a b) / (1.3 mu Q) with mu the
    # limiting coefficient of the fully sliding traction (mu_lim)
    ab = math.sqrt(tri[5] * tri[6])
    spin_rel = abs(
        w[K_WX * CW + c] * w[G_NX * CW + c]
        + w[K_WY * CW + c] * w[G_NY * CW + c]
        + (w[K_WZ * CW + c] - w[K_SPIN * CW + c]) * w[G_NZ * CW + c]
    )
    relax = u / ab + kt * spin_rel * ab / max(SPIN_CREEP_FACTOR * mu_lim * q_el, 1e-12)
    w[C_XI_DECAY * CW + c] = 1.0 / (1.0 + relax * p[P_DT])
    w[C_SRR * CW + c] = (
        (w[O_SX * CW + c] * ex + w[O_SY * CW + c] * ey + w[O_SZ * CW + c] * ez) / u2 if u2 > 0.0 else 0.0
    )
    if not (electrical_now or w[C_CAPACITANCE * CW + c] == 0.0):
        return  # the RC keeps its last value between electrical refreshes
    if tri[1] > 0.0:
        res_ohm, cap_f = contact_electrical(
            q_el,
            tri[2],
            tri[1],
            tri[5],
            tri[6],
            _at_angle(tr, r, ia, fa, t + T_RX),
            _at_angle(tr, r, ia, fa, t + T_RY),
            p[P_OIL_PERMITTIVITY],
            p[P_GAP_LIMIT] if r == 0 else p[P_GAP_LIMIT_OUTER],
            p[P_ASPERITY_RESISTANCE],
            p[P_OIL_RESISTIVITY],
        )
    else:  # no film (no entrainment): metallic contact, no dielectric
        res_ohm, cap_f = p[P_ASPERITY_RESISTANCE], 0.0
    w[C_RESISTANCE * CW + c] = res_ohm
    w[C_CAPACITANCE * CW + c] = cap_f


@njit(inline="always", **JIT_STEP)
def gather_lanes(scal, bx, bv, bw, rx, rv, w, ct, st):
    """The kinematics of every ball-raceway contact into its lanes of `w` (K_* rows, c = 2 j + r;
    r = 0 inner ring, r = 1 fixed outer ring): ball centre relative to the ring and in the world
    frame, the ball's velocity and angular velocity turned by (ct, st) (`compute_accelerations`),
    the ring's velocity and spin, the ball's orbital speed; then the pad lanes. Returns the
    padded lane count. The outer and pad lanes' ring velocity and spin (K_OVX..K_SPIN) are not written:
    the outer ring is fixed (or the frame is its own), they hold the 0 that
    `twin.state.make_state` and `TwinState.clear_contacts` put there (4 Z stores per
    step fewer)."""
    z = bx.shape[0]
    nc = 2 * z
    ring_speed = scal[X_SHAFT_SPEED]
    # the ring's state is read once (the compiler cannot keep it in registers across stores to w, which it may alias)
    rx0 = rx[0]
    rx1 = rx[1]
    rx2 = rx[2]
    rv0 = rv[0]
    rv1 = rv[1]
    rv2 = rv[2]
    for j in range(z):
        x0 = bx[j, 0]
        x1 = bx[j, 1]
        x2 = bx[j, 2]
        v0 = ct * bv[j, 0] - st * bv[j, 1]  # turned velocities (docstring)
        v1 = st * bv[j, 0] + ct * bv[j, 1]
        v2 = bv[j, 2]
        w0 = ct * bw[j, 0] - st * bw[j, 1]
        w1 = st * bw[j, 0] + ct * bw[j, 1]
        w2 = bw[j, 2]
        rho2 = x0 * x0 + x1 * x1
        orbital = (x0 * v1 - x1 * v0) / rho2 if rho2 > 0.0 else 0.0
        ci = 2 * j
        co = ci + 1
        w[K_PX * CW + ci] = x0 - rx0
        w[K_PX * CW + co] = x0
        w[K_PY * CW + ci] = x1 - rx1
        w[K_PY * CW + co] = x1
        w[K_PZ * CW + ci] = x2 - rx2
        w[K_PZ * CW + co] = x2
        w[K_BX * CW + ci] = x0
        w[K_BX * CW + co] = x0
        w[K_BY * CW + ci] = x1
        w[K_BY * CW + co] = x1
        w[K_VX * CW + ci] = v0
        w[K_VX * CW + co] = v0
        w[K_VY * CW + ci] = v1
        w[K_VY * CW + co] = v1
        w[K_VZ * CW + ci] = v2
        w[K_VZ * CW + co] = v2
        w[K_WX * CW + ci] = w0
        w[K_WX * CW + co] = w0
        w[K_WY * CW + ci] = w1
        w[K_WY * CW + co] = w1
        w[K_WZ * CW + ci] = w2
        w[K_WZ * CW + co] = w2
        w[K_OVX * CW + ci] = rv0
        w[K_OVY * CW + ci] = rv1
        w[K_OVZ * CW + ci] = rv2
        w[K_SPIN * CW + ci] = ring_speed
        w[K_ORBIT * CW + ci] = orbital
        w[K_ORBIT * CW + co] = orbital
    # pad lanes up to a whole number of vectors: a copy of the last contact (the last ball's
    # outer one, from the registers), so that the lane passes run without a scalar remainder on
    # finite values nobody reads (twin.kernels.layout); their ring velocity and spin are 0 too
    nl = (nc + LANE_BLOCK - 1) // LANE_BLOCK * LANE_BLOCK  # layout.padded_lane_count
    for c in range(nc, nl):
        w[K_PX * CW + c] = x0
        w[K_PY * CW + c] = x1
        w[K_PZ * CW + c] = x2
        w[K_BX * CW + c] = x0
        w[K_BY * CW + c] = x1
        w[K_VX * CW + c] = v0
        w[K_VY * CW + c] = v1
        w[K_VZ * CW + c] = v2
        w[K_WX * CW + c] = w0
        w[K_WY * CW + c] = w1
        w[K_WZ * CW + c] = w2
        w[K_ORBIT * CW + c] = orbital
    return nl


@njit(inline="always", **JIT_STEP)
def ball_loads_and_cage(p, scal, bx, bv, ba, balpha, w, cage_load, ct, st):
    """Per ball, in one pass: the raceway contacts' forces and torques summed into the ball's
    accelerations (seed 000 eq. 9; ba, balpha), its two cage contacts (`cage_contact`, seed 000
    eq. 3: the cage elements on either side of it, element e at the cage angle + (e + 1/2) 2 pi / Z,
    their unit vectors turned along by the model's P_CAGE_STEP_COS/SIN), loads in `cage_load`.
    The balls' velocities are turned by (ct, st) as `compute_accelerations` reads them.
    Returns the force of the balls on the inner ring (x, y, z) [N], the contacts' torque on the
    inner ring about its axis [N m] and the cage torque [N m]."""
    z = bx.shape[0]
    inv_inertia = 1.0 / p[P_BALL_INERTIA]  # multiplications, not 6 Z divisions per step
    inv_m = 1.0 / p[P_BALL_MASS]
    rc = p[P_CAGE_RADIUS]
    s_cage = p[P_CAGE_CONTACT_DISTANCE]
    k_cage = p[P_CAGE_STIFFNESS]
    m_cage = p[P_CAGE_REDUCED_MASS]
    cage_speed = scal[X_CAGE_SPEED]
    c_step = p[P_CAGE_STEP_COS]
    s_step = p[P_CAGE_STEP_SIN]
    theta = scal[X_CAGE_ANGLE] - 0.5 * (2.0 * math.pi / z)  # element j - 1 of ball 0
    prev_c = math.cos(theta)
    prev_s = math.sin(theta)
    first_c = prev_c
    first_s = prev_s
    ring_fx = 0.0
    ring_fy = 0.0
    ring_fz = 0.0
    ring_tz = 0.0
    cage_tz = 0.0
    for j in range(z):
        ci = 2 * j
        co = ci + 1
        fx = w[O_FX * CW + ci] + w[O_FX * CW + co]
        fy = w[O_FY * CW + ci] + w[O_FY * CW + co]
        fz = w[O_FZ * CW + ci] + w[O_FZ * CW + co]
        balpha[j, 0] = (w[O_TX * CW + ci] + w[O_TX * CW + co]) * inv_inertia
        balpha[j, 1] = (w[O_TY * CW + ci] + w[O_TY * CW + co]) * inv_inertia
        balpha[j, 2] = (w[O_TZ * CW + ci] + w[O_TZ * CW + co]) * inv_inertia
        ring_fx -= w[O_FX * CW + ci]
        ring_fy -= w[O_FY * CW + ci]
        ring_fz -= w[O_FZ * CW + ci]
        ring_tz += w[O_RING_TZ * CW + ci]
        v0 = ct * bv[j, 0] - st * bv[j, 1]
        v1 = st * bv[j, 0] + ct * bv[j, 1]
        next_c = prev_c * c_step - prev_s * s_step
        next_s = prev_s * c_step + prev_c * s_step
        if j == z - 1:
            next_c = first_c
            next_s = first_s
        for slot in range(2):
            ex = rc * (next_c if slot == 0 else prev_c)
            ey = rc * (next_s if slot == 0 else prev_s)
            f, nx, ny, nz = cage_contact(
                bx[j, 0], bx[j, 1], bx[j, 2], v0, v1, bv[j, 2], ex, ey, cage_speed, s_cage, k_cage, m_cage
            )
            cage_load[j, slot] = f
            fx += f * nx
            fy += f * ny
            fz += f * nz
            cage_tz -= ex * f * ny - ey * f * nx
        prev_c = next_c
        prev_s = next_s
        ba[j, 0] = fx * inv_m
        ba[j, 1] = fy * inv_m
        ba[j, 2] = fz * inv_m
    return ring_fx, ring_fy, ring_fz, ring_tz, cage_tz


@njit(inline="always", **JIT_STEP)
def compute_accelerations(
    p,
    tr,
    sp,
    scal,
    bx,
    bv,
    bw,
    ba,
    balpha,
    rx,
    rv,
    ra,
    w,
    cage_load,
    tribology_now,
    electrical_now,
    traction_now,
    ct,
    st,
    stamp,
):
    """Forces and torques of every contact at the current positions -> accelerations of the
    balls (seed 000 eq. 9), the inner ring (translation) and the cage (rotation).

    Ball-raceway contacts: gather the kinematics into the lanes of `w`, one vectorised geometry
    pass, one vectorised force pass, then per ball: sum the forces, refresh the tribology of
    loaded contacts when `tribology_now` (or when a contact closes, `refresh_contact`, centred on
    its period from the refresh stamped `stamp` = 1 + the step index), clear opened contacts.

    The forces see the balls' velocities and angular velocities turned about the axis by the
    angle whose cosine and sine are (ct, st) (`step_n`: the half step of the cage's rotation;
    (1, 0) for none), as they are read: bv and bw themselves are left as they are.

    Positions and velocities are those relative to the outer ring (`step_n` shifts
    them with the housing on); the active defect rows (scal[X_DEFECT_COUNT] of them in the
    workspace after the lanes, twin.kernels.layout W_DEFECTS) open their clearance between the
    geometry and the force pass, with the surface profiles when on (`twin.kernels.vibration.apply_clearances`).
    Returns a status code."""
    z = bx.shape[0]
    nc = 2 * z
    rb = p[P_BALL_RADIUS]
    inertia = p[P_BALL_INERTIA]
    kt_ratio = p[P_KT_RATIO]
    friction_model = int(p[P_FRICTION_MODEL])
    eta = sp[S_VISCOSITY]
    nl = gather_lanes(scal, bx, bv, bw, rx, rv, w, ct, st)
    raceway_geometry(w, nl)
    if scal[X_DEFECT_COUNT] > 0.0 or p[P_PROFILE_ON] != 0.0:  # local defects, surface profiles
        apply_clearances(w, nc, int(scal[X_DEFECT_COUNT]), scal[X_SHAFT_ANGLE], p, rb)
    raceway_forces(w, nl, rb, p[P_DT], kt_ratio, p[P_ALPHA_E])
    # per contact: outputs, tribology refresh, opened contacts
    max_pen = scal[X_MAX_PENETRATION]
    for c in range(nc):
        delta = w[G_DELTA * CW + c]
        if delta <= 0.0:
            if w[C_LAMBDA * CW + c] != -1.0 or w[C_LOAD * CW + c] != 0.0:
                for k in range(N_CACHED):
                    w[k * CW + c] = 0.0
                w[C_LAMBDA * CW + c] = -1.0
                w[C_H_MIN * CW + c] = -1.0
                w[C_H_C * CW + c] = -1.0
                w[H_STAMP * CW + c] = 0.0  # no previous refresh to extrapolate from (centred_inputs)
            continue
        if delta > max_pen:
            max_pen = delta
        q_el = w[G_LOAD * CW + c]
        w[C_LOAD * CW + c] = q_el
        if tribology_now or w[C_LAMBDA * CW + c] < 0.0:
            refresh_contact(p, tr, w, c, q_el, eta, electrical_now, stamp)
    scal[X_MAX_PENETRATION] = max_pen
    if friction_model == FRICTION_ELLIPSE:  # friction over the contact ellipse (twin.kernels.traction)
        if traction_now:
            ellipse_traction(w, nc, p, eta, kt_ratio, inertia, p[P_DT])
        apply_traction_moments(w, nl)
    ring_fx, ring_fy, ring_fz, ring_tz, cage_tz = ball_loads_and_cage(p, scal, bx, bv, ba, balpha, w, cage_load, ct, st)
    inv_mr = 1.0 / p[P_RING_MASS]
    ra[0] = (ring_fx + sp[S_RADIAL_LOAD]) * inv_mr
    ra[1] = ring_fy * inv_mr
    ra[2] = (ring_fz + sp[S_AXIAL_LOAD]) * inv_mr
    scal[X_DRIVE_TORQUE] = -ring_tz
    scal[X_CAGE_TORQUE] = cage_tz
    if not (
        math.isfinite(ra[0])
        and math.isfinite(ra[1])
        and math.isfinite(ra[2])
        and math.isfinite(cage_tz)
        and math.isfinite(ring_tz)
    ):
        return STATUS_NOT_FINITE
    if max_pen > p[P_MAX_PENETRATION]:
        return STATUS_PENETRATION
    return STATUS_OK


@njit(**JIT_STEP)
def step_n(model, state, setpoint, n):
    """Advance n steps of dt (seed 000 eq. 10, velocity-Verlet; velocity-dependent forces use the
    half-step velocity turned on by the cage's half-step rotation). The shaft speed moves towards
    its setpoint at the ramp rate; the torque the shaft supplies is accumulated for averaging.
    Returns (status, steps done).

    `model` is a `twin.kernels.structures.ModelArrays`, `state` a `StateArrays` (written in place),
    `setpoint` the layout.S_* vector. The body reads them through the short local names of the
    equations (bx, bv, bw: ball positions, velocities, angular velocities; rx, rv: inner ring;
    hx, hv, ha: housing; p: the P_* constants; sp: the setpoint).

    With the housing on (p[P_VIB + V_HOUSING_ON]; skipped with the rigid outer ring and no defect)
    the outer ring rides on the housing (twin.vibration.housing DOFs), leapfrogged with the balls,
    the forces evaluated in the outer ring's frame (`shift_frame`) and the outer contacts' reaction
    driving it; the sensed acceleration goes through the anti-aliasing decimator into the sample
    ring every step (twin.vibration.signal.sensor_push_direct; the engine adds the sensor noise
    between frames). The orientation of a ball carrying one of the active defects (in the
    workspace, twin.kernels.layout W_DEFECTS, W_ORIENTATION) is integrated.

    A nonzero sp[S_STOP] (written by another thread while this one runs without the GIL:
    Twin.interrupt_frame) ends the frame at the next step boundary, after at least one step, with
    status OK and done < n; the closing half kick is the same, so frames of k and n - k steps
    give the state of one frame of n (the sub-rates count the steps in scal[X_STEP])."""
    p, tr, hp, taps = model.params, model.angle_table, model.housing_params, model.decimator_taps
    sp = setpoint
    scal, w, cage_load = state.scalars, state.workspace, state.cage_load_n
    bx, bv, bw = state.ball_position_m, state.ball_velocity_m_s, state.ball_angular_velocity_rad_s
    ba, balpha = state.ball_acceleration, state.ball_angular_acceleration
    rx, rv, ra = state.ring_position_m, state.ring_velocity_m_s, state.ring_acceleration
    hx, hv, ha = state.housing_displacement_m, state.housing_velocity_m_s, state.housing_acceleration_m_s2
    dec_state, ring, ring_state = state.decimator_state, state.sample_ring_m_s2, state.sample_ring_state
    z = bx.shape[0]
    dt = p[P_DT]
    half = 0.5 * dt
    cage_inertia = p[P_CAGE_INERTIA]
    substeps = int(p[P_SUBSTEPS])
    traction_every = max(int(p[P_TRACTION_EVERY]), 1)
    ramp = p[P_RAMP] * dt
    # leapfrog form of velocity-Verlet: the closing half kick of one step and the opening half
    # kick of the next are one full kick; the state holds full-step velocities between frames
    status = STATUS_OK
    done = 0
    housing_on = p[P_VIB + V_HOUSING_ON] != 0.0
    ratio = int(p[P_VIB + V_DECIMATION_RATIO])
    defects = defect_table(w, int(scal[X_DEFECT_COUNT]))
    bq = orientations(w, z)
    turning = has_ball_defect(defects)
    for it in range(n):
        if it > 0 and sp[S_STOP] != 0.0:
            break
        kick = half if it == 0 else dt
        for j in range(z):
            for k in range(3):
                bv[j, k] += kick * ba[j, k]
                bw[j, k] += kick * balpha[j, k]
                bx[j, k] += dt * bv[j, k]
        for k in range(3):
            rv[k] += kick * ra[k]
            rx[k] += dt * rv[k]
        if housing_on:
            housing_kick_drift(hx, hv, ha, kick, dt)
        if turning:
            integrate_orientations(bq, bw, defects, dt)
        scal[X_CAGE_SPEED] += kick * scal[X_CAGE_TORQUE] / cage_inertia
        scal[X_CAGE_ANGLE] += dt * scal[X_CAGE_SPEED]
        dw = sp[S_SHAFT_SPEED] - scal[X_SHAFT_SPEED]
        if dw > ramp:
            dw = ramp
        elif dw < -ramp:
            dw = -ramp
        scal[X_SHAFT_SPEED] += dw
        scal[X_SHAFT_ANGLE] += dt * scal[X_SHAFT_SPEED]
        scal[X_TIME] += dt
        step = int(scal[X_STEP])
        scal[X_STEP] = step + 1
        # the forces at x(n+1) see the balls' velocities at n+1/2 turned on by the half step of
        # the cage's rotation (exact for the steady orbit): without it the velocities and spin
        # axes lag the positions by half a step of the orbit, an O(dt) error (3 % of the 7208's
        # friction torque at 1 us, 10 % at 4 us); compute_accelerations turns them as it reads
        # them (the state's velocities stay unturned)
        ct, st = _cos_sin(half * scal[X_CAGE_SPEED])
        if housing_on:  # forces in the outer ring's frame
            shift_frame(bx, bv, rx, rv, hx, hv, -1.0)
        status = compute_accelerations(
            p,
            tr,
            sp,
            scal,
            bx,
            bv,
            bw,
            ba,
            balpha,
            rx,
            rv,
            ra,
            w,
            cage_load,
            step % substeps == 0,
            step % (substeps * ELECTRICAL_EVERY) == 0,
            step % (substeps * traction_every) == 0,
            ct,
            st,
            step + 1.0,
        )  # a tribology step
        if housing_on:  # back to the world frame; the housing and the accelerometer
            shift_frame(bx, bv, rx, rv, hx, hv, 1.0)
            fx, fy, fz = outer_ring_force(w, z)
            sensed = housing_accelerations(hp, hx, hv, fx, fy, fz, dt, ha)
            sensor_push_direct(taps, ratio, dec_state, sensed, ring, ring_state)
            if not math.isfinite(sensed):
                status = STATUS_NOT_FINITE
        scal[X_TORQUE_SUM] += scal[X_DRIVE_TORQUE]
        scal[X_TORQUE_COUNT] += 1.0
        done = it + 1
        if status != STATUS_OK:
            break
    for j in range(z):
        for k in range(3):
            bv[j, k] += half * ba[j, k]
            bw[j, k] += half * balpha[j, k]
    for k in range(3):
        rv[k] += half * ra[k]
    if housing_on:
        housing_close(hv, ha, half)
    scal[X_CAGE_SPEED] += half * scal[X_CAGE_TORQUE] / cage_inertia
    return status, done


@njit(**JIT_STEP)
def evaluate(model, state, setpoint):
    """Contact forces, tribology and accelerations (balls, rings and the housing) at the current
    state without advancing time (used after a warm start). Returns the status. Same structures as
    `step_n`; the accelerometer is not sampled. The tribology is refreshed at the state as it is,
    not centred (stamp 0: a warm-started state has no history to extrapolate from, and the next
    regular refresh takes none from this one)."""
    p, tr, hp = model.params, model.angle_table, model.housing_params
    sp = setpoint
    scal, w, cage_load = state.scalars, state.workspace, state.cage_load_n
    bx, bv, bw = state.ball_position_m, state.ball_velocity_m_s, state.ball_angular_velocity_rad_s
    ba, balpha = state.ball_acceleration, state.ball_angular_acceleration
    rx, rv, ra = state.ring_position_m, state.ring_velocity_m_s, state.ring_acceleration
    hx, hv, ha = state.housing_displacement_m, state.housing_velocity_m_s, state.housing_acceleration_m_s2
    housing_on = p[P_VIB + V_HOUSING_ON] != 0.0
    if housing_on:
        shift_frame(bx, bv, rx, rv, hx, hv, -1.0)
    status = compute_accelerations(
        p, tr, sp, scal, bx, bv, bw, ba, balpha, rx, rv, ra, w, cage_load, True, True, True, 1.0, 0.0, 0.0
    )
    if housing_on:
        shift_frame(bx, bv, rx, rv, hx, hv, 1.0)
        fx, fy, fz = outer_ring_force(w, bx.shape[0])
        housing_accelerations(hp, hx, hv, fx, fy, fz, 0.0, ha)
    return status
