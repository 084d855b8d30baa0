"""Correlations, network assembly and the exact exponential step of the thermal network (twin.thermal)."""

import math

import numpy as np
import pytest
from scipy.linalg import expm

from twin import catalog
from twin.thermal import correlations as cr
from twin.thermal.integrator import steady_state_c, step_c, transition
from twin.thermal.materials import AIR_CONDUCTIVITY_W_M_K, AIR_KINEMATIC_VISCOSITY_M2_S, AIR_PRANDTL
from twin.thermal.network import NODE_NAMES, Network, Operating, assemble, network_geometry
from twin.thermal.settings import ThermalNetworkSettings
from twin.thermal.sources import HeatSources


def test_churchill_chu_against_the_formula_by_hand():
    # Churchill and Chu 1975 (Incropera and DeWitt eq. 9.34): for Pr = 0.71 and Ra = 1e7,
    # [1 + (0.559/0.71)^(9/16)]^(8/27) = 1.2045 and Nu = (0.60 + 0.387 * 14.678 / 1.2045)^2 = 28.3
    d, dt = 0.1, 20.0
    t_film = 30.0 + 273.15
    ra = 9.80665 * dt / t_film * d**3 * AIR_PRANDTL / AIR_KINEMATIC_VISCOSITY_M2_S**2
    nu_hand = (0.60 + 0.387 * ra ** (1 / 6) / 1.2045) ** 2
    h = cr.churchill_chu_cylinder_w_m2_k(d, 40.0, 20.0)
    assert h * d / AIR_CONDUCTIVITY_W_M_K == pytest.approx(nu_hand, rel=2e-3)
    ra7 = 1e7
    assert (0.60 + 0.387 * ra7 ** (1 / 6) / 1.2045) ** 2 == pytest.approx(28.3, rel=2e-3)
    # a few W/(m^2 K): the range of free convection in gases (Incropera and DeWitt Table 1.1: 2-25)
    assert 2.0 < h < 25.0


def test_iso_15312_reference_heat_flow_of_the_6208():
    # ISO 15312:2018: A_r = pi B (D + d) = pi 18 (80 + 40) = 6786 mm^2, q_r = 0.016 W/mm^2 (A_r <= 50 000),
    # Phi_r = 108.6 W carried off at 50 K (70 degC outer ring over 20 degC ambient): 2.171 W/K
    assert cr.iso_15312_reference_area_mm2(40.0, 80.0, 18.0) == pytest.approx(6785.8, rel=1e-4)
    assert cr.iso_15312_dissipation_w_k(40.0, 80.0, 18.0) == pytest.approx(108.57 / 50.0, rel=1e-3)
    # above 50 000 mm^2: q_r = 0.016 (A_r / 50 000)^-0.34
    assert cr.iso_15312_reference_flux_w_mm2(100_000.0) == pytest.approx(0.016 * 2**-0.34, rel=1e-12)


def test_conduction_laws():
    # Fourier through a cylindrical shell and the Hertz spot's constriction 1/(2 k a), a = sqrt(a b)
    assert cr.cylindrical_shell_w_k(0.02, 0.03, 0.018, 46.6) == pytest.approx(
        2 * math.pi * 46.6 * 0.018 / math.log(1.5), rel=1e-12
    )
    assert cr.hertz_constriction_w_k(1.6e-3, 0.25e-3, 46.6) == pytest.approx(2 * 46.6 * math.sqrt(4e-7), rel=1e-12)
    # Becker's rotating shaft: Nu = 0.133 Re^(2/3) Pr^(1/3)
    re = 500.0 * 0.04**2 / (2 * AIR_KINEMATIC_VISCOSITY_M2_S)
    assert cr.rotating_cylinder_w_m2_k(0.04, 500.0) * 0.04 / AIR_CONDUCTIVITY_W_M_K == pytest.approx(
        0.133 * re ** (2 / 3) * AIR_PRANDTL ** (1 / 3), rel=1e-12
    )


def _network(settings=None, ambient=20.0):
    spec = catalog.bearing("6208")
    settings = settings or ThermalNetworkSettings()
    geo = network_geometry(spec, settings)
    axes = np.array([[1.5e-3, 0.2e-3]] * 4)
    op = Operating(1000.0, 400.0, 5000.0, axes, axes, np.full(6, 40.0), ambient, 3e-5)
    return geo, assemble(geo, op, spec, settings)


def test_geometry_of_the_6208():
    # d, D from d_m and D_w (D - d = D_w / 0.3): the seed 6208 (d_m = 60.6 mm, D_w = 12.6 mm) gives
    # d = 39.6 mm, D = 81.6 mm against the catalogue's 40 / 80 mm; the steel of a 6208 (0.37 kg with its
    # cage, SKF catalogue) is split into rings and balls
    geo, _ = _network()
    assert geo.bore_m == pytest.approx(0.040, rel=0.02)
    assert geo.outside_diameter_m == pytest.approx(0.080, rel=0.03)
    steel_kg = geo.capacity_j_k[1:4].sum() / 475.0
    assert steel_kg == pytest.approx(0.35, rel=0.25)


def test_exponential_step_is_exact_and_unconditionally_stable():
    # one step of h equals n steps of h / n (the exact flow of the linear network) for any h, however
    # long against the fastest time constant, and T -> the steady state K^-1 b
    _, net = _network()
    q = np.array([0.0, 40.0, 40.0, 20.0, 0.0, 0.0])
    t0 = np.full(6, 20.0)
    tau = net.time_constants_s()
    assert tau[-1] < 10.0 < 300.0 < tau[0]  # balls in seconds, the housing in many minutes
    for h in (1.0, 100.0, 1e4):
        one = step_c(net, t0, 1.0, 20.0, 20.0, q, h)
        many = t0
        for _ in range(16):
            many = step_c(net, many, 1.0, 20.0, 20.0, q, h / 16)
        assert np.allclose(one, many, atol=1e-9)
    inf = steady_state_c(net, 1.0, 20.0, 20.0, q)
    assert np.allclose(step_c(net, t0, 1.0, 20.0, 20.0, q, 100 * tau[0]), inf, atol=1e-9)
    # energy balance of the steady state: the heat in leaves to the surroundings
    out = float(np.sum(net.ambient_w_k * (inf - 20.0)))
    assert out == pytest.approx(q.sum(), rel=1e-9)


def test_single_node_against_the_analytic_response():
    # C dT/dt = -G (T - Ta) + q: T(t) = Ta + q/G + (T0 - Ta - q/G) exp(-G t / C)
    c, g, q = 500.0, 2.0, 60.0
    net = Network(np.array([c]), np.zeros((1, 1)), np.array([g]), np.zeros(1))
    for t in (10.0, 250.0, 5000.0):
        hand = 20.0 + q / g + (0.0 - q / g) * math.exp(-g * t / c)
        assert step_c(net, np.array([20.0]), 1.0, 20.0, 20.0, np.array([q]), t)[0] == pytest.approx(hand, rel=1e-12)


def test_heat_capacity_scale_speeds_time_not_the_steady_state():
    slow_geo, slow = _network()
    fast_geo, fast = _network(ThermalNetworkSettings(heat_capacity_scale=1e-3))
    assert np.allclose(fast_geo.capacity_j_k, 1e-3 * slow_geo.capacity_j_k)
    assert np.allclose(fast.time_constants_s(), 1e-3 * slow.time_constants_s(), rtol=1e-9)
    q = np.array([0.0, 40.0, 40.0, 20.0, 0.0, 0.0])
    assert np.allclose(steady_state_c(fast, 1.0, 20.0, 20.0, q), steady_state_c(slow, 1.0, 20.0, 20.0, q))


def test_iso_dissipation_settles_the_outer_ring_at_70_for_the_reference_heat():
    # ISO 15312 in the network: with the standard's dissipation the reference heat flow q_r A_r, put into
    # the contacts, brings the rings to 70 degC over 20 degC ambient; the outer ring within the internal
    # gradient (its seat takes D / (D + d) of the dissipation)
    settings = ThermalNetworkSettings(dissipation="iso_15312")
    geo, net = _network(settings)
    phi_r = geo.iso_15312_dissipation_w_k * 50.0
    per = np.zeros((18, 3))
    per[:, 0] = phi_r / 18
    inf = steady_state_c(net, 1.0, 20.0, 20.0, HeatSources(per).node_heat_w())
    assert inf[NODE_NAMES.index("outer_ring")] == pytest.approx(70.0, abs=3.0)
    assert inf[NODE_NAMES.index("inner_ring")] == pytest.approx(70.0, abs=3.0)


def test_transition_equals_the_pade_exponential():
    # the eigen form of exp(-C^-1 K h) against scipy's Pade expm, real and accelerated capacities
    for scale in (1.0, 1e-3):
        _, net = _network(ThermalNetworkSettings(heat_capacity_scale=scale))
        for h in (1e-3, 1.0, 100.0):
            ref = expm(-net.stiffness(1.0) / net.capacity_j_k[:, None] * h)
            assert np.allclose(transition(net, 1.0, h), ref, atol=1e-10, rtol=1e-9)
