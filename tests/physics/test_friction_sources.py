"""Laws of the friction sources beyond the contacts: kinematic starvation, ball drag, seals
(twin.physics.starvation, drag, seals; twin.friction_power)."""

import math

import pytest

from twin import catalog
from twin.friction_power import boundary_dimensions_m, mean_immersed_fraction, seal_moment_n_m
from twin.physics import drag, seals, starvation
from twin.spec import BearingSpec, Lubrication
from twin.validation import skf_friction


@pytest.mark.parametrize(
    "reynolds, c_d", [(1.0, 26.5), (10.0, 4.15), (100.0, 1.09), (1000.0, 0.471), (1e4, 0.405), (1e5, 0.47)]
)
def test_sphere_drag_coefficient_follows_the_standard_drag_curve(reynolds, c_d):
    # the standard drag curve of a sphere (Clift, Grace and Weber 1978, Table 5.2 and Fig. 5.3;
    # the correlation is stated within 6 % of it up to Re = 3e5)
    assert drag.sphere_drag_coefficient(reynolds) == pytest.approx(c_d, rel=0.08)


def test_sphere_drag_tends_to_stokes_law():
    # Stokes: C_D = 24 / Re as Re -> 0 (F = 3 pi eta D v)
    re = 1e-4
    assert drag.sphere_drag_coefficient(re) == pytest.approx(24.0 / re, rel=1e-3)
    d, v, rho, eta = 1e-3, 1e-6, 870.0, 0.04
    assert drag.ball_drag_force_n(d, v, rho, eta) == pytest.approx(3.0 * math.pi * eta * d * v, rel=1e-3)


def test_ball_drag_force_is_harris_kotzalas_form():
    # Harris and Kotzalas vol. 2 ch. 3: F = pi rho C_D D^2 (d_m omega_m)^2 / 32, v = d_m omega_m / 2
    d, dm, omega_m, rho, eta = 12.6e-3, 60.6e-3, 200.0, 870.0, 0.04
    v = 0.5 * dm * omega_m
    c_d = drag.sphere_drag_coefficient(rho * v * d / eta)
    hk = math.pi * rho * c_d * d**2 * (dm * omega_m) ** 2 / 32.0
    assert drag.ball_drag_force_n(d, v, rho, eta) == pytest.approx(hk, rel=1e-12)


def test_drag_loss_factor_reads_the_skf_diagram():
    # SKF catalogue 2018, diagram 'Drag loss factor V_M', ball bearings, as digitised in
    # JRaposo-m/SKF-Bearing-Selection-Tool (ball_bearing_ampliado.csv, ball_bearing.csv): points of the digitisation
    # between the table's rounded abscissae, within 4 %
    for h_over_dm, v_m in ((0.1007, 7.41e-5), (0.1815, 2.14e-4), (0.5, 5.66e-4), (1.0022, 9.49e-4)):
        assert drag.drag_loss_factor(h_over_dm) == pytest.approx(v_m, rel=0.04)
    assert drag.drag_loss_factor(0.0) == 0.0
    assert drag.drag_loss_factor(5.0) == drag.drag_loss_factor(1.2)  # the catalogue caps H at 1.2 d_m


def test_oil_bath_drag_is_the_skf_drag_term_by_hand():
    # SKF catalogue 2018, 'Drag losses in oil bath lubrication', ball bearings: 6208 (d 40, D 80 mm, K_z 3.1), oil to
    # the centre of the lowest ball (H = 6.3 mm), 1500 rad/s, 46.7 mm^2/s; each factor by hand [N mm]
    n, d, big_d, h, nu = 1500.0 * 30.0 / math.pi, 40.0, 80.0, 6.3, 46.7
    dm = 60.0
    v_m = drag.drag_loss_factor(h / dm)
    assert v_m == pytest.approx(8.06e-5, rel=0.03)  # the digitised diagram at H/d_m = 0.105 (between 0.1007 and 0.1085)
    k_ball = 3.1 * (d + big_d) / (big_d - d) * 1e-12
    t = 2.0 * math.acos((0.6 * dm - h) / (0.6 * dm))
    r_s = 0.36 * dm**2 * (t - math.sin(t)) * 0.05 * 3.1 * (big_d + d) / (big_d - d)
    hand = (
        0.4 * v_m * k_ball * dm**5 * n**2 + 1.093e-7 * n**2 * dm**3 * (n * dm**2 * math.sin(t / 2) / nu) ** -1.379 * r_s
    )
    twin = drag.oil_bath_drag_moment_n_m(40e-3, 80e-3, 6.3e-3, 1500.0, 46.7e-6, 3.1)
    assert twin == pytest.approx(hand * 1e-3, rel=1e-12)
    assert twin == pytest.approx(0.0564, rel=0.03)  # N m, the hand evaluation above with the diagram read at 0.105
    # the churning term grows with n^2 and the oil level; nothing without oil or speed
    assert drag.oil_bath_drag_moment_n_m(40e-3, 80e-3, 12.6e-3, 1500.0, 46.7e-6, 3.1) > 2.0 * twin
    assert drag.oil_bath_drag_moment_n_m(40e-3, 80e-3, 0.0, 1500.0, 46.7e-6, 3.1) == 0.0
    assert drag.oil_bath_drag_moment_n_m(40e-3, 80e-3, 6.3e-3, 0.0, 46.7e-6, 3.1) == 0.0
    with pytest.raises(ValueError, match="kinematic_viscosity_m2_s"):
        drag.oil_bath_drag_moment_n_m(40e-3, 80e-3, 6.3e-3, 1500.0, 0.0, 3.1)


def test_immersed_fraction_of_a_ball_is_a_circular_segment():
    d = 10e-3
    assert drag.immersed_area_fraction(-1e-3, d) == 0.0
    assert drag.immersed_area_fraction(0.5 * d, d) == pytest.approx(0.5, abs=1e-12)
    assert drag.immersed_area_fraction(2 * d, d) == 1.0
    # a quarter of the diameter: segment of height R/2, (pi/3 - sqrt(3)/4) / pi of the disc
    assert drag.immersed_area_fraction(0.25 * d, d) == pytest.approx(
        (math.pi / 3 - math.sqrt(3) / 4) / math.pi, rel=1e-12
    )


def test_oil_bath_to_the_lowest_ball_centre_wets_a_small_share_of_the_orbit():
    spec = catalog.bearing("6208", lubrication=Lubrication(method="oil_bath"))
    share = mean_immersed_fraction(spec)
    # the oil reaches the centre of the lowest ball: half its disc there, nothing beyond
    # acos(1 - Rb / r_p) = 37 deg either side of the bottom; the mean lies well under 37/180 / 2
    assert 0.02 < share < 0.5 * 37.0 / 180.0
    assert mean_immersed_fraction(catalog.bearing("6208")) == 0.0  # flooded: no churning


def test_starvation_factor_is_the_skf_replenishment_factor():
    # SI implementation against the catalogue-unit one of the reference (SKF model, phi_rs)
    for speed in (100.0, 500.0, 1500.0):
        for nu in (12e-6, 46e-6):
            twin_value = starvation.kinematic_replenishment_factor(speed, nu, 40e-3, 80e-3, 3e-8, 3.1)
            skf = skf_friction.replenishment_factor(speed * 30.0 / math.pi, nu * 1e6, 40.0, 80.0)
            assert twin_value == pytest.approx(skf, rel=1e-12)
    assert starvation.kinematic_replenishment_factor(0.0, 46e-6, 40e-3, 80e-3, 3e-8, 3.1) == 1.0
    with pytest.raises(ValueError, match="outside_diameter_m"):
        starvation.kinematic_replenishment_factor(100.0, 46e-6, 80e-3, 40e-3, 3e-8, 3.1)


def test_seal_moment_follows_the_catalogue_table():
    # SKF model, M_seal = K_S1 d_s^beta + K_S2 [N mm], RS1 seals of deep-groove ball bearings (SKF catalogue table
    # 'Seal frictional moment: exponent and constants'; the transcription of JRaposo-m/SKF-Bearing-Selection-Tool,
    # seal_frictional_moment.csv): D <= 62 mm: 0.023, 2.25, 2; 62 < D <= 80 mm: 0.018, 2.25, 20; 80 < D <= 100 mm:
    # 0.018, 2.25, 15; D > 100 mm: 0.018, 2.25, 0
    assert seals.seal_moment_n_m("2RS", 31e-3, 52e-3) == pytest.approx((0.023 * 31**2.25 + 2) * 1e-3, rel=1e-12)
    assert seals.seal_moment_n_m("2RS", 52.6e-3, 80e-3) == pytest.approx((0.018 * 52.6**2.25 + 20) * 1e-3, rel=1e-12)
    assert seals.seal_moment_n_m("2RS", 60e-3, 90e-3) == pytest.approx((0.018 * 60**2.25 + 15) * 1e-3, rel=1e-12)
    assert seals.seal_moment_n_m("2RS", 80e-3, 120e-3) == pytest.approx(0.018 * 80**2.25 * 1e-3, rel=1e-12)
    assert seals.seal_moment_n_m("2Z", 52.6e-3, 80e-3) == 0.0  # shields do not touch the inner ring
    assert seals.seal_moment_n_m("open", 52.6e-3, 80e-3) == 0.0
    with pytest.raises(ValueError, match="seal = 'felt'"):
        seals.seal_moment_n_m("felt", 52.6e-3, 80e-3)
    # the spec's seal: a 6208-2RS with the default counterface d + 0.32 (D - d) = 52.8 mm
    spec = catalog.bearing("6208", lubrication=Lubrication(seal="2RS"))
    assert seal_moment_n_m(spec) == pytest.approx((0.018 * 52.8**2.25 + 20) * 1e-3, rel=1e-9)


def test_boundary_dimensions_fall_back_on_the_62_series_proportion():
    for designation, (d, big_d) in {"6205": (25e-3, 52e-3), "6208": (40e-3, 80e-3), "6210": (50e-3, 90e-3)}.items():
        spec = catalog.bearing(designation)
        assert boundary_dimensions_m(spec.geometry) == pytest.approx((d, big_d), rel=1e-12)
        bare = spec.geometry.model_copy(update={"bore_diameter_m": None, "outside_diameter_m": None})
        assert boundary_dimensions_m(bare) == pytest.approx((d, big_d), rel=0.06)


def test_lubrication_input_is_strict():
    with pytest.raises(ValueError, match="method"):
        Lubrication(method="splash")
    with pytest.raises(ValueError, match="oil_level_m"):
        Lubrication(method="oil_bath", oil_level_m=-1e-3)
    spec = catalog.bearing("6208")
    assert BearingSpec.model_validate(spec.model_dump()).lubrication.method == "flooded"
