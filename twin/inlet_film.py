"""`InletFilm`: the film's losses at the contacts' inlet, between frames (seed 003's electro-thermal
coupling, the inlet's shear heating, kinematic starvation) and the balls' drag that goes with the
same oil.

The film the kernel computes is the isothermal, fully flooded film at the oil temperature. Three
factors reduce it, and they enter the kernel through the one viscosity it reads (`update` returns
it): eta_film = eta_oil * factor^(1 / n_u), n_u the film law's exponent of (eta u), so film, Lambda,
regime, mu, fluid damping and the rolling resistance all follow.

- Current heating: the current discharge of the race track heats the inlet (seed 003 eq. 10, with
  the bearing's equivalent resistance) and the film falls by g(dT)^c_T, calibrated against the
  thermal EHL solver's current heating (twin.validation.thermal_law_fit).
- Shear heating (Thermal.shear_heating): the back-flow shear of the inlet reduces the film by the
  Murch-Wilson factor phi_T = 3.94 / (3.94 + L^0.62), L = beta eta u^2 / k_f, at the
  current-heated inlet (twin.physics.thermal).
- Kinematic starvation: SKF's replenishment factor phi_rs for oil bath and jet
  (twin.friction_power.starvation_film_factor).

The factors are recomputed at the start of the frame that completes COUPLING_PERIOD_S of simulated
time (the drivers change slowly), whatever the step. The product is floored at
MIN_FILM_THERMAL_FACTOR: below it there is no film to speak of.
"""

from __future__ import annotations

import math

from twin.friction_power import ball_drag_power_w, mean_immersed_fraction, oil_bath_drag_power_w, starvation_film_factor
from twin.kernels.tribology import T_HMIN_EXP_EU
from twin.model import BearingModel
from twin.physics.thermal import (
    equivalent_inlet_temperature_rise_k,
    murch_wilson_thermal_factor,
    roelands_temperature_viscosity_coefficient_k_inv,
    roelands_temperature_viscosity_pa_s,
    thermal_film_factor,
    thermal_loading_parameter,
)
from twin.physics.viscosity import density_kg_m3
from twin.setpoint import Setpoint

COUPLING_PERIOD_S = 0.01  # the inlet's factors are refreshed every 10 ms of simulated time [s]
MIN_FILM_THERMAL_FACTOR = 1e-4  # floor of the film's reduction factor [-]


class InletFilm:
    """The inlet's film factors of one twin (module docstring). Plain numbers, so a shallow copy
    is a consistent frozen view of them."""

    def __init__(self, model: BearingModel):
        self.model = model
        self.immersed_fraction = mean_immersed_fraction(model.spec)
        self.since_s = 0.0  # simulated time since the last refresh [s]
        self.current_heating_k = 0.0  # inlet temperature rise of the shaft current [K]
        self.shear_heating_k = 0.0  # equivalent inlet temperature rise of the shear heating [K]
        self.shear_film_factor = 1.0  # Murch-Wilson factor [-]
        self.starvation_factor = 1.0  # kinematic starvation factor [-]
        self.film_thermal_factor = 1.0  # the product of the three, floored [-]
        self.inlet_viscosity_pa_s = math.nan  # the oil's viscosity at the heated inlet [Pa s]
        self.drag_power_w = 0.0  # orbit-mean drag power of the balls [W]

    @property
    def temperature_rise_k(self) -> float:
        """The inlet's temperature rise over the film temperature: current plus shear [K]."""
        return self.current_heating_k + self.shear_heating_k

    def due(self, elapsed_s: float, force: bool = False) -> bool:
        """Count `elapsed_s` of simulated time; whether the factors are to be refreshed now."""
        self.since_s += elapsed_s
        return force or self.since_s >= COUPLING_PERIOD_S - 0.5 * self.model.dt_s

    def update(
        self,
        setpoint: Setpoint,
        film_temperature_c: float,
        oil_viscosity_pa_s: float,
        oil_beta_k_inv: float,
        shaft_speed_rad_s: float,
        cage_speed_rad_s: float,
        current_rise_k: float,
        entrainment_speed_m_s: float,
    ) -> float:
        """Refresh every factor at the current conditions; the viscosity the kernel is to read
        [Pa s]. `current_rise_k`: the race track's current heating (0 without current heating);
        `entrainment_speed_m_s`: the loaded contacts' mean entrainment speed (read only with shear
        heating)."""
        self.since_s = 0.0
        th = self.model.spec.thermal
        theta0 = film_temperature_c + 273.15
        eta0, beta = oil_viscosity_pa_s, oil_beta_k_inv
        current_factor = 1.0
        if current_rise_k > 0.0:
            current_factor = thermal_film_factor(current_rise_k, eta0, theta0, beta, th.film_temperature_exponent)
        shear_factor = 1.0
        shear_rise = 0.0
        if th.shear_heating:
            theta_c = theta0 + current_rise_k  # the shear heats an inlet the current has heated
            eta_c = roelands_temperature_viscosity_pa_s(eta0, theta0, theta_c, beta)
            beta_c = roelands_temperature_viscosity_coefficient_k_inv(eta0, theta0, theta_c, beta)
            loading = thermal_loading_parameter(beta_c, eta_c, entrainment_speed_m_s, th.oil_thermal_conductivity_w_m_k)
            shear_factor = murch_wilson_thermal_factor(loading)
            shear_rise = equivalent_inlet_temperature_rise_k(shear_factor, eta_c, theta_c, beta_c)
        rise = current_rise_k + shear_rise
        lub = self.model.spec.lubricant
        rho = density_kg_m3(lub.density_15c_kg_m3, setpoint.oil_temperature_c)
        starved = starvation_film_factor(self.model.spec, shaft_speed_rad_s, eta0 / rho)
        self.starvation_factor = starved
        self.drag_power_w = self._mean_drag_power_w(rho, eta0, shaft_speed_rad_s, cage_speed_rad_s)
        factor = max(MIN_FILM_THERMAL_FACTOR, current_factor * shear_factor * starved)
        self.current_heating_k = current_rise_k
        self.shear_heating_k = shear_rise
        self.shear_film_factor = shear_factor
        self.film_thermal_factor = factor
        self.inlet_viscosity_pa_s = (
            roelands_temperature_viscosity_pa_s(eta0, theta0, theta0 + rise, beta) if rise > 0.0 else eta0
        )
        speed_exponent = float(self.model.race_tribology[0, T_HMIN_EXP_EU])  # d ln h / d ln(eta u)
        return eta0 * factor ** (1.0 / speed_exponent)

    def _mean_drag_power_w(
        self, oil_density_kg_m3: float, oil_viscosity_pa_s: float, shaft_speed_rad_s: float, cage_speed_rad_s: float
    ) -> float:
        """Drag power of the balls [W]: in an oil bath the SKF model's drag moment at the shaft
        speed (twin.friction_power.oil_bath_drag_power_w); in an oil-air mixture each ball's sphere
        drag at the cage speed with the mixture's oil share (twin.friction_power.ball_drag_power_w);
        0 'flooded'."""
        if self.immersed_fraction <= 0.0:
            return 0.0
        m = self.model
        if m.spec.lubrication.method == "oil_bath":
            return oil_bath_drag_power_w(m.spec, shaft_speed_rad_s, oil_viscosity_pa_s / oil_density_kg_m3)
        v = abs(cage_speed_rad_s) * m.pitch_radius_m
        return m.ball_count * ball_drag_power_w(
            2.0 * m.ball_radius_m, v, self.immersed_fraction, oil_density_kg_m3, oil_viscosity_pa_s
        )
