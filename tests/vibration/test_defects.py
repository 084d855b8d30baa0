"""Local defects (twin.vibration.defects): validation, depth profile, quaternions."""

import math

import numpy as np
import pytest
from numba import njit
from pydantic import ValidationError

from twin import catalog
from twin.kernels import layout as L
from twin.model import make_model
from twin.vibration.defect_frequencies import bearing_defect_frequencies
from twin.vibration.defects import (
    OuterRaceSpall,
    contact_defect_drop_m,
    defect_row,
    edge_drop_m,
    pit_drop_m,
    pit_load_loss,
    quat_integrate,
    quat_rotate,
    race_limits,
    validate_defect,
    validate_defects,
)

SPEC = catalog.bearing("6208")
G = SPEC.geometry
MODEL = make_model(SPEC)
RB = G.ball_radius_m
RX_IN, RX_OUT = MODEL.race_params[0, L.R_RX], MODEL.race_params[1, L.R_RX]
# A contact far stiffer than any pit is deep (1 m of deflection) with a tiny ellipse (1 um across):
# the pit covers the ellipse across and the drop is the rolling-direction law alone.
DEEP, TINY = 1.0, 1e-6


# ---- depth profile ---------------------------------------------------------------------------
@pytest.mark.parametrize("width, depth", [(1e-3, 1e-3), (2e-3, 1e-3), (3e-3, 50e-6), (0.3e-3, 1e-6)])
def test_flat_race_centre_drop_is_sawalhi_randall(width, depth):
    """Flat raceway (relative radius = ball radius), long across: at the spall centre
    h_eff = min(depth, Rb - sqrt(Rb^2 - (w/2)^2)) (Sawalhi & Randall 2008 Part I sec. 4.1), exactly."""
    expected = min(depth, RB - math.sqrt(RB**2 - (width / 2) ** 2))
    assert pit_drop_m(0.0, 0.0, width / 2, 0.5, depth, 0.0, RB, DEEP, TINY) == pytest.approx(expected, rel=1e-10)


def _exact_outer(w, ro):
    """Exact drop of a ball (Rb) inside a concave circle (Ro) over a pit with edges at +-w/2 of arc."""
    th = w / (2 * ro)
    return ro * math.cos(th) - ro + RB - math.sqrt(RB**2 - (ro * math.sin(th)) ** 2)


def _exact_inner(w, ri):
    th = w / (2 * ri)
    return ri + RB - ri * math.cos(th) - math.sqrt(RB**2 - (ri * math.sin(th)) ** 2)


@pytest.mark.parametrize("width, tol", [(0.5e-3, 5e-4), (1e-3, 2e-3), (2e-3, 7e-3), (4e-3, 0.03)])
def test_curved_races_follow_the_relative_radius(width, tol):
    """On the curved 6208 races the drop at the centre of a deep, long spall matches the exact
    circle-circle geometry (measured: 0.03 % at 0.5 mm width, 0.6 % at 2 mm, 2.4 % at 4 mm: the law
    is second order in w / R) with the engine's R_RX (1/Rx = 1/Rb -+ 1/R race): the concave
    outer race curves up to meet the ball (it falls less deep than on a flat race), the convex
    inner race curves away (deeper)."""
    ro = G.outer_raceway_radius_m
    ri = G.inner_raceway_radius_m
    out = pit_drop_m(0.0, 0.0, width / 2, 0.5, 1.0, 0.0, RX_OUT, DEEP, TINY)
    inn = pit_drop_m(0.0, 0.0, width / 2, 0.5, 1.0, 0.0, RX_IN, DEEP, TINY)
    assert out == pytest.approx(_exact_outer(width, ro), rel=tol)
    assert inn == pytest.approx(_exact_inner(width, ri), rel=tol)
    flat = RB - math.sqrt(RB**2 - (width / 2) ** 2)
    assert out < flat < inn


def _hertz_strip_fraction(lo, hi, a, b, n=4001):
    """Fraction of the load of a Hertz ellipse (semi-axes a across, b along) carried in the strip
    lo <= y <= hi: the elliptic pressure p0 sqrt(1 - x^2/b^2 - y^2/a^2) integrated on a grid."""
    y = np.linspace(-a, a, n)
    x = np.linspace(-b, b, n)
    yy, xx = np.meshgrid(y, x, indexing="ij")
    p = np.sqrt(np.clip(1.0 - (xx / b) ** 2 - (yy / a) ** 2, 0.0, None))
    inside = (yy >= lo) & (yy <= hi)
    return float((p * inside).sum() / p.sum())


@pytest.mark.parametrize("half_length, offset", [(0.089e-3, 0.0), (0.089e-3, 0.2e-3), (0.2e-3, -0.1e-3)])
def test_deep_pit_narrower_than_the_ellipse_removes_the_hertz_load_of_its_strip(half_length, offset):
    """A pit deeper than the contact's interference and narrower across than its ellipse (CWRU's
    0.178 mm pit under a 0.36 mm semi-major axis): the contact keeps the Hertz pressure outside the
    pit's strip. lambda = 3/2 (l/a) - 1/2 (l/a)^3 for a centred strip (the integral of
    1 - y^2/a^2), and in general the share of the elliptic Hertz pressure (Hertz 1882; Johnson,
    Contact Mechanics, eq. 3.63) over the strip, integrated here independently on a 4001^2 grid
    (agreement within 2e-3, the grid's error at the ellipse's edge)."""
    a, b = 0.36e-3, 0.038e-3
    lost = pit_load_loss(0.0, offset, 1e-3, half_length, 1e-3, 0.0, RX_IN, 1e-6, a)
    expected = _hertz_strip_fraction(-offset - half_length, -offset + half_length, a, b)
    assert lost == pytest.approx(expected, abs=2e-3)
    if offset == 0.0:
        r = half_length / a
        assert lost == pytest.approx(1.5 * r - 0.5 * r**3, rel=1e-12)


@pytest.mark.parametrize("ratio", [0.1, 0.5, 0.9, 1.5])
def test_pit_across_the_whole_ellipse_is_sawalhi_randall_drop(ratio):
    """A pit longer across than the ellipse: every slice loses h, the load is K (delta - h)^1.5
    (Sawalhi & Randall 2008 Part I sec. 4.1: the drop taken off the deflection), so
    1 - lambda = (1 - h/delta)^1.5 and the equivalent drop is min(delta, h), to 1e-12."""
    a, half_width = 0.3e-3, 1e-3
    h = edge_drop_m(half_width, 0.0, RX_OUT)
    delta = h / ratio
    lost = pit_load_loss(0.0, 0.0, half_width, 5e-3, 1.0, 0.0, RX_OUT, delta, a)
    assert 1.0 - lost == pytest.approx(max(0.0, 1.0 - ratio) ** 1.5, abs=1e-12)
    assert pit_drop_m(0.0, 0.0, half_width, 5e-3, 1.0, 0.0, RX_OUT, delta, a) == pytest.approx(min(delta, h), rel=1e-12)


def test_load_loss_grows_with_the_pit_and_vanishes_beside_it():
    """Monotonic in the pit's length across and in its depth below the interference; zero once the
    pit's strip lies beyond the ellipse (|v| >= a + l) or the contact is open (delta <= 0)."""
    a, delta = 0.36e-3, 0.84e-6
    lengths = [
        pit_load_loss(0.0, 0.0, 1e-3, hl, 1e-3, 0.0, RX_IN, delta, a) for hl in (0.05e-3, 0.1e-3, 0.2e-3, 0.4e-3)
    ]
    assert np.all(np.diff(lengths) > 0.0) and lengths[-1] == pytest.approx(1.0)
    depths = [pit_load_loss(0.0, 0.0, 1e-3, 0.089e-3, d, 0.0, RX_IN, delta, a) for d in (0.1e-6, 0.4e-6, 0.8e-6, 2e-6)]
    r = 0.089e-3 / a
    assert np.all(np.diff(depths) > 0.0) and depths[3] == pytest.approx(1.5 * r - 0.5 * r**3, rel=1e-12)
    assert pit_load_loss(0.0, a + 0.089e-3, 1e-3, 0.089e-3, 1e-3, 0.0, RX_IN, delta, a) == 0.0
    assert pit_load_loss(0.0, 0.0, 1e-3, 0.089e-3, 1e-3, 0.0, RX_IN, 0.0, a) == 0.0


def test_profile_shape_unloads_entering_and_closes_at_the_exit_edge():
    """Along a 2 mm wide, 20 um deep spall: zero outside, symmetric, equal to the one-edge law
    R - sqrt(R^2 - a^2) near each edge (a = distance from the edge), flat at the depth in the
    middle. The ball centre turns about the edge on a circle of radius R (R + r_e when rounded): the
    steepest slope, where the profile leaves the depth plateau, is sqrt(2 h / R), the radial
    velocity jump of the strike per unit rolling speed; a rounded edge (0.5 mm) starts the drop
    0.5 mm before the edge and lowers that slope by sqrt(R / (R + r_e)) (2 %)."""
    hw, depth = 1e-3, 20e-6
    u = np.linspace(-2e-3, 2e-3, 4001)
    sharp = np.array([pit_drop_m(x, 0.0, hw, 0.5, depth, 0.0, RX_OUT, DEEP, TINY) for x in u])
    assert np.all(sharp[np.abs(u) >= hw] == 0.0)
    assert sharp == pytest.approx(sharp[::-1], abs=1e-18)
    a = 0.1e-3
    assert pit_drop_m(hw - a, 0.0, hw, 0.5, depth, 0.0, RX_OUT, DEEP, TINY) == pytest.approx(
        RX_OUT - math.sqrt(RX_OUT**2 - a * a), rel=1e-12
    )
    assert sharp[2000] == pytest.approx(depth, rel=1e-9)
    r_e = 0.5e-3
    rounded = np.array([pit_drop_m(x, 0.0, hw, 0.5, depth, r_e, RX_OUT, DEEP, TINY) for x in u])
    assert rounded[np.searchsorted(u, -hw - 0.49e-3)] > 0.0
    assert rounded[np.searchsorted(u, -hw - 0.51e-3)] == 0.0
    slope = lambda h: np.max(np.abs(np.diff(h))) / (u[1] - u[0])  # noqa: E731
    assert slope(sharp) == pytest.approx(math.sqrt(2 * depth / RX_OUT), rel=0.01)
    assert slope(rounded) / slope(sharp) == pytest.approx(math.sqrt(RX_OUT / (RX_OUT + r_e)), rel=0.005)
    assert edge_drop_m(-1e-3, 0.0, RB) == 0.0


# ---- validation -------------------------------------------------------------------------------
def test_spall_within_the_bearing_is_accepted_and_row_is_built():
    d = validate_defect(
        {
            "kind": "outer",
            "azimuth_deg": 30.0,
            "width_m": 1e-3,
            "length_m": 4e-3,
            "depth_m": 50e-6,
            "edge_radius_m": 0.1e-3,
        },
        G,
    )
    row = defect_row(d, G)
    assert row[1] == pytest.approx(math.radians(30.0))
    assert row[6:10] == pytest.approx([0.5e-3, 2e-3, 50e-6, 0.1e-3])


@pytest.mark.parametrize(
    "data, field, limit",
    [
        ({"kind": "outer", "width_m": 0.03, "length_m": 1e-3, "depth_m": 1e-4}, "width_m", 2 * math.pi * 36.6e-3 / 9),
        (
            {"kind": "inner", "width_m": 1e-3, "length_m": 0.02, "depth_m": 1e-4},
            "length_m",
            2 * 6.552e-3 * math.asin(6.3 / 6.552),
        ),
        ({"kind": "outer", "width_m": 1e-3, "length_m": 1e-3, "depth_m": 4e-3}, "depth_m", 3.15e-3),
        ({"kind": "ball", "ball_index": 9, "width_m": 1e-3, "length_m": 1e-3, "depth_m": 1e-4}, "ball_index", 8),
        ({"kind": "ball", "width_m": 7e-3, "length_m": 1e-3, "depth_m": 1e-4}, "width_m", 6.3e-3),
    ],
)
def test_defect_larger_than_the_bearing_is_refused_naming_field_and_range(data, field, limit):
    with pytest.raises(ValidationError) as err:
        validate_defect(data, G)
    msg = str(err.value)
    assert field in msg and f"{limit:g}" in msg, msg


def test_negative_depth_and_oversized_edge_are_refused():
    with pytest.raises(ValidationError) as err:
        validate_defect({"kind": "outer", "width_m": 1e-3, "length_m": 1e-3, "depth_m": -1e-5}, G)
    assert err.value.errors()[0]["loc"][-1] == "depth_m"
    with pytest.raises(ValidationError, match="edge_radius_m"):
        OuterRaceSpall(width_m=1e-3, length_m=2e-3, depth_m=1e-5, edge_radius_m=0.6e-3)
    with pytest.raises(ValidationError) as err:
        validate_defects(
            [{"kind": "outer", "width_m": 1e-3, "length_m": 1e-3, "depth_m": 1e-5}, {"kind": "wear", "width_m": 1e-3}],
            G,
        )
    assert err.value.errors()[0]["loc"][0] == 1


def test_race_limits_of_the_6208():
    lim = race_limits(G, outer=True)
    assert lim["width_m"] == pytest.approx(2 * math.pi * 36.6e-3 / 9)
    assert lim["depth_m"] == pytest.approx(3.15e-3)


# ---- kernel-facing per-contact drop ----------------------------------------------------------------
def _drop(row, race, ball, azimuth, shaft_angle=0.0, nz=0.0, q=(1.0, 0.0, 0.0, 0.0), w=(0.0, 0.0, -950.0)):
    r = G.outer_raceway_radius_m if race == 1 else G.inner_raceway_radius_m
    px, py = G.pitch_radius_m * math.cos(azimuth), G.pitch_radius_m * math.sin(azimuth)
    sign = 1.0 if race == 1 else -1.0
    nx, ny = sign * math.cos(azimuth), sign * math.sin(azimuth)
    rx = RX_OUT if race == 1 else RX_IN
    return contact_defect_drop_m(
        row,
        race,
        ball,
        px,
        py,
        nx,
        ny,
        nz,
        w[0],
        w[1],
        w[2],
        shaft_angle,
        q[0],
        q[1],
        q[2],
        q[3],
        RB,
        r,
        G.outer_groove_radius_m,
        rx,
        DEEP,
        TINY,
    )


def test_race_spall_is_seen_only_by_its_race_at_its_azimuth():
    """Outer spall at 30 deg: full drop for a ball at 30 deg on the outer race, none on the inner
    race or 2 widths away; inner spall at 10 deg on the ring with the shaft at 20 deg sits at 30 deg."""
    spall = dict(width_m=2e-3, length_m=6e-3, depth_m=20e-6)
    outer = defect_row(validate_defect({"kind": "outer", "azimuth_deg": 30.0, **spall}, G), G)
    centre = pit_drop_m(0.0, 0.0, 1e-3, 3e-3, 20e-6, 0.0, RX_OUT, DEEP, TINY)
    assert centre > 0.0
    assert _drop(outer, 1, 3, math.radians(30.0)) == pytest.approx(centre, rel=1e-12)
    assert _drop(outer, 0, 3, math.radians(30.0)) == 0.0
    assert _drop(outer, 1, 3, math.radians(30.0) + 4e-3 / G.outer_raceway_radius_m) == 0.0
    assert _drop(outer, 1, 3, math.radians(30.0) - 2 * math.pi) == pytest.approx(centre, rel=1e-9)
    inner = defect_row(validate_defect({"kind": "inner", "ring_angle_deg": 10.0, **spall}, G), G)
    assert _drop(inner, 0, 0, math.radians(30.0), shaft_angle=math.radians(20.0)) == pytest.approx(
        pit_drop_m(0.0, 0.0, 1e-3, 3e-3, 20e-6, 0.0, RX_IN, DEEP, TINY), rel=1e-9
    )
    assert _drop(inner, 0, 0, math.radians(30.0)) == 0.0  # shaft at 0: the spall is at 10 deg


def test_ball_defect_is_seen_where_it_faces_the_contact():
    """Ball defect at body +x with the identity orientation: at the outer contact of a ball at
    azimuth 0 (normal +x) it opens the pit's centre drop; at the inner contact (normal -x) nothing;
    another ball nothing."""
    row = defect_row(
        validate_defect(
            {
                "kind": "ball",
                "ball_index": 2,
                "colatitude_deg": 90.0,
                "longitude_deg": 0.0,
                "width_m": 1.5e-3,
                "length_m": 3e-3,
                "depth_m": 30e-6,
            },
            G,
        ),
        G,
    )
    centre = pit_drop_m(0.0, 0.0, 0.75e-3, 1.5e-3, 30e-6, 0.0, RX_OUT, DEEP, TINY)
    assert centre > 0.0
    assert _drop(row, 1, 2, 0.0) == pytest.approx(centre, rel=1e-12)
    assert _drop(row, 0, 2, 0.0) == 0.0
    assert _drop(row, 1, 1, 0.0) == 0.0


# ---- quaternions ------------------------------------------------------------------------------------
def _rodrigues(v, axis, angle):
    k = np.asarray(axis) / np.linalg.norm(axis)
    v = np.asarray(v)
    return v * math.cos(angle) + np.cross(k, v) * math.sin(angle) + k * (k @ v) * (1 - math.cos(angle))


def test_quat_rotate_is_the_rotation_it_encodes():
    rng = np.random.default_rng(3)
    for _ in range(20):
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        angle = rng.uniform(-math.pi, math.pi)
        q = (math.cos(angle / 2), *(math.sin(angle / 2) * axis))
        v = rng.normal(size=3)
        assert quat_rotate(*q, *v) == pytest.approx(_rodrigues(v, axis, angle), abs=1e-14)


@njit
def _spin(q, w, dt, n):
    for _ in range(n):
        quat_integrate(q, w[0], w[1], w[2], dt)


def test_quat_integrate_is_exact_for_constant_omega_and_stays_unit():
    """1e5 steps of 1 us at |omega| = 952 rad/s (the 6208 ball at 500 rad/s) about an oblique axis:
    the body point is rotated by |omega| t to 1e-9 and |q| = 1 to 1e-12."""
    w = np.array([100.0, -300.0, 900.0])
    q = np.array([1.0, 0.0, 0.0, 0.0])
    _spin(q, w, 1e-6, 100_000)
    got = quat_rotate(q[0], q[1], q[2], q[3], 0.3, 0.5, -0.2)
    assert got == pytest.approx(_rodrigues([0.3, 0.5, -0.2], w, np.linalg.norm(w) * 0.1), abs=1e-9)
    assert np.linalg.norm(q) == pytest.approx(1.0, abs=1e-12)


@njit
def _roll_ball(row, n, dt, w_cage, w_ball, pitch, rb, ro, ri, rg, rx_o, rx_i, hits):
    """Pure rolling of ball 0 (outer race fixed): orbit at w_cage, world spin w_ball about +z;
    record for each step whether the defect opens a drop at the outer (hits[k, 1]) / inner
    (hits[k, 0]) contact."""
    q = np.array([1.0, 0.0, 0.0, 0.0])
    for k in range(n):
        phi = w_cage * (k * dt)
        c, s = math.cos(phi), math.sin(phi)
        px, py = pitch * c, pitch * s
        hits[k, 1] = contact_defect_drop_m(
            row, 1, 0, px, py, c, s, 0.0, 0.0, 0.0, w_ball, 0.0, q[0], q[1], q[2], q[3], rb, ro, rg, rx_o, 1.0, 1e-6
        )
        hits[k, 0] = contact_defect_drop_m(
            row, 0, 0, px, py, -c, -s, 0.0, 0.0, 0.0, w_ball, 0.0, q[0], q[1], q[2], q[3], rb, ri, rg, rx_i, 1.0, 1e-6
        )
        quat_integrate(q, 0.0, 0.0, w_ball, dt)


def test_ball_defect_meets_the_races_twice_per_ball_revolution():
    """6208 at 500 rad/s, pure rolling (outer race fixed: ball world spin -w_cage d_m / (2 Rb)),
    quaternion integrated at dt = 1 us for 50 ms: a defect on the ball's rolling equator opens the
    outer and the inner contact alternately, and the encounters come at 2 x BSF (Randall & Antoni
    2011 eq. 4) within 0.2 %."""
    shaft = 500.0
    freq = bearing_defect_frequencies(G, shaft)
    w_cage = 2 * math.pi * freq.ftf_hz
    w_ball = -w_cage * G.pitch_radius_m / RB
    row = defect_row(
        validate_defect(
            {
                "kind": "ball",
                "colatitude_deg": 90.0,
                "longitude_deg": 0.0,
                "width_m": 1e-3,
                "length_m": 2e-3,
                "depth_m": 20e-6,
            },
            G,
        ),
        G,
    )
    dt, n = 1e-6, 50_000
    hits = np.zeros((n, 2))
    _roll_ball(
        row,
        n,
        dt,
        w_cage,
        w_ball,
        G.pitch_radius_m,
        RB,
        G.outer_raceway_radius_m,
        G.inner_raceway_radius_m,
        G.outer_groove_radius_m,
        RX_OUT,
        RX_IN,
        hits,
    )
    events = []
    for race in (0, 1):
        on = hits[:, race] > 0.0
        starts = np.flatnonzero(on[1:] & ~on[:-1]) + 1
        ends = np.flatnonzero(~on[1:] & on[:-1]) + 1
        for s in starts:
            e = ends[ends > s]
            if e.size:
                events.append((0.5 * (s + e[0]) * dt, race))
    events.sort()
    times = np.array([t for t, _ in events])
    races = [r for _, r in events]
    assert all(races[i] != races[i + 1] for i in range(len(races) - 1))  # alternating races
    rate = (len(times) - 1) / (times[-1] - times[0])
    assert rate == pytest.approx(freq.two_bsf_hz, rel=2e-3)
    assert len(times) >= 17  # 50 ms x 366 Hz


def test_wrap_angle():
    from twin.vibration.defects import wrap_angle

    for a, w in [
        (0.0, 0.0),
        (math.pi, math.pi),
        (-math.pi, math.pi),
        (3 * math.pi / 2, -math.pi / 2),
        (-7.0, -7.0 + 2 * math.pi),
        (20.0, 20.0 - 6 * math.pi),
    ]:
        assert wrap_angle(a) == pytest.approx(w, abs=1e-12)
