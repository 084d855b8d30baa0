"""SKF's own minimum load bounds the domain of its frictional-moment model, and the friction
table's light-load, high-speed departures lie below it.

SKF Rolling bearings catalogue, deep groove ball bearings, 'Loads', 'Minimum load':
F_rm = k_r (nu n / 1000)^(2/3) (d_m / 100)^2 kN, nu [mm^2/s], n [r/min], d_m [mm], k_r = 0.025 for the
6205 / 6208 / 6210 (product tables; twin.validation.skf_friction). Below F_rm the catalogue expects the
balls' inertia and the lubricant's drag, not the load, to govern the rolling: the load-dependent
formula M_rr = phi_ish phi_rs R1 d_m^1.96 F_r^0.54 (nu n)^0.6 is outside its domain. The friction
table (6205 / 6208 / 6210, 100-1500 rad/s, 0.02-0.2 C0, the seed oil at 40 degC, 46.7 mm^2/s)
misses its criteria (log-log load slope within 0.15 of SKF's, torque within x 1.4) by 1-8 % in
torque and 0.04-0.07 in slope at 1500 rad/s, where the 0.02 C0 load is below F_rm
(tests/physics/test_skf_high_speed.py measures the balls' centrifugal floor that makes the
difference). At and above F_rm three marginal misses remain, none of them at light load: the
torque 0.709 / 0.711 x SKF (1 / 1.4 = 0.714) for the 6205 / 6208 at 100 rad/s and 0.06 C0, the
slope 0.153 short for the 6208 at 500 rad/s."""

import pytest

from twin import catalog
from twin.physics import viscosity
from twin.spec import Lubrication
from twin.validation import skf_friction, studies

BORE_OD_MM = {"6205": (25.0, 52.0), "6208": (40.0, 80.0), "6210": (50.0, 90.0)}
SPEEDS_RAD_S = (100.0, 500.0, 1500.0)
LOAD_SHARES_OF_C0 = (0.02, 0.06, 0.2)


def _nu_mm2_s():
    lub = catalog.lubricant()
    return (
        viscosity.kinematic_viscosity_m2_s(lub.kinematic_viscosity_40c_m2_s, lub.kinematic_viscosity_100c_m2_s, 40.0)
        * 1e6
    )


def _f_rm(designation, speed_rad_s):
    bore, od = BORE_OD_MM[designation]
    return skf_friction.minimum_radial_load_n(designation, bore, od, speed_rad_s, _nu_mm2_s())


def test_the_minimum_load_formula():
    # by hand, 6208 at 1500 rad/s (14 324 r/min), nu = 46.74 mm^2/s, d_m = 60 mm:
    # 0.025 x (46.74 x 14 324 / 1000)^(2/3) x 0.6^2 = 0.025 x 76.54 x 0.36 = 0.6889 kN
    assert _nu_mm2_s() == pytest.approx(46.74, abs=0.01)
    assert _f_rm("6208", 1500.0) == pytest.approx(688.9, abs=0.5)
    # the laws: (nu n)^(2/3), d_m^2, k_r of the 63 series 0.03 against 0.025
    nu = _nu_mm2_s()
    assert skf_friction.minimum_radial_load_n("6208", 40.0, 80.0, 3000.0, nu) == pytest.approx(
        2.0 ** (2.0 / 3.0) * _f_rm("6208", 1500.0), rel=1e-12
    )
    assert skf_friction.minimum_radial_load_n("6208", 40.0, 80.0, 1500.0, 2.0 * nu) == pytest.approx(
        2.0 ** (2.0 / 3.0) * _f_rm("6208", 1500.0), rel=1e-12
    )
    assert skf_friction.minimum_radial_load_n("6308", 40.0, 80.0, 1500.0, nu) == pytest.approx(
        1.2 * _f_rm("6208", 1500.0), rel=1e-12
    )
    # k_r of the product tables (2018 catalogue): 0.025 for the 6205 / 6208 / 6210, 0.03 for the 6200
    assert skf_friction.minimum_radial_load_n("6200", 40.0, 80.0, 1500.0, nu) == pytest.approx(
        1.2 * _f_rm("6208", 1500.0), rel=1e-12
    )
    assert skf_friction.minimum_radial_load_n("6208", 20.0, 100.0, 1500.0, nu) == pytest.approx(
        _f_rm("6208", 1500.0), rel=1e-12
    )


def test_bad_input_names_the_fields():
    with pytest.raises(ValueError, match="kinematic_viscosity_mm2_s"):
        skf_friction.minimum_radial_load_n("6208", 40.0, 80.0, 1500.0, 0.0)
    with pytest.raises(ValueError, match="od_mm > bore_mm"):
        skf_friction.minimum_radial_load_n("6208", 80.0, 40.0, 1500.0, 46.7)
    with pytest.raises(ValueError, match="designation"):
        skf_friction.minimum_radial_load_n("7208", 40.0, 80.0, 1500.0, 46.7)


def test_the_light_load_high_speed_points_lie_below_the_minimum_load():
    # F_rm / C0 = 0.006-0.007 at 100 rad/s, 0.017-0.019 at 500 rad/s, 0.036-0.040 at 1500 rad/s
    # (284 / 689 / 937 N for the 6205 / 6208 / 6210): of the table's 27 points exactly the three at
    # 0.02 C0 and 1500 rad/s are below it, and those are the ones at 1.41-1.51 x SKF
    below = set()
    for d in BORE_OD_MM:
        c0 = catalog.load_ratings(d).static_load_rating_n
        for speed in SPEEDS_RAD_S:
            for share in LOAD_SHARES_OF_C0:
                if share * c0 < _f_rm(d, speed):
                    below.add((d, speed, share))
        assert 0.035 < _f_rm(d, 1500.0) / c0 < 0.041
        assert _f_rm(d, 500.0) / c0 < 0.02
    assert below == {(d, 1500.0, 0.02) for d in BORE_OD_MM}


@pytest.fixture(scope="module")
def at_or_above_minimum_load():
    """{(bearing, speed): [(load, twin contact torque, SKF M_rr + M_sl)]} for F_rm and every table load
    at or above it; oil bath, inlet heating on, as the friction table (service.reports.friction_reference)."""
    nu = _nu_mm2_s()
    out = {}
    for d, (bore, od) in BORE_OD_MM.items():
        c0 = catalog.load_ratings(d).static_load_rating_n
        for speed in SPEEDS_RAD_S:
            f_rm = _f_rm(d, speed)
            loads = [f_rm] + [s * c0 for s in LOAD_SHARES_OF_C0 if s * c0 >= f_rm]
            rows = []
            for load in loads:
                _, twin = studies.mean_friction_torque_n_m(
                    speed, load, designation=d, shear_heating=True, lubrication=Lubrication(method="oil_bath")
                )
                skf = skf_friction.frictional_moment(d, bore, od, load, speed, nu)
                rows.append((load, twin.contact_friction_torque_n_m, skf.total_n_m))
            out[(d, speed)] = rows
    return out


@pytest.mark.slow
def test_at_or_above_the_minimum_load_the_magnitude_within_x_1_4_but_two(at_or_above_minimum_load):
    # twin / SKF within x 1.4 at F_rm and at every table load above it, measured 0.709-1.19 (1.05-1.19 at F_rm itself,
    # against 1.41 / 1.47 / 1.51 at the three 0.02 C0 points below it at 1500 rad/s). Two points miss 1 / 1.4 = 0.714
    # by less than 1 %: the 6205 and the 6208 at 100 rad/s and 0.06 C0 (0.709 / 0.711), ten times F_rm,
    # where the twin runs low in the middle of the load range; the minimum load does not account for them.
    ratios = {(key, round(load)): t / s for key, rows in at_or_above_minimum_load.items() for load, t, s in rows}
    assert all(r < 1.4 for r in ratios.values()), ratios
    misses = {k for k, r in ratios.items() if r <= 1 / 1.4}
    assert misses <= {(("6205", 100.0), 468), (("6208", 100.0), 1140)}, ratios
    assert min(ratios.values()) > 1 / 1.42, ratios


@pytest.mark.slow
def test_at_or_above_the_minimum_load_the_load_slope_within_0_15_but_one(at_or_above_minimum_load):
    # log-log load slope of the twin against SKF's over the table's loads at or above F_rm (0.02-0.2 C0 at 100 and
    # 500 rad/s, 0.06-0.2 C0 at 1500 rad/s): measured twin - SKF = +0.11 / +0.08 / +0.09 at 100 rad/s, -0.13 / -0.153
    # / -0.14 at 500 rad/s, -0.12 / -0.11 / -0.08 at 1500 rad/s (6205 / 6208 / 6210). The 6208 at 500 rad/s misses
    # by 0.003: there the twin is low at the heavy end (0.78 x SKF at 0.2 C0) and every load is above F_rm, so the
    # minimum load does not account for it.
    gaps = {}
    for key, rows in at_or_above_minimum_load.items():
        table = rows[1:]
        loads = [load for load, _, _ in table]
        gaps[key] = abs(
            studies.log_slope(loads, [t for _, t, _ in table]) - studies.log_slope(loads, [s for _, _, s in table])
        )
    assert {key for key, g in gaps.items() if g >= 0.15} <= {("6208", 500.0)}, gaps
    assert max(gaps.values()) < 0.16, gaps
