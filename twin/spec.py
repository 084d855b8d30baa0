"""What a person writes to describe a bearing: validated, SI, every field with its unit.

`BearingSpec` is the human input; `twin.model.make_model` compiles it once into the immutable
arrays the kernels use (MuJoCo's spec -> model split). Validation errors name the field and the
allowed range (pydantic reports the field path; the messages below give the range).
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from twin.thermal.settings import ThermalNetworkSettings
from twin.vibration.housing import Housing
from twin.vibration.surface import SurfaceProfile

# the range of an explicit ModelOptions.time_step_s [s] (twin.timestep.TIME_STEP_RANGE_S)
TIME_STEP_RANGE_S = (1e-8, 2e-5)

_FROZEN = ConfigDict(frozen=True, extra="forbid", strict=True, allow_inf_nan=False)

TWIN_ID_PATTERN = r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,63}$"
TwinId = Annotated[
    str,
    Field(
        pattern=TWIN_ID_PATTERN,
        description="Twin name used in URLs and zenoh keys [text: 1-64 "
        "letters, digits, _ . -, first a letter or digit].",
    ),
]
"""A twin's name: one zenoh key chunk, a URL path segment and a file name."""
Clearance = Annotated[
    float,
    Field(
        ge=-50e-6,
        le=200e-6,
        description="Diametral clearance Pd [m]; negative = preload (seed 000 Appendix A: +-12.6e-6 m).",
    ),
]
"""Diametral clearance Pd [m], from a 50 um preload to 200 um of play."""
BearingKind = Literal["deep_groove", "angular_contact"]
"""The bearing types the engine models."""


TYPICAL_SHOULDER_DEPTH_OVER_BALL = 0.18
"""Shoulder height / ball diameter of a deep-groove ring when the spec gives none: a typical
proportion (the capacitance of the lands moves by under 3 % between 0.15 and 0.22,
tests/physics/test_electrical.py)."""


class Geometry(BaseModel):
    """Internal geometry of the bearing (seed 000 Table 1 names in brackets)."""

    model_config = _FROZEN

    ball_radius_m: float = Field(gt=0.0, le=0.1, description="Ball radius Rb [m].")
    ball_count: int = Field(
        ge=3, le=16, description="Number of balls Z [-] (at most 16: the kernel has 32 contact lanes)."
    )
    inner_raceway_radius_m: float = Field(
        gt=0.0,
        le=1.0,
        description="Inner raceway radius Ri [m]: from the bearing axis to the inner contact, "
        "measured along the nominal contact line (groove bottom for a deep-groove bearing).",
    )
    outer_raceway_radius_m: float = Field(gt=0.0, le=1.0, description="Outer raceway radius Ro [m], measured like Ri.")
    inner_groove_radius_m: float = Field(gt=0.0, le=0.1, description="Inner groove curvature radius [m].")
    outer_groove_radius_m: float = Field(gt=0.0, le=0.1, description="Outer groove curvature radius Rc [m].")
    cage_element_radius_m: float = Field(
        gt=0.0,
        le=0.05,
        description="Radius Rz [m] of the cage elements (seed 000: spheres between neighbouring "
        "balls, rigidly attached to the cage).",
    )
    nominal_contact_angle_deg: float = Field(
        default=0.0,
        ge=0.0,
        le=45.0,
        description="Unloaded contact angle [deg]: 0 for deep-groove, e.g. 40 for a 7208 B.",
    )
    cage_mass_kg: float = Field(default=0.02, gt=0.0, le=100.0, description="Cage mass [kg].")
    ring_width_m: float | None = Field(
        default=None,
        gt=0.0,
        le=1.0,
        description="Ring width B [m] (ISO 15 boundary dimension), for the capacitance of the rings' lands; null: "
        "the lands are left out of the bearing capacitance.",
    )
    shoulder_depth_m: float | None = Field(
        default=None,
        gt=0.0,
        le=0.05,
        description="Depth of the groove below the ring's land (shoulder height) [m], for the capacitance of the gap "
        "around the contacts and the rings' cross-sections of the thermal network; null: 0.18 ball diameters, a "
        "typical deep-groove proportion (an assumption: between 0.15 and 0.22 the contact capacitance moves by "
        "under 3 %, tests/physics/test_electrical.py).",
    )
    bore_diameter_m: float | None = Field(
        default=None,
        gt=0.0,
        le=2.0,
        description="Bore d [m] (ISO 15 boundary dimension), for the kinematic starvation and the seals; null: "
        "the pitch diameter minus 1.6 ball diameters (twin.friction_power.boundary_dimensions_m).",
    )
    outside_diameter_m: float | None = Field(
        default=None,
        gt=0.0,
        le=2.5,
        description="Outside diameter D [m] (ISO 15 boundary dimension); null: the pitch diameter plus 1.6 ball "
        "diameters.",
    )
    seal_counterface_diameter_m: float | None = Field(
        default=None,
        gt=0.0,
        le=2.0,
        description="Diameter d_s of the seals' counterface on the inner ring [m] (d1 of the product tables), for "
        "the seal friction; null: d + 0.32 (D - d), the inner-ring shoulder of the 62 series.",
    )

    @model_validator(mode="after")
    def _fits(self) -> Geometry:
        rb = self.ball_radius_m
        for name in ("inner_groove_radius_m", "outer_groove_radius_m"):
            rg = getattr(self, name)
            if not (1.0 * rb < rg <= 1.25 * rb):
                raise ValueError(
                    f"{name} = {rg:g} m: a ball of radius {rb:g} m needs a groove radius in "
                    f"({rb:g}, {1.25 * rb:g}] m (conformity f = Rg/D in (0.5, 0.625])"
                )
        if self.outer_raceway_radius_m <= self.inner_raceway_radius_m + rb:
            raise ValueError("outer_raceway_radius_m must exceed inner_raceway_radius_m + ball radius")
        gap = self.outer_raceway_radius_m - self.inner_raceway_radius_m - 2.0 * rb
        if abs(gap) > 0.05 * rb:
            raise ValueError(
                f"outer_raceway_radius_m - inner_raceway_radius_m - 2 ball_radius_m = {gap:g} m: "
                f"the ball must fill the raceway gap within +-{0.05 * rb:g} m; set clearance in "
                "Mounting.diametral_clearance_m instead"
            )
        pitch = 0.5 * (self.inner_raceway_radius_m + self.outer_raceway_radius_m)
        half_chord = 2.0 * pitch * math.sin(math.pi / (2 * self.ball_count))
        if half_chord < rb + 1e-6:
            raise ValueError(
                f"ball_count = {self.ball_count}: the balls do not fit on the pitch circle "
                f"(centre spacing {2 * half_chord:g} m < ball diameter {2 * rb:g} m)"
            )
        if half_chord - rb < 0.5 * self.cage_element_radius_m:
            raise ValueError(
                f"cage_element_radius_m = {self.cage_element_radius_m:g} m does not fit between "
                f"neighbouring balls (room {half_chord - rb:g} m)"
            )
        return self

    @property
    def pitch_radius_m(self) -> float:
        """Pitch radius [m], (Ri + Ro) / 2."""
        return 0.5 * (self.inner_raceway_radius_m + self.outer_raceway_radius_m)

    @property
    def shoulder_depth_or_typical_m(self) -> float:
        """The groove's depth below the land [m]: `shoulder_depth_m`, or when the spec gives none
        TYPICAL_SHOULDER_DEPTH_OVER_BALL ball diameters."""
        if self.shoulder_depth_m is not None:
            return self.shoulder_depth_m
        return TYPICAL_SHOULDER_DEPTH_OVER_BALL * 2.0 * self.ball_radius_m


class Material(BaseModel):
    """Ring and ball material (seed 000: steel, E = 210 GPa, nu = 0.3)."""

    model_config = _FROZEN

    youngs_modulus_pa: float = Field(default=210e9, gt=1e9, le=1e12, description="Young's modulus E [Pa].")
    poisson_ratio: float = Field(default=0.3, gt=0.0, lt=0.5, description="Poisson's ratio nu [-].")
    density_kg_m3: float = Field(default=7850.0, gt=100.0, le=30000.0, description="Density [kg/m^3].")


class Surface(BaseModel):
    """Surface roughness, arithmetic mean Ra (seed 000 eq. 7: races 0.3 um, balls negligible)."""

    model_config = _FROZEN

    race_roughness_m: float = Field(default=0.3e-6, gt=0.0, le=1e-4, description="Raceway roughness sigma_a1 [m].")
    ball_roughness_m: float = Field(default=0.0, ge=0.0, le=1e-4, description="Ball roughness sigma_a2 [m].")

    @property
    def composite_roughness_m(self) -> float:
        """1.25 sqrt(sigma_a1^2 + sigma_a2^2) [m], the denominator of seed 000 eq. 7."""
        return 1.25 * math.hypot(self.race_roughness_m, self.ball_roughness_m)


class Lubricant(BaseModel):
    """Oil: kinematic viscosity at 40 and 100 degC (ASTM D341 Walther law between them).

    The default `seed-000` oil has exactly eta = 0.04 Pa s at 40 degC (seed 000 eq. 5, ref. [37])
    with an ISO VG 46 mineral-oil slope; `twin.catalog.lubricant("ISO VG 68")` etc. give others.
    """

    model_config = _FROZEN

    name: str = Field(default="seed-000", max_length=64, description="Lubricant name [text].")
    kinematic_viscosity_40c_m2_s: float = Field(
        default=0.04 / (870.0 * (1.0 - 6.5e-4 * 25.0)),
        gt=1e-7,
        le=1e-2,
        description="Kinematic viscosity at 40 degC [m^2/s].",
    )
    kinematic_viscosity_100c_m2_s: float = Field(
        default=6.8e-6, gt=1e-7, le=1e-3, description="Kinematic viscosity at 100 degC [m^2/s]."
    )
    density_15c_kg_m3: float = Field(default=870.0, gt=500.0, le=2000.0, description="Density at 15 degC [kg/m^3].")
    pressure_viscosity_pa_inv: float = Field(
        default=2.3e-8, gt=0.0, le=1e-7, description="Pressure-viscosity coefficient xi [1/Pa] (seed 000: 2.3e-8)."
    )
    eyring_stress_pa: float = Field(
        default=5e6,
        gt=1e5,
        le=1e8,
        description="Eyring stress tau0 of the film's shear thinning [Pa] (Johnson and Tevaarwerk 1977, Proc. R. Soc. "
        "Lond. A 356: a few MPa for mineral oils; Evans and Johnson 1986 report 2-10 MPa).",
    )
    limiting_shear_coefficient: float = Field(
        default=0.06,
        gt=0.0,
        le=0.2,
        description="gamma = limiting shear stress / pressure of the film [-] (Bair and Winer 1979, J. Lubr. Technol. "
        "101: 0.05-0.08 for mineral oils; the middle of that range).",
    )

    @model_validator(mode="after")
    def _order(self) -> Lubricant:
        if self.kinematic_viscosity_100c_m2_s >= self.kinematic_viscosity_40c_m2_s:
            raise ValueError("kinematic_viscosity_100c_m2_s must be below kinematic_viscosity_40c_m2_s")
        return self


class Electrical(BaseModel):
    """Electrical properties of the lubricated contacts and their calibration constants. The
    capacitances of the geometry (the gap around each contact, the rings' lands) are integrated
    from the bearing's geometry when the model is compiled (twin.model, twin.physics.electrical).

    Defaults: mineral oil eps_r 2.2 and 1e10 ohm m (Prashad, Tribology in electrical
    environments, 2005, ch. 1-2); a fully metallic Hertz contact of ~0.1 ohm (Holm constriction of
    a ~0.2 mm steel contact spot plus film resistance of the oxide, the same order Prashad reports
    for bearings under current); 15 MV/m dielectric strength of a thin oil film; 0.1 and
    0.7 A/mm^2 apparent current density thresholds between harmless, damage possible and
    fluting (Prashad ch. 6; bearing makers' guidance); 10 kHz inverter switching frequency.
    """

    model_config = _FROZEN

    oil_relative_permittivity: float = Field(
        default=2.2, gt=1.0, le=100.0, description="Relative permittivity of the oil at ambient pressure [-]."
    )
    oil_resistivity_ohm_m: float = Field(default=1e10, gt=0.0, le=1e16, description="Oil volume resistivity [ohm m].")
    metallic_contact_resistance_ohm: float = Field(
        default=0.1,
        gt=0.0,
        le=1e6,
        description="Resistance of one contact with all its load on asperities (Lambda -> 0) [ohm].",
    )
    frequency_hz: float = Field(default=10e3, gt=0.0, le=1e8, description="Frequency of the reported impedance [Hz].")
    breakdown_field_v_m: float = Field(
        default=15e6, gt=0.0, le=1e10, description="Dielectric strength of the oil film [V/m]."
    )
    harmless_current_density_a_m2: float = Field(
        default=0.1e6, gt=0.0, description="Below this apparent current density no damage is expected [A/m^2]."
    )
    fluting_current_density_a_m2: float = Field(
        default=0.7e6, gt=0.0, description="Above this apparent current density fluting is likely [A/m^2]."
    )

    @model_validator(mode="after")
    def _thresholds(self) -> Electrical:
        if self.fluting_current_density_a_m2 <= self.harmless_current_density_a_m2:
            raise ValueError("fluting_current_density_a_m2 must exceed harmless_current_density_a_m2")
        return self


class Thermal(BaseModel):
    """Electro-thermal inputs of seed 003 (Appendix 2 values as defaults); an input of the HTTP API,
    so strict like the setpoint (no "1" for 1.0, no "yes" for True)."""

    model_config = ConfigDict(frozen=True, extra="forbid", strict=True, allow_inf_nan=False)

    oil_thermal_conductivity_w_m_k: float = Field(
        default=0.145, gt=0.0, le=10.0, description="Oil thermal conductivity k' [W/(m K)] (seed 003: 0.145)."
    )
    oil_thermal_expansion_k_inv: float = Field(
        default=6.4e-4, ge=0.0, le=1e-2, description="Oil thermal expansion alpha' [1/K] (seed 003: 6.4e-4)."
    )
    crater_depth_m: float = Field(
        default=3e-6,
        gt=0.0,
        le=1e-1,
        description="Depth H_c of the heated layer under slip bands and craters in seed 003 eqs. 8-10 [m]. "
        "Appendix 2 prints '3x10-0'; read as 3e-6 m (a micrometre-scale corrugation depth), the reading the "
        "EHL solver (twin.ehl_solver.params) uses with the anchored equivalent resistance below.",
    )
    ball_specific_heat_j_kg_k: float = Field(
        default=460.0,
        gt=0.0,
        le=5000.0,
        description="Specific heat of the bearing steel c_b [J/(kg K)] (seed 003: 460).",
    )
    equivalent_resistance_ohm: float | None = Field(
        default=2.92e-4,
        gt=0.0,
        le=1e12,
        description="Equivalent bearing resistance R_b of seed 003 eqs. 7-10 [ohm]. Seed 003 gives no value; the "
        "default 2.92e-4 ohm is the one the thermal EHL solver anchors (84.8 % minimum-film reduction at 30 A, the "
        "top of seed 003 Fig. 2's band; twin.ehl_solver.params.DEFAULT_BEARING_RESISTANCE_OHM): the resistance of "
        "a broken-down, conducting contact. null: the resistive part Re(Z) of the twin's own network at the "
        "impedance frequency (an intact film: the heating then saturates at the 250 K cap).",
    )
    current_heating: bool = Field(
        default=True, description="Feed the current-discharge heating (seed 003 eq. 10) back into the film [bool]."
    )
    shear_heating: bool = Field(
        default=True,
        description="Reduce the film by the inlet shear heating of a rolling contact, the Murch-Wilson factor "
        "phi_T = 3.94 / (3.94 + L^0.62), L = beta eta u^2 / k' (Murch and Wilson 1975; twin.physics.thermal). On by "
        "default: a real inlet is shear-heated (SKF's frictional-moment model applies the same physics as phi_ish). "
        "False: the isothermal inlet of seed 000's Hamrock-Dowson solution, which its validations (Table 3, Figs. "
        "8-12; "
        "twin.validation.studies) state explicitly [bool].",
    )
    film_temperature_exponent: float = Field(
        default=1.38,
        gt=0.0,
        le=5.0,
        description="c_T of the loop's current-heating film law h/h_iso = g(dT)^c_T [-], fitted to the current heating "
        "of the thermal EHL solver (twin.validation.thermal_law_fit: the solver's film with current over its film "
        "without, "
        "28 cells of seed 003 Appendix 2, rms 13 % in ln h, max error 6.4 points of reduction).",
    )


class Lubrication(BaseModel):
    """How the oil reaches the bearing, and its seals: sets the kinematic starvation of the
    contacts (twin.physics.starvation), the drag of the balls in the oil (twin.physics.drag) and
    the seal friction (twin.physics.seals). 'flooded' (the default) is seed 000's idealisation:
    fully flooded contacts and no churning."""

    model_config = _FROZEN

    method: Literal["flooded", "oil_bath", "jet", "oil_air"] = Field(
        default="flooded",
        description="'flooded': fully flooded contacts, no drag (seed 000); 'oil_bath': a sump at oil_level_m; "
        "'jet': an oil jet of jet_flow_m3_s at jet_inlet_temperature_c; 'oil_air': oil-air (minimal oil) [text].",
    )
    oil_level_m: float | None = Field(
        default=None,
        ge=0.0,
        le=1.0,
        description="oil_bath: height of the oil surface above the bottom of the outer raceway [m]; null: one ball "
        "radius, to the centre of the lowest ball (the usual recommendation for an oil bath).",
    )
    jet_flow_m3_s: float = Field(
        default=1e-6, gt=0.0, le=1e-2, description="jet: oil flow through the bearing [m^3/s] (1e-6 = 60 ml/min)."
    )
    jet_inlet_temperature_c: float = Field(
        default=40.0, ge=-40.0, le=200.0, description="jet: oil temperature at the jet [degC]."
    )
    cavity_oil_volume_fraction: float = Field(
        default=0.05,
        gt=0.0,
        le=1.0,
        description="jet and oil_air: volume share of oil in the oil-air mixture the balls churn in the cavity [-] "
        "(Harris and Kotzalas, vol. 2 ch. 3: a few percent under jet lubrication); the mixture's density sets the "
        "ball drag. An input: it depends on the flow and the scavenging of the housing.",
    )
    seal: Literal["open", "2Z", "2RS"] = Field(
        default="open", description="Seal execution: 'open', '2Z' (shields, no contact), '2RS' (rubbing seals) [text]."
    )


class Mounting(BaseModel):
    """How the bearing is mounted."""

    model_config = _FROZEN

    diametral_clearance_m: Clearance = 0.0
    rotor_mass_kg: float = Field(
        default=0.5,
        gt=0.01,
        le=1000.0,
        description="Mass carried by the inner ring [kg]: the ring plus the share of the shaft.",
    )


class BearingSpec(BaseModel):
    """A complete bearing description: geometry, materials, surfaces, lubricant, mounting."""

    model_config = _FROZEN

    designation: str = Field(
        max_length=32,
        description="Catalog designation, e.g. '6208', or the name of a bearing that is not in the catalog [text].",
    )
    kind: BearingKind = Field(default="deep_groove", description="'deep_groove' or 'angular_contact' [text].")
    geometry: Geometry = Field(
        description="Internal geometry: ball, raceway and groove radii [m], ball count [-], "
        "contact angle [deg], ... [object]."
    )
    material: Material = Field(
        default=Material(), description="Ring and ball material: E [Pa], nu [-], density [kg/m^3] [object]."
    )
    surface: Surface = Field(default=Surface(), description="Roughness of races and balls, Ra [m] [object].")
    lubricant: Lubricant = Field(
        default=Lubricant(),
        description="Oil: viscosities [m^2/s], pressure-viscosity coefficient [1/Pa], ... [object].",
    )
    mounting: Mounting = Field(
        default=Mounting(), description="Diametral clearance [m] and the mass on the inner ring [kg] [object]."
    )
    electrical: Electrical = Field(
        default=Electrical(),
        description="Oil permittivity [-], resistivity [ohm m], breakdown field [V/m], ... [object].",
    )
    thermal: Thermal = Field(
        default=Thermal(),
        description="Electro-thermal options (seed 003): heating switches [bool], R_b [ohm], H_c [m], ... [object].",
    )
    limiting_speed_rad_s: float | None = Field(
        default=None,
        gt=0.0,
        le=1e5,
        description="Highest shaft speed the twin admits for this bearing [rad/s]; null: the n d_m rule of thumb of "
        "oil-lubricated ball bearings, n d_m = 1.2e6 mm/min (twin.model).",
    )
    lubrication: Lubrication = Field(
        default_factory=Lubrication,
        description="Lubrication method and seals (starvation, ball drag, seal friction); the default 'flooded' "
        "keeps seed 000's fully flooded contacts without churning [object].",
    )
    housing: Housing = Field(
        default_factory=Housing,
        description="Outer ring + housing support and the accelerometer (twin.vibration.housing; Sawalhi & "
        "Randall 2008 defaults); `enabled: false` (the default) keeps the rigid, fixed outer ring [object].",
    )
    surface_profile: SurfaceProfile = Field(
        default_factory=SurfaceProfile,
        description="Race profiles (waviness, roughness) and ball-size spread exciting the contacts "
        "(twin.vibration.surface); `enabled: false` (the default) keeps perfect geometry [object].",
    )


class ModelOptions(BaseModel):
    """Numerical and model choices, fixed when a model is compiled."""

    model_config = _FROZEN

    time_step_s: float | Literal["auto"] = Field(
        default="auto",
        description="Integration step dt [s], or 'auto' (default): 0.8 x the critical step of the explicit "
        "scheme at the bearing's static capacity, a divisor of 1 ms (twin.timestep; about 3.3 us for the "
        "6208). Seed 000 uses 1 us. A number must lie in [1e-08, 2e-05] s.",
    )
    film_formula: Literal["hamrock_dowson", "masjedi_khonsari"] = Field(
        default="hamrock_dowson", description="Minimum film formula: seed 000 eq. 6 or seed 004 eq. 6."
    )
    friction_model: Literal["ellipse_traction", "stribeck_line", "asperity_share"] = Field(
        default="ellipse_traction",
        description="Tangential friction of the ball-raceway contacts: 'ellipse_traction' integrates the traction over "
        "strips of the contact ellipse (differential and spin slip; seed 000 mu(Lambda) x seed 001 eq. A2 asperity "
        "share + Eyring / limiting-shear film; twin.kernels.traction); 'stribeck_line' (seed 000 section 2.3) and "
        "'asperity_share' (seed 001 eq. A1-A2) are centre-point Coulomb laws.",
    )
    traction_strips: int = Field(
        default=12,
        ge=2,
        le=32,
        description="Strips across the major axis of each contact ellipse (ellipse_traction) [-]; 12: moments within "
        "0.5 % "
        "(spin moment 2 %) of 32 strips (tests/kernels/test_traction.py).",
    )
    traction_period_s: float = Field(
        default=4e-4,
        ge=1e-6,
        le=1e-3,
        description="Strip integration (ellipse_traction) every this period [s], a whole number of tribology "
        "refreshes (the nearest, at least 1); 400 us (10 refreshes of 40 us): over the envelope at the auto step "
        "(twin.validation.subrate_study) every output stays within the study's tolerances of "
        "the 10 us / 200 us sub-rates and of the 1 us step (torque 1.14 % of 2 % on the 7208 at 1700 rad/s, "
        "7500 N + 3000 N); 800 us does not (loads 1.3 %, torque 3.1 % there). The torque moves by under 0.5 % from a "
        "solve at every "
        "refresh, the 7208 B's spin moments (Fr = Fa = 3000 N) by under 5 % (tests/physics/test_friction_torque.py), "
        "first order in the period.",
    )
    asperity_regularisation_slip_m_s: float = Field(
        default=1e-3,
        gt=0.0,
        le=0.1,
        description="Slip over which the asperity (Coulomb) friction develops in ellipse_traction [m/s].",
    )
    tribology_period_s: float = Field(
        default=4e-5,
        ge=1e-7,
        le=2e-4,
        description="Film/Lambda/mu/damping/rolling resistance/Hertz stiffness refreshed every this period [s], a "
        "whole number of steps (the nearest, at least 1; 12 steps at the 6208's auto step of 3.3 us), each refresh "
        "centred on its period (centred_refresh); the contacts' RC every 5 refreshes (200 us). 40 us: over the "
        "envelope at the auto step (twin.validation.subrate_study, `bearing-twin timestep-study --subrates`) every "
        "output stays within the study's tolerances of the 10 us / 200 us sub-rates and of the 1 us step (closest: "
        "loads 0.32 % of 0.5 %, Lambda 0.24 %, on the 7208 at 1700 rad/s, 7500 N + 3000 N). Without the centring "
        "20 us is the limit (Lambda 0.30 % there, 30 us 0.64 %).",
    )
    tangential_stiffness_ratio: float = Field(
        default=0.8, ge=2.0 / 3.0, le=1.0, description="Kt/Kn [-] (seed 000 section 2.1: [2/3, 1])."
    )
    tangential_damping_ratio: float = Field(
        default=0.1,
        ge=0.0,
        le=1.0,
        description="Tangential damping as a fraction of critical for the contact's reduced mass [-].",
    )
    restitution_coefficient_s_m: float = Field(
        default=0.08, ge=0.0, le=1.0, description="alpha_e of seed 000 eq. 4 [s/m]."
    )
    speed_ramp_rad_s2: float = Field(
        default=5000.0, gt=0.0, le=1e6, description="Shaft acceleration limit towards the speed setpoint [rad/s^2]."
    )
    rolling_resistance: bool = Field(default=True, description="Apply seed 001 rolling force and moments.")
    centred_refresh: bool = Field(
        default=True,
        description="Evaluate each tribology refresh at the load, entrainment speed and contact angle of the middle of "
        "the period it is held for (extrapolated from the previous refresh and the step's rates, "
        "twin.kernels.step.centred_inputs): the held values' error becomes second order in tribology_period_s "
        "instead of first. False: at the refresh's own step (first order; the configuration of the step reference, "
        "tests/engine/test_step_reference.py).",
    )
    thermal: Literal["network", "fixed"] = Field(
        default="network",
        description="'network': the bearing's thermal network (twin.thermal) runs in the loop, fed by the friction "
        "power; its temperatures set the inlet viscosity and the rings' and balls' expansion the clearance, and the "
        "setpoint's oil temperature is the ambient (sump) or oil-inlet (circulating) temperature. 'fixed': the oil "
        "and the contacts' inlet stay at the setpoint's oil temperature.",
    )
    thermal_period_s: float = Field(
        default=1.0,
        ge=0.01,
        le=60.0,
        description="The thermal network's step [s of thermal time]: every thermal_period_s x heat_capacity_scale of "
        "simulated time, a whole number of milliseconds (the nearest, at least 1); a frame of Twin.advance (10 ms "
        "by default, the service's 20 ms) ends there, so the step holds whatever the caller. The exponential "
        "step is exact for any step; the heat is held over it while the friction falls with the temperature (an "
        "explicit coupling), so it stays short against the balls' time constants (2-10 s). "
        "twin.validation.thermal_studies.period_study (6208 start-up from cold, 1000 rad/s, 3000 N, accelerated "
        "x1000, 900 s): 5 s moves the node temperatures by 0.43 K from 1 s, 20 s by 1.4 K, 50 s by 18 K (the "
        "first step's held heat overshoots the balls); first order, so 1 s lies within about 0.1 K of the limit.",
    )
    thermal_network: ThermalNetworkSettings = Field(
        default_factory=ThermalNetworkSettings,
        description="The bearing's surroundings and oil supply for thermal = 'network' (twin.thermal.settings).",
    )

    @field_validator("time_step_s", mode="before")
    @classmethod
    def _time_step(cls, value):
        low, high = TIME_STEP_RANGE_S
        if isinstance(value, str) and value.strip().lower() == "auto":
            return "auto"
        try:
            number = float(value)
        except (TypeError, ValueError):
            raise ValueError(
                f"time_step_s = {value!r}: must be 'auto' or a number of seconds in [{low:g}, {high:g}] s"
            ) from None
        if isinstance(value, bool) or not (low <= number <= high):
            raise ValueError(f"time_step_s = {value!r}: must be 'auto' or a number of seconds in [{low:g}, {high:g}] s")
        return number
