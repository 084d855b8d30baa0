"""Thermal studies with the engine in the loop: the start-up transient from cold and the
convergence study of the network's period (offline: seconds of simulated time each).

`startup_transient` runs a `Twin` with ModelOptions.thermal = 'network' from every node at the
ambient temperature and samples its thermal block, viscosity, smallest Lambda and friction
torque; `period_study` runs it at several network periods and measures the largest deviation of
the node temperatures from the finest period's.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from twin import catalog
from twin.engine import Twin
from twin.setpoint import Setpoint
from twin.spec import ModelOptions
from twin.thermal.network import NODE_NAMES, Network, coupled_time_constants_s
from twin.thermal.settings import ThermalNetworkSettings
from twin.thermal.sources import RING_SHARE


@dataclass(frozen=True)
class Transient:
    """Samples of a transient (network time [s]; per-node temperatures [degC])."""

    network_time_s: np.ndarray
    temperatures_c: np.ndarray  # (n, nodes)
    viscosity_pa_s: np.ndarray  # inlet viscosity
    min_lambda: np.ndarray  # smallest Lambda of the loaded contacts
    friction_torque_n_m: np.ndarray  # mean over the last network period (its heat / shaft speed)
    heat_w: np.ndarray  # total friction heat
    shear_rise_k: np.ndarray  # inlet shear heating's equivalent temperature rise (Thermal.shear_heating)
    time_constants_s: tuple[float, ...]  # the network's at the end, real heat capacities, slowest first
    heat_capacity_scale: float
    network: Network  # as assembled at the last network step (heat capacities scaled)


def startup_transient(
    designation: str = "6208",
    shaft_speed_rad_s: float = 1000.0,
    radial_load_n: float = 3000.0,
    ambient_c: float = 20.0,
    duration_network_s: float = 1800.0,
    heat_capacity_scale: float = 1e-3,
    thermal_step_s: float = 1.0,
    sample_every_network_s: float = 30.0,
    settings: ThermalNetworkSettings | None = None,
    lubricant=None,
) -> Transient:
    """The start-up from cold: every node at `ambient_c`, the shaft at speed from the warm start."""
    net_settings = (settings or ThermalNetworkSettings()).model_copy(
        update={"heat_capacity_scale": heat_capacity_scale}
    )
    spec = catalog.bearing(designation, lubricant=lubricant) if lubricant is not None else designation
    options = ModelOptions(thermal="network", thermal_period_s=thermal_step_s, thermal_network=net_settings)
    twin = Twin(
        spec,
        options=options,
        setpoint=Setpoint(
            shaft_speed_rad_s=shaft_speed_rad_s, radial_load_n=radial_load_n, oil_temperature_c=ambient_c
        ),
    )
    coupling = twin.thermal
    if coupling is None:
        raise ValueError("thermal: the transient needs ModelOptions.thermal = 'network'")
    dt_sim = sample_every_network_s * heat_capacity_scale
    n = int(round(duration_network_s / sample_every_network_s))
    rows = []
    snap = twin.snapshot()
    rows.append(_row(snap, 0.0))
    for _ in range(n):
        twin.advance(dt_sim)
        snap = twin.snapshot()
        rows.append(_row(snap, coupling.network_time_s))
    if coupling.network is None:
        raise ValueError(f"duration_network_s = {duration_network_s!r}: shorter than one network step")
    a = np.array(rows)
    tau = tuple(float(x) for x in coupling.time_constants_s())
    return Transient(
        a[:, 0],
        a[:, 1 : 1 + len(NODE_NAMES)],
        a[:, -5],
        a[:, -4],
        a[:, -3],
        a[:, -2],
        a[:, -1],
        tau,
        heat_capacity_scale,
        coupling.network,
    )


def _row(snap, t: float) -> list[float]:
    th = snap.thermal
    lams = [c.lambda_ for b in snap.balls for c in (b.inner, b.outer) if c.lambda_ is not None]
    heat = sum(th.heat_w.values())
    torque = heat / snap.shaft_speed_rad_s if t > 0.0 and snap.shaft_speed_rad_s > 0.0 else snap.friction_torque_n_m
    return [
        t,
        *(th.temperatures_c[n] for n in NODE_NAMES),
        snap.viscosity_pa_s,
        min(lams) if lams else float("nan"),
        torque,
        heat,
        snap.electrical.shear_temperature_rise_k,
    ]


def period_study(
    thermal_steps_s=(1.0, 5.0, 20.0, 50.0), heat_capacity_scale: float = 1e-3, **transient
) -> dict[float, float]:
    """Largest |T_node(step) - T_node(finest step)| over the nodes and the reference's sample times
    after the first network step of the coarsest [K], per network step in thermal time [s]
    (ModelOptions.thermal_period_s; each run's samples are interpolated in network time onto the
    finest run's)."""
    runs = {
        h: startup_transient(thermal_step_s=h, heat_capacity_scale=heat_capacity_scale, **transient)
        for h in thermal_steps_s
    }
    ref = runs[min(thermal_steps_s)]
    t = ref.network_time_s
    keep = t >= max(thermal_steps_s)
    out = {}
    for h, r in runs.items():
        dev = [
            np.abs(np.interp(t[keep], r.network_time_s, r.temperatures_c[:, k]) - ref.temperatures_c[keep, k]).max()
            for k in range(len(NODE_NAMES))
        ]
        out[h] = float(max(dev))
    return out


INLET_WEIGHTS = np.array([0.0, 0.25, 0.5, 0.25, 0.0, 0.0])  # T_in = (T_i + T_o + 2 T_b) / 4 (twin.thermal.coupling)
HEAT_SHARE = np.array([0.0, 0.5 * RING_SHARE, 1.0 - RING_SHARE, 0.5 * RING_SHARE, 0.0, 0.0])  # inner ~ outer heat


def heat_slope_w_k(tr: Transient, after_s: float = 300.0) -> float:
    """dP/dT_in of the transient: least-squares slope of the friction heat against the inlet
    temperature over the samples after `after_s` of network time [W/K]."""
    t_in = tr.temperatures_c @ INLET_WEIGHTS
    m = tr.network_time_s >= after_s
    return float(np.polyfit(t_in[m], tr.heat_w[m], 1)[0])


def transient_time_constants_s(tr: Transient) -> np.ndarray:
    """The time constants the network (as assembled at the end of `tr`) states with the friction's
    feedback measured in `tr` (twin.thermal.network.coupled_time_constants_s), real heat
    capacities, slowest first [s]."""
    scaled = coupled_time_constants_s(tr.network, heat_slope_w_k(tr), HEAT_SHARE, INLET_WEIGHTS)
    return scaled / tr.heat_capacity_scale


def decay_time_constant_s(tr: Transient, node: int, start_s: float = 600.0, floor_k: float = 0.3) -> float:
    """Time constant of a node's late approach to its end value [s]: the log-linear fit of
    T_end - T(t) over the samples after `start_s` of network time (the fast modes gone) while the
    deficit exceeds floor_k (above the noise)."""
    deficit = tr.temperatures_c[-1, node] - tr.temperatures_c[:, node]
    t = tr.network_time_s
    m = (t >= start_s) & (deficit > floor_k)
    rate = -np.polyfit(t[m], np.log(deficit[m]), 1)[0]
    return float(1.0 / rate)
