"""The twin's live life (twin.life.LifeMonitor in twin.engine): Palmgren-Miner damage along the
history, the snapshot's `life` block, and the DEM's contact-load life against the quasi-static
equilibrium's."""

import json
import math

import pytest

from twin import catalog, life
from twin.engine import Twin
from twin.model import make_model
from twin.physics.thermal import roelands_temperature_viscosity_pa_s
from twin.physics.viscosity import density_kg_m3, dynamic_viscosity_pa_s, temperature_viscosity_coefficient_k_inv


def test_accumulator_is_miner_sum():
    """Palmgren-Miner: D = sum dt_k / L_k with the rate held over each interval; reading does not
    change it; a clock that goes back adds nothing."""
    acc = life.DamageAccumulator(0.1)
    acc.set_rate(0.0, 1e-3)
    assert acc.damage_at(10.0) == pytest.approx(0.1 + 1e-2)
    acc.set_rate(10.0, 4e-3)
    assert acc.damage_at(15.0) == pytest.approx(0.1 + 1e-2 + 2e-2)
    assert acc.damage_at(10.0) == pytest.approx(0.11)  # reading changed nothing
    acc.set_rate(2.0, 1e-3)  # restarted clock (a scenario restart): the old interval ends at 10 s
    assert acc.damage_at(2.0) == pytest.approx(0.11)
    assert acc.damage_at(3.0) == pytest.approx(0.11 + 1e-3)
    assert life.damage_rate_per_s(1.0) == pytest.approx(1 / 3600.0)
    assert life.damage_rate_per_s(math.inf) == 0.0


@pytest.fixture(scope="module")
def runs():
    """6208 twins at 500 rad/s: 3000 N and 6000 N, damage against ISO 281's L10m, and 3000 N
    against the contact-load life; damage read every 20 ms over 100 ms."""
    out = {}
    for name, load, basis in (
        ("iso_3000", 3000.0, "iso_281"),
        ("iso_6000", 6000.0, "iso_281"),
        ("contact_3000", 3000.0, "contact_loads"),
        ("contact_6000", 6000.0, "contact_loads"),
    ):
        twin = Twin("6208", life=life.LifeSettings(damage_basis=basis))
        twin.set_setpoint(radial_load_n=load)
        twin.reset()  # warm start at this load
        samples = []
        for _ in range(5):
            twin.advance(0.02)
            samples.append((twin.time_s, twin.snapshot()))
        out[name] = samples
    return out


def _increments(samples):
    d = [s.life.damage_fraction for _, s in samples]
    return [b - a for a, b in zip(d, d[1:])]


def test_damage_linear_under_constant_conditions(runs):
    """Constant setpoint: equal damage in equal times (against L10m, exactly: the rate is constant;
    against the contact-load life within 3 %: the DEM loads fluctuate), and the rate is the
    Palmgren-Miner 1 / life: dD/dt = 1 / (3600 L10m_h)."""
    inc = _increments(runs["iso_3000"])
    assert max(inc) == pytest.approx(min(inc), rel=1e-9) and min(inc) > 0.0
    snap = runs["iso_3000"][-1][1]
    assert inc[0] / 0.02 == pytest.approx(1.0 / (3600.0 * snap.life.l10m_h), rel=1e-9)
    assert snap.life.damage_fraction == pytest.approx(snap.time_s / (3600.0 * snap.life.l10m_h), rel=1e-6)
    inc = _increments(runs["contact_3000"])
    assert max(inc) == pytest.approx(min(inc), rel=0.03)


def test_damage_faster_under_heavier_load(runs):
    """Doubling the load (3000 -> 6000 N): ISO 281 L10 falls 8x and a_ISO falls with e_C Cu/P
    (28.7 -> 6.5), so damage accrues 35x faster; against the contact-load life at least 8x."""
    ratio = _increments(runs["iso_6000"])[-1] / _increments(runs["iso_3000"])[-1]
    a, b = runs["iso_3000"][-1][1].life, runs["iso_6000"][-1][1].life
    assert ratio == pytest.approx(a.l10m_h / b.l10m_h, rel=1e-6)
    assert ratio > 30.0
    ratio_c = _increments(runs["contact_6000"])[-1] / _increments(runs["contact_3000"])[-1]
    assert ratio_c > 8.0


def test_snapshot_life_block(runs):
    """The block carries every life key with its value; JSON without NaN; remaining life =
    (1 - D) L10m."""
    snap = runs["iso_3000"][-1][1]
    block = json.loads(snap.to_json(), parse_constant=lambda c: pytest.fail(f"non-finite {c}"))["life"]
    for key in ("kappa", "a_iso", "l10_h", "l10m_h", "l10_contact_loads_h", "damage_fraction", "remaining_life_h"):
        assert block[key] is not None, key
    assert block["l10_h"] == pytest.approx(4438.07, abs=0.05)  # (32.5/3)^3 at 500 rad/s
    # kappa = nu / nu1 (ISO 281) of the film inlet: 5.587 for the seed oil at 40 degC unheated; the default
    # twin's inlet is shear-heated (Thermal.shear_heating, Murch-Wilson) by the published rise dT, so nu
    # falls by Roelands' eta(T0 + dT) / eta(T0) (seed 003 eq. 3) over rho(T0 + dT) / rho(T0) (4.41 at 500 rad/s)
    lub, t0 = catalog.bearing("6208").lubricant, 40.0
    rise = snap.electrical.shear_temperature_rise_k
    assert rise > 0.0
    eta0 = dynamic_viscosity_pa_s(lub, t0)
    eta_ratio = (
        roelands_temperature_viscosity_pa_s(
            eta0, t0 + 273.15, t0 + 273.15 + rise, temperature_viscosity_coefficient_k_inv(lub, t0)
        )
        / eta0
    )
    rho_ratio = density_kg_m3(lub.density_15c_kg_m3, t0 + rise) / density_kg_m3(lub.density_15c_kg_m3, t0)
    assert block["kappa"] == pytest.approx(5.587 * eta_ratio / rho_ratio, abs=0.01)
    assert block["dynamic_load_rating_n"] == 32500.0 and block["equivalent_load_n"] == 3000.0
    assert block["remaining_life_h"] == pytest.approx((1 - block["damage_fraction"]) * block["l10m_h"], rel=1e-9)


def test_dem_contact_life_matches_the_equilibrium(runs):
    """The DEM's ball loads (running mean over the ball passages) give the same contact-load life
    as the quasi-static equilibrium at the same operating point, within 5 % (life ~ Q^-3, so 5 %
    is under 2 % in load)."""
    dem = runs["iso_3000"][-1][1].life.l10_contact_loads_h
    model = make_model(catalog.bearing("6208"))
    eq = life.life_hours(life.equilibrium_contact_life_mrev(model, 3000.0, 0.0, 500.0), 500.0)
    assert dem == pytest.approx(eq, rel=0.05)


def test_at_rest_life_unbounded_and_no_damage():
    """Shaft at rest: no load cycles, ISO 281's lives are unbounded -> null with the reason, and
    the damage stops growing."""
    twin = Twin("6208")
    twin.set_setpoint(shaft_speed_rad_s=0.0)
    twin.reset()
    twin.advance(0.005)
    d0 = twin.snapshot().life.damage_fraction
    twin.advance(0.01)
    lf = twin.snapshot().life
    assert lf.l10_h is None and lf.l10m_h is None and lf.kappa is None and lf.remaining_life_h is None
    assert "rest" in lf.reason
    assert lf.damage_fraction == d0 and lf.damage_rate_per_s == 0.0
