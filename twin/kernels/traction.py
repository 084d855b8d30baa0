"""Friction over the contact ellipse: the traction of every loaded
ball-raceway contact integrated in strips across the major axis of its Hertz ellipse.

Kinematics (rigid-body velocity fields of ball and ring evaluated on the contact surface, which
is curved across the groove with the radius R_d of twin.physics.traction.deformed_surface_radius_m;
contact frame n = normal, t1 = rolling direction, t2 = n x t1 along the major axis): at the
distance y = a t from the centre along t2, the sliding speed ball minus ring along t1 is

    s(y) = s0 - Dw_n y - Dw_2 y^2 / (2 R_d),      Dw = omega_ball - omega_ring,

the spin term Dw_n y and the conformity (Heathcote) term Dw_2 y^2 / (2 R_d) (Johnson, Contact
Mechanics, 1985, section 8.4). Each strip k carries its share w_k of the load at its mean Hertz
pressure p_k (twin.physics.traction.hertz_strip_table) and the traction law of
twin.physics.traction: Qa/Q mu(Lambda) p sgn_reg(s) for the asperities (seed 001 eq. A2, seed 000
mu(Lambda)) plus (1 - Qa/Q) min(tau0 asinh(eta(p) s / (h tau0)), gamma p) sgn(s) for the film
(Johnson-Tevaarwerk Eyring, Bair-Winer limiting shear stress).

Net force and moments. The net tangential force of a contact is carried by the tangential spring
of seed 000 (contacts.raceway_forces: the ball's rolling constraint with the contact's
compliance), limited by the traction capacity of the ellipse; the centre slip s0 is the one
at which the strips transmit that net force (safeguarded Newton, warm-started). The strips' moment
about the contact centre,

    M = (sum_k f_k a t_k) n + (a^2 / (2 R_d)) (sum_k f_k t_k^2) t2   (f_k: strip force opposing s),

acts on the ball (and its reaction on the ring): the t2 part is the rolling resistance of the
differential slip, the n part the spin (pivoting) moment, which replaces seed 001's eq. 11. The
spin moment is applied every step from its value and slope at the solution, clipped to the
all-sliding value, so that it follows the spin rate without a sign chatter.

Cost: the strip solve (a few exponentials per strip pair, one to three Newton passes from the
last solution) runs every `P_TRACTION_EVERY` tribology refreshes (400 us by default): the torque moves by
under 0.04 % between a solve every 10 us and every 500 us (tests/physics/test_friction_torque.py),
and 12 strips hold the moments within 0.5 % of 32 (tests/kernels/test_traction.py). No allocation: the per-strip values
of the contact being solved
live in scratch rows of the lane array.
"""

import math

from numba import njit

from twin.jit import JIT, JIT_VECTOR
from twin.kernels.layout import (
    C_H_C,
    C_LAMBDA,
    C_LOAD,
    C_MU,
    C_SEMI_MAJOR,
    C_SEMI_MINOR,
    CW,
    E_M2X,
    E_M2Y,
    E_M2Z,
    E_MOMENT_T2,
    E_SCRATCH_EY,
    E_SCRATCH_O,
    E_SCRATCH_SE,
    E_SCRATCH_SIGNED_HALF,
    E_SCRATCH_SPREAD,
    E_SCRATCH_SSAT,
    E_SLIP,
    E_SPIN_CAP,
    E_SPIN_MOMENT,
    E_SPIN_RATE,
    E_SPIN_SLOPE,
    G_DELTA,
    G_NX,
    G_NY,
    G_NZ,
    G_SQRT_DELTA,
    K_BX,
    K_BY,
    K_SPIN,
    K_WX,
    K_WY,
    K_WZ,
    M_STIFFNESS,
    O_EX,
    O_EY,
    O_EZ,
    O_RING_TZ,
    O_TX,
    O_TY,
    O_TZ,
    P_ASPERITY_SLIP,
    P_DEFORMED_RADIUS,
    P_EYRING_STRESS,
    P_LIMITING_SHEAR,
    P_PRESSURE_VISCOSITY,
    P_STRIP_TABLE,
    P_TRACTION_STRIPS,
    T_XI0,
    T_XI1,
    T_XI2,
)
from twin.physics.friction import stribeck_line_mu
from twin.physics.hertz import max_pressure_pa
from twin.physics.rolling import asperity_load_share
from twin.physics.traction import barus_viscosity_pa_s, eyring_saturation_slip_m_s, traction_capacity

NEWTON_MAX_ITERATIONS = 40
NEWTON_FORCE_TOLERANCE = 1e-3  # of the capacity Q: |sum f_k - target| below this stops the solve
TARGET_FRACTION = 0.999  # the net force is kept inside the capacity by this factor


@njit(**JIT)
def limiting_traction_coefficient(film_parameter, limiting_shear_coefficient):
    """Traction capacity of a contact over its normal load, every element sliding one way [-]:
    Qa/Q mu(Lambda) + (1 - Qa/Q) gamma (twin.physics.traction.traction_capacity; seed 001 eq. A2
    share, seed 000 mu(Lambda), Bair-Winer gamma). It is the contact's limiting friction
    coefficient: the tangential spring's Coulomb limit (C_MU) and the mu of the fully sliding
    traction that the spin-creep relaxation linearises (twin.kernels.step). In full film
    (Lambda >= 2.26, no asperity share) it is gamma without evaluating a power."""
    return limiting_traction_coefficient_share(
        film_parameter, asperity_load_share(film_parameter), limiting_shear_coefficient
    )


@njit(inline="always", **JIT)
def limiting_traction_coefficient_share(film_parameter, asperity_share, limiting_shear_coefficient):
    """`limiting_traction_coefficient` given the asperity load share Qa/Q(Lambda) (seed 001
    eq. A2) the caller already holds (the tribology refresh takes it from ln Lambda, the strip
    solve needs it anyway): Qa/Q mu(Lambda) + (1 - Qa/Q) gamma, gamma itself without a share."""
    if asperity_share == 0.0:
        return limiting_shear_coefficient
    return traction_capacity(asperity_share, stribeck_line_mu(film_parameter), limiting_shear_coefficient)


@njit(**JIT)
def ellipse_traction(w, nc, p, viscosity_pa_s, kt_ratio, ball_inertia_kg_m2, dt_s):
    """For every loaded contact: the traction capacity (the tangential spring's Coulomb limit,
    C_MU, `limiting_traction_coefficient`) and the strip integration of the module docstring,
    written to the E_* rows. Open contacts get zero moments. Reads the contact lanes after the
    tribology refresh."""
    n_strips = int(p[P_TRACTION_STRIPS])
    gamma = p[P_LIMITING_SHEAR]
    tau0 = p[P_EYRING_STRESS]
    alpha = p[P_PRESSURE_VISCOSITY]
    s_a = p[P_ASPERITY_SLIP]
    max_slope = ball_inertia_kg_m2 / dt_s  # spin-moment slope the explicit step resolves
    for c in range(nc):
        if w[G_DELTA * CW + c] <= 0.0:
            w[E_MOMENT_T2 * CW + c] = 0.0
            w[E_M2X * CW + c] = 0.0
            w[E_M2Y * CW + c] = 0.0
            w[E_M2Z * CW + c] = 0.0
            w[E_SPIN_MOMENT * CW + c] = 0.0
            w[E_SPIN_SLOPE * CW + c] = 0.0
            w[E_SPIN_CAP * CW + c] = 0.0
            continue
        lam = w[C_LAMBDA * CW + c]
        share = asperity_load_share(lam)
        mu_a = stribeck_line_mu(lam)
        capacity = limiting_traction_coefficient_share(lam, share, gamma)  # as the tribology refresh set it
        w[C_MU * CW + c] = capacity
        q = w[C_LOAD * CW + c]
        # net tangential force on the ball: the elastic part of the tangential spring
        kt = kt_ratio * 1.5 * w[M_STIFFNESS * CW + c] * w[G_SQRT_DELTA * CW + c]
        fx = -kt * w[T_XI0 * CW + c]
        fy = -kt * w[T_XI1 * CW + c]
        fz = -kt * w[T_XI2 * CW + c]
        a = w[C_SEMI_MAJOR * CW + c]
        b = w[C_SEMI_MINOR * CW + c]
        h = w[C_H_C * CW + c]
        if not (q > 0.0 and a > 0.0 and b > 0.0):
            continue
        p_h = max_pressure_pa(q, a, b)
        # contact frame: n, t1 along the entrainment (or the orbit when there is none), t2 = n x t1
        nx = w[G_NX * CW + c]
        ny = w[G_NY * CW + c]
        nz = w[G_NZ * CW + c]
        t1x, t1y, t1z = _rolling_direction(w, c, nx, ny, nz)
        t2x = ny * t1z - nz * t1y
        t2y = nz * t1x - nx * t1z
        t2z = nx * t1y - ny * t1x
        dwx = w[K_WX * CW + c]
        dwy = w[K_WY * CW + c]
        dwz = w[K_WZ * CW + c] - w[K_SPIN * CW + c]
        spin = dwx * nx + dwy * ny + dwz * nz
        roll = dwx * t2x + dwy * t2y + dwz * t2z
        r_d = p[P_DEFORMED_RADIUS + (c & 1)]
        spin_a = spin * a  # slip offset per unit t from spin [m/s]
        curv = roll * a * a / (2.0 * r_d)  # slip offset per unit t^2 from conformity [m/s]
        target = -(fx * t1x + fy * t1y + fz * t1z)  # sum of strip forces opposing the slip
        limit = TARGET_FRACTION * capacity * q
        target = min(max(target, -limit), limit)
        # per-strip constants of this contact (pressure-dependent ones shared by mirror strips)
        o_min = math.inf
        o_max = -math.inf
        s_big = 30.0 * s_a
        half_width = 1.0 / n_strips
        fl_q = (1.0 - share) * gamma * q  # strip k's limiting fluid force is w_k fl_q
        as_q = share * mu_a * q  # and its asperity force w_k as_q
        cap = 0.0
        for k in range(n_strips):
            row = P_STRIP_TABLE + 4 * k
            o = spin_a * p[row] + curv * p[row + 1]
            mid = -1.0 + (2 * k + 1) * half_width
            gradient = spin_a + 2.0 * curv * mid  # -ds/dt across the strip
            w[E_SCRATCH_O * CW + k] = o
            w[E_SCRATCH_SPREAD * CW + k] = abs(gradient) * half_width
            w[E_SCRATCH_SIGNED_HALF * CW + k] = -half_width if gradient > 0.0 else half_width
            mirror = n_strips - 1 - k
            if mirror < k:
                w[E_SCRATCH_SE * CW + k] = w[E_SCRATCH_SE * CW + mirror]
                w[E_SCRATCH_SSAT * CW + k] = w[E_SCRATCH_SSAT * CW + mirror]
                w[E_SCRATCH_EY * CW + k] = w[E_SCRATCH_EY * CW + mirror]
            else:
                pk = p[row + 3] * p_h
                eta = barus_viscosity_pa_s(viscosity_pa_s, alpha, pk)
                w[E_SCRATCH_SE * CW + k] = h * tau0 / eta if h > 0.0 else 0.0
                w[E_SCRATCH_SSAT * CW + k] = eyring_saturation_slip_m_s(h, eta, pk, tau0, gamma)
                w[E_SCRATCH_EY * CW + k] = (1.0 - share) * p[row + 2] * q / pk * tau0  # (1 - Qa/Q) A_k tau0
            o_min = min(o_min, o)
            o_max = max(o_max, o)
            s_big = max(s_big, w[E_SCRATCH_SSAT * CW + k])
            cap += p[row + 2] * (fl_q + as_q) * abs(p[row])
        lo = o_min - s_big
        hi = o_max + s_big
        s0 = min(max(w[E_SLIP * CW + c], lo), hi)
        tol = NEWTON_FORCE_TOLERANCE * capacity * q
        # safeguarded Newton on sum_k f_k(s0 - o_k) = target; every pass also sums the moments
        # and the spin-moment slope, so the pass that converges is the last one
        sum_ft = 0.0
        sum_ft2 = 0.0
        sum_d = 0.0
        sum_dt = 0.0
        sum_dtt = 0.0
        for _ in range(NEWTON_MAX_ITERATIONS):
            g = -target
            sum_ft = 0.0
            sum_ft2 = 0.0
            sum_d = 0.0
            sum_dt = 0.0
            sum_dtt = 0.0
            for k in range(n_strips):
                row = P_STRIP_TABLE + 4 * k
                f, df, split, frac = _strip_force(
                    s0 - w[E_SCRATCH_O * CW + k],
                    p[row + 2],
                    fl_q,
                    as_q,
                    w[E_SCRATCH_SE * CW + k],
                    w[E_SCRATCH_SSAT * CW + k],
                    w[E_SCRATCH_EY * CW + k],
                    s_a,
                    w[E_SCRATCH_SPREAD * CW + k],
                )
                t = p[row]
                # a no-slip line inside the strip: the forces on its two sides act on either side
                # of it (first and second moments of a sign change at t_r = mid - F sh)
                sh = w[E_SCRATCH_SIGNED_HALF * CW + k]
                mid = -1.0 + (2 * k + 1) * half_width
                g += f
                sum_ft += f * t + 0.5 * sh * split
                sum_ft2 += f * p[row + 1] + split * (sh * mid - half_width * half_width * frac / 3.0)
                sum_d += df
                sum_dt += df * t
                sum_dtt += df * t * t
            if abs(g) <= tol:
                break
            if g > 0.0:
                hi = s0
            else:
                lo = s0
            if hi - lo <= 1e-14 * (1.0 + abs(s0)):
                break
            nxt = s0 - g / sum_d if sum_d > 0.0 else 0.5 * (lo + hi)
            s0 = nxt if lo < nxt < hi else 0.5 * (lo + hi)
        slope = a * a * (sum_dt * sum_dt / sum_d - sum_dtt) if sum_d > 0.0 else 0.0
        w[E_SLIP * CW + c] = s0
        m2 = a * a / (2.0 * r_d) * sum_ft2
        w[E_MOMENT_T2 * CW + c] = m2
        w[E_M2X * CW + c] = m2 * t2x
        w[E_M2Y * CW + c] = m2 * t2y
        w[E_M2Z * CW + c] = m2 * t2z
        w[E_SPIN_MOMENT * CW + c] = a * sum_ft
        w[E_SPIN_SLOPE * CW + c] = max(slope, -max_slope)
        w[E_SPIN_RATE * CW + c] = spin
        w[E_SPIN_CAP * CW + c] = a * cap


@njit(**JIT)
def _strip_force(s, share_w, fl_q, as_q, s_e, s_sat, eyring, s_a, spread):
    """Force of one strip opposing its mean slip s [N], its derivative d/ds [N s/m], and the
    part of the strip's largest force that is split by a no-slip line inside it, with the
    fraction F = s / spread that fixes where that line lies.

    Law (twin.physics.traction): asperities w_k Qa/Q mu Q sgn_reg(s); film sgn(s) min((1 - Qa/Q)
    A_k tau0 asinh(|s|/s_e), w_k (1 - Qa/Q) gamma Q). Within a strip the slip runs linearly over
    s +- `spread` (the parabola of the module docstring across the strip); where it changes sign
    inside the strip, a sliding (saturated) law gives the strip the force T F, F = s / spread (the
    share of the strip on either side of the no-slip line): each part takes the smaller of its
    law and that ramp. The split part (1 - F^2) T moves the moments' arms off the strip
    centroid (ellipse_traction), which makes the quadrature of the no-slip lines second order in
    the strip width (tests/kernels/test_traction.py)."""
    mag = abs(s)
    ramp = mag / spread if spread > 0.0 else math.inf
    # asperities: regularised Coulomb, bounded by the ramp
    t_as = share_w * as_q
    f_as = 0.0
    df_as = 0.0
    split = 0.0
    if t_as > 0.0:  # no asperity share in full film (seed 001 eq. A2 is 0 from Lambda = 2.26)
        r2 = s * s + s_a * s_a
        root_as = math.sqrt(r2)
        f_as = t_as * mag / root_as
        df_as = t_as * s_a * s_a / (r2 * root_as)
        if ramp < 1.0 and t_as * ramp < f_as:
            f_as = t_as * ramp
            df_as = t_as / spread
            split = t_as
    # film: Eyring bounded by the limiting shear stress, bounded by the ramp
    limit = share_w * fl_q
    f_fl = limit
    df_fl = 0.0
    if mag < s_sat and s_e > 0.0:
        root = math.sqrt(s * s + s_e * s_e)
        ey = eyring * math.log((mag + root) / s_e)
        if ey < limit:
            f_fl = ey
            df_fl = eyring / root
    if ramp < 1.0 and limit * ramp < f_fl:
        f_fl = limit * ramp
        df_fl = limit / spread
        split += limit
    frac = min(ramp, 1.0)
    if s < 0.0:
        return -(f_as + f_fl), df_as + df_fl, split * (1.0 - frac * frac), -frac
    return f_as + f_fl, df_as + df_fl, split * (1.0 - frac * frac), frac


@njit(**JIT)
def _rolling_direction(w, c, nx, ny, nz):
    """Unit rolling direction t1 of contact c: the entrainment velocity, or (without entrainment)
    the circumferential direction at the ball, made normal to n."""
    ex = w[O_EX * CW + c]
    ey = w[O_EY * CW + c]
    ez = w[O_EZ * CW + c]
    e2 = ex * ex + ey * ey + ez * ez
    if e2 <= 1e-24:
        ex = -w[K_BY * CW + c]
        ey = w[K_BX * CW + c]
        ez = 0.0
        en = ex * nx + ey * ny + ez * nz
        ex -= en * nx
        ey -= en * ny
        ez -= en * nz
        e2 = ex * ex + ey * ey + ez * ez
        if e2 <= 0.0:
            return 1.0, 0.0, 0.0
    inv = 1.0 / math.sqrt(e2)
    return ex * inv, ey * inv, ez * inv


@njit(inline="always", **JIT_VECTOR)
def traction_moment_lane(w, c, loaded, nx, ny, nz, spin):
    """The strips' moment on the ball of lane c (module docstring), branch-free: the moment
    along t2 as solved (world frame; the contact frame turns by the ball's orbit, about 1 deg,
    between two solves) plus the spin moment along the current normal n, linear in the current
    relative spin rate `spin` (ball minus ring, about n) about its value at the last solve and
    clipped to the all-sliding moment. `loaded`: 1.0 for a closed contact, 0.0 for an open one.
    Returns (mx, my, mz) [N m]; the ring takes -mz about its axis."""
    cap = w[E_SPIN_CAP * CW + c]
    mn = w[E_SPIN_MOMENT * CW + c] + w[E_SPIN_SLOPE * CW + c] * (spin - w[E_SPIN_RATE * CW + c])
    mn = min(max(mn, -cap), cap)
    mx = loaded * (w[E_M2X * CW + c] + mn * nx)
    my = loaded * (w[E_M2Y * CW + c] + mn * ny)
    mz = loaded * (w[E_M2Z * CW + c] + mn * nz)
    return mx, my, mz


@njit(inline="always", **JIT_VECTOR)
def apply_traction_moments(w, nc):
    """Every lane (vectorised, branch-free): add the strips' moment about the contact centre
    (`traction_moment_lane`) to the ball torque (O_T*) and its reaction to the ring's torque
    about its axis (O_RING_TZ). A pass of its own: carried in the force pass's loop (with the
    force pass's runtime flag) it costs more than it saves."""
    for c in range(nc):
        loaded = 1.0 if w[G_DELTA * CW + c] > 0.0 else 0.0
        nx = w[G_NX * CW + c]
        ny = w[G_NY * CW + c]
        nz = w[G_NZ * CW + c]
        spin = w[K_WX * CW + c] * nx + w[K_WY * CW + c] * ny + (w[K_WZ * CW + c] - w[K_SPIN * CW + c]) * nz
        mx, my, mz = traction_moment_lane(w, c, loaded, nx, ny, nz, spin)
        w[O_TX * CW + c] += mx
        w[O_TY * CW + c] += my
        w[O_TZ * CW + c] += mz
        w[O_RING_TZ * CW + c] -= mz
