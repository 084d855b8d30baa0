"""The contact geometry follows the contact angle: Rx of a ball-raceway contact from its current
angle (Meusnier: the raceway's rolling radius is the distance to the axis along the normal;
Harris & Kotzalas, Rolling Bearing Analysis, ch. 2), and with it k, K, the ellipse and the film
constants, tabulated exactly at compile time on a grid of sin(alpha) and interpolated linearly
by the kernel. The grid is proven by a convergence study at off-grid angles."""

import math

import numpy as np
import pytest

from twin import catalog
from twin.kernels import layout as L
from twin.kernels.tribology import T_HMIN_EXP_EU, T_LN_HC, T_LN_HMIN, T_LN_IVR, T_RX, T_SEMI_MAJOR
from twin.model import _tribology_row, interpolate_angle_table, make_model, raceway_radii_m
from twin.physics import hertz
from twin.spec import ModelOptions

# columns compared in log form (their value is a logarithm: an absolute error is a relative one)
_LOG_COLUMNS = [L.A_TRIBOLOGY + c for c in (T_LN_HMIN, T_LN_HC, T_LN_IVR, T_LN_IVR + 1, T_LN_IVR + 2, T_LN_IVR + 3)]


def _worst_error(designation, points):
    """Largest interpolation error over 157 off-grid angles in [0, 60 deg] for a grid of
    `points` (relative for K and the linear columns, absolute for the log columns)."""
    spec = catalog.bearing(designation)
    opt = ModelOptions()
    model = make_model(spec, opt)
    e_prime, g_param = model.params[L.P_E_PRIME], model.params[L.P_G_PARAM]
    grid = np.linspace(0.0, L.ANGLE_MAX_SIN, points)
    table = np.array(
        [
            [np.r_[k, tri] for k, tri in (_tribology_row(spec, opt, r == 0, s, e_prime, g_param) for s in grid)]
            for r in (0, 1)
        ]
    )
    worst = 0.0
    for s in np.linspace(1e-3, L.ANGLE_MAX_SIN - 1e-3, 157):
        x = s / grid[1]
        i = min(int(x), points - 2)
        for r in (0, 1):
            interp = table[r, i] + (x - i) * (table[r, i + 1] - table[r, i])
            k, tri = _tribology_row(spec, opt, r == 0, s, e_prime, g_param)
            exact = np.r_[k, tri]
            err = np.abs(interp - exact) / np.maximum(np.abs(exact), 1e-300)
            err[_LOG_COLUMNS] = np.abs(interp - exact)[_LOG_COLUMNS]
            worst = max(worst, float(err.max()))
    return worst


@pytest.mark.parametrize("designation", ["6208", "7208", "6200"])
def test_grid_converges_at_second_order_and_the_model_grid_is_within_1e_4(designation):
    coarse = _worst_error(designation, (L.ANGLE_POINTS - 1) // 2 + 1)
    fine = _worst_error(designation, L.ANGLE_POINTS)
    assert fine < 1e-4  # every constant within 0.01 % (K within 1e-5)
    assert coarse / fine == pytest.approx(4.0, rel=0.15)  # halving the step quarters the error


def test_model_table_is_the_exact_constants_on_the_grid():
    spec = catalog.bearing("7208")
    model = make_model(spec)
    e_prime = model.params[L.P_E_PRIME]
    for r in (0, 1):
        for i in (0, 17, L.ANGLE_POINTS - 1):
            s = i * L.ANGLE_STEP
            rx, ry = raceway_radii_m(spec, r == 0, s)
            assert model.angle_table[r, i, L.A_STIFFNESS] == pytest.approx(
                hertz.raceway_stiffness_n_m15(rx, ry, e_prime), rel=1e-12
            )
            assert model.angle_table[r, i, L.A_TRIBOLOGY + T_RX] == pytest.approx(rx, rel=1e-12)
            assert model.angle_table[r, i, L.A_TRIBOLOGY + T_SEMI_MAJOR] == pytest.approx(
                hertz.semi_major_axis_m(1.0, rx, ry, e_prime), rel=1e-12
            )
    # the nominal rows (race_params, race_tribology) are the table at the nominal angle
    s40 = math.sin(math.radians(40.0))
    for r in (0, 1):
        row = interpolate_angle_table(model.angle_table, r, s40)
        assert row[L.A_STIFFNESS] == pytest.approx(model.race_params[r, L.R_STIFFNESS], rel=2e-5)
        assert row[L.A_TRIBOLOGY + T_HMIN_EXP_EU] == model.race_tribology[r, T_HMIN_EXP_EU]
        assert model.stiffness_at(r, -s40) == pytest.approx(row[L.A_STIFFNESS], rel=1e-14)


def test_rolling_radius_follows_the_contact_angle():
    # 7208 (dm/2 = 30.3 mm, Rb = 6.3 mm) at 40 deg: inner r = (30.3 - 6.3 cos 40) / cos 40 =
    # 33.25 mm, Rx = Rb r / (Rb + r) = 5.297 mm; outer r = (30.3 + 6.3 cos 40) / cos 40 =
    # 45.86 mm, Rx = Rb r / (r - Rb) = 7.303 mm; at 0 deg seed 000's 4.990 / 7.610 mm
    spec = catalog.bearing("7208")
    c40 = math.cos(math.radians(40.0))
    ri = (30.3 - 6.3 * c40) / c40
    ro = (30.3 + 6.3 * c40) / c40
    s40 = math.sin(math.radians(40.0))
    assert raceway_radii_m(spec, True, s40)[0] == pytest.approx(6.3 * ri / (6.3 + ri) * 1e-3, rel=1e-12)
    assert raceway_radii_m(spec, False, s40)[0] == pytest.approx(6.3 * ro / (ro - 6.3) * 1e-3, rel=1e-12)
    assert raceway_radii_m(spec, True, s40)[0] == pytest.approx(5.297e-3, rel=1e-3)
    assert raceway_radii_m(spec, False, s40)[0] == pytest.approx(7.303e-3, rel=1e-3)
    assert raceway_radii_m(spec, True, 0.0)[0] == pytest.approx(4.990e-3, rel=1e-3)
    # Rx grows with the angle at the inner race (stiffer, +1.5 % at 50 deg) and shrinks at the
    # outer race (softer, -1.1 %)
    model = make_model(spec)
    s50 = math.sin(math.radians(50.0))
    assert model.stiffness_at(0, s50) / model.stiffness_at(0, 0.0) == pytest.approx(1.0150, abs=5e-4)
    assert model.stiffness_at(1, s50) / model.stiffness_at(1, 0.0) == pytest.approx(0.9889, abs=5e-4)
