"""The bearing's friction power by source and by contact [W]: the heat the friction puts into
the bearing, where it arises (the heat sources of a thermal network).

Sources:
- rolling: the rolling resistance of every ball-raceway contact (seed 001 eqs. 1-5, 9: the
  inlet's hydrodynamic force and the hysteresis) against the ball centre's velocity over the
  raceway, P = -F_R . (v_ball - v_ring(q)) (about F_R u);
- sliding: the tangential traction against the slip of the contact centre, P = -F_t . s (F_t the
  friction force on the ball, s the ball's slip velocity over the raceway), plus the moment of
  the traction across the ellipse (differential slip) against the ball's rotation relative to the
  ring;
- spin: the traction's moment about the contact normal against the relative spin rate,
  P = |M_n omega_spin| (twin.kernels.traction);
- drag: the balls churning the oil of the cavity (twin.physics.drag): in an oil bath the SKF
  model's drag moment times the shaft speed, shared among the balls by the part of each in the
  oil; in an oil-air mixture (jet, oil-air) F_D v per ball;
- seal: the rubbing seals (twin.physics.seals), P = M_seal |omega_shaft| (`seal_power_w`).

The contact powers are read from the contact lanes of the last step (instantaneous); in steady
running their sum equals the contacts' friction torque times the shaft speed (the energy balance,
tests/engine/test_friction_power.py). The spin power is the ellipse traction's
(ModelOptions.friction_model = 'ellipse_traction'); the centre-point laws put none here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from twin.jit import JIT_VECTOR
from twin.kernels import layout as L
from twin.model import BearingModel
from twin.physics import drag, seals, starvation
from twin.physics.viscosity import density_kg_m3
from twin.spec import BearingSpec, Geometry
from twin.state import TwinState

ORBIT_SAMPLES = 720  # azimuths of the orbit-mean immersed fraction of an oil bath
REST_SPEED_RAD_S = 1.0  # below this mean shaft speed over a frame the shaft counts as at rest [rad/s]


@dataclass(frozen=True)
class FrictionPower:
    """Friction power of one instant by source [W]; per-contact arrays have shape (Z, 2), column 0
    the inner, 1 the outer raceway contact of each ball; drag per ball (Z,)."""

    rolling_w: float
    sliding_w: float
    spin_w: float
    drag_w: float
    seal_w: float
    rolling_contact_w: np.ndarray
    sliding_contact_w: np.ndarray
    spin_contact_w: np.ndarray
    drag_ball_w: np.ndarray

    @property
    def total_w(self) -> float:
        """Sum of every source [W]."""
        return self.rolling_w + self.sliding_w + self.spin_w + self.drag_w + self.seal_w

    def by_source_w(self) -> dict[str, float]:
        """{'rolling', 'sliding', 'spin', 'drag', 'seal'} -> power [W]."""
        return {
            "rolling": self.rolling_w,
            "sliding": self.sliding_w,
            "spin": self.spin_w,
            "drag": self.drag_w,
            "seal": self.seal_w,
        }


def boundary_dimensions_m(geometry: Geometry) -> tuple[float, float]:
    """(bore d, outside diameter D) [m] from the spec, or, where it gives none, the pitch diameter
    -+ 1.6 ball diameters (the 62 series' proportion: 6208 40.4 / 80.8 mm against 40 / 80)."""
    pitch_d = geometry.inner_raceway_radius_m + geometry.outer_raceway_radius_m
    ball_d = 2.0 * geometry.ball_radius_m
    d = geometry.bore_diameter_m if geometry.bore_diameter_m is not None else pitch_d - 1.6 * ball_d
    big_d = geometry.outside_diameter_m if geometry.outside_diameter_m is not None else pitch_d + 1.6 * ball_d
    return d, big_d


def starvation_film_factor(spec: BearingSpec, shaft_speed_rad_s: float, kinematic_viscosity_m2_s: float) -> float:
    """Film reduction of kinematic starvation (twin.physics.starvation) for the spec's
    lubrication method [-]; 1 for 'flooded'."""
    method = spec.lubrication.method
    if method == "flooded":
        return 1.0
    d, big_d = boundary_dimensions_m(spec.geometry)
    return starvation.kinematic_replenishment_factor(
        shaft_speed_rad_s, kinematic_viscosity_m2_s, d, big_d, starvation.K_RS[method], starvation.K_Z[spec.kind]
    )


def seal_moment_n_m(spec: BearingSpec) -> float:
    """Frictional moment of the spec's seals [N m] (twin.physics.seals)."""
    g = spec.geometry
    d, big_d = boundary_dimensions_m(g)
    d_s = g.seal_counterface_diameter_m if g.seal_counterface_diameter_m is not None else d + 0.32 * (big_d - d)
    return seals.seal_moment_n_m(spec.lubrication.seal, d_s, big_d)


def oil_level_m(spec: BearingSpec) -> float:
    """Oil bath level above the bottom of the outer raceway [m] (default: one ball radius)."""
    lub = spec.lubrication
    return lub.oil_level_m if lub.oil_level_m is not None else spec.geometry.ball_radius_m


def mean_immersed_fraction(spec: BearingSpec) -> float:
    """Orbit mean of the share of a ball's frontal disc in the oil [-]: the oil bath's immersed
    fraction (twin.physics.drag) averaged over ORBIT_SAMPLES azimuths; the oil-air mixture's oil
    volume share for 'jet' and 'oil_air'; 0 for 'flooded' (no churning modelled)."""
    lub = spec.lubrication
    if lub.method == "flooded":
        return 0.0
    if lub.method != "oil_bath":
        return lub.cavity_oil_volume_fraction
    g = spec.geometry
    pitch = 0.5 * (g.inner_raceway_radius_m + g.outer_raceway_radius_m)
    level = oil_level_m(spec)
    az = (np.arange(ORBIT_SAMPLES) + 0.5) * (2.0 * math.pi / ORBIT_SAMPLES)
    return float(
        np.mean(
            [drag.immersed_area_fraction(drag.ball_depth_in_bath_m(level, a, pitch), 2.0 * g.ball_radius_m) for a in az]
        )
    )


def oil_bath_drag_power_w(spec: BearingSpec, shaft_speed_rad_s: float, kinematic_viscosity_m2_s: float) -> float:
    """Drag power of all the balls in the spec's oil bath [W]: the SKF model's M_drag
    (twin.physics.drag.oil_bath_drag_moment_n_m) at the spec's oil level, times |omega|."""
    d, big_d = boundary_dimensions_m(spec.geometry)
    moment = drag.oil_bath_drag_moment_n_m(
        d, big_d, oil_level_m(spec), shaft_speed_rad_s, kinematic_viscosity_m2_s, starvation.K_Z[spec.kind]
    )
    return moment * abs(shaft_speed_rad_s)


def seal_power_w(seal_moment_n_m: float, shaft_speed_rad_s: float) -> float:
    """Power of the rubbing seals [W]: their moment times the shaft speed, M_seal |omega|."""
    return max(seal_moment_n_m * abs(shaft_speed_rad_s), 0.0)


def ball_drag_power_w(
    ball_diameter_m: float,
    orbital_speed_m_s: float,
    oil_fraction: float,
    oil_density_kg_m3: float,
    oil_viscosity_pa_s: float,
) -> float:
    """Drag power of one ball [W]: the share `oil_fraction` of its frontal disc in oil, the rest in
    air (twin.physics.drag), times its orbital speed."""
    v = abs(orbital_speed_m_s)
    f_oil = drag.ball_drag_force_n(ball_diameter_m, v, oil_density_kg_m3, oil_viscosity_pa_s)
    f_air = drag.ball_drag_force_n(ball_diameter_m, v, drag.AIR_DENSITY_KG_M3, drag.AIR_VISCOSITY_PA_S)
    return (oil_fraction * f_oil + (1.0 - oil_fraction) * f_air) * v


@njit(**JIT_VECTOR)
def contact_powers_w(contacts, ball_angular_velocity_rad_s, ball_radius_m):  # pragma: no cover - compiled
    """(rolling, sliding, spin) power of every ball-raceway contact [W], each (Z, 2), from the
    contact lanes (N_ROWS, 2Z) of the last step, the balls' angular velocities (Z, 3) and radius.

    The work the DEM's forces do: the rolling force (applied at the ball's centre along the
    entrainment, twin.kernels.contacts) against the ball centre's velocity over the raceway's
    contact point; the tangential friction force against the slip of the contact point; the
    traction's moment across the ellipse (differential slip, E_M2*) against the ball's rotation
    relative to the ring; the moment about the normal against the relative spin rate. Their sum
    over the contacts is the shaft's power in steady running. Each is floored at 0 per contact
    (the tangential springs store and give back a little energy from step to step), and is 0 at
    an open contact."""
    c = contacts
    z = c.shape[1] // 2
    rolling = np.zeros((z, 2))
    sliding = np.zeros((z, 2))
    spin_w = np.zeros((z, 2))
    for k in range(2 * z):
        if not c[L.G_DELTA, k] > 0.0:
            continue
        j, side = k // 2, k % 2
        nx, ny, nz = c[L.G_NX, k], c[L.G_NY, k], c[L.G_NZ, k]
        per_speed = c[L.C_ROLLING_PER_SPEED, k]
        rfx, rfy, rfz = per_speed * c[L.O_EX, k], per_speed * c[L.O_EY, k], per_speed * c[L.O_EZ, k]  # on the ball [N]
        spin = c[L.K_SPIN, k]
        qx = c[L.K_PX, k] + ball_radius_m * nx  # contact point relative to the ring centre
        qy = c[L.K_PY, k] + ball_radius_m * ny
        ring_vx = c[L.K_OVX, k] - spin * qy
        ring_vy = c[L.K_OVY, k] + spin * qx
        ring_vz = c[L.K_OVZ, k]
        cx, cy, cz = c[L.K_VX, k] - ring_vx, c[L.K_VY, k] - ring_vy, c[L.K_VZ, k] - ring_vz
        p_roll = -(rfx * cx + rfy * cy + rfz * cz)
        fx, fy, fz = c[L.O_FX, k], c[L.O_FY, k], c[L.O_FZ, k]
        f_n = fx * nx + fy * ny + fz * nz
        ftx, fty, ftz = fx - f_n * nx - rfx, fy - f_n * ny - rfy, fz - f_n * nz - rfz  # tangential friction
        wx = ball_angular_velocity_rad_s[j, 0]
        wy = ball_angular_velocity_rad_s[j, 1]
        wz = ball_angular_velocity_rad_s[j, 2] - spin
        p_slide = -(ftx * c[L.O_SX, k] + fty * c[L.O_SY, k] + ftz * c[L.O_SZ, k]) - (
            c[L.E_M2X, k] * wx + c[L.E_M2Y, k] * wy + c[L.E_M2Z, k] * wz
        )
        p_spin = abs(c[L.E_SPIN_MOMENT, k] * c[L.E_SPIN_RATE, k])
        rolling[j, side] = p_roll if (p_roll > 0.0 or math.isnan(p_roll)) else 0.0
        sliding[j, side] = p_slide if (p_slide > 0.0 or math.isnan(p_slide)) else 0.0
        spin_w[j, side] = p_spin if (p_spin > 0.0 or math.isnan(p_spin)) else 0.0
    return rolling, sliding, spin_w


def friction_power_by_source(
    model: BearingModel,
    state: TwinState,
    oil_temperature_c: float,
    oil_viscosity_pa_s: float,
    immersed_fraction: float,
    seal_w: float,
) -> FrictionPower:
    """Friction power of the current instant by source and by contact [W]: the contacts' rolling,
    sliding and spin power from the last step's lanes (`contact_powers_w`), each ball's drag at
    its own depth in the oil bath (the bath's drag shared by the part of each ball in the oil) or
    in the cavity's oil-air mixture (`immersed_fraction` of oil, `ball_drag_power_w`) at the oil's
    density at `oil_temperature_c` [degC] and `oil_viscosity_pa_s`, and the seals' `seal_w`."""
    s, m = state, model
    rolling, sliding, spin = contact_powers_w(s.contacts, s.ball_angular_velocity_rad_s, m.ball_radius_m)
    lub = m.spec.lubricant
    rho = density_kg_m3(lub.density_15c_kg_m3, oil_temperature_c)
    drag_w = np.zeros(m.ball_count)
    method = m.spec.lubrication.method
    if method == "oil_bath":  # the bath's drag shared by the part of each ball in the oil
        x = s.ball_position_in_bearing_m
        from_bottom = np.arctan2(x[:, 1], x[:, 0])  # the bath's bottom lies on the load line (+x)
        share = np.array(
            [
                drag.immersed_area_fraction(
                    drag.ball_depth_in_bath_m(oil_level_m(m.spec), float(a), m.pitch_radius_m), 2.0 * m.ball_radius_m
                )
                for a in from_bottom
            ]
        )
        if share.sum() > 0.0:
            drag_w = (
                share
                / share.sum()
                * oil_bath_drag_power_w(m.spec, float(s.scalars[L.X_SHAFT_SPEED]), oil_viscosity_pa_s / rho)
            )
    elif method != "flooded":
        v = s.ball_velocity_in_bearing_m_s
        orbit_speed = np.hypot(v[:, 0], v[:, 1])
        for j in range(m.ball_count):
            drag_w[j] = ball_drag_power_w(
                2.0 * m.ball_radius_m, float(orbit_speed[j]), immersed_fraction, rho, oil_viscosity_pa_s
            )
    return FrictionPower(
        rolling_w=float(rolling.sum()),
        sliding_w=float(sliding.sum()),
        spin_w=float(spin.sum()),
        drag_w=float(drag_w.sum()),
        seal_w=seal_w,
        rolling_contact_w=rolling,
        sliding_contact_w=sliding,
        spin_contact_w=spin,
        drag_ball_w=drag_w,
    )


def frame_friction_torque_n_m(
    drive_n_m: float,
    duration_s: float,
    mean_speed_rad_s: float,
    kinetic_energy_change_j: float,
    momentum_change_n_m_s: float,
) -> float:
    """The friction torque of a frame [N m]: the shaft's mean drive torque less the torque that
    speeds the balls and the cage up (or that they give back as they slow down), which is
    inertia, not friction. Turning, the shaft's power drive * omega splits into the friction's
    dissipation and the rate of change of the balls' and cage's kinetic energy E, so
    M_f = drive - dE/dt / omega. With the shaft at rest (|omega| < REST_SPEED_RAD_S) the shaft
    does no work and the torque is the one the outer ring holds: drive less the rate of change
    of the balls' and cage's angular momentum about the axis."""
    if abs(mean_speed_rad_s) >= REST_SPEED_RAD_S:
        return drive_n_m - kinetic_energy_change_j / (duration_s * mean_speed_rad_s)
    return drive_n_m - momentum_change_n_m_s / duration_s
