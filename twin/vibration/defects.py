"""Local defects: outer-race spall, inner-race spall, ball defect; the extra clearance they open
at a ball-raceway contact; unit quaternions for the ball orientation.

Defect geometry (every defect is a pit with straight edges): `width_m` along the rolling
direction, `length_m` across it, `depth_m`, and an edge radius (0 = sharp). Outer spall at a fixed
azimuth; inner spall at an angle fixed on the rotating inner ring; ball defect at a point fixed on
the ball, given in ball body coordinates.

Depth profile (`pit_drop_m`): a slice model of the Hertz contact over the pit.

Along the rolling direction (x) a ball cannot follow the pit's bottom: it bridges the pit and
drops until it touches an edge (Sawalhi & Randall 2008, "Simulating gear and bearing
interactions in the presence of faults, Part I", MSSP 22(8), sec. 4.1, their eq. for the
additional displacement of a ball over a spall; Harsha 2005, Chaos Solitons Fractals 26):

    h(u) = min(depth, R - sqrt(R^2 - s^2)),  s = distance of the contact centre inside the nearer edge,

with R the relative radius of curvature of the contact along the rolling direction (Harris'
curvature sum, the engine's R_RX: R = Rb on a flat race; ~1/(1/Rb - 1/Ro) on the concave outer
race, ~1/(1/Rb + 1/Ri) on the convex inner race). A rounded edge of radius r_e is a quarter circle
tangent to the surface and the wall: h = R + r_e - sqrt((R + r_e)^2 - (s + r_e)^2) for s > -r_e.

Across the track (y) the pit is often narrower than the contact ellipse: CWRU's 0.178 mm pits
against a semi-major axis of 0.3-0.6 mm. The ball then does not drop: the race under the rest of
the ellipse holds it, and the contact loses the load of the part of its area over the pit. The
contact is cut into slices across the track; a slice at y carries a line load proportional to its
interference delta (1 - y^2/a^2) (the Hertz pressure of the ellipse integrated along x is
proportional to 1 - y^2/a^2; the slices' sum is K delta^1.5 because a^2 is proportional to delta,
seed 000 eq. 2). The slices over the pit (|y - y_pit| < half length) lose h(u) of their
interference, so the contact keeps the load fraction

    F / (K delta^1.5) = 1 - lambda,   lambda = 3/4 integral over the pit's slices (s = y/a) of min(1 - s^2, h / delta)
    ds.

Two limits hold exactly: a pit longer across than the ellipse gives 1 - lambda = (1 - h/delta)^1.5,
the load K (delta - h)^1.5 of Sawalhi & Randall's drop; a pit deeper than the interference
(h >= delta) removes the Hertz load of its strip, 3/2 (l/a) - 1/2 (l/a)^3 for a centred strip of half
length l. The engine takes the equivalent clearance delta (1 - (1 - lambda)^(2/3)) off the lane's
deflection, so the Hertz load, the damping and the film see the reduced load. Entering the pit
the ball unloads; at the exit edge the clearance closes over sqrt(2 R h) of travel and the lost
load returns as a strike that excites the housing. Not modelled: the rounding of the edges
across the track, the tilt of the contact normal by the edge (as in Sawalhi & Randall), and the
elastic redistribution of pressure around the pit (the slices are independent).

Ball orientation: a unit quaternion q = (w, x, y, z) per ball maps body to world coordinates;
with the world-frame angular velocity omega (the engine's) q' = 1/2 omega (x) q (Hamilton
product; with a body-frame omega_b it is q' = 1/2 q (x) omega_b), integrated exactly for omega
constant over the step, q <- exp(omega dt / 2) (x) q, and renormalised (Shoemake 1985; any
rigid-body text).
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

import numpy as np
from numba import njit
from pydantic import BaseModel, ConfigDict, Field, TypeAdapter, ValidationInfo, model_validator

from twin.jit import JIT

_FROZEN = ConfigDict(frozen=True, extra="forbid", strict=True, allow_inf_nan=False)

# ---- defect row layout (one float64 row per active defect; `defect_row` builds it) ---------------
D_KIND = 0  # KIND_*
D_ANGLE = 1  # outer: azimuth [rad]; inner: angle on the ring from its reference mark [rad]
D_BALL = 2  # ball index (ball defect)
D_BODY_X = 3  # ball defect centre, unit vector in ball body coordinates
D_BODY_Y = 4
D_BODY_Z = 5
D_HALF_WIDTH = 6  # half width along the rolling direction [m]
D_HALF_LENGTH = 7  # half length across it [m]
D_DEPTH = 8  # [m]
D_EDGE_RADIUS = 9  # [m], 0 = sharp
D_CENTRE_NZ = 10  # race spall: axial component of the contact normal at the spall's centre line
# race spall, for the kernel's quick test of which balls can be over it (twin.kernels.vibration):
D_REACH_COS = 11  # cos of REACH_MARGIN x (half width + edge radius) / raceway radius (-2: every ball)
D_CENTRE_COS = 12  # cos, sin of the spall centre's angle (outer: azimuth; inner: on the ring)
D_CENTRE_SIN = 13
N_DEFECT_PARAMS = 14

# A race spall is looked at by the kernel only for balls within this factor of its angular reach
# (half width + edge radius over the raceway radius) of its centre: the drop is zero beyond the
# reach (`pit_drop_m`); the margin only saves the atan2 / asin of the far lanes.
REACH_MARGIN = 1.5

KIND_OUTER = 1
KIND_INNER = 2
KIND_BALL = 3

RACE_INNER = 0
RACE_OUTER = 1


class _Pit(BaseModel):
    model_config = _FROZEN

    width_m: float = Field(gt=0.0, le=0.05, description="Size along the rolling direction [m].")
    length_m: float = Field(gt=0.0, le=0.05, description="Size across the rolling direction [m].")
    depth_m: float = Field(gt=0.0, le=0.01, description="Depth [m].")
    edge_radius_m: float = Field(
        default=0.0, ge=0.0, le=0.01, description="Radius of the rounded edges [m]; 0 = sharp edges."
    )

    @model_validator(mode="after")
    def _edges(self) -> _Pit:
        half = 0.5 * min(self.width_m, self.length_m)
        if self.edge_radius_m > half:
            raise ValueError(
                f"edge_radius_m = {self.edge_radius_m:g} m: must be in [0, {half:g}] m "
                "(half the smaller of width_m and length_m)"
            )
        return self


class OuterRaceSpall(_Pit):
    """Spall on the stationary outer race at a fixed azimuth."""

    kind: Literal["outer"] = "outer"
    azimuth_deg: float = Field(
        default=0.0,
        ge=0.0,
        lt=360.0,
        description="Azimuth of the spall centre [deg] from +x (load direction) about +z.",
    )

    @model_validator(mode="after")
    def _fits(self, info: ValidationInfo) -> OuterRaceSpall:
        _check_race(self, info, outer=True)
        return self


class InnerRaceSpall(_Pit):
    """Spall on the rotating inner race at an angle fixed on the ring."""

    kind: Literal["inner"] = "inner"
    ring_angle_deg: float = Field(
        default=0.0,
        ge=0.0,
        lt=360.0,
        description="Angle of the spall centre on the inner ring [deg] from the ring's reference mark (the mark "
        "is at azimuth 0 when the shaft angle is 0), about +z.",
    )

    @model_validator(mode="after")
    def _fits(self, info: ValidationInfo) -> InnerRaceSpall:
        _check_race(self, info, outer=False)
        return self


class BallDefect(_Pit):
    """Pit on one ball at a point fixed on the ball (ball body coordinates: the world axes at the
    moment the defect is injected)."""

    kind: Literal["ball"] = "ball"
    ball_index: int = Field(default=0, ge=0, le=15, description="Which ball [-], 0 .. ball_count - 1.")
    colatitude_deg: float = Field(
        default=90.0, ge=0.0, le=180.0, description="Polar angle of the defect centre from the body +z axis [deg]."
    )
    longitude_deg: float = Field(
        default=0.0,
        ge=0.0,
        lt=360.0,
        description="Azimuth of the defect centre about the body +z axis from body +x [deg].",
    )

    @property
    def body_point(self) -> tuple[float, float, float]:
        """Unit vector to the defect centre in ball body coordinates."""
        t, p = math.radians(self.colatitude_deg), math.radians(self.longitude_deg)
        return (math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t))

    @model_validator(mode="after")
    def _fits(self, info: ValidationInfo) -> BallDefect:
        geometry = _geometry(info)
        if geometry is None:
            return self
        rb = geometry.ball_radius_m
        if self.ball_index >= geometry.ball_count:
            raise ValueError(
                f"ball_index = {self.ball_index}: must be in [0, {geometry.ball_count - 1}] "
                f"(the bearing has {geometry.ball_count} balls)"
            )
        for name in ("width_m", "length_m"):
            value = getattr(self, name)
            if value > rb:
                raise ValueError(
                    f"{name} = {value:g} m: must be in (0, {rb:g}] m for a local ball defect (at most the ball radius)"
                )
        _check_depth(self, rb)
        return self


Defect = Annotated[OuterRaceSpall | InnerRaceSpall | BallDefect, Field(discriminator="kind")]
_DEFECT = TypeAdapter(Defect)
_DEFECTS = TypeAdapter(list[Defect])


def _geometry(info: ValidationInfo):
    ctx = info.context if info is not None else None
    return ctx.get("geometry") if isinstance(ctx, dict) else None


def _check_depth(pit: _Pit, rb: float) -> None:
    limit = 0.5 * rb
    if pit.depth_m > limit:
        raise ValueError(
            f"depth_m = {pit.depth_m:g} m: must be in (0, {limit:g}] m (a quarter of the ball "
            "diameter: beyond it the defect is no longer a local pit under a ball)"
        )


def race_limits(geometry, outer: bool) -> dict[str, float]:
    """Largest spall on a raceway of this bearing [m]:

    - width_m (along the rolling direction) <= the ball spacing on the raceway, 2 pi R / Z (R the
      raceway radius at the contact): a local defect holds at most one ball; longer is an extended
      (distributed) fault;
    - length_m (across) <= the groove arc the ball can touch, 2 Rg asin(Rb / Rg);
    - depth_m <= Rb / 2."""
    rb = geometry.ball_radius_m
    radius = geometry.outer_raceway_radius_m if outer else geometry.inner_raceway_radius_m
    rg = geometry.outer_groove_radius_m if outer else geometry.inner_groove_radius_m
    return {
        "width_m": 2.0 * math.pi * radius / geometry.ball_count,
        "length_m": 2.0 * rg * math.asin(min(rb / rg, 1.0)),
        "depth_m": 0.5 * rb,
    }


def _check_race(pit: _Pit, info: ValidationInfo, outer: bool) -> None:
    geometry = _geometry(info)
    if geometry is None:
        return
    lim = race_limits(geometry, outer)
    race = "outer" if outer else "inner"
    why = {
        "width_m": f"the ball spacing on the {race} raceway, 2 pi R / Z",
        "length_m": f"the {race} groove arc the ball can touch, 2 Rg asin(Rb / Rg)",
    }
    for name, reason in why.items():
        value = getattr(pit, name)
        if value > lim[name]:
            raise ValueError(f"{name} = {value:g} m: must be in (0, {lim[name]:g}] m for this bearing ({reason})")
    _check_depth(pit, geometry.ball_radius_m)


def validate_defect(data, geometry):
    """A defect from plain data (dict with `kind` = outer | inner | ball), checked against the
    bearing's `twin.spec.Geometry`. Raises pydantic.ValidationError whose message names the field
    and its allowed range for this bearing (a spall larger than the raceway, a negative depth)."""
    return _DEFECT.validate_python(data, context={"geometry": geometry})


def validate_defects(data, geometry) -> list:
    """`validate_defect` for a list (error locations carry the list index)."""
    return _DEFECTS.validate_python(data, context={"geometry": geometry})


def defect_row(defect, geometry) -> np.ndarray:
    """The float64 row (D_* layout) the numba functions read for one defect of this bearing."""
    row = np.zeros(N_DEFECT_PARAMS)
    row[D_HALF_WIDTH] = 0.5 * defect.width_m
    row[D_HALF_LENGTH] = 0.5 * defect.length_m
    row[D_DEPTH] = defect.depth_m
    row[D_EDGE_RADIUS] = defect.edge_radius_m
    sin_a = math.sin(math.radians(geometry.nominal_contact_angle_deg))
    if defect.kind in ("outer", "inner"):
        radius = geometry.outer_raceway_radius_m if defect.kind == "outer" else geometry.inner_raceway_radius_m
        reach = REACH_MARGIN * (0.5 * defect.width_m + defect.edge_radius_m) / radius
        row[D_REACH_COS] = math.cos(reach) if reach < 0.5 * math.pi else -2.0
        angle = math.radians(defect.azimuth_deg if defect.kind == "outer" else defect.ring_angle_deg)
        row[D_CENTRE_COS], row[D_CENTRE_SIN] = math.cos(angle), math.sin(angle)
    if defect.kind == "outer":
        row[D_KIND] = KIND_OUTER
        row[D_ANGLE] = math.radians(defect.azimuth_deg)
        row[D_CENTRE_NZ] = sin_a  # outer normal (groove centre -> ball) points up under +z load
    elif defect.kind == "inner":
        row[D_KIND] = KIND_INNER
        row[D_ANGLE] = math.radians(defect.ring_angle_deg)
        row[D_CENTRE_NZ] = -sin_a
    else:
        row[D_KIND] = KIND_BALL
        row[D_BALL] = defect.ball_index
        row[D_BODY_X : D_BODY_Z + 1] = defect.body_point
    return row


# ---- depth profile -----------------------------------------------------------------------------
@njit(**JIT)
def edge_drop_m(inside_m, edge_radius_m, relative_radius_m):
    """Drop [m] of a body of relative radius R allowed by one straight edge at distance `inside_m`
    (> 0: the contact is inside the pit) with a rounded edge of radius r_e (module docstring):
    0 for inside <= -r_e, else R + r_e - sqrt((R + r_e)^2 - (inside + r_e)^2); unlimited (inf)
    once inside + r_e >= R + r_e (the body fits in the pit: only the depth stops it)."""
    if inside_m <= -edge_radius_m:
        return 0.0
    r = relative_radius_m + edge_radius_m
    t = inside_m + edge_radius_m
    if t >= r:
        return math.inf
    return t * t / (r + math.sqrt(r * r - t * t))  # = r - sqrt(r^2 - t^2), without cancellation


@njit(**JIT)
def _slice_load_integral(s, eta, s_star):
    """Integral of min(1 - t^2, eta) dt from -1 to s (|s| <= 1), with s_star = sqrt(1 - eta) the
    slice where 1 - t^2 = eta (0 when eta >= 1)."""
    g_low = -s_star + s_star**3 / 3.0 + 2.0 / 3.0  # integral of 1 - t^2 from -1 to -s_star
    if s <= -s_star:
        return s - s**3 / 3.0 + 2.0 / 3.0
    if s <= s_star:
        return g_low + eta * (s + s_star)
    return g_low + 2.0 * eta * s_star + (s - s**3 / 3.0) - (s_star - s_star**3 / 3.0)


@njit(**JIT)
def pit_load_loss(u_m, v_m, half_width_m, half_length_m, depth_m, edge_radius_m, rx_m, delta_m, semi_major_m):
    """Fraction lambda [-] of the Hertz load that a pit removes from a contact of deflection delta
    and semi-major axis a whose centre is at (u, v) [m] from the pit centre (u along the rolling
    direction, v across): the slice model of the module docstring, 0 <= lambda <= 1."""
    if delta_m <= 0.0 or semi_major_m <= 0.0:
        return 0.0
    h = min(depth_m, edge_drop_m(half_width_m - abs(u_m), edge_radius_m, rx_m))
    if h <= 0.0:
        return 0.0
    s1 = max(-1.0, (-v_m - half_length_m) / semi_major_m)
    s2 = min(1.0, (-v_m + half_length_m) / semi_major_m)
    if s2 <= s1:
        return 0.0
    eta = h / delta_m
    s_star = math.sqrt(1.0 - eta) if eta < 1.0 else 0.0
    lost = 0.75 * (_slice_load_integral(s2, eta, s_star) - _slice_load_integral(s1, eta, s_star))
    return min(1.0, max(0.0, lost))


@njit(**JIT)
def pit_drop_m(u_m, v_m, half_width_m, half_length_m, depth_m, edge_radius_m, rx_m, delta_m, semi_major_m):
    """Extra radial clearance [m] equivalent to the pit's load loss: delta (1 - (1 - lambda)^(2/3)),
    so that K (delta - drop)^1.5 is the load the contact keeps (`pit_load_loss`); 0 for an open
    contact. For a pit that covers the ellipse across it is min(delta, h(u)), Sawalhi & Randall's drop."""
    lost = pit_load_loss(u_m, v_m, half_width_m, half_length_m, depth_m, edge_radius_m, rx_m, delta_m, semi_major_m)
    if lost <= 0.0:
        return 0.0
    if lost >= 1.0:
        return delta_m
    return -delta_m * math.expm1(2.0 / 3.0 * math.log1p(-lost))  # no cancellation for small lambda


@njit(**JIT)
def wrap_angle(a):
    """Angle wrapped into (-pi, pi] [rad]."""
    return a - 2.0 * math.pi * math.ceil((a - math.pi) / (2.0 * math.pi))


@njit(**JIT)
def contact_defect_drop_m(
    d,
    race,
    ball,
    px,
    py,
    nx,
    ny,
    nz,
    wx,
    wy,
    wz,
    shaft_angle,
    qw,
    qx,
    qy,
    qz,
    rb,
    race_radius,
    groove_radius,
    rx,
    delta,
    semi_major,
):
    """Extra radial clearance [m] that the defect row `d` (D_* layout) opens at the contact of
    ball `ball` with race `race` (0 inner, 1 outer): the kernel subtracts it from the contact's
    deflection.

    (px, py): ball centre relative to the ring centre [m]; (nx, ny, nz): unit contact normal,
    groove-curvature centre -> ball centre (the contact point is at ball centre + Rb n);
    (wx, wy, wz): ball angular velocity, world frame [rad/s]; shaft_angle [rad]; q the ball's
    orientation quaternion; rb ball radius, race_radius raceway radius at the contact, groove_radius,
    rx the contact's relative radius of curvature along the rolling direction, delta its deflection
    and semi_major its ellipse's semi-major axis (across the rolling direction) [m].

    Race spall: u = race_radius wrap(ball azimuth - spall azimuth) (inner: spall azimuth = shaft
    angle + ring angle), v = groove_radius (asin nz - asin nz_centre). Ball defect: the defect
    centre p = q body q* in the world; u, v = Rb p.t, Rb p.b with t = (omega x n)/|omega x n| the
    rolling direction of the ball surface at the contact and b = n x t; zero when p.n <= 0."""
    kind = int(d[D_KIND])
    if kind == KIND_OUTER or kind == KIND_INNER:
        if (kind == KIND_OUTER) != (race == RACE_OUTER):
            return 0.0
        centre = d[D_ANGLE] + (shaft_angle if kind == KIND_INNER else 0.0)
        u = race_radius * wrap_angle(math.atan2(py, px) - centre)
        v = groove_radius * (math.asin(min(1.0, max(-1.0, nz))) - math.asin(d[D_CENTRE_NZ]))
        return pit_drop_m(u, v, d[D_HALF_WIDTH], d[D_HALF_LENGTH], d[D_DEPTH], d[D_EDGE_RADIUS], rx, delta, semi_major)
    if kind == KIND_BALL and ball == int(d[D_BALL]):
        ex, ey, ez = quat_rotate(qw, qx, qy, qz, d[D_BODY_X], d[D_BODY_Y], d[D_BODY_Z])
        cos_n = ex * nx + ey * ny + ez * nz
        if cos_n <= 0.0:
            return 0.0
        tx = wy * nz - wz * ny
        ty = wz * nx - wx * nz
        tz = wx * ny - wy * nx
        tn = math.sqrt(tx * tx + ty * ty + tz * tz)
        if tn > 0.0:
            tx /= tn
            ty /= tn
            tz /= tn
            bx = ny * tz - nz * ty
            by = nz * tx - nx * tz
            bz = nx * ty - ny * tx
            u = rb * (ex * tx + ey * ty + ez * tz)
            v = rb * (ex * bx + ey * by + ez * bz)
        else:  # ball not spinning: no rolling direction, measure the distance both ways
            dist = rb * math.sqrt(max(0.0, 1.0 - cos_n * cos_n))
            u = dist
            v = dist
        return pit_drop_m(u, v, d[D_HALF_WIDTH], d[D_HALF_LENGTH], d[D_DEPTH], d[D_EDGE_RADIUS], rx, delta, semi_major)
    return 0.0


# ---- unit quaternions (w, x, y, z), body -> world ---------------------------------------------------
@njit(**JIT)
def quat_multiply(aw, ax, ay, az, bw, bx, by, bz):
    """Hamilton product a (x) b."""
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


@njit(**JIT)
def quat_rotate(qw, qx, qy, qz, vx, vy, vz):
    """q v q* for a unit quaternion: a body vector in world coordinates (t = 2 q_v x v,
    v' = v + w t + q_v x t)."""
    tx = 2.0 * (qy * vz - qz * vy)
    ty = 2.0 * (qz * vx - qx * vz)
    tz = 2.0 * (qx * vy - qy * vx)
    return (vx + qw * tx + (qy * tz - qz * ty), vy + qw * ty + (qz * tx - qx * tz), vz + qw * tz + (qx * ty - qy * tx))


@njit(**JIT)
def quat_integrate(q, wx, wy, wz, dt):
    """Advance the unit quaternion q (array of 4, in place) by a world-frame angular velocity
    (wx, wy, wz) [rad/s] held over dt [s]: q <- exp(omega dt / 2) (x) q (exact for constant omega,
    the solution of q' = 1/2 omega (x) q), then renormalised."""
    w = math.sqrt(wx * wx + wy * wy + wz * wz)
    half = 0.5 * w * dt
    if half > 1e-12:
        s = math.sin(half) / w
        dw = math.cos(half)
    else:
        s = 0.5 * dt
        dw = 1.0
    rw, rx, ry, rz = quat_multiply(dw, s * wx, s * wy, s * wz, q[0], q[1], q[2], q[3])
    n = math.sqrt(rw * rw + rx * rx + ry * ry + rz * rz)
    q[0] = rw / n
    q[1] = rx / n
    q[2] = ry / n
    q[3] = rz / n
