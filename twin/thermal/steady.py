"""The bearing's thermal steady state with the engine in the loop (fixed-point iteration).

The network's steady state T_inf = K^-1 b (twin.thermal.integrator) depends on the friction
heat, which depends on the film's viscosity at the inlet temperature, which the network sets.
`steady_state` iterates: run the engine with the film at the inlet temperature for `settle_s`
(ModelOptions.thermal = 'fixed', the setpoint's oil temperature = the inlet temperature), take
its heat by source from the contact lanes and its drive power (twin.thermal.sources), assemble
the network at that operating point, solve for the steady temperatures, and repeat with the new
inlet temperature (under-relaxed by `relaxation`) until it moves by less than `tolerance_k`.
The heat capacities play no part: a real and an accelerated bearing reach this same state.
The clearance is the spec's (the expansion's effect on the load distribution is the
transient's, twin.thermal.coupling).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from twin.kernels import layout as L
from twin.thermal.coupling import ThermalCoupling
from twin.thermal.integrator import steady_state_c
from twin.thermal.network import NODE_NAMES, assemble
from twin.thermal.settings import ThermalNetworkSettings
from twin.thermal.sources import HeatSources, friction_heat


@dataclass(frozen=True)
class SteadyState:
    """The converged state."""

    temperatures_c: dict[str, float]   # per node [degC]
    inlet_temperature_c: float         # [degC]
    friction_torque_n_m: float         # mean over the last settle [N m]
    heat: HeatSources                  # by contact and source [W]
    viscosity_pa_s: float              # film inlet viscosity [Pa s]
    min_lambda: float | None           # smallest Lambda of the loaded contacts [-]
    iterations: int
    converged: bool
    time_constants_s: tuple[float, ...]   # the network's, real heat capacities, slowest first [s]


def steady_state(twin_factory, settings: ThermalNetworkSettings, ambient_c: float, *, settle_s: float = 0.03,
                 tolerance_k: float = 0.2, relaxation: float = 0.7, max_iterations: int = 12,
                 start_rise_k: float = 10.0) -> SteadyState:
    """`twin_factory(oil_temperature_c)`: a `Twin` with ModelOptions.thermal = 'fixed' at the
    operating point and that film temperature (the next iterations set it with set_setpoint)."""
    inlet = ambient_c + start_rise_k
    twin = twin_factory(inlet)
    coupling = ThermalCoupling(twin.model, settings, 1.0, ambient_c)
    converged, it = False, 0
    temps = np.full(len(NODE_NAMES), inlet)
    for it in range(1, max_iterations + 1):
        twin.set_setpoint(oil_temperature_c=inlet)
        twin.advance(settle_s)
        s = twin.state
        speed = float(s.scalars[L.X_SHAFT_SPEED])
        torque = float(twin.snapshot().friction_torque_n_m)
        heat = friction_heat(s.contacts, twin.model.ball_count, torque * speed,
                             twin.model.options.friction_model == "ellipse_traction")
        coupling.filter.x[:len(NODE_NAMES)] = temps
        spin = float(np.mean(np.linalg.norm(s.ball_angular_velocity_rad_s, axis=1)))
        net = assemble(coupling.geometry, coupling.operating_point(s.contacts, s.scalars, spin), twin.model.spec,
                       settings)
        temps = steady_state_c(net, 1.0, ambient_c, ambient_c, heat.node_heat_w())
        coupling.filter.x[:len(NODE_NAMES)] = temps
        new_inlet = coupling.inlet_temperature_c
        step = new_inlet - inlet
        inlet = inlet + relaxation * step
        if abs(step) < tolerance_k:
            converged = True
            break
    snap = twin.snapshot()
    lams = [c.lambda_ for b in snap.balls for c in (b.inner, b.outer) if c.lambda_ is not None]
    tau = net.time_constants_s(1.0) / settings.heat_capacity_scale
    return SteadyState({n: float(t) for n, t in zip(NODE_NAMES, temps)}, float(coupling.inlet_temperature_c),
                       torque, heat, float(snap.viscosity_pa_s), min(lams) if lams else None, it, converged,
                       tuple(float(x) for x in tau))
