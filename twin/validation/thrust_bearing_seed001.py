"""Seed 001 validation case: friction torque of the modified 51205 thrust ball bearing with three
balls (Balan, Houpert, Olaru et al.), from the rolling laws of twin.physics.rolling, and the
measured torque fits of the seed's Tables 1 and 2.

Plain Python (not a kernel): a reference calculation for tests and validation scenarios.

Set-up of seed 001 Section 2-3: three balls at 120 deg between the two washers of a 51205 thrust
bearing; groove (race curvature) radius 4.16 mm on both races; ball load Q = G/3; spin-down of
the upper race 2 at omega2 while race 1 is held still, so the ball centres orbit at omega2/2 and
the mean entrainment speed of each ball-race contact is u = omega2 r / 2.

Contact geometry (thrust bearing, contact angle 90 deg): in the rolling (circumferential)
direction the race is straight, so Rx = d/2; across it the ball sits in the groove of radius
rc, so 1/Ry = 2/d - 1/rc, i.e. Ry = rc (d/2) / (rc - d/2) and k = Ry/Rx = rc / (rc - d/2).
Check: d = 7.938 mm gives k = 21.78, the value seed 001 Section 4.5 states.
"""

import math
from dataclasses import dataclass

from twin.physics.hertz import semi_major_axis_m
from twin.physics.rolling import (
    ehl_parameter_m,
    ehl_share,
    hysteresis_moment_n_m,
    pivoting_moment_n_m,
    rolling_force_ehl_n,
    rolling_force_ivr_n,
    rolling_force_transition_n,
)

E_STAR_PA = 2.3e11  # seed 001 below eq. 7, steel ball on steel race
GROOVE_RADIUS_M = 4.16e-3  # seed 001 Sections 1 and 3.1: race curvature radius 4.16 mm
# Race (pitch) radius r of the ball-race contact circle. Seed 001 only shows it in Figure 1; it
# is not printed. 51205 catalogue: bore 25 mm, outside diameter 47 mm -> pitch diameter about
# (25 + 47)/2 = 36 mm, r = 18 mm.
RACE_PITCH_RADIUS_M = 18.0e-3
VISCOSITY_PA_S = 0.05  # seed 001 Tables 1-2 (the other oil of the paper is 0.08 Pa s)
N_BALLS = 3

# Seed 001 Table 1 (d = 3 mm, Q = 0.633 N, eta0 = 0.05 Pa s, Lambda = 0.3-0.8) and Table 2
# (d = 6.35 mm, Q = 0.125 N, eta0 = 0.05 Pa s, Lambda = 0.6-3.2): fits Tz_exp = K* omega2^n of
# one spin-down run each, keyed by the run's initial speed [rpm]. Units as the seed gives them:
# K* printed as "x 10^-5", i.e. the values below are K* / 1e-5 in N m (rad/s)^-n, omega2 in
# rad/s, Tz in N m (the only reading that puts the measurements within tens of % of eq. 22 and
# the dry torque at the 2-12 % the seed reports). Stored as (K* [1e-5 N m (rad/s)^-n], n [-]).
TABLE_1_D3MM_Q0633N = {
    60: (4.001, 0.116),
    90: (3.287, 0.277),
    120: (2.864, 0.318),
    150: (2.796, 0.366),
    180: (3.210, 0.344),
    210: (3.213, 0.339),
}
TABLE_2_D635MM_Q0125N = {
    60: (4.208, 0.652),
    90: (3.839, 0.647),
    120: (3.943, 0.620),
    150: (3.779, 0.654),
    180: (3.457, 0.622),
    210: (3.354, 0.649),
}
K_STAR_UNIT_N_M = 1.0e-5  # the "x 10^-5" of Tables 1-2


def rpm_to_rad_s(rpm: float) -> float:
    """omega [rad/s] from a rotational speed in rpm."""
    return rpm * 2.0 * math.pi / 60.0


def ball_race_geometry(ball_diameter_m: float, groove_radius_m: float = GROOVE_RADIUS_M):
    """(Rx, Ry, k) of a ball in a thrust-bearing groove [m, m, -]: Rx = d/2,
    Ry = rc (d/2) / (rc - d/2), k = Ry/Rx (seed 001 below eq. 7; k = 21.78 for d = 7.938 mm,
    Section 4.5). Raises ValueError if the ball does not fit the groove (d/2 >= rc)."""
    rx = 0.5 * ball_diameter_m
    if not (0.0 < rx < groove_radius_m):
        raise ValueError("need 0 < d/2 < groove radius")
    ry = groove_radius_m * rx / (groove_radius_m - rx)
    return rx, ry, ry / rx


def entrainment_speed_m_s(rpm: float, pitch_radius_m: float = RACE_PITCH_RADIUS_M) -> float:
    """u = omega2 r / 2 [m/s]: race 2 at omega2, race 1 held, ball centre at omega2 r / 2; each
    surface moves at omega2 r / 2 relative to the contact (seed 001 Section 2, eq. 6)."""
    return rpm_to_rad_s(rpm) * pitch_radius_m / 2.0


def measured_torque_n_m(table: dict, rpm: int) -> float:
    """Measured-fit torque Tz_exp = K* omega2^n [N m] of the seed 001 Table 1 or 2 run that
    started at `rpm`, evaluated at its initial speed omega2 = 2 pi rpm / 60."""
    k_star, n = table[rpm]
    return k_star * K_STAR_UNIT_N_M * rpm_to_rad_s(rpm) ** n


@dataclass(frozen=True)
class Seed001Torque:
    """Result of thrust_torque_seed001 (one speed)."""

    torque_n_m: float  # Tz = 6 r FR [N m]
    rolling_force_n: float  # FR of one contact for the chosen law [N]
    ehl_share: float  # (M/6.6)/(1 + M/6.6) [-]
    m_parameter: float  # M of eq. 4 [-]
    entrainment_speed_m_s: float  # u = omega2 r / 2 [m/s]
    k_radii_ratio: float  # Ry/Rx [-]


def thrust_torque_seed001(
    ball_diameter_m: float,
    ball_load_n: float,
    rpm: float,
    law: str = "transition",
    eta_pa_s: float = VISCOSITY_PA_S,
    groove_radius_m: float = GROOVE_RADIUS_M,
    pitch_radius_m: float = RACE_PITCH_RADIUS_M,
    e_star_pa: float = E_STAR_PA,
) -> Seed001Torque:
    """Hydrodynamic friction torque of the 3-ball 51205 bearing, Tz = 6 r FR [N m]
    (seed 001 eqs. 14 and 22; FR from eqs. 1-5 per `law` = "ivr" | "ehl" | "transition").

    Why 6 r FR: 3 balls x 2 contacts (ball-race 1 and ball-race 2). Each FR acts on both surfaces
    of its contact, and the force equilibrium of a ball (seed 001 eqs. 12, B1-B3) makes the
    tangential force the ball puts on race 2 equal to FR2 + FS2 = 2 FR (hysteresis and inertia
    neglected), so 3 balls give 3 * 2 FR at lever arm r. Energy check: each contact dissipates
    FR times the sum of its two surface speeds, 2 FR u = FR omega2 r, and 6 contacts give
    6 FR r omega2 = Tz omega2.
    The seed advises "ivr" when the IVR partition dominates (Q = 0.125 N) and "transition" when
    the EHL share exceeds 50 % (Sections 4.4-4.5).
    """
    rx, _ry, k = ball_race_geometry(ball_diameter_m, groove_radius_m)
    u = entrainment_speed_m_s(rpm, pitch_radius_m)
    args = (e_star_pa, rx, k, ball_load_n, eta_pa_s, u)
    if law == "ivr":
        fr = rolling_force_ivr_n(*args)
    elif law == "ehl":
        fr = rolling_force_ehl_n(*args)
    elif law == "transition":
        fr = rolling_force_transition_n(*args)
    else:
        raise ValueError(f"unknown law {law!r}: 'ivr', 'ehl' or 'transition'")
    m = ehl_parameter_m(*args)
    return Seed001Torque(
        torque_n_m=2.0 * N_BALLS * pitch_radius_m * fr,
        rolling_force_n=fr,
        ehl_share=ehl_share(m),
        m_parameter=m,
        entrainment_speed_m_s=u,
        k_radii_ratio=k,
    )


def secondary_torques_seed001(
    ball_diameter_m: float,
    ball_load_n: float,
    mu_s: float,
    groove_radius_m: float = GROOVE_RADIUS_M,
    pitch_radius_m: float = RACE_PITCH_RADIUS_M,
    e_star_pa: float = E_STAR_PA,
) -> tuple[float, float]:
    """(Tz_MER, Tz_MP) [N m]: hysteresis torque 6 r MER / d and pivoting torque 3 MP of the
    3-ball bearing (seed 001 eq. 14 with eqs. 9 and 11), both speed independent. The seed
    neglects them (Appendix A: with inertia, 5.6 % to 2.6 % of the hydrodynamic torque for
    d = 3 mm, Q = 0.633 N). a_c is the Hamrock-Brewe major semi-axis (twin.physics.hertz)."""
    rx, ry, k = ball_race_geometry(ball_diameter_m, groove_radius_m)
    mer = hysteresis_moment_n_m(ball_diameter_m, ball_load_n, k)
    a_c = semi_major_axis_m(ball_load_n, rx, ry, e_star_pa)
    mp = pivoting_moment_n_m(mu_s, ball_load_n, a_c, k)
    return 2.0 * N_BALLS * pitch_radius_m * mer / ball_diameter_m, N_BALLS * mp
