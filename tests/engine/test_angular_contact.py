"""Angular-contact 7208 family (7208 = B 40 deg, 7208AC 25 deg, 7208C 15 deg; seed 004's internal
geometry) against Jones' quasi-static solution (Jones 1960; Harris & Kotzalas, Rolling Bearing
Analysis, 5th ed., vol. 1 ch. 7-8 and vol. 2 ch. 3): under Fr = Fa = 3000 N and under pure axial
3000 N at 500 rad/s the DEM, after settling, carries every ball's load within 3 % of Qmax and the
loaded balls' contact angles within 0.5 deg of Jones' solution at the DEM's own ball azimuths,
and holds that state (the inner-ring displacement, averaged over one ball pass, drifts < 1 %
over 50 ms). Also seed 004 section 3.1's load parameter eps = (1 + delta_a tan(alpha) /
delta_r) / 2, and why its printed 2.46 is out of reach of this geometry."""

import math

import numpy as np
import pytest
from scipy import optimize

from twin import catalog
from twin.engine import Twin
from twin.kernels import layout as L
from twin.model import contact_constants, make_model
from twin.setpoint import Setpoint
from twin.spec import BearingSpec, ModelOptions
from twin.validation import analytic

SPEED = 500.0
SETTLE_S = 0.03
WINDOW_S = 0.05
SAMPLE_S = 1e-4
LOADED = 0.2  # contact angles are compared for balls carrying >= 20 % of Qmax (see below)
HEAVY = 0.6  # ... and held to 0.5 deg for balls carrying >= 60 % of Qmax


def _run(designation, radial, time_step):
    twin = Twin(
        designation,
        options=ModelOptions(time_step_s=time_step),
        setpoint=Setpoint(shaft_speed_rad_s=SPEED, radial_load_n=radial, axial_load_n=3000.0),
    )
    twin.advance(SETTLE_S)
    disp = []
    for _ in range(int(round(WINDOW_S / SAMPLE_S))):
        twin.advance(SAMPLE_S, frame_steps=100)
        disp.append(np.linalg.norm(twin.state.inner_ring_offset_m))
    snap = twin.snapshot()
    jones = analytic.jones_equilibrium(
        twin.model, radial, 3000.0, snap.shaft_speed_rad_s, azimuths_rad=twin.ball_azimuths_rad()
    )
    return twin, snap, jones, np.array(disp)


CASES = [(d, fr) for d in ("7208", "7208AC", "7208C") for fr in (3000.0, 0.0)]


@pytest.fixture(scope="module", params=CASES, ids=[f"{d}-Fr{int(fr)}" for d, fr in CASES])
def settled(request, time_step):
    return request.param, *_run(*request.param, time_step)


def test_catalog_7208_family_is_seed_004_geometry_at_catalog_angles():
    for name, angle in (("7208", 40.0), ("7208AC", 25.0), ("7208C", 15.0)):
        g = catalog.bearing(name).geometry
        assert (g.ball_count, g.cage_element_radius_m, g.ball_radius_m) == (13, 1.01e-3, 6.3e-3)
        assert g.nominal_contact_angle_deg == angle
        b = (g.inner_groove_radius_m + g.outer_groove_radius_m) / (2 * g.ball_radius_m) - 1.0
        assert b == pytest.approx(0.14, rel=1e-9)  # conformity B of seed 004 section 3.1
        assert g.inner_groove_radius_m / (2 * g.ball_radius_m) == pytest.approx(0.57, rel=1e-12)


def test_ball_loads_and_contact_angles_match_jones(settled, time_step):
    (name, radial), twin, snap, jones, _ = settled
    assert snap.status == "ok" and jones.converged
    qmax = jones.qmax_n
    qi = np.array([b.inner.load_n for b in snap.balls])
    qo = np.array([b.outer.load_n for b in snap.balls])
    assert np.max(np.abs(qi - jones.inner_load_n)) <= 0.03 * qmax
    assert np.max(np.abs(qo - jones.outer_load_n)) <= 0.03 * qmax
    # DEM angles: asin of the normal's axial component (the snapshot's contact_angle_rad)
    ai = np.degrees(np.abs([b.inner.contact_angle_rad for b in snap.balls]))
    ao = np.degrees(np.abs([b.outer.contact_angle_rad for b in snap.balls]))
    dev = np.maximum(np.abs(ai - np.degrees(jones.inner_angle_rad)), np.abs(ao - np.degrees(jones.outer_angle_rad)))
    q = jones.inner_load_n / qmax
    # The loaded balls' angles carry the bearing's load: within 0.5 deg of Jones (twin.analytic). A
    # lightly loaded ball's angle is set by a balance of a few newtons, and Jones' quasi-static,
    # frictionless solution has neither the ball's dynamics nor the contacts' traction: the DEM's
    # angles lag at the entry of the load zone (up to +1.0 / -0.9 deg inner / outer at 0.2-0.4
    # Qmax) and lead at its exit (-0.5 / +0.2 deg), the same at 1 us and at the auto step, and
    # cut to a fifth (0.2 deg) when the traction is cut
    # (test_angle_departure_from_jones_is_the_same_at_1us_and_auto): the traction Jones leaves
    # out, not a step error nor a geometry error, bounded here at 1.1 deg.
    loaded = q >= LOADED
    assert loaded.sum() >= 4  # 40 deg under Fr = Fa: eps = 0.42, four or five balls
    assert np.max(dev[q >= HEAVY], initial=0.0) <= 0.5
    assert np.max(dev[loaded]) <= 1.1
    # the twin follows the contact angle: every loaded contact's stiffness lane is K(alpha)
    rows = twin.state.contacts
    for c in range(2 * twin.model.ball_count):
        if rows[L.C_LOAD, c] > 0.0:
            assert rows[L.M_STIFFNESS, c] == pytest.approx(twin.model.stiffness_at(c % 2, rows[L.G_NZ, c]), rel=2e-3)


def _angle_departure_by_azimuth(time_step, bins_deg, limiting_shear_coefficient=None):
    """Mean DEM - Jones contact angle (inner, outer) [deg] of the 7208 B's balls under Fr = Fa =
    3000 N in azimuth bins, over 30 snapshots 0.1 ms apart (more than one ball pass)."""
    spec = catalog.bearing("7208")
    if limiting_shear_coefficient is not None:
        spec = BearingSpec.model_validate(
            {
                **spec.model_dump(),
                "lubricant": {**spec.lubricant.model_dump(), "limiting_shear_coefficient": limiting_shear_coefficient},
            }
        )
    twin = Twin(
        spec,
        options=ModelOptions(time_step_s=time_step),
        setpoint=Setpoint(shaft_speed_rad_s=SPEED, radial_load_n=3000.0, axial_load_n=3000.0),
    )
    twin.advance(SETTLE_S + WINDOW_S)
    rows = []
    for _ in range(30):
        twin.advance(SAMPLE_S, frame_steps=100)
        snap = twin.snapshot()
        az = twin.ball_azimuths_rad()
        jones = analytic.jones_equilibrium(twin.model, 3000.0, 3000.0, snap.shaft_speed_rad_s, azimuths_rad=az)
        ai = np.degrees(np.abs([b.inner.contact_angle_rad for b in snap.balls]))
        ao = np.degrees(np.abs([b.outer.contact_angle_rad for b in snap.balls]))
        for j, a in enumerate(np.degrees(np.angle(np.exp(1j * np.asarray(az))))):
            if jones.inner_load_n[j] >= LOADED * jones.qmax_n:
                rows.append(
                    (a, ai[j] - np.degrees(jones.inner_angle_rad[j]), ao[j] - np.degrees(jones.outer_angle_rad[j]))
                )
    rows = np.array(rows)
    idx = np.digitize(rows[:, 0], bins_deg)
    return np.array([rows[idx == k, 1:].mean(axis=0) for k in range(1, len(bins_deg))])


def test_angle_departure_from_jones_is_the_same_at_1us_and_auto():
    """The auto step changes no output beyond its tolerance, here on the one quantity where
    the DEM departs from Jones: the loaded balls' contact-angle departure, resolved by azimuth over
    the load zone (15 deg bins from -75 to +75 deg; measured: the two profiles agree within
    0.03 deg, the departure itself reaches 1.0 deg at the zone's entry), agrees within 0.1 deg."""
    bins = np.arange(-75.0, 76.0, 15.0)
    fine = _angle_departure_by_azimuth(1e-6, bins)
    auto = _angle_departure_by_azimuth("auto", bins)
    assert np.all(np.isfinite(fine)) and np.all(np.isfinite(auto))
    assert np.max(np.abs(auto - fine)) <= 0.1
    # and the departure is the load-zone lag described in test_ball_loads_and_contact_angles_match_jones:
    # positive inner / negative outer at the entry (-75..-45 deg), smaller and reversed at the exit
    assert fine[0, 0] > 0.5 and fine[0, 1] < -0.5
    assert fine[-1, 0] < 0.0 and fine[-1, 1] > 0.0
    # ... and it is the contacts' traction, which Jones' frictionless model leaves out: with the
    # film's limiting shear coefficient cut from 0.06 to 0.005 (the traction capacity of these
    # full-film contacts) the departure shrinks to a fifth: measured 0.22 / 0.20 deg inner / outer
    # in the entry bin against 1.02 / 0.86 deg, within 0.11 deg elsewhere
    low = _angle_departure_by_azimuth("auto", bins, limiting_shear_coefficient=0.005)
    assert np.max(np.abs(low)) <= 0.3
    assert np.max(np.abs(low[1:])) <= 0.15


def test_state_is_steady(settled):
    (name, radial), twin, snap, jones, disp = settled
    # ball-pass period Z * cage speed; a running mean over one period removes the ball-pass
    # vibration, the drift is the change of that mean over the 50 ms window
    period = 2 * math.pi / (twin.model.ball_count * abs(snap.cage_speed_rad_s))
    n = max(1, int(round(period / SAMPLE_S)))
    means = np.convolve(disp, np.ones(n) / n, mode="valid")
    assert abs(means[-1] - means[0]) <= 0.01 * disp.mean()
    assert np.ptp(means) <= 0.02 * disp.mean()
    # and the mean sits on Jones' displacement
    assert disp.mean() == pytest.approx(np.linalg.norm(jones.ring_displacement_m), rel=0.03)


def test_load_parameter_of_seed_004(settled):
    (name, radial), twin, snap, jones, _ = settled
    if radial == 0.0:
        assert all(b.inner.load_n > 0 for b in snap.balls)  # pure axial: every ball loaded
        return
    dx, dy, dz = snap.inner_ring_displacement_m
    eps = 0.5 * (1.0 + dz * math.tan(twin.model.contact_angle_rad) / math.hypot(dx, dy))
    expected = {"7208": 0.415, "7208AC": 1.151, "7208C": 1.563}[name]  # Jones, exact Hertz
    assert jones.epsilon == pytest.approx(expected, abs=0.005)
    assert eps == pytest.approx(expected, abs=0.05)


def test_eps_2_46_of_seed_004_is_out_of_reach_of_its_geometry():
    # seed 004 section 3.1 prints eps = 2.46 under Fr = Fa = 3000 N; with its conformity
    # B = 0.14 Jones' solution peaks near 8-9 deg nominal contact angle at 1.76 and falls to 1.56
    # (15 deg), 1.15 (25 deg), 0.42 (40 deg): the loaded angle grows under the axial load
    base = catalog.bearing("7208")
    eps = {}
    for angle in (5.0, 8.5, 12.0, 15.0, 25.0, 40.0):
        g = base.geometry.model_copy(update={"nominal_contact_angle_deg": angle})
        spec = BearingSpec.model_validate({**base.model_dump(), "geometry": g.model_dump()})
        eps[angle] = analytic.jones_equilibrium(make_model(spec), 3000.0, 3000.0, SPEED).epsilon
    assert max(eps.values()) == pytest.approx(1.76, abs=0.01)
    assert max(eps.values()) < 2.46 / 1.3
    assert eps[15.0] == pytest.approx(1.563, abs=0.005)


def test_jones_static_radial_equals_the_rigid_ring_solution():
    # without speed the Jones solution of the 6208 (deep groove, nominal angle 0) is seed 000
    # Appendix A's rigid-ring equilibrium (an independent implementation): eps 0.684/0.500/0.402
    for pd, eps in ((-12.6e-6, 0.684), (0.0, 0.5), (12.6e-6, 0.402)):
        model = make_model(catalog.bearing("6208", diametral_clearance_m=pd))
        jones = analytic.jones_equilibrium(model, 3000.0, 0.0, 0.0)
        ref = analytic.radial_equilibrium(model, 3000.0, jones.azimuths_rad, clearance_m=pd)
        assert jones.converged
        assert jones.inner_load_n == pytest.approx(ref["ball_loads_n"], abs=1e-6 * ref["qmax_n"])
        assert ref["epsilon"] == pytest.approx(eps, abs=6e-4)


def test_jones_pure_thrust_equals_harris_closed_form():
    # Harris & Kotzalas vol. 1 ch. 7 (pure thrust, no speed): every ball carries Fa / (Z sin a)
    # with Fa / Z = Kn (B D)^1.5 sin(a) (cos(a0) / cos(a) - 1)^1.5, B D = ri + ro - D the
    # groove-centre distance and Kn the series stiffness of the two contacts at the loaded angle a
    model = make_model(catalog.bearing("7208"))
    jones = analytic.jones_equilibrium(model, 0.0, 3000.0, 0.0)
    g = model.spec.geometry
    bd = g.inner_groove_radius_m + g.outer_groove_radius_m - 2 * g.ball_radius_m
    a0 = math.radians(40.0)
    e_prime = float(model.params[L.P_E_PRIME])

    def thrust(a):
        s = math.sin(a)
        kn = analytic.series_stiffness_n_m15(
            contact_constants(model.spec, True, s, e_prime)["stiffness_n_m15"],
            contact_constants(model.spec, False, s, e_prime)["stiffness_n_m15"],
        )
        return 13 * kn * bd**1.5 * s * (math.cos(a0) / math.cos(a) - 1) ** 1.5 - 3000.0

    a = optimize.brentq(thrust, a0 + 1e-6, math.radians(60.0), xtol=1e-14)
    assert np.degrees(jones.inner_angle_rad) == pytest.approx(math.degrees(a), abs=1e-6)
    assert np.degrees(jones.outer_angle_rad) == pytest.approx(math.degrees(a), abs=1e-6)
    assert jones.inner_load_n == pytest.approx(3000.0 / (13 * math.sin(a)), rel=1e-8)
