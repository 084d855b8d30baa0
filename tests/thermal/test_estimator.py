"""The dissipation Kalman filter follows a measured outer-ring temperature and flags heat the friction
cannot explain (twin.thermal.estimator)."""

import numpy as np
import pytest

from twin import catalog
from twin.thermal.estimator import DissipationEstimator, EstimatorSettings, convergence_time_s
from twin.thermal.integrator import steady_state_c, step_c
from twin.thermal.network import NODE_NAMES, Operating, assemble, network_geometry
from twin.thermal.settings import ThermalNetworkSettings

OUTER = NODE_NAMES.index("outer_ring")
HEAT_W = np.array([0.0, 60.0, 60.0, 60.0, 0.0, 0.0])  # 180 W: the 6208 at 1000 rad/s, 3 kN (tests/thermal)


def _net():
    spec = catalog.bearing("6208")
    settings = ThermalNetworkSettings()
    geo = network_geometry(spec, settings)
    axes = np.array([[1.5e-3, 0.2e-3]] * 4)
    return assemble(geo, Operating(1000.0, 400.0, 5000.0, axes, axes, np.full(6, 40.0), 20.0, 3e-5), spec, settings)


def _factor_for_offset(net, offset_k):
    """The dissipation factor whose steady outer ring lies offset_k above the nominal's (bisection)."""
    nominal = steady_state_c(net, 1.0, 20.0, 20.0, HEAT_W)[OUTER]
    lo, hi = 0.05, 1.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if steady_state_c(net, mid, 20.0, 20.0, HEAT_W)[OUTER] - nominal > offset_k:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def test_follows_a_bearing_8_k_warmer_and_raises_on_an_unexplained_20_k_step():
    net = _net()
    s_true = _factor_for_offset(net, 8.0)
    settings = EstimatorSettings(measurement_sigma_k=0.3)
    rng = np.random.default_rng(24)
    period = 30.0
    t_conv = convergence_time_s(net)
    truth = np.full(6, 20.0)
    est = DissipationEstimator(np.full(6, 20.0), settings)
    nominal = np.full(6, 20.0)
    residuals, times = [], []
    n = int(2.5 * t_conv / period)
    for k in range(n):
        truth = step_c(net, truth, s_true, 20.0, 20.0, HEAT_W, period)
        nominal = step_c(net, nominal, 1.0, 20.0, 20.0, HEAT_W, period)
        est.predict(net, 20.0, 20.0, HEAT_W, period)
        residuals.append(est.update(OUTER, truth[OUTER] + rng.normal(0.0, 0.3)))
        times.append((k + 1) * period)
        if (k + 1) * period <= t_conv < (k + 2) * period:
            at_conv = (est.dissipation_factor, est.dissipation_factor_sigma)
    # the measured bearing runs 8 K above the nominal network's prediction at the end
    assert truth[OUTER] - nominal[OUTER] == pytest.approx(8.0, abs=0.3)
    # the estimate has converged by the stated time (3 x the slowest time constant): within 5 % and its 2 sigma
    s_hat, sigma = at_conv
    assert abs(s_hat - s_true) < max(2.0 * sigma, 0.0) and abs(s_hat / s_true - 1.0) < 0.05, (s_hat, sigma, s_true)
    # and the residual has returned within the noise: RMS over the last quarter below 1.5 x sigma_sensor
    late = np.array(residuals[-len(residuals) // 4 :])
    assert np.sqrt(np.mean(late**2)) < 1.5 * 0.3
    assert not est.unexplained
    # a +20 K step the dissipation cannot explain: gated, not assimilated, flagged while it lasts
    before = est.dissipation_factor
    for _ in range(3):
        truth = step_c(net, truth, s_true, 20.0, 20.0, HEAT_W, period)
        est.predict(net, 20.0, 20.0, HEAT_W, period)
        r = est.update(OUTER, truth[OUTER] + 20.0 + rng.normal(0.0, 0.3))
        assert est.unexplained and r == pytest.approx(20.0, abs=1.5)
    assert est.dissipation_factor == pytest.approx(before, rel=0.01)
    # back to what the network explains: assimilated again
    est.predict(net, 20.0, 20.0, HEAT_W, period)
    est.update(OUTER, truth[OUTER])
    assert not est.unexplained


def test_stated_convergence_time_is_three_slowest_time_constants():
    net = _net()
    assert convergence_time_s(net) == pytest.approx(3.0 * net.time_constants_s()[0], rel=1e-12)
