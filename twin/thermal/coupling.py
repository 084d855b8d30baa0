"""`ThermalCoupling`: the thermal network in the loop of a `Twin`, at its own multirate period.

Every `period_s` of simulated time (ModelOptions.thermal_period_s of thermal time times the
heat-capacity scale, a whole number of milliseconds; `Twin.advance` ends a frame there) the twin hands it the
engine's contact lanes and its drive power; it turns them into heat by contact and source
(twin.thermal.sources, or the friction laws' own split when the engine states it), assembles
the network at the operating point (twin.thermal.network), advances the node temperatures by
the exact exponential step inside the dissipation estimator (twin.thermal.estimator; without a
measurement its prediction is the network's own), and assimilates the latest measured
temperature. It gives back:

* the contacts' inlet temperature, which sets the film's viscosity: the mean of the surfaces
  bounding the inlets, (T_inner + T_outer + 2 T_ball) / 4 (the engine reads one viscosity for all
  contacts; the inlet oil takes the temperature of the surfaces that drag it in, Harris and
  Kotzalas, Advanced Concepts of Bearing Technology, 2007, ch. 7);
* the rings' and balls' expansion over their start temperature (twin.thermal.expansion), which
  the twin writes into the contacts' groove radii.

The setpoint's oil temperature is the ambient (sump) or the oil-inlet (circulating) temperature.
The network starts with every node at it; a change of it shifts every node by the change (the
linear network's settled response to its surroundings; the friction's rise above them is kept),
so a twin that sets an oil temperature starts from the viscosity of that temperature.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from twin.kernels import layout as L
from twin.physics.viscosity import kinematic_viscosity_m2_s
from twin.snapshot import ThermalState
from twin.thermal.estimator import DissipationEstimator, EstimatorSettings
from twin.thermal.expansion import Expansion, expansion
from twin.thermal.network import (
    BALLS,
    INNER_RING,
    NODE_NAMES,
    OIL,
    OUTER_RING,
    Network,
    Operating,
    assemble,
    network_geometry,
)
from twin.thermal.settings import ThermalNetworkSettings
from twin.thermal.sources import HeatSources

MEASURABLE_NODES = ("outer_ring", "housing", "oil")
TEMPERATURE_RANGE_C = (-60.0, 400.0)
"""The temperatures the network takes, measured or held [degC]: the range of an industrial RTD or
thermocouple on a bearing, wide of any oil's; beyond it a node has run away."""
RATE_WINDOW_S = 60.0  # the outer ring's rate of rise is taken over this much network time [s]


@dataclass(frozen=True)
class Measurement:
    """A measured node temperature [degC] at simulated time [s]."""

    node: str
    temperature_c: float
    time_s: float


class ThermalCoupling:
    """The network's state and its exchange with the engine (see the module docstring)."""

    def __init__(
        self,
        model,
        settings: ThermalNetworkSettings,
        period_s: float,
        ambient_c: float,
        estimator: EstimatorSettings | None = None,
    ):
        self.model = model
        self.settings = settings
        self.period_s = period_s
        self.geometry = network_geometry(model.spec, settings)
        self.ambient_c = float(ambient_c)
        self.reference_c = np.full(len(NODE_NAMES), self.ambient_c)
        self.filter = DissipationEstimator(self.reference_c.copy(), estimator)
        self.heat = HeatSources(per_contact_w=np.zeros((2 * model.ball_count, 3)))
        self.network: Network | None = None
        self.network_time_s = 0.0  # thermal time: simulated time / heat_capacity_scale [s]
        self.since_step_s = 0.0
        self.pending: Measurement | None = None
        self.last_measurement: Measurement | None = None
        # (network time [s], outer ring [degC]) over the last RATE_WINDOW_S, from the start's temperature
        self._rate_history: list[tuple[float, float]] = [(0.0, self.ambient_c)]
        self._time_constants: tuple[Network, float, np.ndarray] | None = None  # (network, s, tau) of the last call
        self._work_j = 0.0
        self._work_s = 0.0
        self._block: tuple[tuple, ThermalState] | None = None  # (state key, block) of the last call

    # ---- inputs -----------------------------------------------------------------------------
    @property
    def accelerated(self) -> bool:
        """True when the heat capacities are scaled down (ThermalNetworkSettings.heat_capacity_scale < 1)."""
        return self.settings.heat_capacity_scale < 1.0

    def set_ambient(self, ambient_c: float) -> None:
        """A new ambient / oil-inlet temperature [degC]: every node shifts by the change, and so
        does the rate's history (the shift is the new reference, not a rise of the ring)."""
        shift = float(ambient_c) - self.ambient_c
        if shift != 0.0:
            self.filter.x[: len(NODE_NAMES)] += shift
            self.reference_c += shift
            self._rate_history = [(t, c + shift) for t, c in self._rate_history]
            self.ambient_c = float(ambient_c)

    def measure(self, node: str, temperature_c: float, time_s: float) -> None:
        """Hand in a measured temperature of `node` (MEASURABLE_NODES) [degC]; assimilated at the
        next network step. Raises ValueError naming the field and its range."""
        if node not in MEASURABLE_NODES:
            raise ValueError(f"node: {node!r} cannot be measured; one of {', '.join(MEASURABLE_NODES)}")
        low, high = TEMPERATURE_RANGE_C
        if not (math.isfinite(temperature_c) and low <= temperature_c <= high):
            raise ValueError(f"temperature_c = {temperature_c!r}: must be finite, in [{low:g}, {high:g}] degC")
        self.pending = Measurement(node, float(temperature_c), float(time_s))

    # ---- outputs ----------------------------------------------------------------------------
    @property
    def temperature_c(self) -> np.ndarray:
        """Node temperatures [degC] (NODE_NAMES)."""
        return self.filter.temperature_c

    @property
    def inlet_temperature_c(self) -> float:
        """The contacts' inlet temperature [degC] (module docstring)."""
        t = self.temperature_c
        return float(0.25 * (t[INNER_RING] + t[OUTER_RING] + 2.0 * t[BALLS]))

    @property
    def expansion(self) -> Expansion:
        """Growth of the raceways and balls over their start temperatures [m]."""
        g, rise = self.model.spec.geometry, self.temperature_c - self.reference_c
        return expansion(
            rise[INNER_RING],
            rise[OUTER_RING],
            rise[BALLS],
            g.inner_raceway_radius_m,
            g.outer_raceway_radius_m,
            g.ball_radius_m,
        )

    def dissipated_w(self) -> float:
        """Heat carried to the surroundings and the oil supply now [W]."""
        if self.network is None:
            return 0.0
        t = self.temperature_c
        s = self.filter.dissipation_factor
        return float(
            np.sum(self.network.ambient_w_k * s * (t - self.ambient_c))
            + np.sum(self.network.supply_w_k * (t - self.ambient_c))
        )

    def time_constants_s(self) -> np.ndarray:
        """The network's time constants at the last operating point, in network time (real heat
        capacities: divide the simulated time by heat_capacity_scale), slowest first [s]."""
        if self.network is None:
            return np.array([])
        net, factor = self.network, self.filter.dissipation_factor
        memo = self._time_constants
        if memo is None or memo[0] is not net or memo[1] != factor:
            # an eigenvalue problem per call (about 0.3 ms on the stepping thread at every snapshot);
            # network and factor change only at a network step, the snapshots come 50 times as often
            memo = self._time_constants = (
                net,
                factor,
                net.time_constants_s(factor) / self.settings.heat_capacity_scale,
            )
        return memo[2].copy()

    def rate_k_per_min(self) -> float:
        """Rise of the outer ring over the last minute of network time [K/min] (0 before two steps).
        Within the first minute the bearing counts as having stood at its starting temperature
        before the start (the rise since the start, over a minute): the first seconds of a warm-up
        are not extrapolated to a minute, which would read as a runaway."""
        h = self._rate_history
        if len(h) < 2 or h[-1][0] <= h[0][0]:
            return 0.0
        return 60.0 * (h[-1][1] - h[0][1]) / max(RATE_WINDOW_S, h[-1][0] - h[0][0])

    # ---- the step ---------------------------------------------------------------------------
    def add_work(self, drive_power_w: float, duration_s: float) -> None:
        """Count the drive power [W] of a frame of `duration_s` [s] (its mean torque x shaft speed)."""
        if math.isfinite(drive_power_w):
            self._work_j += drive_power_w * duration_s
            self._work_s += duration_s

    def take_mean_power_w(self) -> float:
        """Mean drive power over the frames counted since the last call [W] (the period's heat)."""
        power = self._work_j / self._work_s if self._work_s > 0.0 else 0.0
        self._work_j = self._work_s = 0.0
        return power

    def due(self, elapsed_s: float, dt_s: float) -> bool:
        """Count `elapsed_s` of simulated time; True when a network period is complete."""
        self.since_step_s += elapsed_s
        return self.since_step_s >= self.period_s - 0.5 * dt_s

    def steps_to_due(self, dt_s: float) -> int:
        """The fewest steps of `dt_s` [s] after which `due` holds (at least 1): a frame of the
        engine ends there, so the network steps every `period_s` whatever the caller's frames."""
        return max(1, math.ceil((self.period_s - self.since_step_s) / dt_s - 0.5 - 1e-9))

    def operating_point(self, contacts: np.ndarray, scalars: np.ndarray, ball_spin_rad_s: float) -> Operating:
        """The conductances' operating point from the engine's state."""
        z = self.model.ball_count
        c = contacts[:, : 2 * z]
        axes = np.stack([c[L.C_SEMI_MAJOR], c[L.C_SEMI_MINOR]], axis=1)
        loaded = c[L.C_LOAD] > 0.0
        inner = axes[0::2][loaded[0::2]]
        outer = axes[1::2][loaded[1::2]]
        lub = self.model.spec.lubricant
        oil_c = float(self.temperature_c[OIL])
        nu = kinematic_viscosity_m2_s(
            lub.kinematic_viscosity_40c_m2_s, lub.kinematic_viscosity_100c_m2_s, min(max(oil_c, -30.0), 250.0)
        )
        return Operating(
            float(scalars[L.X_SHAFT_SPEED]),
            float(scalars[L.X_CAGE_SPEED]),
            ball_spin_rad_s,
            inner,
            outer,
            self.temperature_c.copy(),
            self.ambient_c,
            nu,
        )

    def step(
        self,
        contacts: np.ndarray,
        scalars: np.ndarray,
        ball_spin_rad_s: float,
        time_s: float,
        heat: HeatSources,
    ) -> None:
        """Advance the network over the elapsed period with the heat of the engine's state
        (`heat`: twin.thermal.sources.friction_heat of the engine's contact powers)."""
        elapsed = self.since_step_s
        self.since_step_s = 0.0
        if elapsed <= 0.0:
            return
        self.heat = heat
        op = self.operating_point(contacts, scalars, ball_spin_rad_s)
        self.network = assemble(self.geometry, op, self.model.spec, self.settings)
        scale = self.settings.heat_capacity_scale
        self.filter.predict(self.network, self.ambient_c, self.ambient_c, self.heat.node_heat_w(), elapsed, scale)
        self.network_time_s += elapsed / scale
        if self.pending is not None:
            self.last_measurement = self.pending
            self.filter.update(NODE_NAMES.index(self.pending.node), self.pending.temperature_c)
            self.pending = None
        self._rate_history.append((self.network_time_s, float(self.temperature_c[OUTER_RING])))
        while len(self._rate_history) > 2 and self._rate_history[-1][0] - self._rate_history[1][0] >= RATE_WINDOW_S:
            self._rate_history.pop(0)

    def block(self) -> ThermalState:
        """The snapshot's `thermal` block (twin.snapshot.ThermalState). Every field is a function
        of the network's state (its time, ambient, estimator, heat sources and measurement), which
        changes at a network step, a new ambient or held temperatures, not between them: the
        block is made again only when that state differs from the last call's (a snapshot comes
        every frame, a network step every `period_s`)."""
        f = self.filter
        key = (
            self.network_time_s,
            self.ambient_c,
            f.x.tobytes(),
            f.p.tobytes(),
            f.residual_k,
            f.innovation_sigma_k,
            f.unexplained,
            id(self.heat),
            id(self.network),
            id(self.last_measurement),
        )
        memo = self._block
        if memo is not None and memo[0] == key:
            return memo[1]
        block = self._make_block()
        self._block = (key, block)
        return block

    def _make_block(self) -> ThermalState:
        per = self.heat.per_contact_w.sum(axis=1)
        f = self.filter
        m = self.last_measurement
        tau = self.time_constants_s()
        return ThermalState(
            accelerated=self.accelerated,
            heat_capacity_scale=self.settings.heat_capacity_scale,
            network_time_s=self.network_time_s,
            ambient_c=self.ambient_c,
            temperatures_c={n: float(t) for n, t in zip(NODE_NAMES, self.temperature_c)},
            inlet_temperature_c=self.inlet_temperature_c,
            heat_w=self.heat.by_source_w,
            heat_inner_contacts_w=float(per[0::2].sum()),
            heat_outer_contacts_w=float(per[1::2].sum()),
            dissipated_w=self.dissipated_w(),
            slowest_time_constant_s=float(tau[0]) if tau.size else None,
            clearance_change_m=self.expansion.diametral_clearance_change_m,
            outer_ring_rate_k_per_min=self.rate_k_per_min(),
            dissipation_factor=f.dissipation_factor,
            dissipation_factor_sigma=f.dissipation_factor_sigma,
            measured_node=m.node if m else None,
            measured_c=m.temperature_c if m else None,
            residual_k=f.residual_k,
            residual_sigma_k=f.innovation_sigma_k,
            unexplained_heating=f.unexplained,
        )
