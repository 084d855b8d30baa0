"""Each in-loop tribology law against a hand-computed value (seed 000 eqs. 5-7, Table 2,
section 2.3; seed 004 eq. 6; README readings)."""

import math

import pytest

from twin import catalog
from twin.physics import damping, ehl, friction, viscosity

E_PRIME = 210e9 / (1 - 0.3**2)
XI = 2.3e-8  # seed 000 section 2.2
RX_OUT = 6.3 * 36.6 / (36.6 - 6.3) * 1e-3
RY = 6.3 * 6.552 / (6.552 - 6.3) * 1e-3
K_OUT = (RY / RX_OUT) ** (2 / math.pi)


def test_hamrock_dowson_outer_contact_6208_by_hand():
    # seed 000 eq. 6 at the outer contact, Q = 1480 N, u = 7.244 m/s, eta = 0.04 Pa s
    u_par = 0.04 * 7.244 / (E_PRIME * RX_OUT)
    w_par = 1480.0 / (E_PRIME * RX_OUT**2)
    g_par = XI * E_PRIME
    hand = 3.63 * RX_OUT * u_par**0.68 * g_par**0.49 * w_par**-0.073 * (1 - math.exp(-0.68 * K_OUT))
    assert hand == pytest.approx(7.93e-7, rel=2e-3)  # 0.79 um
    law = ehl.hamrock_dowson_h_min_m(
        RX_OUT,
        ehl.speed_parameter(0.04, 7.244, E_PRIME, RX_OUT),
        g_par,
        ehl.load_parameter(1480.0, E_PRIME, RX_OUT),
        K_OUT,
    )
    assert law == pytest.approx(hand, rel=1e-12)
    # seed 000 eq. 7: Lambda = h / (1.25 sqrt(0.3^2 + 0^2) um) = h / 3.75e-7 -> about 2.1 (Fig. 8)
    surf = catalog.bearing("6208").surface
    assert surf.composite_roughness_m == pytest.approx(3.75e-7, rel=1e-12)
    assert ehl.film_parameter(law, surf.composite_roughness_m) == pytest.approx(2.115, rel=3e-3)


def test_masjedi_khonsari_by_hand_and_circular_limit():
    # seed 004 eq. 6, exponents as products (README)
    u_par, g_par, w_par, k = 2e-11, 5000.0, 1e-4, 7.0
    hand = (
        1.637
        * RX_OUT
        * u_par ** (0.711 * k**-0.023)
        * g_par ** (0.65 * k**-0.045)
        * w_par ** (-0.09 * k**-0.15)
        * (1 - 0.974 * math.exp(-0.676 * k))
    )
    assert ehl.masjedi_khonsari_h_min_m(RX_OUT, u_par, g_par, w_par, k) == pytest.approx(hand, rel=1e-12)
    # at k = 1 the exponents reduce to the circular-contact 0.711, 0.65, -0.09
    circ = 1.637 * u_par**0.711 * g_par**0.65 * w_par**-0.09 * (1 - 0.974 * math.exp(-0.676))
    assert ehl.masjedi_khonsari_h_min_m(1.0, u_par, g_par, w_par, 1.0) == pytest.approx(circ, rel=1e-12)


def test_central_film_hamrock_dowson_by_hand():
    u_par, g_par, w_par = 1.6e-10, 5307.7, 1.1e-4
    hand = 2.69 * RX_OUT * u_par**0.67 * g_par**0.53 * w_par**-0.067 * (1 - 0.61 * math.exp(-0.73 * K_OUT))
    assert ehl.hamrock_dowson_h_c_m(RX_OUT, u_par, g_par, w_par, K_OUT) == pytest.approx(hand, rel=1e-12)
    assert hand > ehl.hamrock_dowson_h_min_m(RX_OUT, u_par, g_par, w_par, K_OUT)


def test_no_entrainment_means_no_film():
    assert ehl.hamrock_dowson_h_min_m(RX_OUT, 0.0, 5000.0, 1e-4, K_OUT) == 0.0
    assert ehl.masjedi_khonsari_h_min_m(RX_OUT, 0.0, 5000.0, 1e-4, K_OUT) == 0.0


@pytest.mark.parametrize(
    "lam, regime",
    [
        (0.0, "boundary"),
        (1.0, "boundary"),
        (1.0001, "mixed"),
        (3.0, "mixed"),
        (3.0001, "full_film"),
        (5.0, "full_film"),
    ],
)
def test_regime_switches_where_table_2_says(lam, regime):
    assert friction.REGIME_NAMES[friction.regime_code(lam)] == regime


@pytest.mark.parametrize("lam, mu", [(0.3, 0.1), (1.0, 0.1), (2.0, 0.055), (2.5, 0.0325), (3.0, 0.01), (4.5, 0.01)])
def test_stribeck_line(lam, mu):
    # seed 000 section 2.3: 0.1 for Lambda <= 1, linear to 0.01 at Lambda = 3, 0.01 above
    assert friction.stribeck_line_mu(lam) == pytest.approx(mu, rel=1e-12)


def test_fluid_damping_eq5_by_hand():
    # seed 000 eq. 5: C = 3 pi eta a / sqrt(2) (Rb / h)^1.5 with a = 1.7 mm, h = 0.8 um
    hand = 3 * math.pi * 0.04 * 1.7e-3 / math.sqrt(2) * (6.3e-3 / 0.8e-6) ** 1.5
    assert hand == pytest.approx(316.7, rel=1e-3)
    assert damping.fluid_damping_n_s_m(0.04, 1.7e-3, 6.3e-3, 0.8e-6) == pytest.approx(hand, rel=1e-12)


def test_hysteretic_damping_eq4_by_hand():
    # seed 000 eq. 4: C_hyst = 3 alpha_e Kn delta / 2 with Kn = K delta^0.5, alpha_e = 0.08 s/m
    hand = 1.5 * 0.08 * 4.2e10 * 10e-6**1.5
    assert damping.hysteretic_damping_n_s_m(0.08, 4.2e10, 10e-6) == pytest.approx(hand, rel=1e-12)
    assert hand == pytest.approx(159.4, rel=1e-3)


@pytest.mark.parametrize(
    "lam, which", [(0.5, "hyst"), (1.0, "hyst"), (2.0, "series"), (3.0, "series"), (3.5, "fluid"), (6.0, "fluid")]
)
def test_normal_damping_switches_where_table_2_says(lam, which):
    ch, cf = 160.0, 320.0
    expected = {"hyst": ch, "series": 1 / (1 / ch + 1 / cf), "fluid": cf}[which]
    assert damping.regime_damping_n_s_m(lam, ch, cf) == pytest.approx(expected, rel=1e-12)


def test_seed_viscosity_is_exactly_0_04_at_40_c():
    # seed 000 eq. 5: eta = 0.04 Pa s at operating temperature; default oil, 40 degC
    oil = catalog.lubricant("seed-000")
    assert viscosity.dynamic_viscosity_pa_s(oil, 40.0) == pytest.approx(0.04, rel=1e-14)


def test_iso_vg_walther_law():
    # ASTM D341 through the grade's two points; VG 68 (ISO 3448: 68 mm2/s at 40 degC)
    oil = catalog.lubricant("ISO VG 68")
    nu40 = viscosity.kinematic_viscosity_m2_s(oil.kinematic_viscosity_40c_m2_s, oil.kinematic_viscosity_100c_m2_s, 40.0)
    nu100 = viscosity.kinematic_viscosity_m2_s(
        oil.kinematic_viscosity_40c_m2_s, oil.kinematic_viscosity_100c_m2_s, 100.0
    )
    assert nu40 == pytest.approx(68e-6, rel=1e-12)
    assert nu100 == pytest.approx(8.7e-6, rel=1e-9)
    temps = [0.0, 20.0, 40.0, 60.0, 80.0, 100.0, 120.0]
    etas = [viscosity.dynamic_viscosity_pa_s(oil, t) for t in temps]
    assert all(a > b for a, b in zip(etas, etas[1:]))
    # hand: log10 log10(nu + 0.7) linear in log10 T at 70 degC
    a = math.log10(math.log10(68.7))
    b = math.log10(math.log10(8.7 + 0.7))
    t1, t2, t = math.log10(313.15), math.log10(373.15), math.log10(343.15)
    y = a + (b - a) * (t - t1) / (t2 - t1)
    hand = (10 ** (10**y) - 0.7) * 1e-6
    assert viscosity.kinematic_viscosity_m2_s(68e-6, 8.7e-6, 70.0) == pytest.approx(hand, rel=1e-9)
    with pytest.raises(ValueError, match="lubricant"):
        catalog.lubricant("ISO VG 47")
