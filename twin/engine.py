"""`Twin`: the Python face of the engine (set_setpoint, advance, snapshot).

It owns one immutable `BearingModel` and one mutable `TwinState` and calls the compiled
`step_n(model arrays, state arrays, setpoint vector, n)` once per frame. No threads, no I/O.
"""

from __future__ import annotations

import math

import numpy as np

from twin import catalog
from twin.kernels import layout as L
from twin.kernels.step import evaluate, step_n
from twin.model import BearingModel, make_model
from twin.physics.friction import REGIME_NAMES
from twin.physics.hertz import max_pressure_pa
from twin.kernels.tribology import T_HMIN_EXP_EU
from twin.physics.thermal import (MAX_CURRENT_HEATING_K, current_heating_temperature_rise_k,
                                  inlet_shear_heating_temperature_rise_k, roelands_temperature_viscosity_pa_s,
                                  thermal_film_factor)
from twin.physics.viscosity import dynamic_viscosity_pa_s, temperature_viscosity_coefficient_k_inv
from twin.setpoint import Setpoint, SetpointUpdate, check_limits
from twin.electrical import bearing_network
from twin.snapshot import BallState, ContactState, SetpointState, Snapshot
from twin.snapshot import ElectricalState as ElectricalSnapshot
from twin.spec import BearingSpec, ModelOptions
from twin.state import TwinState, make_state
from twin.warmstart import warm_start

FRAME_S = 1e-3  # simulated time per compiled call [s] (1000 steps at dt = 1 us)
RESTART_WINDOW_S = 0.01  # a second failure this soon after a restart halts the twin
MIN_FILM_THERMAL_FACTOR = 1e-4  # floor of the thermal film factor [-]
COUPLING_PERIOD_S = 0.01  # electro-thermal coupling refreshed every 10 ms of simulated time [s]


def _finite_or_none(value: float) -> float | None:
    return float(value) if math.isfinite(value) else None


class Twin:
    """A running bearing twin.

    >>> twin = Twin("6208")                       # warm-started at 500 rad/s, 3000 N
    >>> twin.set_setpoint(radial_load_n=5000.0)   # partial update
    >>> twin.advance(0.01)                        # 10 ms of simulated time
    >>> twin.snapshot().balls[0].inner.load_n
    """

    def __init__(self, bearing: str | BearingSpec = "6208", *, options: ModelOptions | None = None,
                 setpoint: Setpoint | None = None, bearing_id: str = "default",
                 diametral_clearance_m: float | None = None, warm: bool = True):
        spec = bearing if isinstance(bearing, BearingSpec) else catalog.bearing(bearing)
        if diametral_clearance_m is not None:
            mounting = spec.mounting.model_copy(update={"diametral_clearance_m": diametral_clearance_m})
            spec = BearingSpec.model_validate({**spec.model_dump(), "mounting": mounting.model_dump()})
        self.bearing_id = bearing_id
        self.model: BearingModel = make_model(spec, options)
        self.state: TwinState = make_state(self.model)
        self._setpoint_vector = np.zeros(L.N_SETPOINT)
        self._setpoint = Setpoint()
        self.seq = 0
        self.restarts = 0
        self.status = "ok"
        self.halted = False
        self._last_restart_time_s = -math.inf
        self._last_good_time_s = 0.0
        self._last_torque_n_m = 0.0
        self._apply(setpoint or self.default_setpoint())
        self.reset(warm=warm)

    def default_setpoint(self) -> Setpoint:
        """Seed 000's operating point (500 rad/s, 3000 N, 40 degC) where the bearing can hold it;
        for a small bearing the radial load is a quarter of what it can hold."""
        m = self.model
        return Setpoint(shaft_speed_rad_s=min(500.0, 0.5 * m.max_shaft_speed_rad_s),
                        radial_load_n=min(3000.0, round(0.25 * m.max_radial_load_n)))

    # ---- setpoint ---------------------------------------------------------------------------
    @property
    def limits(self) -> dict[str, tuple[float, float]]:
        """Allowed (low, high) of each setpoint field for this bearing."""
        m = self.model
        axial_low = 0.0 if m.spec.kind == "angular_contact" else -m.max_axial_load_n
        return {
            "shaft_speed_rad_s": (0.0, m.max_shaft_speed_rad_s),
            "radial_load_n": (0.0, m.max_radial_load_n),
            "axial_load_n": (axial_low, m.max_axial_load_n),
            "oil_temperature_c": (-30.0, 150.0),
            "shaft_current_a": (0.0, 100.0),
            "shaft_voltage_v": (0.0, 1000.0),
        }

    @property
    def setpoint(self) -> Setpoint:
        """The setpoint in force."""
        return self._setpoint

    def _apply(self, new: Setpoint) -> Setpoint:
        check_limits(new, self.limits)
        self._setpoint = new
        v = self._setpoint_vector
        v[L.S_SHAFT_SPEED] = new.shaft_speed_rad_s
        v[L.S_RADIAL_LOAD] = new.radial_load_n
        v[L.S_AXIAL_LOAD] = new.axial_load_n
        lub = self.model.spec.lubricant
        self._oil_viscosity_pa_s = dynamic_viscosity_pa_s(lub, new.oil_temperature_c)
        self._oil_beta_k_inv = temperature_viscosity_coefficient_k_inv(lub, new.oil_temperature_c)
        self._update_inlet_viscosity(force=True)
        return new

    # ---- electro-thermal coupling (seed 003) ------------------------------------------------
    def _update_inlet_viscosity(self, force: bool = False, elapsed_s: float = 0.0) -> None:
        """Electro-thermal film loss (seed 003): the inlet is heated by the current discharge of the
        race track (eq. 10, with the bearing's equivalent resistance) and by shear (eq. 6 at the
        inlet); the film the loop computes is the isothermal film at the oil temperature times
        the thermal film factor g(dT)^c_T calibrated against the thermal EHL solver
        (twin.thermal_calibration). The factor enters the kernel through the one viscosity it
        reads: eta_film = eta_oil * factor^(1 / n_u), n_u the film law's exponent of (eta u), so
        film, Lambda, regime, mu and fluid damping all follow. Recomputed at the start of the frame
        that completes COUPLING_PERIOD_S of simulated time (`elapsed_s`: the frame's length; the
        drivers change slowly), whatever the step."""
        self._since_coupling_s = getattr(self, "_since_coupling_s", 0.0) + elapsed_s
        if not force and self._since_coupling_s < COUPLING_PERIOD_S - 0.5 * self.model.dt_s:
            return
        self._since_coupling_s = 0.0
        sp = self._setpoint
        th = self.model.spec.thermal
        have_state = hasattr(self, "state")
        current_rise = 0.0
        if sp.shaft_current_a > 0.0 and th.current_heating and have_state:
            current_rise = self.current_heating_k()
        theta0 = sp.oil_temperature_c + 273.15
        eta0, beta = self._oil_viscosity_pa_s, self._oil_beta_k_inv
        shear_rise = 0.0
        if th.shear_heating and have_state:
            shear_rise = inlet_shear_heating_temperature_rise_k(
                self.mean_entrainment_speed_m_s(), eta0, theta0, beta, th.oil_thermal_conductivity_w_m_k,
                other_rise_k=current_rise, shear_factor=th.inlet_shear_heating_factor)
        rise = current_rise + shear_rise
        factor = 1.0
        if rise > 0.0:  # floored: below 1e-4 of the isothermal film there is no film to speak of
            factor = max(MIN_FILM_THERMAL_FACTOR, thermal_film_factor(rise, eta0, theta0, beta, th.film_temperature_exponent))
        self._current_heating_k = current_rise
        self._shear_heating_k = shear_rise
        self._film_thermal_factor = factor
        self._inlet_viscosity_pa_s = (roelands_temperature_viscosity_pa_s(eta0, theta0, theta0 + rise, beta)
                                      if rise > 0.0 else eta0)
        speed_exponent = float(self.model.race_tribology[0, T_HMIN_EXP_EU])  # d ln h / d ln(eta u)
        self._setpoint_vector[L.S_VISCOSITY] = eta0 * factor ** (1.0 / speed_exponent)

    def mean_entrainment_speed_m_s(self) -> float:
        """Mean entrainment speed of the loaded inner-race contacts (all inner contacts if none
        is loaded) [m/s]."""
        c = self.state.contacts
        u = c[L.C_ENTRAINMENT, 0::2]
        loaded = c[L.C_LOAD, 0::2] > 0.0
        return float(np.mean(np.abs(u[loaded] if loaded.any() else u)))

    def loaded_zone_ball_count(self) -> float:
        """Balls in the inner race's loaded zone (K of seed 003 eq. 10) as the zone's arc in ball
        pitches: the mean number of loaded balls over a ball pass. The count at an instant jumps
        by one whenever a ball crosses an edge of the zone, and sampled every 10 ms by the
        electro-thermal coupling it made the heating a step function of the state (at 1700 rad/s
        and 20 A: 6.5 or 8.1 K, 25 % apart, by when a sample fell). The edges are interpolated
        between neighbouring balls on their inner approach (G_DELTA, < 0: gap)."""
        z = self.model.ball_count
        delta = self.state.contacts[L.G_DELTA, 0::2]
        loaded = delta > 0.0
        if loaded.all() or not loaded.any():
            return float(z) if loaded.all() else 0.0
        az = self.ball_azimuths_rad()
        order = np.argsort(az)
        az, d = az[order], delta[order]
        arc = 0.0
        for j in range(z):
            k = (j + 1) % z
            gap = (az[k] - az[j]) % (2.0 * math.pi)
            if d[j] > 0.0 and d[k] > 0.0:
                arc += gap
            elif d[j] > 0.0 or d[k] > 0.0:  # one edge of the zone lies between the two balls
                inside = d[j] if d[j] > 0.0 else d[k]
                arc += gap * inside / (abs(d[j]) + abs(d[k]))
        return arc * z / (2.0 * math.pi)

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
        return min(MAX_CURRENT_HEATING_K, current_heating_temperature_rise_k(
            sp.shaft_current_a, r_b, 2.0 * m.pitch_radius_m, 2.0 * m.ball_radius_m, loaded,
            float(self.state.scalars[L.X_SHAFT_SPEED]) / (2.0 * math.pi), th.crater_depth_m,
            m.spec.material.density_kg_m3, th.ball_specific_heat_j_kg_k, m.contact_angle_rad))

    def set_setpoint(self, update: SetpointUpdate | None = None, **fields) -> Setpoint:
        """Apply a partial setpoint (validated; raises SetpointError / ValidationError naming the
        field and its range). Takes effect at the next frame; returns the setpoint in force."""
        update = update or SetpointUpdate(**fields)
        applied = self._apply(update.apply_to(self._setpoint))
        if self.halted:  # a new setpoint: try again from the warm start
            self.halted = False
            self.status = "ok"
            self.reset(keep_time=True)
        return applied

    # ---- running ----------------------------------------------------------------------------
    def reset(self, *, warm: bool = True, shaft_speed_rad_s: float | None = None,
              keep_time: bool = False) -> None:
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
        evaluate(m.params, m.race_tribology, self._setpoint_vector, *self.state.kernel_args())
        if self._setpoint.shaft_current_a > 0.0 or m.spec.thermal.shear_heating:
            # the inlet heating of the warm state (loaded balls, entrainment), not of the state
            # before it (no loaded ball: the current heating at its cap for the first 10 ms)
            self._update_inlet_viscosity(force=True)
            evaluate(m.params, m.race_tribology, self._setpoint_vector, *self.state.kernel_args())

    def _frame(self, n: int) -> int:
        self._update_inlet_viscosity(elapsed_s=n * self.model.dt_s)
        s = self.state
        s.scalars[L.X_TORQUE_SUM] = 0.0
        s.scalars[L.X_TORQUE_COUNT] = 0.0
        m = self.model
        status, done = step_n(m.params, m.race_tribology, self._setpoint_vector,
                              *s.kernel_args(), n)
        if s.scalars[L.X_TORQUE_COUNT] > 0:
            self._last_torque_n_m = s.scalars[L.X_TORQUE_SUM] / s.scalars[L.X_TORQUE_COUNT]
        if status != L.STATUS_OK:
            self._recover(status)
        else:
            self._last_good_time_s = self.time_s
        return done

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
            self.status = (f"halted: {reason} again within {RESTART_WINDOW_S * 1e3:.0f} ms of a restart "
                           f"at t = {t:.6f} s; the setpoint cannot be held, waiting for a new one")
        else:
            self.status = f"restarted: {reason} at t = {t:.6f} s"
        self._last_restart_time_s = t
        self.state.scalars[L.X_TIME] = t
        self.reset(keep_time=True)

    def advance(self, seconds: float, frame_steps: int | None = None, *,
                max_restarts: int | None = None) -> int:
        """Integrate `seconds` of simulated time (a whole number of steps, the nearest) in frames of
        `frame_steps` steps (default: FRAME_S of simulated time).

        A state the kernel cannot hold at the setpoint in force fails again right after its warm
        restart, i.e. at nearly every step (each restart costs a warm start): `max_restarts`
        stops the call after that many restarts within it (None: no bound). Returns the steps
        left undone (0 unless stopped by `max_restarts`)."""
        if not (math.isfinite(seconds) and seconds >= 0.0):
            raise ValueError(f"seconds = {seconds!r}: must be finite and >= 0")
        remaining = int(round(seconds / self.model.dt_s))
        if frame_steps is None:
            frame_steps = max(1, int(round(FRAME_S / self.model.dt_s)))
        first = self.restarts
        while remaining > 0:
            n = min(frame_steps, remaining)
            remaining -= max(self._frame(n), 1)  # a failing frame still consumes a step: no hang
            if max_restarts is not None and self.restarts - first >= max_restarts:
                return max(remaining, 0)
        return 0

    @property
    def time_s(self) -> float:
        """Simulated time [s]."""
        return float(self.state.scalars[L.X_TIME])

    # ---- outputs ----------------------------------------------------------------------------
    def ball_azimuths_rad(self) -> np.ndarray:
        """Ball centre angles from the load line (+x), in (-pi, pi] [rad]."""
        x = self.state.ball_position_m
        return np.arctan2(x[:, 1], x[:, 0])

    def _contact(self, j: int, r: int, net) -> ContactState:
        c = self.state.contacts[:, 2 * j + r]
        loaded = c[L.C_LOAD] > 0.0
        regime = REGIME_NAMES[int(c[L.C_REGIME])] if loaded else "no_contact"
        return ContactState(
            load_n=float(c[L.C_LOAD]),
            h_min_m=_finite_or_none(c[L.C_H_MIN]) if loaded else None,
            h_c_m=_finite_or_none(c[L.C_H_C]) if loaded else None,
            **{"lambda": _finite_or_none(c[L.C_LAMBDA]) if loaded else None},
            regime=regime, mu=float(c[L.C_MU]) if loaded else 0.0,
            entrainment_speed_m_s=float(c[L.C_ENTRAINMENT]) if loaded else 0.0,
            slide_roll_ratio=float(c[L.C_SRR]) if loaded else 0.0,
            contact_angle_rad=float(math.asin(min(1.0, max(-1.0, c[L.G_NZ])))) if loaded else 0.0,
            max_pressure_pa=float(max_pressure_pa(c[L.C_LOAD], c[L.C_SEMI_MAJOR], c[L.C_SEMI_MINOR])),
            resistance_ohm=_finite_or_none(net.contact_resistance_ohm[2 * j + r]),
            capacitance_f=float(net.contact_capacitance_f[2 * j + r]),
        )

    def electrical(self):
        """The bearing's electrical network at the current state (twin.electrical)."""
        sp = self._setpoint
        return bearing_network(self.model, self.state.contacts, sp.shaft_voltage_v, sp.shaft_current_a)

    def snapshot(self, real_time_factor: float | None = None) -> Snapshot:
        """An immutable copy of the public state (schema bearing-twin/state/1)."""
        s = self.state
        x, v, w = s.ball_position_m, s.ball_velocity_m_s, s.ball_angular_velocity_rad_s
        az = self.ball_azimuths_rad()
        rho2 = x[:, 0] ** 2 + x[:, 1] ** 2
        orbital = (x[:, 0] * v[:, 1] - x[:, 1] * v[:, 0]) / rho2
        spin = np.linalg.norm(w, axis=1)
        net = self.electrical()
        balls = tuple(
            BallState(index=j, azimuth_rad=float(az[j]), spin_rad_s=float(spin[j]),
                      orbital_speed_rad_s=float(orbital[j]),
                      cage_load_n=float(s.cage_load_n[j].max()),
                      inner=self._contact(j, 0, net), outer=self._contact(j, 1, net),
                      resistance_ohm=_finite_or_none(net.ball_resistance_ohm[j]),
                      capacitance_f=float(net.ball_capacitance_f[j]))
            for j in range(self.model.ball_count))
        self.seq += 1
        sp = self._setpoint
        return Snapshot(
            bearing_id=self.bearing_id, designation=self.model.spec.designation, seq=self.seq,
            time_s=self.time_s,
            real_time_factor=_finite_or_none(real_time_factor) if real_time_factor is not None else None,
            status=self.status, restarts=self.restarts,
            setpoint=SetpointState(**sp.model_dump()),
            shaft_speed_rad_s=float(s.scalars[L.X_SHAFT_SPEED]),
            cage_speed_rad_s=float(s.scalars[L.X_CAGE_SPEED]),
            inner_ring_displacement_m=tuple(float(a) for a in s.ring_position_m),
            friction_torque_n_m=float(self._last_torque_n_m),
            viscosity_pa_s=float(self._inlet_viscosity_pa_s),
            electrical=ElectricalSnapshot(
                resistance_ohm=_finite_or_none(net.resistance_ohm), capacitance_f=net.capacitance_f,
                impedance_ohm=net.impedance_ohm, phase_rad=net.phase_rad,
                frequency_hz=net.frequency_hz, shaft_voltage_v=net.shaft_voltage_v,
                shaft_current_a=net.shaft_current_a, max_film_field_v_m=net.max_film_field_v_m,
                current_density_a_m2=net.current_density_a_m2, discharge_risk=net.discharge_risk,
                reason=net.reason,
                contact_temperature_rise_k=float(self._current_heating_k + self._shear_heating_k),
                current_temperature_rise_k=float(self._current_heating_k),
                shear_temperature_rise_k=float(self._shear_heating_k),
                film_thermal_factor=float(self._film_thermal_factor)),
            balls=balls)
