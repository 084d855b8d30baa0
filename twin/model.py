"""Compile a `BearingSpec` once into an immutable `BearingModel` (MuJoCo's mjModel role).

Every derived constant the kernels need lives in read-only float64 arrays: `params` (indexed by
`twin.kernels.layout.P_*`), `race_params[r]` (r = 0 inner, 1 outer, indexed by `R_*`, at the
nominal contact angle) and `angle_table[r, i, :]` (`A_*`: Hertz stiffness and the tribology
coefficients of race r at sin(alpha) = i * ANGLE_STEP). The Hertz constants (ellipticity and the
complete elliptic integrals) are solved exactly for every one of these geometries
(`twin.physics.hertz.elliptic_constants`); the rolling-direction radius Rx of a contact follows
its contact angle (Meusnier: the raceway's rolling radius is the distance from the contact to the
bearing axis along the normal), Ry is the groove's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from twin import timestep
from twin.kernels import layout as L
from twin.kernels.profile import write_profile_params
from twin.kernels.structures import ModelArrays
from twin.kernels.tribology import N_TRIBOLOGY, T_PIVOT, tribology_coefficients
from twin.physics import hertz
from twin.physics.electrical import ball_raceway_gap_integral_m, coaxial_capacitance_f, equivalent_gap_limit_m
from twin.physics.traction import deformed_surface_radius_m, hertz_strip_table
from twin.physics.viscosity import dynamic_viscosity_pa_s
from twin.spec import BearingSpec, ModelOptions
from twin.vibration.housing import housing_params
from twin.vibration.signal import DecimatorDesign, design_decimator, integer_ratio_time_step

# ISO 76 static limit for ball bearings: 4.2 GPa; the model refuses loads whose analytic maximum
# contact pressure would exceed it (plastic flow, beyond Hertz theory; it is also the static load
# rating C0 of the bearing: 21 kN radial for the 6208 of seed 000, SKF lists 19 kN).
STATIC_PRESSURE_LIMIT_PA = 4.2e9
MODEL_PRESSURE_FACTOR = 1.0
GAP_LIMIT_REFERENCE_GAP_M = 1e-6  # central gap at which the exact gap integral is matched


@dataclass(frozen=True)
class BearingModel:
    """Immutable compiled bearing: arrays for the kernels plus derived figures for people."""

    spec: BearingSpec
    options: ModelOptions
    params: np.ndarray
    race_params: np.ndarray
    race_tribology: np.ndarray
    angle_table: np.ndarray
    ball_count: int
    pitch_radius_m: float
    contact_angle_rad: float
    inner_ring_radius_at_contact_m: float
    max_radial_load_n: float
    max_axial_load_n: float
    max_shaft_speed_rad_s: float
    # twin.vibration: housing H_* vector; reversed FIR taps of the accelerometer decimator (K R,),
    # without the housing a (1,) zero array, as the kernel's signature takes an array
    housing_params: np.ndarray
    decimator_taps: np.ndarray
    time_step: timestep.CriticalTimeStep  # critical step of the scheme (twin.timestep)

    gap_limit_m: tuple[float, float] = (50e-6, 50e-6)  # inner, outer: geometric gap limit of the contact capacitance
    rest_capacitance_f: float = 0.0  # the rings' lands across the oil-filled annulus [F]
    decimator: DecimatorDesign | None = None  # accelerometer decimator; None with the rigid outer ring

    def arrays(self) -> ModelArrays:
        """The model's arrays as the kernels take them (`twin.kernels.structures.ModelArrays`)."""
        return ModelArrays(self.params, self.angle_table, self.housing_params, self.decimator_taps)

    @property
    def vibration_params(self) -> np.ndarray:
        """The V_* vector (twin.kernels.layout), a view of params[P_VIB:]."""
        return self.params[L.P_VIB : L.P_VIB + L.N_VIB_PARAMS]

    @property
    def housing_on(self) -> bool:
        """Whether the outer ring rides on the housing and the accelerometer is sampled."""
        return self.decimator is not None

    @property
    def sample_rate_hz(self) -> float | None:
        """Accelerometer output rate [Hz] (None with the rigid outer ring)."""
        return None if self.decimator is None else self.decimator.output_rate_hz

    def stiffness_at(self, race: int, sin_alpha: float) -> float:
        """Hertz K [N/m^1.5] of race `race` (0 inner, 1 outer) at contact angle alpha, interpolated
        in the angle table exactly as the kernel does."""
        x = min(abs(sin_alpha), L.ANGLE_MAX_SIN) * L.ANGLE_INV_STEP
        i = min(int(x), L.ANGLE_POINTS - 2)
        lo = float(self.angle_table[race, i, L.A_STIFFNESS])
        return lo + (x - i) * (float(self.angle_table[race, i + 1, L.A_STIFFNESS]) - lo)

    @property
    def dt_s(self) -> float:
        """Integration step [s]."""
        return float(self.params[L.P_DT])

    # ---- rolling-bearing kinematics (rigid, no slip; outer ring fixed) ----------------------
    def cage_speed_rad_s(self, shaft_speed_rad_s: float) -> float:
        """FTF in rad/s: omega/2 (1 - D cos(alpha)/dm)."""
        g = self.ball_radius_m * math.cos(self.contact_angle_rad) / self.pitch_radius_m
        return 0.5 * shaft_speed_rad_s * (1.0 - g)

    @property
    def ball_radius_m(self) -> float:
        """Ball radius Rb [m]."""
        return float(self.params[L.P_BALL_RADIUS])


def raceway_radii_m(spec: BearingSpec, inner: bool, sin_alpha: float) -> tuple[float, float]:
    """(Rx, Ry) [m] of a ball-raceway contact at contact angle alpha (|sin alpha| given):
    Rx = Rb r / (r +- Rb) with the raceway's rolling radius r = (dm/2 -+ Rb cos alpha) / cos alpha
    (seed 000 eq. 2 and Fig. 3 at alpha = 0; Harris & Kotzalas, Rolling Bearing Analysis, ch. 2,
    for alpha > 0), Ry = Rb Rg / (Rg - Rb) of the groove radius Rg."""
    g = spec.geometry
    rb = g.ball_radius_m
    pitch = g.pitch_radius_m
    cos_a = math.sqrt(max(1.0 - sin_alpha * sin_alpha, 0.0))
    if inner:
        rx = hertz.convex_radius_m(rb, (pitch - rb * cos_a) / cos_a)
        groove = g.inner_groove_radius_m
    else:
        rx = hertz.concave_radius_m(rb, (pitch + rb * cos_a) / cos_a)
        groove = g.outer_groove_radius_m
    return rx, hertz.concave_radius_m(rb, groove)


def contact_constants(spec: BearingSpec, inner: bool, sin_alpha: float, e_prime: float) -> dict:
    """Exact Hertz constants of one race at contact angle alpha: Rx, Ry [m], ellipticity k,
    Fbar, Ebar [-], stiffness K [N/m^1.5], semi-axis coefficients a/Q^(1/3), b/Q^(1/3) [m/N^(1/3)]."""
    rx, ry = raceway_radii_m(spec, inner, sin_alpha)
    c = hertz.elliptic_constants(rx, ry)
    r = hertz.curvature_sum_radius_m(rx, ry)
    return {
        "rx_m": rx,
        "ry_m": ry,
        "ellipticity": c.ellipticity,
        "first_kind": c.first_kind,
        "second_kind": c.second_kind,
        "stiffness_n_m15": hertz.stiffness_from_constants(c.ellipticity, c.first_kind, c.second_kind, r, e_prime),
        # semi-axes grow as Q^(1/3): the law at Q = 1 N is the coefficient
        "semi_major_coef": hertz.semi_major_from_constants(1.0, c.ellipticity, c.second_kind, r, e_prime),
        "semi_minor_coef": hertz.semi_minor_from_constants(1.0, c.ellipticity, c.second_kind, r, e_prime),
    }


def _race_row(spec: BearingSpec, inner: bool, alpha: float, e_prime: float) -> np.ndarray:
    g = spec.geometry
    rb = g.ball_radius_m
    pitch = g.pitch_radius_m
    groove = g.inner_groove_radius_m if inner else g.outer_groove_radius_m
    offset = groove - rb
    row = np.zeros(L.N_RACE_PARAMS)
    if inner:
        row[L.R_GROOVE_CENTRE_RADIUS] = pitch + offset * math.cos(alpha)
        row[L.R_GROOVE_CENTRE_Z] = offset * math.sin(alpha)
    else:
        row[L.R_GROOVE_CENTRE_RADIUS] = pitch - offset * math.cos(alpha) + 0.5 * spec.mounting.diametral_clearance_m
        row[L.R_GROOVE_CENTRE_Z] = -offset * math.sin(alpha)
    c = contact_constants(spec, inner, math.sin(alpha), e_prime)
    row[L.R_GROOVE_RADIUS] = groove
    row[L.R_STIFFNESS] = c["stiffness_n_m15"]
    row[L.R_RX] = c["rx_m"]
    row[L.R_RY] = c["ry_m"]
    row[L.R_K_ELLIPTICITY] = c["ellipticity"]
    row[L.R_SEMI_MAJOR_COEF] = c["semi_major_coef"]
    row[L.R_SEMI_MINOR_COEF] = c["semi_minor_coef"]
    return row


def _tribology_row(
    spec: BearingSpec, options: ModelOptions, inner: bool, sin_alpha: float, e_prime: float, g_param: float
) -> tuple[float, np.ndarray]:
    """(K [N/m^1.5], tribology coefficients) of one race at |sin(alpha)| = sin_alpha."""
    c = contact_constants(spec, inner, sin_alpha, e_prime)
    tri = tribology_coefficients(
        c["rx_m"],
        c["ry_m"],
        c["ellipticity"],
        e_prime,
        g_param,
        spec.geometry.ball_radius_m,
        c["semi_major_coef"],
        c["semi_minor_coef"],
        options.film_formula,
    )
    return c["stiffness_n_m15"], tri


def make_angle_table(spec: BearingSpec, options: ModelOptions, e_prime: float, g_param: float) -> np.ndarray:
    """angle_table[r, i, :]: `A_STIFFNESS` and the tribology coefficients (from `A_TRIBOLOGY`) of
    race r at sin(alpha) = i * ANGLE_STEP, i = 0 .. ANGLE_POINTS - 1 (exact Hertz constants)."""
    table = np.zeros((2, L.ANGLE_POINTS, L.A_TRIBOLOGY + N_TRIBOLOGY))
    for r in range(2):
        for i in range(L.ANGLE_POINTS):
            k, tri = _tribology_row(spec, options, r == 0, i * L.ANGLE_STEP, e_prime, g_param)
            table[r, i, L.A_STIFFNESS] = k
            table[r, i, L.A_TRIBOLOGY :] = tri
    return table


def interpolate_angle_table(table: np.ndarray, race: int, sin_alpha: float) -> np.ndarray:
    """The row of `table` for race `race` at |sin(alpha)|, linear between grid points exactly as
    the kernel's tribology refresh does (`twin.kernels.step`); clamped to the grid."""
    x = min(abs(sin_alpha), L.ANGLE_MAX_SIN) * L.ANGLE_INV_STEP
    i = min(int(x), L.ANGLE_POINTS - 2)
    f = x - i
    return table[race, i] + f * (table[race, i + 1] - table[race, i])


@lru_cache(maxsize=64)
def _geometry_capacitance(
    rb: float,
    inner_groove: float,
    outer_groove: float,
    pitch: float,
    alpha: float,
    shoulder: float,
    width: float | None,
    permittivity: float,
    rx_in: float,
    ry_in: float,
    rx_out: float,
    ry_out: float,
) -> tuple[float, float, float]:
    """(gap limit inner [m], gap limit outer [m], rest capacitance [F]) from the geometry: the exact
    ball-groove gap integral matched at 1 um by the paraboloid law's gap limit
    (twin.physics.electrical.equivalent_gap_limit_m), and the rings' lands as a coaxial capacitor
    filled with oil over the width where both rings are lands."""
    limits = []
    lands = []
    half_widths = []
    for inner, groove, rx, ry in ((True, inner_groove, rx_in, ry_in), (False, outer_groove, rx_out, ry_out)):
        offset = groove - rb
        centre = pitch + offset * math.cos(alpha) if inner else pitch - offset * math.cos(alpha)
        land = centre - groove + shoulder if inner else centre + groove - shoulder
        integral = ball_raceway_gap_integral_m(rb, groove, centre, alpha, inner, land, width, GAP_LIMIT_REFERENCE_GAP_M)
        limits.append(equivalent_gap_limit_m(integral, rx, ry, GAP_LIMIT_REFERENCE_GAP_M))
        lands.append(land)
        reach = groove * groove - (centre - land) ** 2
        half_widths.append(offset * math.sin(alpha) + math.sqrt(max(reach, 0.0)))
    rest = 0.0
    if width is not None:
        rest = coaxial_capacitance_f(permittivity, width - 2.0 * max(half_widths), lands[0], lands[1])
    return limits[0], limits[1], rest


def _load_at_pressure(row: np.ndarray, pressure_pa: float) -> float:
    """Ball load [N] at which the Hertz maximum pressure of this race reaches pressure_pa."""
    # p = 3 Q / (2 pi a b), a b = ca cb Q^(2/3) -> Q^(1/3) = 2 pi ca cb p / 3
    return (2.0 * math.pi * row[L.R_SEMI_MAJOR_COEF] * row[L.R_SEMI_MINOR_COEF] * pressure_pa / 3.0) ** 3


def make_model(spec: BearingSpec, options: ModelOptions | None = None) -> BearingModel:
    """Compile spec + options into the immutable model."""
    options = options or ModelOptions()
    g, mat = spec.geometry, spec.material
    rb = g.ball_radius_m
    z = g.ball_count
    alpha = math.radians(g.nominal_contact_angle_deg)
    e_prime = hertz.effective_modulus_pa(mat.youngs_modulus_pa, mat.poisson_ratio)
    shear = hertz.shear_modulus_pa(mat.youngs_modulus_pa, mat.poisson_ratio)
    ball_mass = mat.density_kg_m3 * 4.0 / 3.0 * math.pi * rb**3
    ball_inertia = 0.4 * ball_mass * rb * rb
    pitch = g.pitch_radius_m
    cage_inertia = g.cage_mass_kg * pitch * pitch
    cage_mass_at_pitch = cage_inertia / pitch**2
    half_chord = 2.0 * pitch * math.sin(math.pi / (2 * z))
    # cage elements sit at half pitch between balls; keep at least 20 um pocket clearance
    contact_distance = min(rb + g.cage_element_radius_m, half_chord - 20e-6)

    p = np.zeros(L.N_PARAMS)
    p[L.P_BALL_RADIUS] = rb
    p[L.P_BALL_MASS] = ball_mass
    p[L.P_BALL_INERTIA] = ball_inertia
    p[L.P_RING_MASS] = spec.mounting.rotor_mass_kg
    p[L.P_CAGE_INERTIA] = cage_inertia
    p[L.P_CAGE_RADIUS] = pitch
    p[L.P_CAGE_CONTACT_DISTANCE] = contact_distance
    p[L.P_CAGE_STIFFNESS] = hertz.ball_ball_stiffness_n_m15(rb, g.cage_element_radius_m, shear, mat.poisson_ratio)
    p[L.P_CAGE_REDUCED_MASS] = ball_mass * cage_mass_at_pitch / (ball_mass + cage_mass_at_pitch)
    p[L.P_CAGE_STEP_COS] = math.cos(2.0 * math.pi / z)  # the step's cage pass turns element to element
    p[L.P_CAGE_STEP_SIN] = math.sin(2.0 * math.pi / z)
    p[L.P_E_PRIME] = e_prime
    p[L.P_G_PARAM] = spec.lubricant.pressure_viscosity_pa_inv * e_prime
    p[L.P_ROUGHNESS] = spec.surface.composite_roughness_m
    p[L.P_LN_ROUGHNESS] = math.log(spec.surface.composite_roughness_m)
    p[L.P_KT_RATIO] = options.tangential_stiffness_ratio
    p[L.P_CT_RATIO] = options.tangential_damping_ratio
    p[L.P_ALPHA_E] = options.restitution_coefficient_s_m
    p[L.P_RAMP] = options.speed_ramp_rad_s2
    p[L.P_FILM_FORMULA] = 0.0 if options.film_formula == "hamrock_dowson" else 1.0
    p[L.P_FRICTION_MODEL] = L.FRICTION_MODEL_CODES[options.friction_model]
    p[L.P_ROLLING] = 1.0 if options.rolling_resistance else 0.0
    p[L.P_BALL_REDUCED_TANGENT_MASS] = ball_mass / (1.0 + ball_mass * rb * rb / ball_inertia)
    p[L.P_MAX_PENETRATION] = 0.01 * rb
    el = spec.electrical
    p[L.P_OIL_PERMITTIVITY] = el.oil_relative_permittivity
    p[L.P_ASPERITY_RESISTANCE] = el.metallic_contact_resistance_ohm
    p[L.P_OIL_RESISTIVITY] = el.oil_resistivity_ohm_m
    p[L.P_TRACTION_STRIPS] = options.traction_strips
    p[L.P_EYRING_STRESS] = spec.lubricant.eyring_stress_pa
    p[L.P_LIMITING_SHEAR] = spec.lubricant.limiting_shear_coefficient
    p[L.P_PRESSURE_VISCOSITY] = spec.lubricant.pressure_viscosity_pa_inv
    p[L.P_ASPERITY_SLIP] = options.asperity_regularisation_slip_m_s
    p[L.P_DEFORMED_RADIUS] = deformed_surface_radius_m(rb, g.inner_groove_radius_m)
    p[L.P_DEFORMED_RADIUS + 1] = deformed_surface_radius_m(rb, g.outer_groove_radius_m)
    strips = hertz_strip_table(options.traction_strips)
    p[L.P_STRIP_TABLE : L.P_STRIP_TABLE + strips.size] = strips.ravel()

    race = np.stack([_race_row(spec, True, alpha, e_prime), _race_row(spec, False, alpha, e_prime)])
    shoulder = g.shoulder_depth_or_typical_m
    gap_in, gap_out, rest = _geometry_capacitance(
        rb,
        g.inner_groove_radius_m,
        g.outer_groove_radius_m,
        pitch,
        alpha,
        shoulder,
        g.ring_width_m,
        el.oil_relative_permittivity,
        float(race[0, L.R_RX]),
        float(race[0, L.R_RY]),
        float(race[1, L.R_RX]),
        float(race[1, L.R_RY]),
    )
    p[L.P_GAP_LIMIT] = gap_in
    p[L.P_GAP_LIMIT_OUTER] = gap_out
    # load limits: analytic Qmax = Fr / (Z Jr), Jr(0.5) = 0.2288 (seed 000 eq. A3)
    q_limit = min(
        _load_at_pressure(race[0], MODEL_PRESSURE_FACTOR * STATIC_PRESSURE_LIMIT_PA),
        _load_at_pressure(race[1], MODEL_PRESSURE_FACTOR * STATIC_PRESSURE_LIMIT_PA),
    )
    max_radial = q_limit * z * 0.2288 * max(math.cos(alpha), 0.2)
    max_axial = q_limit * z * max(math.sin(alpha), 0.2)
    # limiting speed by the n dm rule of thumb (1.2e6 mm/min for oil-lubricated ball bearings)
    max_speed = 1.2e6 / (2.0 * pitch * 1e3) * 2.0 * math.pi / 60.0
    if spec.limiting_speed_rad_s is not None:  # the bearing's own limiting speed, where the spec gives it
        max_speed = spec.limiting_speed_rad_s
    tribology = np.stack(
        [
            tribology_coefficients(
                race[r, L.R_RX],
                race[r, L.R_RY],
                race[r, L.R_K_ELLIPTICITY],
                e_prime,
                p[L.P_G_PARAM],
                rb,
                race[r, L.R_SEMI_MAJOR_COEF],
                race[r, L.R_SEMI_MINOR_COEF],
                options.film_formula,
            )
            for r in range(2)
        ]
    )
    angle_table = make_angle_table(spec, options, e_prime, p[L.P_G_PARAM])
    # the step: the number asked for, or the auto step from the stiffest element at the static
    # capacity q_limit (twin.timestep); the tribology sub-rate is a period, as steps of this dt
    critical = timestep.estimate(
        p, race, tribology, q_limit, dynamic_viscosity_pa_s(spec.lubricant, timestep.REFERENCE_OIL_TEMPERATURE_C), z
    )
    p[L.P_DT] = timestep.resolve_time_step_s(options.time_step_s, critical)
    housing = spec.housing
    decimator = None
    if housing.enabled:
        # the accelerometer is sampled by an integer decimation of the step: dt = 1 / (R f_s), the
        # largest such step not above the one resolved (auto or given; twin.vibration.signal)
        fs = housing.accelerometer.sample_rate_hz
        p[L.P_DT] = integer_ratio_time_step(min(p[L.P_DT], 0.5 / fs), fs)[0]
        decimator = design_decimator(1.0 / p[L.P_DT], fs)
    taps = decimator.reversed_taps if decimator is not None else np.zeros(1)
    # the defect drops (twin.kernels.vibration) take the raceway and curvature radii at the
    # nominal contact angle (the drop is second order in the pit's size over these radii)
    v = p[L.P_VIB : L.P_VIB + L.N_VIB_PARAMS]  # a view: written into p
    v[L.V_HOUSING_ON] = 1.0 if housing.enabled else 0.0
    v[L.V_DECIMATION_RATIO] = decimator.ratio if decimator is not None else 1.0
    v[L.V_INNER_RACEWAY_RADIUS] = g.inner_raceway_radius_m
    v[L.V_OUTER_RACEWAY_RADIUS] = g.outer_raceway_radius_m
    v[L.V_INNER_GROOVE_RADIUS] = g.inner_groove_radius_m
    v[L.V_OUTER_GROOVE_RADIUS] = g.outer_groove_radius_m
    v[L.V_INNER_RX], v[L.V_OUTER_RX] = race[0, L.R_RX], race[1, L.R_RX]
    # a = coef Q^(1/3) and Q = K delta^1.5 (seed 000 eq. 2), so a / sqrt(delta) = coef K^(1/3)
    v[L.V_INNER_FOOTPRINT], v[L.V_OUTER_FOOTPRINT] = (
        race[r, L.R_SEMI_MAJOR_COEF] * race[r, L.R_STIFFNESS] ** (1.0 / 3.0) for r in (0, 1)
    )
    p[L.P_SUBSTEPS] = timestep.steps_per_period(options.tribology_period_s, p[L.P_DT])
    p[L.P_CENTRED_REFRESH] = 1.0 if options.centred_refresh else 0.0
    p[L.P_PROFILE_ON] = 1.0 if spec.surface_profile.enabled else 0.0
    write_profile_params(p, spec.surface_profile, g)
    # the strip solve's period as a whole number of tribology refreshes (nearest, at least 1)
    p[L.P_TRACTION_EVERY] = timestep.steps_per_period(options.traction_period_s, p[L.P_SUBSTEPS] * p[L.P_DT])
    if options.friction_model == "ellipse_traction":
        # the strips' spin moment replaces seed 001's eq. 11, at every contact angle
        tribology[:, T_PIVOT] = 0.0
        angle_table[:, :, L.A_TRIBOLOGY + T_PIVOT] = 0.0
    hp = housing_params(housing)
    for a in (p, race, tribology, angle_table, taps, hp):
        a.setflags(write=False)
    return BearingModel(
        spec=spec,
        options=options,
        params=p,
        race_params=race,
        race_tribology=tribology,
        angle_table=angle_table,
        ball_count=z,
        pitch_radius_m=pitch,
        contact_angle_rad=alpha,
        inner_ring_radius_at_contact_m=pitch - rb * math.cos(alpha),
        max_radial_load_n=float(max_radial),
        max_axial_load_n=float(max_axial),
        max_shaft_speed_rad_s=float(max_speed),
        time_step=critical,
        gap_limit_m=(gap_in, gap_out),
        rest_capacitance_f=rest,
        housing_params=hp,
        decimator=decimator,
        decimator_taps=taps,
    )
