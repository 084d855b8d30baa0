"""Kernel passes of condition monitoring: local defects in the contact geometry, the
outer ring's reaction that drives the housing, the ball orientations. Called by
`twin.kernels.step` (one function per pass; the housing and sensor steps themselves are
`twin.vibration.housing` and `twin.vibration.signal`).

- `apply_clearances`: between the geometry pass and the force pass, every active defect row
  (`twin.vibration.defects`, D_* layout) opens an extra radial clearance at the contacts it lies
  under (`contact_defect_drop_m`: Sawalhi & Randall 2008 Part I sec. 4.1 along the rolling
  direction, generalised to curved bodies, and the load of the ellipse's slices over the pit
  across it); the deepest drop of all defects is taken off the lane's deflection before the Hertz
  load (seed 000 eq. 2), so a ball entering a spall loses load and strikes its exit edge: the
  impulses come from the dynamics. With the surface profile on, the race profiles and ball sizes
  (`twin.vibration.surface`) add their signed clearance to the same row.
- `outer_ring_force`: the force of the balls on the outer ring (minus the sum of the outer
  contacts' forces on the balls), the excitation of the housing.
- `shift_frame`: the balls and the inner ring moved into (and back out of) the frame of the outer
  ring, which translates with the housing, around the force evaluation: the contact and cage
  kernels see positions and velocities relative to the outer ring, as with the rigid ring.
- `integrate_orientations`: the unit quaternions of the balls that carry a defect (world frame
  angular velocity at the half step, exact for a constant rate over the step: second order, like
  the leapfrog; a ball's body axes are the world axes when its defect is injected).
"""

import math

from numba import njit

from twin.jit import JIT, JIT_VECTOR
from twin.kernels.layout import (
    CW,
    G_DEFECT_DROP,
    G_DELTA,
    G_LOAD,
    G_NX,
    G_NY,
    G_NZ,
    G_SQRT_DELTA,
    K_PX,
    K_PY,
    K_WX,
    K_WY,
    K_WZ,
    M_STIFFNESS,
    N_VIB_PARAMS,
    O_FX,
    O_FY,
    O_FZ,
    P_PROFILE_ON,
    P_VIB,
    V_INNER_FOOTPRINT,
    V_INNER_GROOVE_RADIUS,
    V_INNER_RACEWAY_RADIUS,
    V_INNER_RX,
    V_OUTER_FOOTPRINT,
    V_OUTER_GROOVE_RADIUS,
    V_OUTER_RACEWAY_RADIUS,
    V_OUTER_RX,
    W_DEFECTS,
    W_ORIENTATION,
)
from twin.kernels.profile import profile_drops
from twin.vibration.defects import (
    D_BALL,
    D_CENTRE_COS,
    D_CENTRE_SIN,
    D_KIND,
    D_REACH_COS,
    KIND_BALL,
    KIND_INNER,
    KIND_OUTER,
    N_DEFECT_PARAMS,
    RACE_INNER,
    RACE_OUTER,
    contact_defect_drop_m,
    quat_integrate,
)

# Called every step: inlined at numba level (a call that passes arrays costs their reference
# counting, ~100 ns per step on the test machine for these passes); the rare ones stay calls.
JIT_INLINE = dict(JIT, inline="always")


@njit(**JIT)
def _lane_drop(defects, k, c, w, bq, shaft_angle, vp, rb):
    """Drop [m] of defect row k at lane c (contact_defect_drop_m with the lane's kinematics, its
    deflection and its ellipse's semi-major axis a = V_*_FOOTPRINT sqrt(delta))."""
    r = c & 1
    j = c >> 1
    outer = r == 1
    delta = w[G_DELTA * CW + c]
    if delta <= 0.0:
        return 0.0
    semi_major = (vp[V_OUTER_FOOTPRINT] if outer else vp[V_INNER_FOOTPRINT]) * math.sqrt(delta)
    return contact_defect_drop_m(
        defects[k],
        r,
        j,
        w[K_PX * CW + c],
        w[K_PY * CW + c],
        w[G_NX * CW + c],
        w[G_NY * CW + c],
        w[G_NZ * CW + c],
        w[K_WX * CW + c],
        w[K_WY * CW + c],
        w[K_WZ * CW + c],
        shaft_angle,
        bq[j, 0],
        bq[j, 1],
        bq[j, 2],
        bq[j, 3],
        rb,
        vp[V_OUTER_RACEWAY_RADIUS] if outer else vp[V_INNER_RACEWAY_RADIUS],
        vp[V_OUTER_GROOVE_RADIUS] if outer else vp[V_INNER_GROOVE_RADIUS],
        vp[V_OUTER_RX] if outer else vp[V_INNER_RX],
        delta,
        semi_major,
    )


@njit(**JIT_INLINE)
def defect_drops(w, nc, defects, bq, shaft_angle, vp, rb):
    """Row G_DEFECT_DROP of every lane: the largest extra clearance [m] any active defect row opens
    there (0 elsewhere); returns whether any lane has one. Race spalls visit the lanes of their race whose ball lies
    within the
    spall's reach (D_REACH_COS, twin.vibration.defects.REACH_MARGIN; a dot product, no root or
    angle); a ball defect the two lanes of its ball."""
    for c in range(nc):
        w[G_DEFECT_DROP * CW + c] = 0.0
    found = False
    for k in range(defects.shape[0]):
        kind = int(defects[k, D_KIND])
        if kind == KIND_BALL:
            j = int(defects[k, D_BALL])
            for c in range(2 * j, 2 * j + 2):
                if c < nc:
                    h = _lane_drop(defects, k, c, w, bq, shaft_angle, vp, rb)
                    w[G_DEFECT_DROP * CW + c] = max(w[G_DEFECT_DROP * CW + c], h)
                    found = found or h > 0.0
        elif kind == KIND_OUTER or kind == KIND_INNER:
            r = RACE_OUTER if kind == KIND_OUTER else RACE_INNER
            cos_reach = defects[k, D_REACH_COS]
            cx = defects[k, D_CENTRE_COS]
            cy = defects[k, D_CENTRE_SIN]
            if kind == KIND_INNER:  # the spall turns with the shaft
                cs = math.cos(shaft_angle)
                ss = math.sin(shaft_angle)
                cx, cy = cx * cs - cy * ss, cy * cs + cx * ss
            limit = cos_reach * cos_reach
            for c in range(r, nc, 2):
                px = w[K_PX * CW + c]
                py = w[K_PY * CW + c]
                dot = px * cx + py * cy
                # within the reach: cos(angle to the centre) >= cos_reach (>= 0 whenever it is used)
                if cos_reach >= 0.0 and (dot <= 0.0 or dot * dot < limit * (px * px + py * py)):
                    continue
                h = _lane_drop(defects, k, c, w, bq, shaft_angle, vp, rb)
                w[G_DEFECT_DROP * CW + c] = max(w[G_DEFECT_DROP * CW + c], h)
                found = found or h > 0.0
    return found


@njit(**JIT_VECTOR)
def subtract_drops(w, nc):
    """The drop taken off every lane's deflection and the Hertz load recomputed (seed 000 eq. 2,
    as `twin.kernels.contacts.raceway_geometry`; branch-free, a lane without drop is unchanged)."""
    for c in range(nc):
        delta = w[G_DELTA * CW + c] - w[G_DEFECT_DROP * CW + c]
        pos = max(delta, 0.0)
        sq = math.sqrt(pos)
        w[G_DELTA * CW + c] = delta
        w[G_SQRT_DELTA * CW + c] = sq
        w[G_LOAD * CW + c] = w[M_STIFFNESS * CW + c] * pos * sq


def defect_table(w, count):
    """The first `count` defect rows of the workspace (twin.kernels.layout.W_DEFECTS), a
    (count, N_DEFECT_PARAMS) view."""
    return w[W_DEFECTS : W_DEFECTS + count * N_DEFECT_PARAMS].reshape((count, N_DEFECT_PARAMS))


def orientations(w, z):
    """The balls' unit quaternions in the workspace (W_ORIENTATION), a (z, 4) view."""
    return w[W_ORIENTATION : W_ORIENTATION + 4 * z].reshape((z, 4))


defect_table = njit(**JIT_INLINE)(defect_table)
orientations = njit(**JIT_INLINE)(orientations)


@njit(**JIT_INLINE)
def apply_clearances(w, nc, count, shaft_angle, p, rb):
    """`defect_drops` of the `count` active defect rows of the workspace, plus, with the surface
    profile on (p[P_PROFILE_ON]), the race profiles and ball sizes (`twin.vibration.surface.
    profile_drops`); then, where anything opens or closes a clearance, `subtract_drops` (module
    docstring). Called only while a defect is active (X_DEFECT_COUNT > 0) or the profile is on."""
    defects = defect_table(w, count)
    bq = orientations(w, nc // 2)
    vp = p[P_VIB : P_VIB + N_VIB_PARAMS]
    found = defect_drops(w, nc, defects, bq, shaft_angle, vp, rb)
    if p[P_PROFILE_ON] != 0.0:
        profile_drops(w, nc, p, shaft_angle)
        found = True
    if found:
        subtract_drops(w, nc)


@njit(**JIT_INLINE)
def outer_ring_force(w, z):
    """(fx, fy, fz) [N]: force of the balls on the outer ring, minus the outer lanes' forces on
    the balls (lane 2 j + 1 of ball j)."""
    fx = 0.0
    fy = 0.0
    fz = 0.0
    for j in range(z):
        c = 2 * j + 1
        fx -= w[O_FX * CW + c]
        fy -= w[O_FY * CW + c]
        fz -= w[O_FZ * CW + c]
    return fx, fy, fz


@njit(**JIT_INLINE)
def shift_frame(bx, bv, rx, rv, hx, hv, sign):
    """Add sign x the outer ring's displacement hx[0:3] [m] and velocity hv[0:3] [m/s] to every
    ball's and the inner ring's position and velocity: sign = -1 before the force pass (positions
    and velocities relative to the outer ring, whose own lane velocity is then 0, as the gather of
    `twin.kernels.step.compute_accelerations` assumes), +1 after it (the forces do not depend on
    the frame; the round trip changes a coordinate by at most one rounding, ~1e-18 m).
    Inlined: called twice per step with the housing on."""
    h0 = sign * hx[0]
    h1 = sign * hx[1]
    h2 = sign * hx[2]
    u0 = sign * hv[0]
    u1 = sign * hv[1]
    u2 = sign * hv[2]
    for j in range(bx.shape[0]):
        bx[j, 0] += h0
        bx[j, 1] += h1
        bx[j, 2] += h2
        bv[j, 0] += u0
        bv[j, 1] += u1
        bv[j, 2] += u2
    rx[0] += h0
    rx[1] += h1
    rx[2] += h2
    rv[0] += u0
    rv[1] += u1
    rv[2] += u2


@njit(**JIT)
def has_ball_defect(defects):
    """Whether any active defect row is a ball defect (the orientations are then integrated)."""
    for k in range(defects.shape[0]):
        if int(defects[k, D_KIND]) == KIND_BALL:
            return True
    return False


@njit(**JIT_INLINE)
def integrate_orientations(bq, bw, defects, dt):
    """The unit quaternion bq[j] of every ball carrying a ball defect advanced by its world-frame
    angular velocity bw[j] [rad/s] over dt [s] (`twin.vibration.defects.quat_integrate`; the other
    balls' orientations are not needed, and cost ~60 ns per ball per step)."""
    for k in range(defects.shape[0]):
        if int(defects[k, D_KIND]) != KIND_BALL:
            continue
        j = int(defects[k, D_BALL])
        seen = False
        for e in range(k):  # a ball with two defects turns once
            if int(defects[e, D_KIND]) == KIND_BALL and int(defects[e, D_BALL]) == j:
                seen = True
        if not seen:
            quat_integrate(bq[j], bw[j, 0], bw[j, 1], bw[j, 2], dt)
