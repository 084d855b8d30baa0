"""Housing support of the outer ring and the accelerometer on it.

Model (Sawalhi & Randall 2008, "Simulating gear and bearing interactions in the presence of
faults, Part I", MSSP 22(8) 1924-1951, sec. 3 bearing model): the outer ring and its pedestal
move as one mass m_p on a radial spring-damper (k_p, c_p) in x and y (and, here, an axial one in
z); a "sprung mass" m_r on a stiff spring-damper (k_r, c_r) sits on the pedestal and represents
the typical high-frequency bearing/housing resonance that an accelerometer sees the impacts
through. The accelerometer measures the absolute acceleration of the sprung mass along its axis.

Default values are the published ones (Sawalhi & Randall 2008 Part I, as tabulated in the 5-DoF
bearing model of Ruan, Li & Guehmann 2021, Proc. 14th Int. Modelica Conf., "Modeling of a bearing
test bench and analysis of defect bearing dynamics in Modelica"): m_p = 6.638 kg,
k_p = 1.51e7 N/m, c_p = 2210.7 N s/m (a ~240 Hz pedestal mode, 11 % damping), m_r = 1 kg,
k_r = 8.8826e9 N/m, c_r = 9424.8 N s/m, i.e. sqrt(k_r/m_r) = 2 pi 15.0 kHz with 5 % damping
(coupled to the pedestal the sensed resonance is ~16 kHz). Sawalhi & Randall give no axial
support; the axial defaults repeat the radial ones (an assumption, stated in the field).

Degrees of freedom (state arrays of length N_HOUSING_DOF, SI): 0..2 the outer-ring/pedestal
centre displacement x, y, z [m] (world frame, bearing axis +z, radial load along +x), 3 the
sprung-mass displacement along the accelerometer axis e [m] (absolute). Equations of motion
(F the force of the balls on the outer ring [N], k_i/c_i = radial in x, y and axial in z):

    f_r = k_r (u_r - e.x_p) + c_r (v_r - e.v_p)
    m_p a_p,i = F_i - k_i x_p,i - c_i v_p,i + f_r e_i
    m_r a_r   = -f_r                                        sensor reading: a_r [m/s^2]

Time integration (`housing_accelerations`, `housing_kick_drift`, `housing_close`): the engine's
velocity-Verlet in leapfrog form (seed 000 eq. 10). The viscous terms are taken at the end-of-step
velocity v_{n+1} = v_{n+1/2} + dt/2 a_{n+1}, solved in closed form (the system is linear), which
keeps the scheme second order with damping (the engine's contacts use the half-step velocity,
first order in the damping term). Stable for omega dt < 2: 0.63 at the 16 kHz mode and dt = 6 us.
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
import scipy.linalg
from numba import njit
from pydantic import BaseModel, ConfigDict, Field, model_validator

from twin.jit import JIT

# The functions the kernel calls every step are inlined at numba level: a call that passes arrays
# costs reference counting of each array (measured ~100 ns per step for these on the test machine).
JIT_INLINE = dict(JIT, inline="always")

MIN_WINDOW_SAMPLES = 1024  # the fewest samples an analysed window holds (indicators, envelope, kurtogram)

_FROZEN = ConfigDict(frozen=True, extra="forbid", strict=True, allow_inf_nan=False)

# Whether a bearing's outer ring rides on the housing unless its spec says otherwise. Off: with the
# housing on, two seed checks leave their tolerances at the auto step (the 7208 B's inner-ring
# displacement under Fr = Fa 3.1 % off Jones' for 3 %, the 5 A case of the timestep study 0.9 % on
# mu for 0.5 %), the step no longer divides 1 ms and a step costs ~10 % more (docs/physics.md,
# Vibration). `bearing-twin vibration` and the vibration bench case switch it on.
HOUSING_ENABLED_BY_DEFAULT = False

# ---- housing parameter vector (immutable, from `housing_params`) ---------------------------------
H_PEDESTAL_MASS = 0  # m_p [kg] (outer ring + pedestal)
H_RADIAL_STIFFNESS = 1  # k_p [N/m] in x and y
H_RADIAL_DAMPING = 2  # c_p [N s/m]
H_AXIAL_STIFFNESS = 3  # [N/m] in z
H_AXIAL_DAMPING = 4  # [N s/m]
H_SPRUNG_MASS = 5  # m_r [kg]
H_SPRUNG_STIFFNESS = 6  # k_r [N/m]
H_SPRUNG_DAMPING = 7  # c_r [N s/m]
H_EX = 8  # accelerometer axis e, unit vector (world frame)
H_EY = 9
H_EZ = 10
N_HOUSING_PARAMS = 11

# ---- housing state (displacement, velocity, acceleration arrays of this length) -----------------
HX = 0  # outer ring / pedestal centre [m]
HY = 1
HZ = 2
HR = 3  # sprung mass along e [m]
N_HOUSING_DOF = 4


class Accelerometer(BaseModel):
    """Where the accelerometer sits, what it measures, how it is sampled."""

    model_config = _FROZEN

    azimuth_deg: float = Field(
        default=0.0,
        ge=0.0,
        lt=360.0,
        description="Azimuth of the sensor on the housing [deg] from +x (the radial load direction, the "
        "centre of the load zone), positive about the bearing axis +z.",
    )
    direction: Literal["radial", "axial"] = Field(
        default="radial", description="Measuring axis: radial at the sensor's azimuth, or axial (+z)."
    )
    sample_rate_hz: float = Field(
        default=51200.0,
        ge=1000.0,
        le=204800.0,
        description="Output sample rate of the in-kernel decimator [Hz] (51.2 kHz: a usual DAQ rate).",
    )
    window_s: float = Field(
        default=1.0,
        ge=0.05,
        le=60.0,
        description="Indicator window [s]: RMS, kurtosis, envelope spectrum ... are computed on each whole window.",
    )
    noise_density_m_s2_rthz: float = Field(
        default=0.0,
        ge=0.0,
        le=1.0,
        description="White sensor noise density [m/s^2/sqrt(Hz)] (one-sided); 0 = noiseless. A general-purpose "
        "ICP accelerometer is ~1e-3 (100 ug/sqrt(Hz)).",
    )
    noise_seed: int | None = Field(
        default=None,
        ge=0,
        le=2**32 - 1,
        description="Seed of the twin's sensor noise generator (numpy); null: fresh entropy.",
    )

    @property
    def axis(self) -> tuple[float, float, float]:
        """Unit measuring axis e in the world frame."""
        if self.direction == "axial":
            return (0.0, 0.0, 1.0)
        a = math.radians(self.azimuth_deg)
        return (math.cos(a), math.sin(a), 0.0)


class Housing(BaseModel):
    """Outer ring + housing support and the sprung mass carrying the accelerometer (module docstring;
    defaults: Sawalhi & Randall 2008 Part I). `enabled` False keeps seed 000's rigid, fixed outer
    ring (no housing DOFs, no sensor)."""

    model_config = _FROZEN

    enabled: bool = Field(
        default=HOUSING_ENABLED_BY_DEFAULT,
        description="Outer ring on the housing support, accelerometer sampled in the kernel (twin.vibration). "
        "False: seed 000's rigid, fixed outer ring, no vibration signal.",
    )

    pedestal_mass_kg: float = Field(
        default=6.638, gt=0.01, le=1e4, description="Outer ring + pedestal mass m_p [kg] (Sawalhi & Randall 2008)."
    )
    radial_stiffness_n_m: float = Field(
        default=1.51e7, gt=1e3, le=1e12, description="Pedestal radial stiffness k_p in x and y [N/m]."
    )
    radial_damping_n_s_m: float = Field(
        default=2210.7, ge=0.0, le=1e8, description="Pedestal radial damping c_p [N s/m]."
    )
    axial_stiffness_n_m: float = Field(
        default=1.51e7,
        gt=1e3,
        le=1e12,
        description="Pedestal axial stiffness [N/m] (not in Sawalhi & Randall: the radial value is assumed).",
    )
    axial_damping_n_s_m: float = Field(
        default=2210.7, ge=0.0, le=1e8, description="Pedestal axial damping [N s/m] (radial value assumed)."
    )
    sprung_mass_kg: float = Field(
        default=1.0, gt=1e-4, le=1e3, description="Sprung mass m_r carrying the accelerometer [kg]."
    )
    sprung_stiffness_n_m: float = Field(
        default=8.8826e9,
        gt=1e3,
        le=1e13,
        description="Sprung-mass stiffness k_r [N/m] (8.8826e9 with 1 kg: a 15.0 kHz resonance).",
    )
    sprung_damping_n_s_m: float = Field(
        default=9424.8, ge=0.0, le=1e8, description="Sprung-mass damping c_r [N s/m] (5 % of critical)."
    )
    accelerometer: Accelerometer = Accelerometer()

    @model_validator(mode="after")
    def _resonance_in_band(self) -> Housing:
        if not self.enabled:  # no signal is sampled
            return self
        f = sensor_resonance(self)[0]
        limit = PASSBAND_FRACTION * self.accelerometer.sample_rate_hz
        if f > limit:
            raise ValueError(
                f"the sensed housing resonance is {f:.0f} Hz, above the anti-aliasing passband "
                f"({PASSBAND_FRACTION:g} x accelerometer.sample_rate_hz = {limit:.0f} Hz): raise "
                f"accelerometer.sample_rate_hz to at least {f / PASSBAND_FRACTION:.0f} Hz or soften "
                "sprung_stiffness_n_m"
            )
        acc = self.accelerometer
        if acc.window_s * acc.sample_rate_hz < MIN_WINDOW_SAMPLES:
            raise ValueError(
                f"accelerometer.window_s = {acc.window_s:g} s holds {acc.window_s * acc.sample_rate_hz:.0f} "
                f"samples at {acc.sample_rate_hz:g} Hz: must be in [{MIN_WINDOW_SAMPLES / acc.sample_rate_hz:g}, 60] s "
                f"(at least {MIN_WINDOW_SAMPLES} samples per indicator window)"
            )
        return self


# decimator passband edge as a fraction of the output rate (twin.vibration.signal uses the same)
PASSBAND_FRACTION = 0.4


def housing_params(housing: Housing) -> np.ndarray:
    """The read-only parameter vector (H_* layout) the numba functions take."""
    p = np.zeros(N_HOUSING_PARAMS)
    p[H_PEDESTAL_MASS] = housing.pedestal_mass_kg
    p[H_RADIAL_STIFFNESS] = housing.radial_stiffness_n_m
    p[H_RADIAL_DAMPING] = housing.radial_damping_n_s_m
    p[H_AXIAL_STIFFNESS] = housing.axial_stiffness_n_m
    p[H_AXIAL_DAMPING] = housing.axial_damping_n_s_m
    p[H_SPRUNG_MASS] = housing.sprung_mass_kg
    p[H_SPRUNG_STIFFNESS] = housing.sprung_stiffness_n_m
    p[H_SPRUNG_DAMPING] = housing.sprung_damping_n_s_m
    p[H_EX : H_EZ + 1] = housing.accelerometer.axis
    p.setflags(write=False)
    return p


def matrices(housing: Housing) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Mass, damping and stiffness matrices M, C, K (4 x 4, DOF order x, y, z, sprung mass) of the
    equations of motion in the module docstring."""
    e = np.array(housing.accelerometer.axis)
    m = np.diag([housing.pedestal_mass_kg] * 3 + [housing.sprung_mass_kg])

    def coupled(ped_xy, ped_z, spring):
        a = np.diag([ped_xy, ped_xy, ped_z, 0.0])
        b = np.concatenate([-e, [1.0]])  # u_r - e.x_p
        return a + spring * np.outer(b, b)

    c = coupled(housing.radial_damping_n_s_m, housing.axial_damping_n_s_m, housing.sprung_damping_n_s_m)
    k = coupled(housing.radial_stiffness_n_m, housing.axial_stiffness_n_m, housing.sprung_stiffness_n_m)
    return m, c, k


def modes(housing: Housing) -> list[tuple[float, float, np.ndarray]]:
    """Oscillatory modes of the housing, by frequency: (natural frequency [Hz], damping ratio [-],
    complex mode shape over the 4 DOFs). From the eigenvalues lambda of the first-order state
    matrix [[0, I], [-M^-1 K, -M^-1 C]]: f = |lambda| / 2 pi, zeta = -Re(lambda) / |lambda|
    (exact for non-proportional damping; overdamped real eigenvalues are not modes and are left out)."""
    m, c, k = matrices(housing)
    minv = np.linalg.inv(m)
    a = np.block([[np.zeros((4, 4)), np.eye(4)], [-minv @ k, -minv @ c]])
    lam, vec = scipy.linalg.eig(a)
    out = []
    for i in np.argsort(np.abs(lam)):
        if lam[i].imag > 0.0:
            w = abs(lam[i])
            out.append((float(w / (2.0 * math.pi)), float(-lam[i].real / w), vec[:4, i]))
    return out


def sensor_resonance(housing: Housing) -> tuple[float, float]:
    """(frequency [Hz], damping ratio [-]) of the mode the accelerometer sees the impacts through:
    the one with the largest stretch of the sprung-mass spring, |u_r - e.x_p| / |mode|."""
    e = np.array(housing.accelerometer.axis)
    best: tuple[float, float] | None = None
    score = -1.0
    for f, zeta, shape in modes(housing):
        stretch = abs(shape[3] - e @ shape[:3]) / np.linalg.norm(shape)
        if stretch > score:
            best, score = (f, zeta), stretch
    if best is None:
        raise ValueError("housing: no vibration mode")
    return best


@njit(**JIT_INLINE)
def housing_accelerations(hp, hx, hv, fx, fy, fz, dt, ha):
    """Accelerations of the housing DOFs at the end of a step (module docstring equations).

    hx: displacements at step n+1 [m]; hv: velocities at n+1/2 [m/s] (the leapfrog state, or the
    full-step velocity with dt = 0 for an explicit evaluation); (fx, fy, fz): force of the balls on
    the outer ring at n+1 [N]; dt the step [s]. The damping forces use v_{n+1} = v_{n+1/2} +
    dt/2 a_{n+1}, solved in closed form. Writes ha [m/s^2]; returns the accelerometer reading a_r."""
    h = 0.5 * dt
    mp = hp[H_PEDESTAL_MASS]
    mr = hp[H_SPRUNG_MASS]
    cr = hp[H_SPRUNG_DAMPING]
    ex = hp[H_EX]
    ey = hp[H_EY]
    ez = hp[H_EZ]
    rel = hx[HR] - (ex * hx[HX] + ey * hx[HY] + ez * hx[HZ])
    relv = hv[HR] - (ex * hv[HX] + ey * hv[HY] + ez * hv[HZ])
    f_h = hp[H_SPRUNG_STIFFNESS] * rel + cr * relv
    cxy = hp[H_RADIAL_DAMPING]
    cz = hp[H_AXIAL_DAMPING]
    dx = mp + h * cxy
    dz = mp + h * cz
    rx = fx - hp[H_RADIAL_STIFFNESS] * hx[HX] - cxy * hv[HX] + f_h * ex
    ry = fy - hp[H_RADIAL_STIFFNESS] * hx[HY] - cxy * hv[HY] + f_h * ey
    rz = fz - hp[H_AXIAL_STIFFNESS] * hx[HZ] - cz * hv[HZ] + f_h * ez
    beta = h * cr
    s0 = ex * rx / dx + ey * ry / dx + ez * rz / dz
    g = ex * ex / dx + ey * ey / dx + ez * ez / dz
    s = (s0 * (mr + beta) - beta * g * f_h) / (mr + beta + beta * g * mr)
    ar = (beta * s - f_h) / (mr + beta)
    extra = beta * (ar - s)
    ha[HX] = (rx + extra * ex) / dx
    ha[HY] = (ry + extra * ey) / dx
    ha[HZ] = (rz + extra * ez) / dz
    ha[HR] = ar
    return ar


@njit(**JIT_INLINE)
def housing_kick_drift(hx, hv, ha, kick, dt):
    """Leapfrog kick + drift of the housing DOFs (as `twin.kernels.step.step_n` does for the balls):
    v += kick a; x += dt v. kick = dt/2 on the first step of a frame, dt after."""
    for k in range(N_HOUSING_DOF):
        hv[k] += kick * ha[k]
        hx[k] += dt * hv[k]


@njit(**JIT_INLINE)
def housing_close(hv, ha, half):
    """Closing half kick at the end of a frame: v += dt/2 a (full-step velocities between frames)."""
    for k in range(N_HOUSING_DOF):
        hv[k] += half * ha[k]


@njit(**JIT)
def housing_verlet_step(hp, hx, hv, ha, fx, fy, fz, dt):
    """One complete velocity-Verlet step of the housing alone under the ball force (fx, fy, fz) [N]
    held over the step (hv, ha full-step on entry and exit). Returns the accelerometer reading
    [m/s^2]. The engine interleaves the three parts with its own step instead."""
    housing_kick_drift(hx, hv, ha, 0.5 * dt, dt)
    ar = housing_accelerations(hp, hx, hv, fx, fy, fz, dt, ha)
    housing_close(hv, ha, 0.5 * dt)
    return ar


@njit(**JIT)
def housing_equilibrium(hp, fx, fy, fz, hx, hv, ha):
    """Static equilibrium under the ball force (fx, fy, fz) [N] (for the warm start): x_p = F / k,
    the sprung mass at rest with its spring relaxed; velocities and accelerations zero."""
    hx[HX] = fx / hp[H_RADIAL_STIFFNESS]
    hx[HY] = fy / hp[H_RADIAL_STIFFNESS]
    hx[HZ] = fz / hp[H_AXIAL_STIFFNESS]
    hx[HR] = hp[H_EX] * hx[HX] + hp[H_EY] * hx[HY] + hp[H_EZ] * hx[HZ]
    for k in range(N_HOUSING_DOF):
        hv[k] = 0.0
        ha[k] = 0.0
