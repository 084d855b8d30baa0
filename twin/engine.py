"""`Twin`: the Python face of the engine (set_setpoint, advance, snapshot).

It owns one immutable `BearingModel` and one mutable `TwinState` and calls the compiled
`step_n(model arrays, state arrays, setpoint vector, n)` once per frame. No threads, no I/O.
"""

from __future__ import annotations

import copy
import math
from typing import Any

import numpy as np

from twin import catalog, state_measures
from twin.accelerometer import SensorReader, WaveformBlock
from twin.electrical_network import ElectricalNetwork, bearing_network
from twin.faults import Fault, FaultKind
from twin.friction_power import (
    REST_SPEED_RAD_S,
    FrictionPower,
    contact_powers_w,
    frame_friction_torque_n_m,
    friction_power_by_source,
    seal_moment_n_m,
    seal_power_w,
)
from twin.inlet_film import COUPLING_PERIOD_S, InletFilm
from twin.kernels import layout as L
from twin.kernels.step import evaluate, step_n
from twin.kernels.structures import ModelArrays, StateArrays
from twin.life.monitor import LifeMonitor
from twin.life.settings import LifeSettings
from twin.model import BearingModel, make_model
from twin.physics.thermal import MAX_CURRENT_HEATING_K, current_heating_temperature_rise_k
from twin.physics.viscosity import density_kg_m3, dynamic_viscosity_pa_s, temperature_viscosity_coefficient_k_inv
from twin.setpoint import Admitted, Setpoint, SetpointLimits, SetpointUpdate
from twin.snapshot import FrictionPowerState, LifeState, Snapshot, ThermalState
from twin.snapshot_blocks import ball_arrays, electrical_state, finite_or_none
from twin.snapshot_frame import SnapshotFrame
from twin.spec import BearingSpec, ModelOptions
from twin.state import MAX_DEFECTS, TwinState, make_state
from twin.thermal.coupling import TEMPERATURE_RANGE_C, ThermalCoupling
from twin.thermal.expansion import write_groove_lanes
from twin.thermal.sources import friction_heat
from twin.timestep import STEP_DIVISOR_S
from twin.vibration.defects import BallDefect, defect_row, validate_defects
from twin.warmstart import place_on_housing, warm_start

# simulated time per compiled call of `advance` by default [s]: the inlet's refresh period (also the
# life's default refresh_s), so each call ends where one is due and the Python between calls runs
# once per refresh
FRAME_S = COUPLING_PERIOD_S
RESTART_WINDOW_S = 0.01  # a second failure this soon after a restart halts the twin


def _xyz(vector: np.ndarray) -> tuple[float, float, float]:
    """The first three components of a state vector (x, y, z) as floats."""
    return float(vector[0]), float(vector[1]), float(vector[2])


class Twin:
    """A running bearing twin.

    >>> twin = Twin("6208")                       # warm-started at 500 rad/s, 3000 N
    >>> twin.set_setpoint(radial_load_n=5000.0)   # partial update
    >>> twin.advance(0.01)                        # 10 ms of simulated time
    >>> twin.snapshot().balls[0].inner.load_n
    """

    def __init__(
        self,
        bearing: str | BearingSpec = "6208",
        *,
        options: ModelOptions | None = None,
        setpoint: Setpoint | None = None,
        bearing_id: str = "default",
        diametral_clearance_m: float | None = None,
        warm: bool = True,
        life: LifeSettings | None = None,
    ):
        spec = bearing if isinstance(bearing, BearingSpec) else catalog.bearing(bearing)
        if diametral_clearance_m is not None:
            mounting = spec.mounting.model_copy(update={"diametral_clearance_m": diametral_clearance_m})
            spec = BearingSpec.model_validate({**spec.model_dump(), "mounting": mounting.model_dump()})
        self.bearing_id = bearing_id
        self.model: BearingModel = make_model(spec, options)
        self._effective_mu = self.model.options.friction_model == "ellipse_traction"
        self.state: TwinState = make_state(self.model)
        self.life_monitor = LifeMonitor(self.model, life)  # rating life and damage (twin.life)
        self._setpoint_vector = np.zeros(L.N_SETPOINT)
        self._setpoint = Setpoint()
        self.limits: SetpointLimits = SetpointLimits.for_model(self.model)
        """Allowed [low, high] of each setpoint field for this bearing (twin.setpoint)."""
        self.seq = 0
        self.restarts = 0
        self.frame_interrupted = False  # the last advance ended early (interrupt_frame)
        self.fault: Fault | None = None  # the last fault (None: none since start or the last new setpoint)
        self.halted = False
        self._last_restart_time_s = -math.inf
        self._last_good_time_s = 0.0
        self._last_torque_n_m = 0.0
        self._contact_torque_n_m = 0.0  # friction torque of the contacts over the last frame [N m]
        self.inlet = InletFilm(self.model)
        """The inlet's film losses and the balls' drag (twin.inlet_film), refreshed between frames."""
        self._seal_moment_n_m = seal_moment_n_m(spec)
        self._defects: tuple = ()  # the active local defects (twin.vibration.defects)
        self._sensor = SensorReader(self.model) if self.model.housing_on else None
        self._frozen_vibration = None  # a frozen copy's last window (`frozen`); the live twin reads its sensor
        self.thermal: ThermalCoupling | None = None
        """The thermal network in the loop (ModelOptions.thermal = 'network', twin.thermal.coupling)."""
        self._frozen_thermal: ThermalState | None = None
        if self.model.options.thermal == "network":
            opts = self.model.options
            period = opts.thermal_period_s * opts.thermal_network.heat_capacity_scale  # thermal -> simulated time
            units = max(1, int(round(period / STEP_DIVISOR_S)))  # a whole number of auto steps
            self.thermal = ThermalCoupling(
                self.model,
                opts.thermal_network,
                units * STEP_DIVISOR_S,
                (setpoint or self.default_setpoint()).oil_temperature_c,
            )
        c = self.state.contacts
        self._groove_lanes = (c[L.M_GROOVE_CENTRE_RADIUS].copy(), c[L.M_GROOVE_CLEARANCE].copy())
        self._apply(self.limits.admit(setpoint or self.default_setpoint()))
        self.reset(warm=warm)

    def default_setpoint(self) -> Setpoint:
        """Seed 000's operating point (500 rad/s, 3000 N, 40 degC) where the bearing can hold it;
        for a small bearing the radial load is a quarter of what it can hold. An angular-contact
        bearing also gets an equal axial load (seed 004's Fr = Fa): a single row cannot carry a
        radial load without an axial reaction (its inner ring would slide out axially)."""
        m = self.model
        radial = min(3000.0, round(0.25 * m.max_radial_load_n))
        axial = min(radial, round(0.25 * m.max_axial_load_n)) if m.spec.kind == "angular_contact" else 0.0
        return Setpoint(
            shaft_speed_rad_s=min(500.0, 0.5 * m.max_shaft_speed_rad_s), radial_load_n=radial, axial_load_n=axial
        )

    # ---- setpoint ---------------------------------------------------------------------------
    @property
    def setpoint(self) -> Setpoint:
        """The setpoint in force."""
        return self._setpoint

    @property
    def status(self) -> str:
        """'ok', or what the last fault was and what the engine did (`fault.describe()`)."""
        return "ok" if self.fault is None else self.fault.describe()

    def _apply(self, admitted: Admitted) -> Setpoint:
        new = admitted.setpoint
        self._setpoint = new
        v = self._setpoint_vector
        v[L.S_SHAFT_SPEED] = new.shaft_speed_rad_s
        v[L.S_RADIAL_LOAD] = new.radial_load_n
        v[L.S_AXIAL_LOAD] = new.axial_load_n
        if self.thermal is not None:
            self.thermal.set_ambient(new.oil_temperature_c)
        self._refresh_oil_viscosity()
        return new

    # ---- thermal network (twin.thermal) -------------------------------------------------------
    def film_temperature_c(self) -> float:
        """The temperature the film's viscosity is taken at [degC]: the setpoint's oil temperature
        (ModelOptions.thermal = 'fixed') or the network's contact inlet temperature ('network')."""
        if self.thermal is None:
            return self._setpoint.oil_temperature_c
        return self.thermal.inlet_temperature_c

    def _refresh_oil_viscosity(self) -> None:
        """Viscosity and its temperature coefficient at the film temperature, and the inlet's."""
        lub = self.model.spec.lubricant
        t = self.film_temperature_c()
        self._oil_viscosity_pa_s = dynamic_viscosity_pa_s(lub, t)
        self._oil_beta_k_inv = temperature_viscosity_coefficient_k_inv(lub, t)
        self._update_inlet_viscosity(force=True)

    def measure_temperature(self, node: str, temperature_c: float) -> None:
        """A measured temperature of a node ('outer_ring', 'housing' or 'oil') [degC], assimilated by
        the dissipation estimator at the next network step (twin.thermal.estimator). Raises
        ValueError naming the field and its range, or with ModelOptions.thermal = 'fixed'."""
        if self.thermal is None:
            raise ValueError("thermal: a measured temperature needs ModelOptions.thermal = 'network'")
        self.thermal.measure(node, float(temperature_c), self.time_s)

    def hold_thermal_state(self, temperature_c) -> None:
        """Set the network's node temperatures [degC] (twin.thermal.network.NODE_NAMES order) and
        apply them at once: inlet viscosity and expansion (a steady-state solver, or a restart from
        a known thermal state). Raises ValueError with the fixed oil temperature or a bad array."""
        th = self.thermal
        if th is None:
            raise ValueError("thermal: node temperatures need ModelOptions.thermal = 'network'")
        t = np.asarray(temperature_c, dtype=float)
        low, high = TEMPERATURE_RANGE_C
        if t.shape != th.temperature_c.shape or not np.all(np.isfinite(t)) or t.min() < low or t.max() > high:
            raise ValueError(
                f"temperature_c: {th.temperature_c.size} finite node temperatures in [{low:g}, {high:g}] degC"
            )
        th.filter.x[: t.size] = t
        write_groove_lanes(self.state.contacts, self._groove_lanes, th.expansion, self.model.ball_count)
        self._refresh_oil_viscosity()

    def _thermal_step(self) -> None:
        """One network period: heat from the engine's state, node temperatures, then the inlet
        viscosity and the expansion of the rings and balls (written into the contacts' groove lanes)."""
        s, th = self.state, self.thermal
        assert th is not None, "the thermal step runs only with the network on"
        spin = float(np.mean(np.linalg.norm(s.ball_angular_velocity_rad_s, axis=1)))
        # the drive power is the contacts' friction plus the balls' drag and the seals' rubbing:
        # the contacts' share is split over the contacts by their lanes, drag heats the oil and
        # the seals the outer ring (twin.thermal.sources.HeatSources.node_heat_w)
        drag_w = max(float(self.inlet.drag_power_w), 0.0)
        seal_w = self._seal_power_w()
        contacts_w = max(th.take_mean_power_w() - drag_w - seal_w, 0.0)
        rolling, sliding, spin_w = contact_powers_w(s.contacts, s.ball_angular_velocity_rad_s, self.model.ball_radius_m)
        heat = friction_heat(rolling, sliding, spin_w, contacts_w, drag_w=drag_w, seal_w=seal_w)
        th.step(s.contacts, s.scalars, spin, self.time_s, heat=heat)
        write_groove_lanes(s.contacts, self._groove_lanes, th.expansion, self.model.ball_count)
        self._refresh_oil_viscosity()

    def _thermal_state(self) -> ThermalState | None:
        return self._frozen_thermal if self.thermal is None else self.thermal.block()

    # ---- the inlet's film losses (twin.inlet_film) ------------------------------------------
    def _update_inlet_viscosity(self, force: bool = False, elapsed_s: float = 0.0) -> None:
        """Count `elapsed_s` of the frame and, when due (or `force`), refresh the inlet's film
        factors (current and shear heating, starvation; twin.inlet_film.InletFilm) into the
        viscosity the kernel reads."""
        inlet = self.inlet
        if not inlet.due(elapsed_s, force):
            return
        sp = self._setpoint
        th = self.model.spec.thermal
        current_rise = self.current_heating_k() if sp.shaft_current_a > 0.0 and th.current_heating else 0.0
        scalars = self.state.scalars
        self._setpoint_vector[L.S_VISCOSITY] = inlet.update(
            sp,
            self.film_temperature_c(),
            self._oil_viscosity_pa_s,
            self._oil_beta_k_inv,
            float(scalars[L.X_SHAFT_SPEED]),
            float(scalars[L.X_CAGE_SPEED]),
            current_rise,
            self.mean_entrainment_speed_m_s() if th.shear_heating else 0.0,
        )

    # ---- measures of the state (twin.state_measures) ----------------------------------------
    def axial_angular_momentum_n_m_s(self) -> float:
        """Angular momentum of the balls and the cage about the bearing axis [N m s]."""
        return state_measures.axial_angular_momentum_n_m_s(self.model, self.state)

    def kinetic_energy_j(self) -> float:
        """Kinetic energy of the balls (translation and rotation) and the cage [J]."""
        return state_measures.kinetic_energy_j(self.model, self.state)

    def mean_entrainment_speed_m_s(self) -> float:
        """Mean entrainment speed of the loaded inner-race contacts [m/s]."""
        return state_measures.mean_entrainment_speed_m_s(self.state)

    def loaded_zone_ball_count(self) -> float:
        """Balls in the inner race's loaded zone as the zone's arc in ball pitches (K of seed 003
        eq. 10, twin.state_measures.loaded_zone_ball_count)."""
        return state_measures.loaded_zone_ball_count(self.model, self.state)

    def ball_azimuths_rad(self) -> np.ndarray:
        """Ball centre angles about the outer ring's centre from the load line (+x), in (-pi, pi]
        [rad]."""
        return state_measures.ball_azimuths_rad(self.state)

    def current_heating_k(self) -> float:
        """Race-track temperature rise from the shaft current (seed 003 eq. 10) [K]."""
        sp = self._setpoint
        th = self.model.spec.thermal
        m = self.model
        r_b = th.equivalent_resistance_ohm
        if r_b is None:
            net = self.electrical()
            r_b = net.impedance_ohm * math.cos(net.phase_rad)
        loaded = self.loaded_zone_ball_count()
        return min(
            MAX_CURRENT_HEATING_K,
            current_heating_temperature_rise_k(
                sp.shaft_current_a,
                r_b,
                2.0 * m.pitch_radius_m,
                2.0 * m.ball_radius_m,
                loaded,
                float(self.state.scalars[L.X_SHAFT_SPEED]) / (2.0 * math.pi),
                th.crater_depth_m,
                m.spec.material.density_kg_m3,
                th.ball_specific_heat_j_kg_k,
                m.contact_angle_rad,
            ),
        )

    def set_setpoint(self, update: SetpointUpdate | Setpoint | Admitted | None = None, **fields) -> Setpoint:
        """Apply a setpoint: a partial `SetpointUpdate` (or keyword fields), a complete
        `Setpoint`, or one already `Admitted` by this twin's limits (not checked again). Raises
        SetpointError naming every field outside the bearing's range (pydantic's ValidationError
        for a wrong type). Takes effect at the next frame; returns the setpoint in force."""
        if not (isinstance(update, Admitted) and update.limits == self.limits):
            if isinstance(update, Admitted):
                update = update.setpoint
            update = self.limits.admit(update if update is not None else SetpointUpdate(**fields), self._setpoint)
        applied = self._apply(update)
        if self.halted:  # a new setpoint: try again from the warm start
            self.halted = False
            self.fault = None
            self.reset(keep_time=True)
        return applied

    # ---- running ----------------------------------------------------------------------------
    def reset(self, *, warm: bool = True, shaft_speed_rad_s: float | None = None, keep_time: bool = False) -> None:
        """Restart from the quasi-static equilibrium at the current setpoint (or unloaded when
        `warm` is False), at `shaft_speed_rad_s` if given; `keep_time` keeps the simulated clock."""
        sp = self._setpoint
        t = self.time_s if keep_time else 0.0
        speed = sp.shaft_speed_rad_s if shaft_speed_rad_s is None else shaft_speed_rad_s
        if warm:
            warm_start(self.model, self.state, speed, sp.radial_load_n, sp.axial_load_n)
        else:
            warm_start(self.model, self.state, speed, 0.0, 0.0)
        self.state.scalars[L.X_TIME] = t
        m = self.model
        if m.housing_on:
            place_on_housing(m, self.state, sp.radial_load_n if warm else 0.0, sp.axial_load_n if warm else 0.0)
        if self._sensor is not None:
            self._sensor.reset(t)
        evaluate(*self._kernel_args())
        if self._setpoint.shaft_current_a > 0.0 or m.spec.thermal.shear_heating:
            # the inlet heating of the warm state (loaded balls, entrainment), not of the state
            # before it (no loaded ball: the current heating at its cap for the first 10 ms)
            self._update_inlet_viscosity(force=True)
            evaluate(*self._kernel_args())
        self._update_life(force=True)

    def _kernel_args(self) -> tuple[ModelArrays, StateArrays, np.ndarray]:
        """(model, state, setpoint) as `step_n` / `evaluate` take them (without n)."""
        return self.model.arrays(), self.state.arrays(), self._setpoint_vector

    # ---- rating life (twin.life) --------------------------------------------------------------
    def _update_life(self, force: bool = False) -> None:
        """Feed the life monitor the current conditions (it re-evaluates every refresh_s of
        simulated time): setpoint loads, the ramped shaft speed, the kinematic viscosity of the
        film inlet (oil temperature plus the inlet's current and shear heating) and the contacts."""
        if not (force or self.life_monitor.due(self.time_s)):
            return
        sp = self._setpoint
        rho = density_kg_m3(
            self.model.spec.lubricant.density_15c_kg_m3, self.film_temperature_c() + self.inlet.temperature_rise_k
        )
        self.life_monitor.update(
            self.time_s,
            float(self.state.scalars[L.X_SHAFT_SPEED]),
            sp.radial_load_n,
            sp.axial_load_n,
            self.inlet.inlet_viscosity_pa_s / rho,
            self.state.contacts,
            force=force,
        )

    def _frame(self, n: int) -> int:
        self._update_inlet_viscosity(elapsed_s=n * self.model.dt_s)
        s = self.state
        s.scalars[L.X_TORQUE_SUM] = 0.0
        s.scalars[L.X_TORQUE_COUNT] = 0.0
        energy_before = self.kinetic_energy_j()
        speed_before = float(s.scalars[L.X_SHAFT_SPEED])
        # the frame can end at rest (mean speed under REST_SPEED_RAD_S) only from near rest: only
        # then does the friction torque need the angular momentum
        near_rest = abs(speed_before) < REST_SPEED_RAD_S + self.model.options.speed_ramp_rad_s2 * n * self.model.dt_s
        momentum_before = self.axial_angular_momentum_n_m_s() if near_rest else 0.0
        status, done = step_n(*self._kernel_args(), n)
        if done < n and status == L.STATUS_OK:  # interrupted (interrupt_frame): n - done not run
            self.inlet.since_s -= (n - done) * self.model.dt_s
        if self._sensor is not None:
            self._sensor.after_frame(s, done, float(s.scalars[L.X_SHAFT_SPEED]))
            if status != L.STATUS_OK:
                self._sensor.flush(s)
        if s.scalars[L.X_TORQUE_COUNT] > 0 and status == L.STATUS_OK:
            self._contact_torque_n_m = frame_friction_torque_n_m(
                s.scalars[L.X_TORQUE_SUM] / s.scalars[L.X_TORQUE_COUNT],
                done * self.model.dt_s,
                0.5 * (speed_before + float(s.scalars[L.X_SHAFT_SPEED])),
                self.kinetic_energy_j() - energy_before,
                (self.axial_angular_momentum_n_m_s() - momentum_before) if near_rest else 0.0,
            )
            self._last_torque_n_m = self._contact_torque_n_m + self._churning_and_seal_torque_n_m()
        if status != L.STATUS_OK:
            self._recover(status)
        else:
            self._last_good_time_s = self.time_s
            if self.thermal is not None:
                frame_s = done * self.model.dt_s
                self.thermal.add_work(self._last_torque_n_m * float(s.scalars[L.X_SHAFT_SPEED]), frame_s)
                if self.thermal.due(frame_s, self.model.dt_s):
                    self._thermal_step()
            self._update_life()
        return done

    @property
    def contact_friction_torque_n_m(self) -> float:
        """Friction torque of the ball-raceway contacts over the last frame [N m]: the
        snapshot's friction_torque_n_m without the balls' drag and the seals."""
        return float(self._contact_torque_n_m)

    @property
    def drag_power_w(self) -> float:
        """Drag power of the balls at the last coupling refresh [W] (twin.inlet_film: the SKF drag
        term in an oil bath, sphere drag in an oil-air mixture); the snapshot's torque carries it
        as power / omega."""
        return float(self.inlet.drag_power_w)

    def _churning_and_seal_torque_n_m(self) -> float:
        """Shaft torque of the ball drag and the seals [N m]: the drag power over the shaft speed
        (the shaft supplies it through the balls) and the seals' moment while the shaft turns."""
        speed = abs(float(self.state.scalars[L.X_SHAFT_SPEED]))
        if speed <= 0.0:
            return 0.0
        return self.inlet.drag_power_w / speed + self._seal_moment_n_m

    def _seal_power_w(self) -> float:
        """Power of the rubbing seals at the current shaft speed [W] (twin.friction_power.seal_power_w):
        the one evaluation the thermal network's heat and `friction_power_w` share."""
        return seal_power_w(self._seal_moment_n_m, float(self.state.scalars[L.X_SHAFT_SPEED]))

    def friction_power_w(self) -> FrictionPower:
        """Friction power of the current instant by source and by contact [W]
        (twin.friction_power.friction_power_by_source): the contacts' rolling, sliding and spin
        power from the last step's lanes, each ball's drag at its own depth in the oil bath (or in
        the cavity's oil-air mixture) and the seals' moment times the shaft speed."""
        return friction_power_by_source(
            self.model,
            self.state,
            self._setpoint.oil_temperature_c,
            self._oil_viscosity_pa_s,
            self.inlet.immersed_fraction,
            self._seal_power_w(),
        )

    def _recover(self, status: int) -> None:
        """A kernel reported a diverged or overloaded state: restart from the warm start at the
        setpoint in force, keep the simulated time, count it, say why in `status`. If the state
        fails again within RESTART_WINDOW_S of simulated time, the setpoint cannot be held: the
        twin halts (time goes on, the physics does not) until the next setpoint."""
        t = float(self.state.scalars[L.X_TIME])
        reason = L.STATUS_NAMES[status]
        if not math.isfinite(t):
            t = self._last_good_time_s
        self.restarts += 1
        if t - self._last_restart_time_s < RESTART_WINDOW_S:
            self.halted = True
            self.fault = Fault(FaultKind.HALTED, reason, t, RESTART_WINDOW_S)
        else:
            self.fault = Fault(FaultKind.RESTARTED, reason, t)
        self._last_restart_time_s = t
        self.state.scalars[L.X_TIME] = t
        self.reset(keep_time=True)

    def advance(self, seconds: float, frame_steps: int | None = None, *, max_restarts: int | None = None) -> int:
        """Integrate `seconds` of simulated time (a whole number of steps, the nearest) in frames of
        `frame_steps` steps (default: FRAME_S of simulated time). With the thermal network on, a
        frame also ends where the network's next step is due, so the network steps every period
        it states (ThermalCoupling.period_s) whatever frames the caller asks for.

        A state the kernel cannot hold at the setpoint in force fails again right after its warm
        restart, i.e. at nearly every step (each restart costs a warm start): `max_restarts`
        stops the call after that many restarts within it (None: no other bound than the next
        one). Whatever `max_restarts`, the call stops as soon as the twin halts (a second failure
        within RESTART_WINDOW_S of a restart, `status` says why): without a new setpoint every
        later step would fail and restart again, one warm start per step. Returns the steps left
        undone (0 unless stopped by `max_restarts`, a halt or `interrupt_frame`)."""
        if not (math.isfinite(seconds) and seconds >= 0.0):
            raise ValueError(f"seconds = {seconds!r}: must be finite and >= 0")
        remaining = int(round(seconds / self.model.dt_s))
        if frame_steps is None:
            frame_steps = max(1, int(round(FRAME_S / self.model.dt_s)))
        first = self.restarts
        self.frame_interrupted = False
        while remaining > 0:
            n = min(frame_steps, remaining)
            if self.thermal is not None:  # no frame runs past a network step (its period is exact)
                n = min(n, self.thermal.steps_to_due(self.model.dt_s))
            remaining -= max(self._frame(n), 1)  # a failing frame still consumes a step: no hang
            if max_restarts is not None and self.restarts - first >= max_restarts:
                return max(remaining, 0)
            if self.halted:  # the setpoint cannot be held: stop instead of a warm start per step
                return max(remaining, 0)
            if remaining > 0 and self._setpoint_vector[L.S_STOP] != 0.0:
                self.frame_interrupted = True  # interrupt_frame: the caller has input waiting
                return remaining
        return 0

    def interrupt_frame(self) -> None:
        """Ask the frame in progress to end at its next step boundary (after at least one step;
        any thread, without waiting): `advance` then returns the steps left undone with
        `frame_interrupted` set. A real-time runner asks it when a setpoint arrives mid-frame,
        so the setpoint applies within a step instead of at the end of the frame. Stays
        asked (every later frame ends after one step) until `clear_frame_interrupt`."""
        self._setpoint_vector[L.S_STOP] = 1.0

    def clear_frame_interrupt(self) -> None:
        """Withdraw `interrupt_frame` (call it BEFORE taking the input the interrupt was for, so
        that an input arriving after the take still interrupts the next frame)."""
        self._setpoint_vector[L.S_STOP] = 0.0

    @property
    def time_s(self) -> float:
        """Simulated time [s]."""
        return float(self.state.scalars[L.X_TIME])

    # ---- local defects and the accelerometer (twin.vibration) ----------------------------------
    @property
    def defects(self) -> tuple:
        """The active local defects (twin.vibration.defects models)."""
        return self._defects

    def set_defects(self, defects) -> tuple:
        """Replace the active local defects (a list of dicts with `kind` outer | inner | ball, or
        twin.vibration.defects models; [] clears them). Validated against this bearing: raises
        pydantic.ValidationError naming the field and the bearing's allowed range, or ValueError for
        more than MAX_DEFECTS. Takes effect at the next step, without recompiling; a ball defect
        not active before starts with the ball's body axes = the world axes now. Returns the
        defects in force."""
        data = [d.model_dump() if hasattr(d, "model_dump") else d for d in defects]
        if len(data) > MAX_DEFECTS:
            raise ValueError(f"defects: {len(data)} given, at most {MAX_DEFECTS} at once")
        items = tuple(validate_defects(data, self.model.spec.geometry))
        s = self.state
        geometry = self.model.spec.geometry
        for d in items:
            if isinstance(d, BallDefect) and d not in self._defects:
                s.ball_orientation[d.ball_index] = (1.0, 0.0, 0.0, 0.0)
        s.defect_rows[:] = 0.0
        for k, d in enumerate(items):
            s.defect_rows[k] = defect_row(d, geometry)
        s.defect_count = len(items)
        if not items:
            s.contacts[L.G_DEFECT_DROP] = 0.0
        self._defects = items
        return items

    def clear_defects(self) -> tuple:
        """Remove every local defect (the raceways and balls are healthy again); returns ()."""
        return self.set_defects([])

    @property
    def vibration(self):
        """Indicators of the last complete accelerometer window (twin.snapshot.VibrationState), or
        None before the first window or with the rigid outer ring."""
        if self._sensor is None:
            return self._frozen_vibration
        self._sensor.flush(self.state)
        return self._sensor.latest

    def frozen(self) -> Twin:
        """A copy that `snapshot()` can read in another thread while this twin steps on: the
        object shallow-copied (the model, setpoint, defects and fault are immutable; numbers are
        values), its state arrays copied, and the accelerometer reader replaced by its last window.
        Call it from the thread that steps this twin: the copy never touches the live reader (its
        cursor, waveform queue and window are the stepping thread's alone), so the samples it
        drains stay contiguous."""
        latest = self.vibration  # flushes the live reader here, in the stepping thread
        frozen = copy.copy(self)
        frozen.state = self.state.copy()
        frozen.inlet = copy.copy(self.inlet)
        frozen._sensor = None
        frozen._frozen_vibration = latest
        frozen._frozen_thermal = self._thermal_state()
        frozen.thermal = None
        return frozen

    def drain_waveform(self) -> list[WaveformBlock]:
        """The accelerometer samples [m/s^2] produced since the last call, as contiguous float32
        blocks with their start time t0_s [s] and rate (twin.accelerometer.WaveformBlock;
        twin.vibration.waveform encodes them for a bus). At most WAVEFORM_QUEUE_S of signal is
        kept between calls. [] with the rigid outer ring."""
        if self._sensor is None:
            return []
        self._sensor.flush(self.state)
        return self._sensor.drain_waveform()

    # ---- outputs ----------------------------------------------------------------------------
    def electrical(self) -> ElectricalNetwork:
        """The bearing's electrical network at the current state (twin.electrical_network)."""
        sp = self._setpoint
        return bearing_network(self.model, self.state.contacts, sp.shaft_voltage_v, sp.shaft_current_a)

    def snapshot(self, real_time_factor: float | None = None) -> Snapshot:
        """An immutable copy of the public state (schema bearing-twin/state/1)."""
        return self.frame(real_time_factor).snapshot

    def frame(self, real_time_factor: float | None = None, **head: Any) -> SnapshotFrame:
        """The public state captured as a `twin.snapshot_frame.SnapshotFrame`: the balls as
        arrays, the pydantic tree built only when read. `head`: snapshot fields set beside the
        engine's (late_fraction, status)."""
        s = self.state
        net = self.electrical()
        balls = ball_arrays(self.model, s, net, self._effective_mu)
        self.seq += 1
        fields = dict(
            bearing_id=self.bearing_id,
            designation=self.model.spec.designation,
            seq=self.seq,
            time_s=self.time_s,
            real_time_factor=finite_or_none(real_time_factor) if real_time_factor is not None else None,
            status=self.status,
            restarts=self.restarts,
            setpoint=self._setpoint,
            shaft_speed_rad_s=float(s.scalars[L.X_SHAFT_SPEED]),
            cage_speed_rad_s=float(s.scalars[L.X_CAGE_SPEED]),
            inner_ring_displacement_m=_xyz(s.inner_ring_offset_m),
            friction_torque_n_m=float(self._last_torque_n_m),
            friction_power_w=FrictionPowerState(**self.friction_power_w().by_source_w()),
            viscosity_pa_s=float(self.inlet.inlet_viscosity_pa_s),
            electrical=electrical_state(net, self.inlet),
            balls=(),
            life=self._life_state(),
            outer_ring_displacement_m=_xyz(s.housing_displacement_m),
            defects=self._defects,
            vibration=self.vibration,
            thermal=self._thermal_state(),
        )
        return SnapshotFrame(Snapshot(**{**fields, **head}), balls)

    def _life_state(self) -> LifeState | None:
        block = self.life_monitor.block(self.time_s)
        return None if block is None else LifeState(**block)
