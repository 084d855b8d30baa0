"""The in-loop log-form tribology (twin.kernels.tribology) equals the law functions of
twin.physics it is compiled from (seed 000 eqs. 5-7, seed 004 eq. 6, seed 001 eqs. 1-5, 9, 11)."""

import math

import numpy as np
import pytest

from twin import catalog
from twin.kernels import layout as L
from twin.kernels.tribology import T_PIVOT, contact_tribology
from twin.model import make_model
from twin.physics import damping, ehl, rolling
from twin.spec import ModelOptions


@pytest.mark.parametrize("formula", ["hamrock_dowson", "masjedi_khonsari"])
def test_fast_path_equals_laws(formula):
    # the centre-point friction keeps seed 001's pivoting moment (eq. 11) in the fast path; with
    # the ellipse friction (the default) the strips' spin moment replaces it (T_PIVOT = 0)
    model = make_model(catalog.bearing("6208"), ModelOptions(film_formula=formula, friction_model="stribeck_line"))
    assert make_model(catalog.bearing("6208"), ModelOptions(film_formula=formula)).race_tribology[0, T_PIVOT] == 0.0
    rng = np.random.default_rng(7)
    p = model.params
    for _ in range(200):
        r = int(rng.integers(0, 2))
        q = float(10 ** rng.uniform(0, 4))  # 1 N .. 10 kN
        u = float(10 ** rng.uniform(-2, 1.5))  # 1 cm/s .. 30 m/s
        eta = float(10 ** rng.uniform(-3, -0.5))
        tr = model.race_tribology[r]
        out = contact_tribology(q, u, eta, p[L.P_ROUGHNESS], *tr[:15], 0, True)
        rx, ry = model.race_params[r, L.R_RX], model.race_params[r, L.R_RY]
        k = model.race_params[r, L.R_K_ELLIPTICITY]
        e = p[L.P_E_PRIME]
        args = (rx, ehl.speed_parameter(eta, u, e, rx), p[L.P_G_PARAM], ehl.load_parameter(q, e, rx), k)
        h = (ehl.hamrock_dowson_h_min_m if formula == "hamrock_dowson" else ehl.masjedi_khonsari_h_min_m)(*args)
        assert out[0] == pytest.approx(h, rel=1e-10)
        assert out[1] == pytest.approx(ehl.hamrock_dowson_h_c_m(*args), rel=1e-10)
        assert out[2] == pytest.approx(h / p[L.P_ROUGHNESS], rel=1e-10)
        a = out[5]
        assert a == pytest.approx(model.race_params[r, L.R_SEMI_MAJOR_COEF] * q ** (1 / 3), rel=1e-12)
        assert out[7] == pytest.approx(damping.fluid_damping_n_s_m(eta, a, 6.3e-3, h), rel=1e-10)
        ratio = ry / rx
        fr = (
            rolling.rolling_force_transition_n(e, rx, ratio, q, eta, u)
            + rolling.hysteresis_moment_n_m(12.6e-3, q, ratio) / 6.3e-3
        )
        assert out[8] == pytest.approx(fr, rel=1e-10)
        assert out[9] == pytest.approx(rolling.pivoting_moment_n_m(out[4], q, a, ratio), rel=1e-10)


def test_no_entrainment_is_boundary_without_film_force():
    model = make_model(catalog.bearing("6208"))
    out = contact_tribology(1000.0, 0.0, 0.04, 3.75e-7, *model.race_tribology[0, :15], 0, True)
    assert out[0] == 0.0 and out[2] == 0.0 and out[3] == 1 and out[4] == 0.1
    # every output finite but ln h_min (the refresh's ln Lambda comes from it), -inf for h_min = 0
    assert all(math.isfinite(v) for v in out[:10]) and out[10] == -math.inf


def test_asperity_share_from_the_film_logarithm():
    """The refresh takes ln Lambda = ln h_min - ln sigma from contact_tribology's last
    output (no log of Lambda). It is the logarithm of the h_min it returns (to rounding: 1e-15 of
    |ln h| ~ 14, abs 1e-13), and the asperity share (seed 001 eq. A2) and the limiting traction
    coefficient through it equal those from Lambda itself to 1e-13 across Lambda = 0.1-3."""
    from twin.kernels.traction import limiting_traction_coefficient, limiting_traction_coefficient_share
    from twin.physics.rolling import asperity_load_share, asperity_load_share_ln

    model = make_model(catalog.bearing("6208"))
    p = model.params
    sigma = p[L.P_ROUGHNESS]
    assert p[L.P_LN_ROUGHNESS] == math.log(sigma)
    tr = model.race_tribology[1]
    for q in (50.0, 700.0, 3000.0):
        for u in (0.05, 0.5, 2.0, 7.0, 20.0):
            out = contact_tribology(q, u, 0.02, sigma, *tr[:15], 2, True)
            assert out[10] == pytest.approx(math.log(out[0]), abs=1e-13)
            lam, ln_lam = out[2], out[10] - p[L.P_LN_ROUGHNESS]
            share = asperity_load_share_ln(lam, ln_lam)
            assert share == pytest.approx(asperity_load_share(lam), rel=1e-13, abs=1e-15)
            assert limiting_traction_coefficient_share(lam, share, 0.06) == pytest.approx(
                limiting_traction_coefficient(lam, 0.06), rel=1e-13
            )
    lams = [float(x) for x in np.linspace(0.1, 3.0, 30)]
    assert any(0.0 < asperity_load_share(x) < 1.0 for x in lams)
    for x in lams:
        assert asperity_load_share_ln(x, math.log(x)) == asperity_load_share(x)
