"""The hot loop: `step_n` integrates the bearing for n steps of velocity-Verlet (seed 000 eq. 10).

One compiled call per frame, no allocation, no Python objects, no array passed to another
function inside the loop; problems are reported through the returned status code
(`twin.kernels.layout.STATUS_*`), never raised.
"""

import math

import numpy as np
from numba import njit

from twin.jit import JIT
from twin.kernels.contacts import (
    cage_contact, contact_slip, normal_force_n, pivoting_moment_signed, raceway_geometry,
    tangential_force,
)
from twin.kernels.layout import (
    C_ENTRAINMENT, C_FLUID_DAMPING, C_H_C, C_H_MIN, C_LAMBDA, C_LOAD, C_MU, C_NX, C_NY, C_NZ,
    C_PENETRATION, C_REGIME, C_ROLLING_FORCE, C_ROLLING_PER_SPEED, C_SEMI_MAJOR, C_SEMI_MINOR,
    C_SPIN_MOMENT, C_SRR, C_TANGENT_DAMPING, N_CONTACT, P_ALPHA_E, P_BALL_INERTIA,
    P_BALL_MASS, P_BALL_RADIUS, P_BALL_REDUCED_TANGENT_MASS, P_CAGE_CONTACT_DISTANCE,
    P_CAGE_INERTIA, P_CAGE_RADIUS, P_CAGE_REDUCED_MASS, P_CAGE_STIFFNESS, P_CT_RATIO, P_DT,
    P_FRICTION_MODEL, P_KT_RATIO, P_MAX_PENETRATION, P_RAMP, P_RING_MASS, P_ROLLING, P_ROUGHNESS,
    P_SUBSTEPS, S_AXIAL_LOAD, S_RADIAL_LOAD, S_SHAFT_SPEED, S_VISCOSITY, STATUS_NOT_FINITE,
    STATUS_OK, STATUS_PENETRATION, X_CAGE_ANGLE, X_CAGE_SPEED, X_CAGE_TORQUE, X_DRIVE_TORQUE,
    X_MAX_PENETRATION, X_SHAFT_ANGLE, X_SHAFT_SPEED, X_STEP, X_TIME, X_TORQUE_COUNT, X_TORQUE_SUM,
)
from twin.kernels.tribology import contact_tribology


# Below this entrainment speed [m/s] the rolling resistance (applied as (F_R / u) times the
# entrainment vector) turns into a bounded viscous drag, F_R / 0.01 N s/m at most, instead of a
# force of fixed size along an undefined direction; dividing by the actual u there made a
# damper stiff enough to destabilise the explicit integration (seen at 1 rad/s).
ROLLING_REGULARISATION_SPEED = 0.01


@njit(**JIT)
def compute_accelerations(p, groove, tr, sp, scal, bx, bv, bw, ba, balpha, rx, rv, ra, tang,
                          cont, cage_load, rel, geo, tribology_now):
    """Forces and torques of every contact at the current positions -> accelerations of the
    balls (seed 000 eq. 9), the inner ring (translation) and the cage (rotation). The geometry
    of the ball-raceway contacts c = 2 ball + race runs as one vectorised pass; the
    tribology of loaded contacts is refreshed when `tribology_now` (or when a contact closes).
    `rel` (3, 2Z) and `geo` (6, 2Z) are scratch arrays. Returns a status."""
    z = bx.shape[0]
    rb = p[P_BALL_RADIUS]
    m = p[P_BALL_MASS]
    inertia = p[P_BALL_INERTIA]
    kt_ratio = p[P_KT_RATIO]
    ct_ratio = p[P_CT_RATIO]
    tangent_mass = p[P_BALL_REDUCED_TANGENT_MASS]
    friction_model = int(p[P_FRICTION_MODEL])
    rolling_on = p[P_ROLLING] != 0.0
    roughness = p[P_ROUGHNESS]
    ring_speed = scal[X_SHAFT_SPEED]
    cage_speed = scal[X_CAGE_SPEED]
    eta = sp[S_VISCOSITY]
    dt = p[P_DT]
    alpha_e = p[P_ALPHA_E]
    # geometry of every ball-raceway contact at once (c = 2 j + r; r = 0 inner ring, 1 outer)
    for j in range(z):
        rel[0, 2 * j] = bx[j, 0] - rx[0]
        rel[1, 2 * j] = bx[j, 1] - rx[1]
        rel[2, 2 * j] = bx[j, 2] - rx[2]
        rel[0, 2 * j + 1] = bx[j, 0]
        rel[1, 2 * j + 1] = bx[j, 1]
        rel[2, 2 * j + 1] = bx[j, 2]
    raceway_geometry(rel, groove, geo)
    max_pen = scal[X_MAX_PENETRATION]
    ring_fx = 0.0
    ring_fy = 0.0
    ring_fz = 0.0
    ring_tz = 0.0
    for j in range(z):
        x0 = bx[j, 0]
        x1 = bx[j, 1]
        v0 = bv[j, 0]
        v1 = bv[j, 1]
        v2 = bv[j, 2]
        w0 = bw[j, 0]
        w1 = bw[j, 1]
        w2 = bw[j, 2]
        rho2 = x0 * x0 + x1 * x1
        orbital = (x0 * v1 - x1 * v0) / rho2 if rho2 > 0.0 else 0.0
        fx = 0.0
        fy = 0.0
        fz = 0.0
        tx = 0.0
        ty = 0.0
        tz = 0.0
        for r in range(2):
            c = 2 * j + r
            delta = geo[0, c]
            if delta <= 0.0:
                if cont[C_LAMBDA, c] != -1.0 or cont[C_LOAD, c] != 0.0:
                    for k in range(N_CONTACT):
                        cont[k, c] = 0.0
                    cont[C_LAMBDA, c] = -1.0
                    cont[C_H_MIN, c] = -1.0
                    cont[C_H_C, c] = -1.0
                    tang[0, c] = 0.0
                    tang[1, c] = 0.0
                    tang[2, c] = 0.0
                continue
            if delta > max_pen:
                max_pen = delta
            if r == 0:
                ovx, ovy, ovz, spin = rv[0], rv[1], rv[2], ring_speed
            else:
                ovx, ovy, ovz, spin = 0.0, 0.0, 0.0, 0.0
            nx = geo[1, c]
            ny = geo[2, c]
            nz = geo[3, c]
            q_el = geo[5, c]
            qx = rel[0, c] + rb * nx
            qy = rel[1, c] + rb * ny
            # seed 000 eq. 8: kinematics, normal and tangential laws; seed 001 rolling resistance
            slip_x, slip_y, slip_z, ex, ey, ez = contact_slip(
                rb, nx, ny, nz, x0, x1, qx, qy, v0, v1, v2, w0, w1, w2, ovx, ovy, ovz, spin, orbital)
            fn = normal_force_n(q_el, cont[C_LAMBDA, c], cont[C_FLUID_DAMPING, c], alpha_e,
                                (v0 - ovx) * nx + (v1 - ovy) * ny + (v2 - ovz) * nz)
            kt = kt_ratio * 1.5 * groove[3, c] * geo[4, c]
            ftx, fty, ftz, xi0, xi1, xi2 = tangential_force(
                tang[0, c], tang[1, c], tang[2, c], nx, ny, nz, slip_x, slip_y, slip_z, dt, kt,
                cont[C_TANGENT_DAMPING, c], cont[C_MU, c] * fn)
            tang[0, c] = xi0
            tang[1, c] = xi1
            tang[2, c] = xi2
            roll = cont[C_ROLLING_PER_SPEED, c]
            mp = pivoting_moment_signed(cont[C_SPIN_MOMENT, c], w0, w1, w2, nx, ny, nz, spin)
            cfx = -fn * nx + ftx + roll * ex
            cfy = -fn * ny + fty + roll * ey
            cfz = -fn * nz + ftz + roll * ez
            fx += cfx
            fy += cfy
            fz += cfz
            tx += rb * (ny * ftz - nz * fty) + mp * nx
            ty += rb * (nz * ftx - nx * ftz) + mp * ny
            tz += rb * (nx * fty - ny * ftx) + mp * nz
            if r == 0:
                # reaction on the inner ring: -F at the contact point and -M, about its axis
                ring_fx -= cfx
                ring_fy -= cfy
                ring_fz -= cfz
                ring_tz += -(qx * cfy - qy * cfx) - mp * nz
            cont[C_LOAD, c] = q_el
            if tribology_now or cont[C_LAMBDA, c] < 0.0:
                u2 = ex * ex + ey * ey + ez * ez
                u = math.sqrt(u2)
                tri = contact_tribology(
                    q_el, u, eta, roughness, tr[r, 0], tr[r, 1], tr[r, 2], tr[r, 3], tr[r, 4],
                    tr[r, 5], tr[r, 6], tr[r, 7], tr[r, 8], tr[r, 9], tr[r, 10], tr[r, 11],
                    tr[r, 12], tr[r, 13], tr[r, 14], friction_model, rolling_on)
                cont[C_H_MIN, c] = tri[0]
                cont[C_H_C, c] = tri[1]
                cont[C_LAMBDA, c] = tri[2]
                cont[C_REGIME, c] = tri[3]
                cont[C_MU, c] = tri[4]
                cont[C_SEMI_MAJOR, c] = tri[5]
                cont[C_SEMI_MINOR, c] = tri[6]
                cont[C_FLUID_DAMPING, c] = tri[7]
                cont[C_ROLLING_FORCE, c] = tri[8]
                cont[C_ROLLING_PER_SPEED, c] = tri[8] / max(u, ROLLING_REGULARISATION_SPEED)
                cont[C_SPIN_MOMENT, c] = tri[9]
                cont[C_TANGENT_DAMPING, c] = ct_ratio * 2.0 * math.sqrt(kt * tangent_mass)
                cont[C_ENTRAINMENT, c] = u
                cont[C_SRR, c] = (slip_x * ex + slip_y * ey + slip_z * ez) / u2 if u2 > 0.0 else 0.0
                cont[C_PENETRATION, c] = delta
                cont[C_NX, c] = nx
                cont[C_NY, c] = ny
                cont[C_NZ, c] = nz
        ba[j, 0] = fx
        ba[j, 1] = fy
        ba[j, 2] = fz
        balpha[j, 0] = tx / inertia
        balpha[j, 1] = ty / inertia
        balpha[j, 2] = tz / inertia
    scal[X_MAX_PENETRATION] = max_pen
    # cage elements: element e sits at theta + (e + 1/2) step; rotate a unit vector along
    rc = p[P_CAGE_RADIUS]
    s_cage = p[P_CAGE_CONTACT_DISTANCE]
    k_cage = p[P_CAGE_STIFFNESS]
    m_cage = p[P_CAGE_REDUCED_MASS]
    step_angle = 2.0 * math.pi / z
    c_step = math.cos(step_angle)
    s_step = math.sin(step_angle)
    theta = scal[X_CAGE_ANGLE] - 0.5 * step_angle  # element j - 1 of ball 0
    prev_c = math.cos(theta)
    prev_s = math.sin(theta)
    first_c = prev_c
    first_s = prev_s
    cage_tz = 0.0
    for j in range(z):
        fx = ba[j, 0]
        fy = ba[j, 1]
        fz = ba[j, 2]
        next_c = prev_c * c_step - prev_s * s_step
        next_s = prev_s * c_step + prev_c * s_step
        if j == z - 1:
            next_c = first_c
            next_s = first_s
        for slot in range(2):
            ex = rc * (next_c if slot == 0 else prev_c)
            ey = rc * (next_s if slot == 0 else prev_s)
            f, nx, ny, nz = cage_contact(bx[j, 0], bx[j, 1], bx[j, 2], bv[j, 0], bv[j, 1],
                                         bv[j, 2], ex, ey, cage_speed, s_cage, k_cage, m_cage)
            cage_load[j, slot] = f
            fx += f * nx
            fy += f * ny
            fz += f * nz
            cage_tz -= ex * f * ny - ey * f * nx
        prev_c = next_c
        prev_s = next_s
        ba[j, 0] = fx / m
        ba[j, 1] = fy / m
        ba[j, 2] = fz / m
    mr = p[P_RING_MASS]
    ra[0] = (ring_fx + sp[S_RADIAL_LOAD]) / mr
    ra[1] = ring_fy / mr
    ra[2] = (ring_fz + sp[S_AXIAL_LOAD]) / mr
    scal[X_DRIVE_TORQUE] = -ring_tz
    scal[X_CAGE_TORQUE] = cage_tz
    if not (math.isfinite(ra[0]) and math.isfinite(ra[1]) and math.isfinite(ra[2])
            and math.isfinite(cage_tz) and math.isfinite(ring_tz)):
        return STATUS_NOT_FINITE
    if max_pen > p[P_MAX_PENETRATION]:
        return STATUS_PENETRATION
    return STATUS_OK


@njit(**JIT)
def step_n(p, groove, tr, sp, scal, bx, bv, bw, ba, balpha, rx, rv, ra, tang, cont, cage_load,
           n):
    """Advance n steps of dt (seed 000 eq. 10, velocity-Verlet; velocity-dependent forces use the
    half-step velocity). The shaft speed moves towards its setpoint at the ramp rate; the torque
    the shaft supplies is accumulated for averaging. Returns (status, steps done)."""
    z = bx.shape[0]
    dt = p[P_DT]
    half = 0.5 * dt
    cage_inertia = p[P_CAGE_INERTIA]
    substeps = int(p[P_SUBSTEPS])
    ramp = p[P_RAMP] * dt
    rel = np.empty((3, 2 * z))
    geo = np.empty((6, 2 * z))
    # leapfrog form of velocity-Verlet: the closing half kick of one step and the opening half
    # kick of the next are one full kick; the state holds full-step velocities between frames
    status = STATUS_OK
    done = 0
    for it in range(n):
        kick = half if it == 0 else dt
        for j in range(z):
            for k in range(3):
                bv[j, k] += kick * ba[j, k]
                bw[j, k] += kick * balpha[j, k]
                bx[j, k] += dt * bv[j, k]
        for k in range(3):
            rv[k] += kick * ra[k]
            rx[k] += dt * rv[k]
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
        status = compute_accelerations(p, groove, tr, sp, scal, bx, bv, bw, ba, balpha, rx, rv, ra,
                                       tang, cont, cage_load, rel, geo, step % substeps == 0)
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
    scal[X_CAGE_SPEED] += half * scal[X_CAGE_TORQUE] / cage_inertia
    return status, done


@njit(**JIT)
def evaluate(p, groove, tr, sp, scal, bx, bv, bw, ba, balpha, rx, rv, ra, tang, cont, cage_load):
    """Contact forces, tribology and accelerations at the current state without advancing time
    (used after a warm start). Returns the status."""
    z = bx.shape[0]
    rel = np.empty((3, 2 * z))
    geo = np.empty((6, 2 * z))
    return compute_accelerations(p, groove, tr, sp, scal, bx, bv, bw, ba, balpha, rx, rv, ra, tang,
                                 cont, cage_load, rel, geo, True)
