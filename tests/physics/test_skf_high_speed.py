"""Why the twin's friction torque departs from the SKF model at light load and high speed: the
centrifugal force of the balls.

At 1500 rad/s a 6208 ball presses on the outer raceway with F_c = m (d_m / 2) omega_c^2, about
88 N, whether the rings load it or not (Harris and Kotzalas, Advanced Concepts of Bearing
Technology, 5th ed. 2007, ch. 3, ball centrifugal force). The balls outside the loaded zone roll
on the outer raceway under that force and dissipate rolling resistance (seed 001 eqs. 1-5) at
every radial load: a floor under the torque. The SKF model's G_rr for deep-groove ball bearings,
R1 d_m^1.96 F_r^0.54, has no such term; for angular-contact and self-aligning ball bearings the
same catalogue table adds F_g = R3 d_m^4 n^2 to the load (SKF Rolling bearings catalogue 2018,
'Geometry and load dependent variables for rolling and sliding frictional moments'; e.g.
R3 = 2.44e-12 for 72 BECBP, as transcribed in github.com/JRaposo-m/SKF-Bearing-Selection-Tool,
friction_RS_constants.csv). The tests measure the floor and show that it accounts for the
departure: the twin less the floor holds the slope and magnitude criteria against SKF's deep-groove
formula, the twin with it does not. The other candidates do not depart: the twin's sliding power
matches SKF's M_sl, and its inlet shear heating (Murch-Wilson) is SKF's phi_ish within 5 %."""

import math

import numpy as np
import pytest

from twin import catalog
from twin.kernels import layout as L
from twin.physics import viscosity
from twin.spec import Lubrication
from twin.validation import skf_friction, studies

pytestmark = pytest.mark.slow

SPEED_RAD_S = 1500.0
LOAD_SHARES_OF_C0 = (0.02, 0.06, 0.2)
BORE_OD_MM = {"6205": (25.0, 52.0), "6208": (40.0, 80.0), "6210": (50.0, 90.0)}


@pytest.fixture(scope="module", params=sorted(BORE_OD_MM))
def runs(request):
    designation = request.param
    c0 = catalog.load_ratings(designation).static_load_rating_n
    out = {}
    for share in LOAD_SHARES_OF_C0:
        _, twin = studies.mean_friction_torque_n_m(
            SPEED_RAD_S,
            share * c0,
            designation=designation,
            shear_heating=True,
            lubrication=Lubrication(method="oil_bath"),
        )
        out[share * c0] = twin
    return out


def _skf(twin, load_n, nu_mm2_s):
    designation = twin.model.spec.designation
    bore, od = BORE_OD_MM[designation]
    return skf_friction.frictional_moment(designation, bore, od, load_n, SPEED_RAD_S, nu_mm2_s)


def _nu_mm2_s():
    lub = catalog.lubricant()
    return (
        viscosity.kinematic_viscosity_m2_s(lub.kinematic_viscosity_40c_m2_s, lub.kinematic_viscosity_100c_m2_s, 40.0)
        * 1e6
    )


def _unloaded_outer(twin):
    """(outer contact loads [N], their rolling torque [N m]) of the balls the inner ring does not load."""
    c = twin.state.contacts
    free = c[L.C_LOAD, 0::2] <= 0.0
    rolling = twin.friction_power_w().rolling_contact_w[:, 1]
    return c[L.C_LOAD, 1::2][free], float(rolling[free].sum()) / SPEED_RAD_S


def test_balls_outside_the_loaded_zone_carry_their_centrifugal_force(runs):
    # F_c = m (d_m / 2) omega_c^2 (Harris and Kotzalas ch. 3) with the cage speed of the run (14 / 87 / 111 N for the
    # 6205 / 6208 / 6210): the mean within 2 %,
    # each ball within 5 % + 1 N (the instant's vibration)
    for twin in runs.values():
        m = twin.model
        omega_c = float(twin.state.scalars[L.X_CAGE_SPEED])
        f_c = m.params[L.P_BALL_MASS] * m.pitch_radius_m * omega_c**2
        loads, _ = _unloaded_outer(twin)
        assert len(loads) >= 4
        assert float(np.mean(loads)) == pytest.approx(f_c, rel=0.02)
        np.testing.assert_allclose(loads, f_c, rtol=0.05, atol=1.0)
        assert 10.0 < f_c < 130.0


def test_the_centrifugal_floor_accounts_for_the_departure_from_skf(runs):
    nu = _nu_mm2_s()
    loads = sorted(runs)
    skf = [_skf(runs[f], f, nu).total_n_m for f in loads]
    twin = [runs[f].contact_friction_torque_n_m for f in loads]
    # the floor: the rolling of the outer contacts of the balls outside the loaded zone, per ball the same at every
    # load (within 5 %)
    floors = [_unloaded_outer(runs[f]) for f in loads]
    per_ball = [torque / len(q) for q, torque in floors]
    assert max(per_ball) == pytest.approx(min(per_ball), rel=0.05)
    # with it the twin misses the criteria at 1500 rad/s (slope within 0.15 of SKF's, torque within x 1.4; measured
    # slopes 0.43 / 0.48 / 0.51 against 0.66 / 0.70 / 0.70, 1.41 / 1.47 / 1.51 x at 0.02 C0) ...
    slope_skf = studies.log_slope(loads, skf)
    assert studies.log_slope(loads, twin) < slope_skf - 0.15
    assert twin[0] / skf[0] > 1.35
    # ... and without it meets both (measured slopes 0.56 / 0.63 / 0.68, 0.72-0.93 x): the departure is the centrifugal
    # load SKF's deep-groove formula leaves out
    bare = [t - torque for t, (_, torque) in zip(twin, floors)]
    assert abs(studies.log_slope(loads, bare) - slope_skf) < 0.15, (bare, skf)
    assert all(1 / 1.4 < b / s < 1.4 for b, s in zip(bare, skf)), (bare, skf)
    assert floors[0][1] > 0.25 * twin[0]  # a quarter or more of the torque at 0.02 C0 (5.5 / 17.4 / 24.4 mN m)


def test_the_other_candidates_agree_with_skf(runs):
    # sliding: the twin's sliding power over the shaft speed against SKF's M_sl = G_sl mu_sl, within 25 % + 1 mN m at
    # each load (the 6205 at 0.02 C0: 2.0 against 1.5 mN m, a tenth of its torque)
    nu = _nu_mm2_s()
    for load, twin in runs.items():
        skf = _skf(twin, load, nu)
        assert twin.friction_power_w().sliding_w / SPEED_RAD_S == pytest.approx(skf.sliding_n_m, rel=0.25, abs=1e-3)
    # inlet shear heating: the twin's film factor (Murch and Wilson 1975, twin.physics.thermal) against SKF's
    # phi_ish = 1 / (1 + 1.84e-9 (n d_m)^1.28 nu^0.64), within 5 % (measured 0.692 / 0.561 / 0.514 against 0.675 /
    # 0.541 / 0.491 for the 6205 / 6208 / 6210)
    twin = next(iter(runs.values()))
    bore, od = BORE_OD_MM[twin.model.spec.designation]
    phi_ish = skf_friction.inlet_shear_heating_factor(SPEED_RAD_S * 30.0 / math.pi, 0.5 * (bore + od), nu)
    assert twin.inlet.shear_film_factor == pytest.approx(phi_ish, rel=0.05)
