"""Contact kernels: ball-raceway (torus groove) and ball-cage-element contacts.

The ball-raceway contacts of all balls are processed as lanes of one flat array `w` (row k of
contact c at w[k * CW + c], see `twin.kernels.layout`): a branch-free geometry pass and a
branch-free force pass that LLVM vectorises. Ball-cage contacts are scalar (mostly open).

Frame: bearing axis +z, radial load along +x (azimuth 0 = most loaded), shaft speed about +z.
"""

import math

from numba import njit

from twin.jit import JIT, JIT_VECTOR
from twin.kernels.layout import (
    C_FLUID_DAMPING,
    C_LAMBDA,
    C_MU,
    C_ROLLING_PER_SPEED,
    C_SPIN_MOMENT,
    C_TANGENT_DAMPING,
    C_XI_DECAY,
    CW,
    G_DELTA,
    G_LOAD,
    G_NX,
    G_NY,
    G_NZ,
    G_SQRT_DELTA,
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
    M_GROOVE_CENTRE_RADIUS,
    M_GROOVE_CENTRE_Z,
    M_GROOVE_CLEARANCE,
    M_STIFFNESS,
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
    T_XI0,
    T_XI1,
    T_XI2,
)
from twin.physics.friction import BOUNDARY_LAMBDA_MAX, MIXED_LAMBDA_MAX


@njit(**JIT)
def groove_penetration(px, py, pz, groove_centre_radius, groove_centre_z, groove_radius, ball_radius):
    """Penetration of a ball (centre p relative to the ring centre, ring axis +z) into a torus
    groove, and the unit normal from the groove-curvature centre to the ball centre.

    The groove surface is the torus of minor radius `groove_radius` around the circle of radius
    `groove_centre_radius` at height `groove_centre_z`; the ball touches it when its centre is
    farther than groove_radius - ball_radius from that circle (seed 000 Fig. 3 curvatures).
    Returns (delta [m], nx, ny, nz); delta <= 0 means no contact.
    """
    rho = math.sqrt(px * px + py * py)
    if rho <= 0.0:
        return -1.0, 1.0, 0.0, 0.0
    inv_rho = 1.0 / rho
    dx = px - groove_centre_radius * px * inv_rho
    dy = py - groove_centre_radius * py * inv_rho
    dz = pz - groove_centre_z
    d = math.sqrt(dx * dx + dy * dy + dz * dz)
    if d <= 0.0:
        return -(groove_radius - ball_radius), px * inv_rho, py * inv_rho, 0.0
    inv_d = 1.0 / d
    return d - (groove_radius - ball_radius), dx * inv_d, dy * inv_d, dz * inv_d


@njit(inline="always", **JIT_VECTOR)
def raceway_geometry(w, nc):
    """`groove_penetration` for every contact lane at once (vectorised, branch-free): reads
    K_PX..K_PZ and the M_* groove rows, writes G_DELTA, G_NX..G_NZ, G_SQRT_DELTA and
    G_LOAD = K delta^1.5 (seed 000 eq. 2; 0 when open)."""
    for c in range(nc):
        px = w[K_PX * CW + c]
        py = w[K_PY * CW + c]
        pz = w[K_PZ * CW + c]
        rho = math.sqrt(px * px + py * py)
        # (dx, dy) = p (1 - R / rho), of length rho - R: one division, 1 / (rho d), for both
        radial = rho - w[M_GROOVE_CENTRE_RADIUS * CW + c]
        dz = pz - w[M_GROOVE_CENTRE_Z * CW + c]
        d = math.sqrt(radial * radial + dz * dz)
        inv = 1.0 / (rho * d)
        delta = d - w[M_GROOVE_CLEARANCE * CW + c]
        pos = max(delta, 0.0)
        sq = math.sqrt(pos)
        w[G_DELTA * CW + c] = delta
        w[G_NX * CW + c] = px * radial * inv
        w[G_NY * CW + c] = py * radial * inv
        w[G_NZ * CW + c] = dz * rho * inv
        w[G_SQRT_DELTA * CW + c] = sq
        w[G_LOAD * CW + c] = w[M_STIFFNESS * CW + c] * pos * sq


@njit(inline="always", **JIT_VECTOR)
def raceway_forces(w, nc, rb, dt, kt_ratio, alpha_e):
    """Seed 000 eq. 8 for every contact lane at once (vectorised, branch-free):

    - kinematics: slip (ball minus ring surface velocity, tangential) and entrainment (mean
      surface velocity relative to the contact point, which orbits with the ball; docs/physics.md
      reading of eq. 6, ~7.25 m/s for the 6208 at 500 rad/s);
    - Fn = K delta^1.5 + C_n(Lambda) d(delta)/dt, never adhesive, C_n per Table 2: C_hyst =
      3 alpha_e K delta^1.5 / 2 (eq. 4) for Lambda <= 1, C_hyst C_fluid / (C_hyst + C_fluid) for
      1 < Lambda <= 3, C_fluid (eq. 5) above;
    - Ft = -(Kt xi + Ct v_t) capped at mu Fn (tangential spring xi with a Coulomb limit,
      Cundall-Strack: the spring is reset to the capped force when sliding), Kt = ratio dQ/ddelta;
      the spring forgets over a rolling distance L = sqrt(a b) and by spin sliding (rate r =
      u / L + spin term, twin.kernels.step), integrated by backward Euler, xi <- (xi + v dt) /
      (1 + r dt) (C_XI_DECAY = 1 / (1 + r dt)): unconditionally stable, and its steady state
      under a constant slip is the creep law xi = v / r at any dt (decaying before adding the
      slip would give v (1 / r + dt), (1 + r dt) times too stiff, and r dt reaches 1-15 at the auto
      step on the spinning contacts of a 40 deg 7208): a rolling contact renews its material continuously, so its
      tangential force follows the creepage v_slip / u with a creep coefficient Kt L of the order
      of Kalker's linear one, G a b C11 (7.8e4 N against 7e4-1.2e5 N at the 6208's inner
      contact under 1457 N), instead of holding a static-friction memory of past lateral motion
      (Kalker 1990, Three-dimensional elastic bodies in rolling contact, ch. 5: transient creep
      settles within about one contact length of rolling); at rest (u = 0) it is Cundall-Strack's;
    - seed 001 rolling resistance at the ball centre along the entrainment, and the pivoting
      moment against the spin of the ball relative to the ring about the normal.

    Reads the G_*, K_*, M_STIFFNESS rows and the cached C_* rows; writes the O_* rows (with
    O_NORMAL_RATE between its two loops) and the spring T_XI* (reset where the contact is
    open)."""
    # two loops, not one: the kinematics (slip, entrainment, normal rate, kept in their rows),
    # then the forces; one loop holds more values than the 16 vector registers and goes to the
    # stack 77 times per 4 lanes, two go 40 times (with the moment pass 461 ns against 504 in one
    # process, same operations, bitwise the same results; three loops are slower)
    for c in range(nc):
        nx = w[G_NX * CW + c]
        ny = w[G_NY * CW + c]
        nz = w[G_NZ * CW + c]
        qx = w[K_PX * CW + c] + rb * nx
        qy = w[K_PY * CW + c] + rb * ny
        wx = w[K_WX * CW + c]
        wy = w[K_WY * CW + c]
        wz = w[K_WZ * CW + c]
        spin = w[K_SPIN * CW + c]
        bvx = w[K_VX * CW + c]
        bvy = w[K_VY * CW + c]
        bvz = w[K_VZ * CW + c]
        ovx = w[K_OVX * CW + c]
        ovy = w[K_OVY * CW + c]
        ovz = w[K_OVZ * CW + c]
        # surface velocities at the contact point, slip and entrainment
        vbx = bvx + rb * (wy * nz - wz * ny)
        vby = bvy + rb * (wz * nx - wx * nz)
        vbz = bvz + rb * (wx * ny - wy * nx)
        vrx = ovx - spin * qy
        vry = ovy + spin * qx
        vrz = ovz
        sx = vbx - vrx
        sy = vby - vry
        sz = vbz - vrz
        sn = sx * nx + sy * ny + sz * nz
        orbit = w[K_ORBIT * CW + c]
        ex = 0.5 * (vbx + vrx) + orbit * (w[K_BY * CW + c] + rb * ny)
        ey = 0.5 * (vby + vry) - orbit * (w[K_BX * CW + c] + rb * nx)
        ez = 0.5 * (vbz + vrz)
        en = ex * nx + ey * ny + ez * nz
        w[O_EX * CW + c] = ex - en * nx
        w[O_EY * CW + c] = ey - en * ny
        w[O_EZ * CW + c] = ez - en * nz
        w[O_SX * CW + c] = sx - sn * nx
        w[O_SY * CW + c] = sy - sn * ny
        w[O_SZ * CW + c] = sz - sn * nz
        w[O_NORMAL_RATE * CW + c] = (bvx - ovx) * nx + (bvy - ovy) * ny + (bvz - ovz) * nz
    for c in range(nc):
        loaded = 1.0 if w[G_DELTA * CW + c] > 0.0 else 0.0
        nx = w[G_NX * CW + c]
        ny = w[G_NY * CW + c]
        nz = w[G_NZ * CW + c]
        tx = w[O_SX * CW + c]
        ty = w[O_SY * CW + c]
        tz = w[O_SZ * CW + c]
        # normal force with the regime damping of Table 2
        q_el = w[G_LOAD * CW + c]
        lam = w[C_LAMBDA * CW + c]
        c_fluid = w[C_FLUID_DAMPING * CW + c]
        c_hyst = 1.5 * alpha_e * q_el
        c_series = c_hyst * c_fluid / (c_hyst + c_fluid + 1e-300)
        c_n = c_fluid if lam > MIXED_LAMBDA_MAX else c_series
        c_n = c_hyst if (lam <= BOUNDARY_LAMBDA_MAX or c_fluid <= 0.0) else c_n
        fn = loaded * max(q_el + c_n * w[O_NORMAL_RATE * CW + c], 0.0)
        # tangential spring with Coulomb limit
        kt = kt_ratio * 1.5 * w[M_STIFFNESS * CW + c] * w[G_SQRT_DELTA * CW + c]
        xix = w[T_XI0 * CW + c]
        xiy = w[T_XI1 * CW + c]
        xiz = w[T_XI2 * CW + c]
        xn = xix * nx + xiy * ny + xiz * nz
        decay = w[C_XI_DECAY * CW + c]
        xix = (xix - xn * nx + tx * dt) * decay
        xiy = (xiy - xn * ny + ty * dt) * decay
        xiz = (xiz - xn * nz + tz * dt) * decay
        ct = w[C_TANGENT_DAMPING * CW + c]
        ftx = -kt * xix - ct * tx
        fty = -kt * xiy - ct * ty
        ftz = -kt * xiz - ct * tz
        limit = w[C_MU * CW + c] * fn
        ft = math.sqrt(ftx * ftx + fty * fty + ftz * ftz)
        sliding = ft > limit
        inv = 1.0 / ((ft + 1e-150) * (kt + 1e-150))  # one division for limit / ft and 1 / kt
        scale = limit * (kt + 1e-150) * inv if sliding else 1.0
        ftx *= scale
        fty *= scale
        ftz *= scale
        inv_kt = (ft + 1e-150) * inv
        xix = -ftx * inv_kt if sliding else xix
        xiy = -fty * inv_kt if sliding else xiy
        xiz = -ftz * inv_kt if sliding else xiz
        w[T_XI0 * CW + c] = loaded * xix
        w[T_XI1 * CW + c] = loaded * xiy
        w[T_XI2 * CW + c] = loaded * xiz
        # rolling resistance (seed 001) and pivoting moment
        roll = w[C_ROLLING_PER_SPEED * CW + c]
        wx = w[K_WX * CW + c]
        wy = w[K_WY * CW + c]
        wz = w[K_WZ * CW + c]
        spin = w[K_SPIN * CW + c]
        spin_rel = (wx * nx + wy * ny + wz * nz) - spin * nz
        ms = w[C_SPIN_MOMENT * CW + c]
        mp = -ms if spin_rel > 0.0 else ms
        mp = loaded * (0.0 if spin_rel == 0.0 else mp)
        fx = -fn * nx + loaded * (ftx + roll * w[O_EX * CW + c])
        fy = -fn * ny + loaded * (fty + roll * w[O_EY * CW + c])
        fz = -fn * nz + loaded * (ftz + roll * w[O_EZ * CW + c])
        w[O_FX * CW + c] = fx
        w[O_FY * CW + c] = fy
        w[O_FZ * CW + c] = fz
        ox = loaded * rb * (ny * ftz - nz * fty) + mp * nx
        oy = loaded * rb * (nz * ftx - nx * ftz) + mp * ny
        oz = loaded * rb * (nx * fty - ny * ftx) + mp * nz
        # reaction on the ring: -F at the contact point q and -M, about the ring axis
        qx = w[K_PX * CW + c] + rb * nx
        qy = w[K_PY * CW + c] + rb * ny
        oring = -(qx * fy - qy * fx) - mp * nz
        w[O_TX * CW + c] = ox
        w[O_TY * CW + c] = oy
        w[O_TZ * CW + c] = oz
        w[O_RING_TZ * CW + c] = oring


@njit(inline="always", **JIT)
def cage_contact(bx, by, bz, bvx, bvy, bvz, ex, ey, cage_speed, contact_distance, k_cage, reduced_mass):
    """Ball (centre b, velocity bv) against a cage element centred at (ex, ey, 0) on the cage
    turning at cage_speed: Q = K delta^1.5 (seed 000 eq. 3) with critical damping and no
    friction (seed 000 section 2.1). Returns (force on the ball [N], nx, ny, nz: unit vector
    from the element to the ball); force 0 without contact."""
    dx = bx - ex
    dy = by - ey
    dz = bz
    d2 = dx * dx + dy * dy + dz * dz
    if d2 >= contact_distance * contact_distance or d2 <= 0.0:
        return 0.0, 0.0, 0.0, 0.0
    d = math.sqrt(d2)
    inv_d = 1.0 / d
    nx = dx * inv_d
    ny = dy * inv_d
    nz = dz * inv_d
    delta = contact_distance - d
    vrel_n = (bvx + cage_speed * ey) * nx + (bvy - cage_speed * ex) * ny + bvz * nz
    sq = math.sqrt(delta)
    damping = 2.0 * math.sqrt(1.5 * k_cage * sq * reduced_mass)
    f = k_cage * delta * sq - damping * vrel_n
    if f < 0.0:
        f = 0.0
    return f, nx, ny, nz
