"""Kalman filter that makes the network follow a measured temperature by correcting its
dissipation to the surroundings.

The uncertain part of the network is what carries the heat away (the housing's convection,
its conduction into the frame, the shaft's): the filter estimates the factor s on those
conductances (twin.thermal.network: G_amb s). State x = [T_1..T_n, theta], theta = ln s
(s > 0 always), an extended Kalman filter (Simon, Optimal State Estimation, 2006, ch. 13.2;
joint state and parameter estimation, ch. 13.4):

* predict over the network period h with the exact exponential step (twin.thermal.integrator):
  T' = T_inf(theta) + Phi(theta)(T - T_inf(theta)), theta' = theta; F = [[Phi, dT'/dtheta],
  [0, 1]] (dT'/dtheta by a central difference), P' = F P F^T + Q, Q = diag(q_T h, q_theta h);
* update with a measured node temperature z (variance r): y = z - T_m, S = P_mm + r,
  K = P H^T / S, Joseph form for P.

The start temperatures (every node at the ambient) carry one offset common to all nodes
(`initial_temperature_sigma_k`, fully correlated): a twin started beside a bearing that is already
warm takes the first measurement's offset into every node at once.

A measurement whose innovation lies beyond `gate_sigma` standard deviations (sqrt(S)) is not
one the dissipation can explain (a network cannot jump; a heat burst from lubricant loss, an
overload, a failing bearing can): it is not assimilated and `unexplained` is raised while it
lasts (chi-square innovation gating, Bar-Shalom, Li and Kirubarajan, Estimation with
Applications to Tracking and Navigation, 2001, sec. 5.4.2).

Stated convergence time: `convergence_time_s` = 3 x the slowest time constant of the network.
A change of the dissipation shows in a temperature only through the slow mode, which reaches
95 % of its new value in 3 tau; the estimate cannot settle sooner, and settles by then when the
noise is small against the offset (tests/thermal/test_estimator.py).

Written here rather than taken from filterpy: filterpy's last release is 1.4.5 (2018), and the
filter is thirty lines of numpy around the network's own exact step.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from twin.thermal.integrator import steady_state_c, transition
from twin.thermal.network import N_NODES, Network

THETA_STEP = 1e-4  # central difference of dT'/dtheta [-]
THETA_BOUND = math.log(50.0)  # |ln s| kept within a factor 50 of the correlations [-]


@dataclass(frozen=True)
class EstimatorSettings:
    """Noise model of the filter."""

    measurement_sigma_k: float = 0.3  # sensor noise of a thermocouple / RTD reading [K]
    initial_temperature_sigma_k: float = 10.0  # the start temperatures, one offset common to every node [K]
    initial_theta_sigma: float = 0.7  # prior on ln s: the correlations within a factor 2 [-]
    theta_process_sigma_per_sqrt_s: float = 1e-3  # random walk of ln s [1/sqrt(s)]
    temperature_process_sigma_k_per_sqrt_s: float = 0.01  # model error of the node temperatures [K/sqrt(s)]
    gate_sigma: float = 5.0  # innovation gate [-]


def convergence_time_s(net: Network, dissipation_factor: float = 1.0) -> float:
    """The filter's stated convergence time: 3 x the network's slowest time constant [s] (module
    docstring), in the network's time (its heat capacities as given)."""
    return 3.0 * float(net.time_constants_s(dissipation_factor)[0])


class DissipationEstimator:
    """Joint EKF over the node temperatures and the log dissipation factor."""

    def __init__(self, temperature_c: np.ndarray, settings: EstimatorSettings | None = None):
        self.settings = settings or EstimatorSettings()
        self.x = np.concatenate([np.asarray(temperature_c, dtype=float), [0.0]])
        self.p = np.zeros((N_NODES + 1, N_NODES + 1))
        self.p[:N_NODES, :N_NODES] = self.settings.initial_temperature_sigma_k**2
        self.p[N_NODES, N_NODES] = self.settings.initial_theta_sigma**2
        self.residual_k: float | None = None
        self.innovation_sigma_k: float | None = None
        self.unexplained = False
        self.measurements = 0

    @property
    def temperature_c(self) -> np.ndarray:
        """Node temperatures [degC]."""
        return self.x[:N_NODES]

    @property
    def dissipation_factor(self) -> float:
        """s = exp(theta) [-]."""
        return math.exp(self.x[N_NODES])

    @property
    def dissipation_factor_sigma(self) -> float:
        """Standard deviation of s, s sigma_theta to first order [-]."""
        return self.dissipation_factor * math.sqrt(max(self.p[N_NODES, N_NODES], 0.0))

    def _propagate(self, net: Network, theta: float, temps: np.ndarray, b_args: tuple, h: float):
        s = math.exp(theta)
        t_inf = steady_state_c(net, s, *b_args)
        phi = transition(net, s, h)
        return t_inf + phi @ (temps - t_inf), phi

    def predict(
        self,
        net: Network,
        ambient_c: float,
        supply_c: float,
        heat_w: np.ndarray,
        period_s: float,
        capacity_scale: float = 1.0,
    ) -> None:
        """Advance the state and covariance over one network period [s] of network time
        (`capacity_scale`: the heat-capacity factor, which speeds the network's time by its inverse;
        the noise densities are per second of network time)."""
        b_args = (ambient_c, supply_c, heat_w)
        theta = self.x[N_NODES]
        new_t, phi = self._propagate(net, theta, self.x[:N_NODES], b_args, period_s)
        up, _ = self._propagate(net, theta + THETA_STEP, self.x[:N_NODES], b_args, period_s)
        dn, _ = self._propagate(net, theta - THETA_STEP, self.x[:N_NODES], b_args, period_s)
        f = np.eye(N_NODES + 1)
        f[:N_NODES, :N_NODES] = phi
        f[:N_NODES, N_NODES] = (up - dn) / (2.0 * THETA_STEP)
        st = self.settings
        h_net = period_s / capacity_scale
        q = np.full(N_NODES + 1, st.temperature_process_sigma_k_per_sqrt_s**2 * h_net)
        q[N_NODES] = st.theta_process_sigma_per_sqrt_s**2 * h_net
        self.x[:N_NODES] = new_t
        self.p = f @ self.p @ f.T + np.diag(q)

    def update(self, node: int, measured_c: float) -> float:
        """Assimilate a measured temperature of `node` [degC]; returns the residual measured -
        predicted before the update [K]."""
        st = self.settings
        r = st.measurement_sigma_k**2
        y = float(measured_c - self.x[node])
        s = float(self.p[node, node] + r)
        self.residual_k = y
        self.innovation_sigma_k = math.sqrt(s)
        self.measurements += 1
        if abs(y) > st.gate_sigma * math.sqrt(s):
            self.unexplained = True
            return y
        self.unexplained = False
        k = self.p[:, node] / s
        self.x = self.x + k * y
        self.x[N_NODES] = min(max(self.x[N_NODES], -THETA_BOUND), THETA_BOUND)
        i_kh = np.eye(N_NODES + 1)
        i_kh[:, node] -= k
        self.p = i_kh @ self.p @ i_kh.T + r * np.outer(k, k)
        return y
