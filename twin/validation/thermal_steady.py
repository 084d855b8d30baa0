"""The bearing's thermal steady state with the engine in the loop (fixed-point iteration).

The network's steady state T_inf = K^-1 b (twin.thermal.integrator) depends on the friction
heat, which depends on the film's viscosity at the inlet temperature and on the clearance, both
set by the network. `steady_state` iterates on a `Twin` with the network in the loop: run the
engine for `settle_s` at the node temperatures held (their drift over it is a few mK with real
heat capacities), take the heat by source of its last network period and the network it
assembled there (twin.thermal.coupling), solve for the steady temperatures, hold them
(under-relaxed by `relaxation`: viscosity and expansion follow at once, Twin.hold_thermal_state)
and repeat until the inlet temperature moves by less than `tolerance_k`. The heat capacities play
no part: a real and an accelerated bearing reach this same state.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from twin import catalog
from twin.engine import Twin
from twin.setpoint import Setpoint
from twin.spec import BearingSpec, ModelOptions
from twin.thermal.coupling import TEMPERATURE_RANGE_C
from twin.thermal.integrator import steady_state_c
from twin.thermal.network import NODE_NAMES
from twin.thermal.settings import ThermalNetworkSettings
from twin.thermal.sources import HeatSources

STEADY_PERIOD_S = 0.05  # network step of the steady iteration [s] (real heat capacities: 50 ms of simulated time)


@dataclass(frozen=True)
class SteadyState:
    """The converged state."""

    temperatures_c: dict[str, float]  # per node [degC]
    inlet_temperature_c: float  # [degC]
    friction_torque_n_m: float  # heat / shaft speed over the last network period [N m]
    heat: HeatSources  # by contact and source [W]
    viscosity_pa_s: float  # film inlet viscosity [Pa s]
    min_lambda: float | None  # smallest Lambda of the loaded contacts [-]
    clearance_change_m: float  # by thermal expansion [m]
    iterations: int
    converged: bool
    time_constants_s: tuple[float, ...]  # the network's, real heat capacities, slowest first [s]


RUNAWAY_C = TEMPERATURE_RANGE_C[1]  # the network's node range ends here: beyond it, no steady state


def steady_state(
    twin: Twin,
    *,
    settle_s: float = 0.1,
    tolerance_k: float = 0.1,
    relaxation: float = 0.6,
    max_iterations: int = 20,
    start_rise_k: float = 20.0,
) -> SteadyState:
    """Iterate `twin` (ModelOptions.thermal = 'network', real heat capacities, a network step
    shorter than `settle_s`) to its thermal steady state at its setpoint (module docstring)."""
    th = twin.thermal
    if th is None:
        raise ValueError("thermal: the steady state needs ModelOptions.thermal = 'network'")
    ambient = th.ambient_c
    temps = np.full(len(NODE_NAMES), ambient + start_rise_k)
    twin.hold_thermal_state(temps)
    converged, iterations = False, 0
    for iteration in range(1, max_iterations + 1):
        iterations = iteration
        twin.advance(settle_s)
        if th.network is None:
            raise ValueError(f"settle_s = {settle_s!r}: shorter than the network step (ModelOptions.thermal_period_s)")
        target = steady_state_c(th.network, th.filter.dissipation_factor, ambient, ambient, th.heat.node_heat_w())
        before = th.inlet_temperature_c
        temps = temps + relaxation * (target - temps)
        if not (np.all(np.isfinite(temps)) and temps.max() <= RUNAWAY_C):
            hottest = NODE_NAMES[int(np.nanargmax(np.where(np.isfinite(temps), temps, np.inf)))]
            raise ValueError(
                f"no thermal steady state at this operating point: the friction heat "
                f"({th.heat.total_w:.0f} W) drives the {hottest} past {RUNAWAY_C:g} degC, a thermal runaway "
                "(lower the speed or the load, or cool the bearing: jet or circulating oil)"
            )
        twin.hold_thermal_state(temps)
        if abs(th.inlet_temperature_c - before) < tolerance_k and np.max(np.abs(target - temps)) < 2 * tolerance_k:
            converged = True
            break
    snap = twin.snapshot()
    lams = [c.lambda_ for b in snap.balls for c in (b.inner, b.outer) if c.lambda_ is not None]
    speed = snap.shaft_speed_rad_s
    return SteadyState(
        {n: float(t) for n, t in zip(NODE_NAMES, temps)},
        float(th.inlet_temperature_c),
        th.heat.total_w / speed if speed > 0.0 else 0.0,
        th.heat,
        float(snap.viscosity_pa_s),
        min(lams) if lams else None,
        th.expansion.diametral_clearance_change_m,
        iterations,
        converged,
        tuple(float(x) for x in th.time_constants_s()),
    )


def steady_operating_point(
    designation: str,
    shaft_speed_rad_s: float,
    radial_load_n: float,
    axial_load_n: float = 0.0,
    ambient_c: float = 20.0,
    settings: ThermalNetworkSettings | None = None,
    lubricant=None,
    spec: BearingSpec | None = None,
) -> dict:
    """The steady state of a catalogue bearing (or of `spec`, which then replaces the designation's
    catalogue entry and `lubricant`) at one operating point, as a plain dict (SI, temperatures in
    degC): node temperatures, friction torque, heat by source and by ring."""
    settings = (settings or ThermalNetworkSettings()).model_copy(update={"heat_capacity_scale": 1.0})
    spec = spec if spec is not None else catalog.bearing(designation, lubricant=lubricant)
    options = ModelOptions(thermal="network", thermal_period_s=STEADY_PERIOD_S, thermal_network=settings)
    twin = Twin(
        spec,
        options=options,
        setpoint=Setpoint(
            shaft_speed_rad_s=shaft_speed_rad_s,
            radial_load_n=radial_load_n,
            axial_load_n=axial_load_n,
            oil_temperature_c=ambient_c,
        ),
    )
    ss = steady_state(twin)
    per = ss.heat.per_contact_w.sum(axis=1)
    return {
        "bearing": spec.designation,
        "shaft_speed_rad_s": shaft_speed_rad_s,
        "radial_load_n": radial_load_n,
        "axial_load_n": axial_load_n,
        "ambient_c": ambient_c,
        "dissipation": settings.dissipation,
        "temperatures_c": ss.temperatures_c,
        "inlet_temperature_c": ss.inlet_temperature_c,
        "friction_torque_n_m": ss.friction_torque_n_m,
        "heat_w": ss.heat.by_source_w,
        "heat_total_w": ss.heat.total_w,
        "heat_inner_contacts_w": float(per[0::2].sum()),
        "heat_outer_contacts_w": float(per[1::2].sum()),
        "viscosity_pa_s": ss.viscosity_pa_s,
        "min_lambda": ss.min_lambda,
        "clearance_change_m": ss.clearance_change_m,
        "iterations": ss.iterations,
        "converged": ss.converged,
        "time_constants_s": list(ss.time_constants_s),
    }
