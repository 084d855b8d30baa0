"""Exact exponential step of the linear network over a period with the heat held constant.

C dT/dt = -K T + b, b = G_amb s T_amb + G_sup T_sup + q constant over the period h:
T(t + h) = T_inf + exp(-C^-1 K h) (T(t) - T_inf), T_inf = K^-1 b (the steady state). Exact for
any h (no stability limit: the network's time constants run from a fraction of a second for the
balls to tens of minutes for the housing); the only error of the multirate coupling is holding
the heat and the conductances over the period, which twin.validation.thermal_studies.period_study measures.
"""

from __future__ import annotations

import numpy as np

from twin.thermal.network import Network


def forcing_w(
    net: Network, dissipation_factor: float, ambient_c: float, supply_c: float, heat_w: np.ndarray
) -> np.ndarray:
    """b = G_amb s T_amb + G_sup T_sup + q [W] (temperatures in degC: the network is linear)."""
    return net.ambient_w_k * dissipation_factor * ambient_c + net.supply_w_k * supply_c + heat_w


def steady_state_c(
    net: Network, dissipation_factor: float, ambient_c: float, supply_c: float, heat_w: np.ndarray
) -> np.ndarray:
    """T_inf = K^-1 b [degC]: the temperatures the held heat and conductances lead to."""
    return np.linalg.solve(
        net.stiffness(dissipation_factor), forcing_w(net, dissipation_factor, ambient_c, supply_c, heat_w)
    )


def transition(net: Network, dissipation_factor: float, period_s: float) -> np.ndarray:
    """Phi = exp(-C^-1 K h) [-], through the symmetric S = C^-1/2 K C^-1/2 (K symmetric, C > 0):
    S = V diag(lambda) V^T, Phi = C^-1/2 V diag(exp(-lambda h)) V^T C^1/2 (exact; an eigh of the
    6 x 6 costs a tenth of a Pade expm, whose scaling and squaring grows with the accelerated
    mode's small capacities)."""
    r = 1.0 / np.sqrt(net.capacity_j_k)
    lam, v = np.linalg.eigh(net.stiffness(dissipation_factor) * r[:, None] * r[None, :])
    return (r[:, None] * v) @ (np.exp(-lam * period_s)[:, None] * (v.T / r[None, :]))


def step_c(
    net: Network,
    temperature_c: np.ndarray,
    dissipation_factor: float,
    ambient_c: float,
    supply_c: float,
    heat_w: np.ndarray,
    period_s: float,
) -> np.ndarray:
    """T(t + h) by the exact exponential step [degC]."""
    t_inf = steady_state_c(net, dissipation_factor, ambient_c, supply_c, heat_w)
    return t_inf + transition(net, dissipation_factor, period_s) @ (temperature_c - t_inf)
