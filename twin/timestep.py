"""Time step from the physics: the critical step of the explicit scheme and `time_step_s = "auto"`.

The engine integrates with the leapfrog form of velocity-Verlet (seed 000 eq. 10), velocity-
dependent forces taking the half-step velocity (turned on by the cage's half-step rotation, a
turn of under 1e-3 rad that leaves the limit below unchanged, `twin.validation.timestep_study` measures it):
the central-difference scheme. For a linear oscillator of circular frequency omega and damping ratio zeta it is stable
for

    dt <= dt_crit = 2 / omega (sqrt(1 + zeta^2) - zeta)

(Belytschko, Liu, Moran, Elkhodary, Nonlinear Finite Elements for Continua and Structures, 2nd ed.,
section 6.2: the central-difference method with damping). The model's stiffest elements are
linearised at the bearing's static capacity (the ball load `static_load_n` at which the Hertz
pressure reaches 4.2 GPa, ISO 76: the model refuses larger loads, so no contact is stiffer in
use), where the Hertz stiffness of seed 000 eq. 2, Q = K delta^1.5, has the slope

    k_n = dQ/d(delta) = 1.5 K delta^0.5 = 1.5 K^(2/3) Q^(1/3).

Elements (each an eigenproblem K phi = omega^2 M phi of a few degrees of freedom, damping ratio
of each mode phi^T C phi / (2 omega phi^T M phi)):

- ball normal: the ball between the fixed outer ring (k_n outer) and the inner ring (k_n inner),
  the inner ring (rotor mass) held by the other balls; damping: seed 000 Table 2's normal
  damping, bounded by the larger of C_hyst = 1.5 alpha_e Q (eq. 4, the boundary and, through the
  series law, the mixed regime) and C_fluid (eq. 5) at the Lambda = 3 edge of the full-film
  regime for the oil at `REFERENCE_OIL_TEMPERATURE_C` (C_fluid only falls as the film grows);
- ball tangential: ball translation and rotation on the two tangential springs
  Kt = kt_ratio k_n (`twin.kernels.contacts.raceway_forces`), their damping
  Ct = ct_ratio 2 sqrt(Kt m_t) and the rolling-resistance drag F_R / max(u, 0.01 m/s) of the
  kernel at its largest (u = 0.01 m/s);
- one tangential contact with the ball's reduced tangential mass m_t = m / (1 + m Rb^2 / I)
  (the mass the kernel's tangential damping refers to);
- ball-cage element: seed 000 eq. 3 stiffness linearised at the same load, the ball-cage reduced
  mass, critical damping (seed 000 section 2.1).

`time_step_s = "auto"` is `SAFETY_FACTOR` x the smallest critical step, rounded down to a whole
divisor of `STEP_DIVISOR_S` = 1 ms (so the engine's frames, the runner's and every period that is a
whole number of milliseconds hold a whole number of steps).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final

import numpy as np
from scipy import linalg

from twin.kernels import layout as L
from twin.kernels.step import ROLLING_REGULARISATION_SPEED
from twin.kernels.tribology import contact_tribology
from twin.physics.damping import fluid_damping_n_s_m, hysteretic_damping_n_s_m
from twin.spec import TIME_STEP_RANGE_S

AUTO: Final = "auto"

# The auto step is this fraction of the critical step. Why 0.8 and not 1: the critical step is
# exact for a linear oscillator; the model is not linear (the Hertz stiffness grows as
# Q^(1/3) under the dynamic overshoot of a load step, a few % on omega), its elements are coupled
# (the estimate treats each alone, and coupling raises the highest frequency slightly), and the
# bound of the fluid damping holds at the reference oil temperature only. 0.8 leaves 25 % on the
# step for these. Accuracy is not what sets it: `twin.validation.timestep_study` shows that the outputs at
# the auto step agree with 1 us within the study's tolerances over the operating envelope.
SAFETY_FACTOR = 0.8
STEP_DIVISOR_S = 1e-3  # the auto step divides 1 ms [s]
REFERENCE_OIL_TEMPERATURE_C = 40.0  # ISO 3448 reference temperature, the seeds' oil temperature


def central_difference_critical_step_s(omega_rad_s: float, damping_ratio: float) -> float:
    """dt_crit = 2 / omega (sqrt(1 + zeta^2) - zeta) [s] of the central-difference scheme with
    damping (Belytschko et al., section 6.2). omega [rad/s], zeta [-]."""
    if omega_rad_s <= 0.0:
        return math.inf
    z = max(damping_ratio, 0.0)
    return float(2.0 / omega_rad_s * (math.sqrt(1.0 + z * z) - z))


def hertz_tangent_stiffness_n_m(stiffness_n_m15: float, load_n: float) -> float:
    """k_n = dQ/d(delta) = 1.5 K^(2/3) Q^(1/3) [N/m] of Q = K delta^1.5 (seed 000 eqs. 2-3)."""
    return 1.5 * stiffness_n_m15 ** (2.0 / 3.0) * max(load_n, 0.0) ** (1.0 / 3.0)


@dataclass(frozen=True)
class Element:
    """One stiff element of the model, linearised at the static capacity."""

    name: str
    omega_rad_s: float  # highest circular frequency of the element [rad/s]
    damping_ratio: float  # of that mode [-]
    critical_step_s: float  # central-difference stability limit [s]


@dataclass(frozen=True)
class CriticalTimeStep:
    """The critical step of a compiled model and the elements it comes from."""

    static_load_n: float  # ball load at which the elements are linearised [N]
    reference_viscosity_pa_s: float  # oil viscosity of the fluid-damping bound [Pa s]
    elements: tuple[Element, ...]

    @property
    def critical_step_s(self) -> float:
        """The smallest critical step of all elements [s]."""
        return min(e.critical_step_s for e in self.elements)

    @property
    def limiting_element(self) -> str:
        """Name of the element that sets the critical step."""
        return min(self.elements, key=lambda e: e.critical_step_s).name

    @property
    def auto_time_step_s(self) -> float:
        """SAFETY_FACTOR x the critical step, rounded down to a divisor of STEP_DIVISOR_S [s]."""
        return auto_time_step_s(self.critical_step_s)

    def as_dict(self) -> dict:
        """Plain-data form (SI, units in the keys)."""
        return {
            "critical_time_step_s": self.critical_step_s,
            "limiting_element": self.limiting_element,
            "auto_time_step_s": self.auto_time_step_s,
            "safety_factor": SAFETY_FACTOR,
            "static_load_n": self.static_load_n,
            "reference_viscosity_pa_s": self.reference_viscosity_pa_s,
            "elements": [
                {
                    "name": e.name,
                    "omega_rad_s": e.omega_rad_s,
                    "damping_ratio": e.damping_ratio,
                    "critical_time_step_s": e.critical_step_s,
                }
                for e in self.elements
            ],
        }


def _highest_mode(name: str, k: np.ndarray, m: np.ndarray, c: np.ndarray) -> Element:
    """The mode of K phi = omega^2 M phi with the smallest critical step (modal damping)."""
    omega2, phi = linalg.eigh(k, m)  # phi is mass-normalised: phi^T M phi = 1
    best: Element | None = None
    for i, w2 in enumerate(omega2):
        if w2 <= 0.0:
            continue
        w = math.sqrt(w2)
        zeta = float(phi[:, i] @ c @ phi[:, i]) / (2.0 * w)
        e = Element(name, w, float(zeta), central_difference_critical_step_s(w, zeta))
        if best is None or e.critical_step_s < best.critical_step_s:
            best = e
    if best is None:
        raise ValueError(f"{name}: no mode of positive stiffness")
    return best


def estimate(
    params: np.ndarray,
    race_params: np.ndarray,
    race_tribology: np.ndarray,
    static_load_n: float,
    reference_viscosity_pa_s: float,
    ball_count: int,
) -> CriticalTimeStep:
    """The critical step of the model arrays (`twin.model`), every element at `static_load_n`."""
    p = params
    q = float(static_load_n)
    m = p[L.P_BALL_MASS]
    inertia = p[L.P_BALL_INERTIA]
    rb = p[L.P_BALL_RADIUS]
    m_ring = p[L.P_RING_MASS]
    m_t = p[L.P_BALL_REDUCED_TANGENT_MASS]
    kn, cn, kt, ct, croll = [], [], [], [], []
    for r in range(2):
        big_k = race_params[r, L.R_STIFFNESS]
        k = hertz_tangent_stiffness_n_m(big_k, q)
        delta = (q / big_k) ** (2.0 / 3.0)
        a = race_params[r, L.R_SEMI_MAJOR_COEF] * q ** (1.0 / 3.0)
        c_hyst = hysteretic_damping_n_s_m(p[L.P_ALPHA_E], big_k, delta)
        c_fluid = fluid_damping_n_s_m(reference_viscosity_pa_s, a, rb, 3.0 * p[L.P_ROUGHNESS])
        kn.append(k)
        cn.append(max(c_hyst, c_fluid))
        kt.append(p[L.P_KT_RATIO] * k)
        ct.append(p[L.P_CT_RATIO] * 2.0 * math.sqrt(p[L.P_KT_RATIO] * k * m_t))
        roll = 0.0
        if p[L.P_ROLLING] != 0.0:
            tri = contact_tribology(
                q,
                ROLLING_REGULARISATION_SPEED,
                reference_viscosity_pa_s,
                p[L.P_ROUGHNESS],
                *race_tribology[r, :15],
                int(p[L.P_FRICTION_MODEL]),
                True,
            )
            roll = tri[8] / ROLLING_REGULARISATION_SPEED
        croll.append(roll)
    ki, ko = kn
    ci, co = cn
    rest = max(ball_count - 1, 0)
    # ball normal: (ball, inner ring) along the contact line; the ring also rests on the others
    normal = _highest_mode(
        "ball normal (inner + outer Hertz contacts, inner-ring mass)",
        np.array([[ki + ko, -ki], [-ki, ki * (1 + rest)]]),
        np.diag([m, m_ring]),
        np.array([[ci + co, -ci], [-ci, ci * (1 + rest)]]),
    )
    # ball tangential: translation x and rotation theta; contact slips x + Rb theta, x - Rb theta
    g = (np.array([1.0, rb]), np.array([1.0, -rb]))
    k_tan = kt[0] * np.outer(g[0], g[0]) + kt[1] * np.outer(g[1], g[1])
    c_tan = ct[0] * np.outer(g[0], g[0]) + ct[1] * np.outer(g[1], g[1]) + np.diag([croll[0] + croll[1], 0.0])
    tangential = _highest_mode(
        "ball tangential (two tangential springs, translation + rotation)", k_tan, np.diag([m, inertia]), c_tan
    )
    r_stiff = int(np.argmax(kt))
    w_single = math.sqrt(kt[r_stiff] / m_t)
    single = Element(
        "one tangential contact, reduced mass m / (1 + m Rb^2 / I)",
        w_single,
        float(p[L.P_CT_RATIO]),
        central_difference_critical_step_s(w_single, p[L.P_CT_RATIO]),
    )
    k_cage = hertz_tangent_stiffness_n_m(p[L.P_CAGE_STIFFNESS], q)
    w_cage = math.sqrt(k_cage / p[L.P_CAGE_REDUCED_MASS])
    cage = Element("ball-cage element (critical damping)", w_cage, 1.0, central_difference_critical_step_s(w_cage, 1.0))
    return CriticalTimeStep(
        static_load_n=q,
        reference_viscosity_pa_s=float(reference_viscosity_pa_s),
        elements=(normal, tangential, single, cage),
    )


def auto_time_step_s(
    critical_step_s: float, safety_factor: float = SAFETY_FACTOR, divisor_s: float = STEP_DIVISOR_S
) -> float:
    """safety_factor x critical_step_s rounded down to divisor_s / n, n a whole number [s]."""
    target = min(safety_factor * critical_step_s, TIME_STEP_RANGE_S[1])
    return divisor_s / math.ceil(divisor_s / target - 1e-9)


def resolve_time_step_s(requested: float | str, critical: CriticalTimeStep) -> float:
    """The step a model integrates with: the number given, or the auto step for "auto" [s]."""
    if requested == AUTO:
        return critical.auto_time_step_s
    return float(requested)


def steps_per_period(period_s: float, time_step_s: float) -> int:
    """A sub-rate period [s] as a whole number of steps (nearest, at least 1)."""
    return max(1, int(round(period_s / time_step_s)))


def parse_time_step(text: str) -> float | str:
    """`auto` or a number of seconds (command-line form of ModelOptions.time_step_s)."""
    t = str(text).strip().lower()
    if t == AUTO:
        return AUTO
    try:
        return float(t)
    except ValueError:
        raise ValueError(f"time step: {text!r} is neither 'auto' nor a number of seconds") from None
