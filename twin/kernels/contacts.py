"""Contact kernels: ball-raceway (torus groove) and ball-cage-element forces, and the per-contact
tribology. Scalar in, tuple out: the hot loop (`twin.kernels.step`) owns every array access.

Measured reasons for the style: passing arrays to a non-inlined numba function costs an atomic
incref/decref pair per array per call, so the per-contact laws are scalar functions (inlined by
LLVM); the branch-free geometry pass vectorises (vsqrtpd), while a vectorised force pass did not
(too many arrays for LLVM's runtime alias checks) and was slower than the fused scalar loop.

Frame: bearing axis +z, radial load along +x (azimuth 0 = most loaded), shaft speed about +z.
"""

import math

from numba import njit

from twin.jit import JIT, JIT_VECTOR
from twin.physics.damping import regime_damping_n_s_m


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
    erx = px * inv_rho
    ery = py * inv_rho
    dx = px - groove_centre_radius * erx
    dy = py - groove_centre_radius * ery
    dz = pz - groove_centre_z
    d = math.sqrt(dx * dx + dy * dy + dz * dz)
    if d <= 0.0:
        return -(groove_radius - ball_radius), erx, ery, 0.0
    inv_d = 1.0 / d
    return d - (groove_radius - ball_radius), dx * inv_d, dy * inv_d, dz * inv_d


@njit(**JIT_VECTOR)
def raceway_geometry(rel, groove, out):
    """Seed 000 Fig. 3 torus geometry for every ball-raceway contact at once (vectorised).

    rel[0:3, c]: ball centre relative to its ring's centre [m] for contact c = 2 ball + race;
    groove[0:4, c]: groove-centre circle radius, its height, groove radius - ball radius [m], Hertz
    K [N/m^1.5]. Writes out[0, c] = penetration delta [m] (<= 0: no contact), out[1:4, c] = unit
    normal from the groove-curvature centre to the ball centre, out[4, c] = sqrt(max(delta, 0)),
    out[5, c] = elastic load K delta^1.5 [N] (0 without contact). Branch-free so that LLVM turns
    the square roots and divisions into vector instructions (measured 6 ns per contact instead
    of ~45 ns for the fused scalar form)."""
    for c in range(rel.shape[1]):
        px = rel[0, c]
        py = rel[1, c]
        pz = rel[2, c]
        rho = math.sqrt(px * px + py * py)
        scale = 1.0 - groove[0, c] / rho
        dx = px * scale
        dy = py * scale
        dz = pz - groove[1, c]
        d = math.sqrt(dx * dx + dy * dy + dz * dz)
        inv_d = 1.0 / d
        delta = d - groove[2, c]
        out[0, c] = delta
        out[1, c] = dx * inv_d
        out[2, c] = dy * inv_d
        out[3, c] = dz * inv_d
        sq = math.sqrt(max(delta, 0.0))
        out[4, c] = sq
        out[5, c] = groove[3, c] * max(delta, 0.0) * sq


@njit(**JIT)
def contact_slip(rb, nx, ny, nz, bx, by, qx, qy, bvx, bvy, bvz, wx, wy, wz, ovx, ovy, ovz,
                 ring_speed, orbital_speed):
    """Surface kinematics of a ball-race contact at the point rb n from the ball centre (q from
    the ring centre, b the ball centre in the world frame). Returns the tangential slip velocity
    ball minus ring (tx, ty, tz) [m/s] and the tangential entrainment velocity (ex, ey, ez) [m/s]:
    the mean of the two surface velocities relative to the contact point, which orbits with the
    ball at orbital_speed (DESIGN.md reading of seed 000 eq. 6: ~7.25 m/s for the 6208 at 500 rad/s)."""
    vbx = bvx + rb * (wy * nz - wz * ny)
    vby = bvy + rb * (wz * nx - wx * nz)
    vbz = bvz + rb * (wx * ny - wy * nx)
    vrx = ovx - ring_speed * qy
    vry = ovy + ring_speed * qx
    vrz = ovz
    sx = vbx - vrx
    sy = vby - vry
    sz = vbz - vrz
    sn = sx * nx + sy * ny + sz * nz
    ex = 0.5 * (vbx + vrx) + orbital_speed * (by + rb * ny)
    ey = 0.5 * (vby + vry) - orbital_speed * (bx + rb * nx)
    ez = 0.5 * (vbz + vrz)
    en = ex * nx + ey * ny + ez * nz
    return (sx - sn * nx, sy - sn * ny, sz - sn * nz, ex - en * nx, ey - en * ny, ez - en * nz)


@njit(**JIT)
def normal_force_n(q_elastic, film_param, c_fluid, alpha_e, penetration_rate):
    """Fn = K delta^1.5 + C_n(Lambda) d(delta)/dt, never adhesive (seed 000 eq. 8 with eq. 4,
    C_hyst = 3 alpha_e K delta^1.5 / 2, eq. 5 and Table 2)."""
    c_n = regime_damping_n_s_m(film_param, 1.5 * alpha_e * q_elastic, c_fluid)
    fn = q_elastic + c_n * penetration_rate
    return fn if fn > 0.0 else 0.0


@njit(**JIT)
def tangential_force(xix, xiy, xiz, nx, ny, nz, tx, ty, tz, dt, kt, ct, limit):
    """Seed 000 eq. 8 tangential law: spring history xi rotated into the tangent plane plus this
    step's slip, trial force -Kt xi - Ct v_t, capped at mu Fn (Cundall-Strack: when sliding the
    spring is reset to the capped force). Returns (Ftx, Fty, Ftz, xi_x, xi_y, xi_z)."""
    xn = xix * nx + xiy * ny + xiz * nz
    xix = xix - xn * nx + tx * dt
    xiy = xiy - xn * ny + ty * dt
    xiz = xiz - xn * nz + tz * dt
    ftx = -kt * xix - ct * tx
    fty = -kt * xiy - ct * ty
    ftz = -kt * xiz - ct * tz
    ft2 = ftx * ftx + fty * fty + ftz * ftz
    if ft2 > limit * limit:
        scale = limit / math.sqrt(ft2)
        ftx *= scale
        fty *= scale
        ftz *= scale
        inv_kt = 1.0 / kt
        xix = -ftx * inv_kt
        xiy = -fty * inv_kt
        xiz = -ftz * inv_kt
    return ftx, fty, ftz, xix, xiy, xiz


@njit(**JIT)
def pivoting_moment_signed(spin_moment, wx, wy, wz, nx, ny, nz, ring_speed):
    """Seed 001 pivoting moment about the normal [N m], opposing the spin of the ball relative
    to the ring about the contact normal."""
    spin_rel = (wx * nx + wy * ny + wz * nz) - ring_speed * nz
    mp = -spin_moment if spin_rel > 0.0 else spin_moment
    return 0.0 if spin_rel == 0.0 else mp


@njit(**JIT)
def cage_contact(bx, by, bz, bvx, bvy, bvz, ex, ey, cage_speed, contact_distance, k_cage,
                 reduced_mass):
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
    nx = dx / d
    ny = dy / d
    nz = dz / d
    delta = contact_distance - d
    vrel_n = (bvx + cage_speed * ey) * nx + (bvy - cage_speed * ex) * ny + bvz * nz
    sq = math.sqrt(delta)
    damping = 2.0 * math.sqrt(1.5 * k_cage * sq * reduced_mass)
    f = k_cage * delta * sq - damping * vrel_n
    if f < 0.0:
        f = 0.0
    return f, nx, ny, nz
