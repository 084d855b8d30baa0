"""Bearing designations and lubricant grades -> validated specs.

- 6208: exactly seed 000 Table 1 (Rb 6.3, Ri 24.0, Ro 36.6, Rc 6.552, Rz 4.19 mm, Z = 9).
- 7208 (= 7208 B, 40 deg), 7208AC (25 deg), 7208C (15 deg): the catalog contact angles of the
  72xx executions with seed 004's internal geometry (Table 1 and section 3: ball radius 6.3 mm,
  raceway radii 24.0 / 36.6 mm, Z = 13, cage elements Rz = 1.01 mm, conformity
  B = (Rci + Rce)/(2 Rb) - 1 = 0.14, i.e. groove radii 0.57 D). Seed 004 gives no contact angle
  and prints eps = 2.46 under Fr = Fa = 3000 N at 500 rad/s; no contact angle reproduces it with
  this geometry: a Jones quasi-static solution (twin.validation.analytic.jones_equilibrium, exact Hertz,
  centrifugal force) gives eps = (1 + delta_a tan(alpha) / delta_r) / 2 = 0.42 (40 deg), 1.15
  (25 deg), 1.56 (15 deg), and at most 1.76 (near 8-9 deg): with the loose conformity
  B = 0.14 the loaded contact angle grows under the axial load (15 -> 17.3 deg), which bounds
  delta_a / delta_r; eps = 2.46 would need a closer conformity or a different load. The twin
  reproduces the Jones solution (tests/engine/test_angular_contact.py).
- 6200-6210 (but 6208): public catalog boundary dimensions (bore d, outside diameter D) with the
  ball count and ball diameter of the usual steel-cage execution; pitch diameter (d + D)/2,
  groove radii 0.52 Dw as in the seed's 6208, cage elements sized like the seed's (30 um pocket
  clearance on the pitch circle). Approximate: manufacturers differ by a few percent.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import yaml

from twin.spec import BearingKind, BearingSpec, Geometry, Lubricant, Mounting
from twin.vibration.housing import Accelerometer, Housing
from twin.vibration.surface import SurfaceProfile
from twin.yaml_numbers import load_yaml

# designation: (bore mm, outside diameter mm, ball count, ball diameter mm)
_DEEP_GROOVE_MM = {
    "6200": (10.0, 30.0, 8, 4.762),
    "6201": (12.0, 32.0, 7, 5.953),
    "6202": (15.0, 35.0, 8, 5.953),
    "6203": (17.0, 40.0, 8, 6.747),
    "6204": (20.0, 47.0, 8, 7.938),
    "6205": (25.0, 52.0, 9, 7.938),
    "6206": (30.0, 62.0, 9, 9.525),
    "6207": (35.0, 72.0, 9, 11.112),
    "6209": (45.0, 85.0, 10, 12.7),
    "6210": (50.0, 90.0, 10, 12.7),
}

DEFAULT_DESIGNATION = "6208"
"""The bearing of seed 000, the default of every entry point (API, CLI, scenarios, settings)."""

_POCKET_CLEARANCE_M = 30e-6

# ISO 15 ring width B [mm] of the dimension series 02 (62xx, 72xx): the rings' lands' capacitance
_RING_WIDTH_MM = {
    "6200": 9.0,
    "6201": 10.0,
    "6202": 11.0,
    "6203": 12.0,
    "6204": 14.0,
    "6205": 15.0,
    "6206": 16.0,
    "6207": 17.0,
    "6208": 18.0,
    "6209": 19.0,
    "6210": 20.0,
    "7208": 18.0,
}

# ISO 3448 grade (nu_40 in mm^2/s) -> nu_100 [mm^2/s] of a VI ~ 100 mineral oil (ASTM D2270 table)
_ISO_VG_NU100_MM2_S = {
    10: 2.6,
    15: 3.3,
    22: 4.2,
    32: 5.4,
    46: 6.8,
    68: 8.7,
    100: 11.1,
    150: 14.5,
    220: 18.8,
    320: 24.0,
    460: 30.5,
}


# ISO 15312 thermal reference speed [r/min] of the SKF executions (SKF Rolling bearings catalogue,
# PUB BU/P1 17000/1 EN, 2018, deep-groove ball bearing product tables of the 62 series, SKF
# Explorer, column 'Reference speed'):
# the speed at which, under the standard's reference conditions (P = 0.05 C0, ISO VG 32 at an outer
# ring of 70 degC over an ambient of 20 degC, oil bath to the centre of the lowest ball), the
# bearing's friction power equals the reference heat flow 0.016 W/mm^2 over A_r = pi B (D + d).
_THERMAL_REFERENCE_SPEED_RPM = {"6205": 28000.0, "6208": 20000.0, "6210": 17000.0}


def thermal_reference_speed_rad_s(designation: str) -> float:
    """ISO 15312 thermal reference speed of a catalog bearing [rad/s] (SKF product tables)."""
    key = designation.strip().upper()
    if key not in _THERMAL_REFERENCE_SPEED_RPM:
        raise ValueError(
            f"designation = {designation!r}: a thermal reference speed is known for "
            f"{', '.join(sorted(_THERMAL_REFERENCE_SPEED_RPM))}"
        )
    return _THERMAL_REFERENCE_SPEED_RPM[key] * math.pi / 30.0


def _seed_6208() -> Geometry:
    return Geometry(
        ball_radius_m=6.3e-3,
        ball_count=9,
        inner_raceway_radius_m=24.0e-3,
        outer_raceway_radius_m=36.6e-3,
        inner_groove_radius_m=6.552e-3,
        outer_groove_radius_m=6.552e-3,
        cage_element_radius_m=4.19e-3,
        nominal_contact_angle_deg=0.0,
        cage_mass_kg=0.02,
        bore_diameter_m=40e-3,
        outside_diameter_m=80e-3,
    )


# angular-contact executions of the 7208 with seed 004's geometry: designation -> contact angle
_ANGULAR_7208_DEG = {"7208": 40.0, "7208AC": 25.0, "7208C": 15.0}


def _seed_7208(contact_angle_deg: float) -> Geometry:
    rb = 6.3e-3
    groove = 0.5 * (1.0 + 0.14) * 2.0 * rb  # B = 0.14 (seed 004 section 3) -> 7.182 mm
    return Geometry(
        ball_radius_m=rb,
        ball_count=13,
        inner_raceway_radius_m=24.0e-3,
        outer_raceway_radius_m=36.6e-3,
        inner_groove_radius_m=groove,
        outer_groove_radius_m=groove,
        cage_element_radius_m=1.01e-3,
        nominal_contact_angle_deg=contact_angle_deg,
        cage_mass_kg=0.025,
        bore_diameter_m=40e-3,
        outside_diameter_m=80e-3,
    )


def _deep_groove(bore_mm: float, od_mm: float, z: int, dw_mm: float) -> Geometry:
    rb = 0.5 * dw_mm * 1e-3
    pitch = 0.25 * (bore_mm + od_mm) * 1e-3
    half_chord = 2.0 * pitch * math.sin(math.pi / (2 * z))
    return Geometry(
        ball_radius_m=rb,
        ball_count=z,
        inner_raceway_radius_m=pitch - rb,
        outer_raceway_radius_m=pitch + rb,
        inner_groove_radius_m=0.52 * 2 * rb,
        outer_groove_radius_m=0.52 * 2 * rb,
        cage_element_radius_m=half_chord - rb - _POCKET_CLEARANCE_M,
        cage_mass_kg=0.02 * (pitch / 30.3e-3) ** 3,
        bore_diameter_m=bore_mm * 1e-3,
        outside_diameter_m=od_mm * 1e-3,
    )


# ---- the CWRU drive-end test bearing ---------------------------------------------------------
# Case Western Reserve University Bearing Data Center rig (engineering.case.edu/bearingdatacenter):
# a 2 hp Reliance induction motor whose drive-end shaft runs in an SKF 6205-2RS JEM, the
# accelerometer on a magnetic base at 12 o'clock on the motor housing.
_INCH_M = 0.0254
CWRU_BALL_DIAMETER_M = 0.3126 * _INCH_M  # 7.940 mm (data center: bearing specification)
CWRU_PITCH_DIAMETER_M = 1.537 * _INCH_M  # 39.04 mm
# Not published; estimated. The rotor of a 2 hp 4-pole induction motor (NEMA 145T frame: core about
# 90 mm across and 100 mm long, 5 kg of steel and copper, 1.5 kg of shaft) is ~6.5 kg; the drive-end
# bearing carries half of it plus half of the coupling to the torque transducer (~1 kg): 3.75 kg on
# the inner ring, and its weight, 3.75 x 9.80665 = 36.8 N, is the radial load at 0 hp (the
# coupling's misalignment forces are unknown and left out).
CWRU_ROTOR_MASS_KG = 3.75
CWRU_RADIAL_LOAD_N = 36.8
# ISO 5753-1 normal (CN) radial internal clearance of a 25 mm bore deep-groove ball bearing:
# 5-20 um; the middle of the range as the mounted diametral clearance.
CWRU_DIAMETRAL_CLEARANCE_M = 12.5e-6
# Calibrated once on the healthy record 97 only (twin.validation.cwru.calibrate_housing): the
# healthy acceleration's power spectrum (Welch, 512 points at 12 kHz) peaks in 2.95-3.6 kHz at
# 3234 Hz with a half-power bandwidth of 108 Hz (damping ratio 0.0167); the sprung mass (1 kg on
# the Sawalhi & Randall pedestal) is tuned to sense that mode. The spectrum is within 5 dB flat
# there; the fault records' impacts ring at 3.43-3.59 kHz with damping ratios 0.013-0.019
# (tests/vibration/test_cwru_ring_down.py).
CWRU_SPRUNG_STIFFNESS_N_M = 3.587e8
CWRU_SPRUNG_DAMPING_N_S_M = 549.9
# Calibrated once on the healthy record 97 only (`twin.validation.cwru.calibrate_background`):
# - the sensor and rig floor: the white noise density of the record's 2.0-2.9 kHz band, between the
#   motor's low-frequency content and the housing resonance, where the twin's healthy bearing is
#   20 dB below it: 0.0144 g over 900 Hz, rho = 0.0144 x 9.80665 / sqrt(900) = 4.7e-3 m/s2/sqrt(Hz);
# - the race profile: the record has no broadband hump above that floor at the 3.2 kHz resonance
#   (2.9-3.6 kHz: 0.0123 g measured, 0.0127 g of floor), so the profile's RMS is the largest that keeps
#   the twin's healthy 2.9-3.6 kHz RMS within 10 % of the record's: 2 nm (5 nm gives 0.0105 g alone).
# The rig's own lines (4.1-4.3 kHz, and the motor below 2 kHz) are not modelled: they carry most of
# the record's 0.071 g RMS, so the twin's healthy RMS is about half of it.
CWRU_NOISE_DENSITY_M_S2_RTHZ = 4.7e-3
CWRU_RACE_PROFILE_RMS_M = 2e-9

# designations with a rig: their default radial load [N] (`default_radial_load_n`)
_RIG_RADIAL_LOAD_N = {"CWRU-DE": CWRU_RADIAL_LOAD_N}


def _cwru_drive_end() -> BearingSpec:
    """`CWRU-DE`: the SKF 6205-2RS JEM of the CWRU rig's drive end as the data center publishes it
    (ball diameter 0.3126 in, pitch diameter 1.537 in, 9 balls, contact angle 0: BPFI 5.4152,
    BPFO 3.5848, FTF 0.39828, 2 x BSF 4.7135 x shaft), groove radii 0.52 Dw (not published; the
    usual deep-groove conformity, as the 62xx entries), the motor's rotor on the inner ring
    (CWRU_ROTOR_MASS_KG, estimated), the housing path to the accelerometer at 12 o'clock (azimuth
    180 deg from the load direction +x, i.e. 6 o'clock is +x) with its resonance and damping and
    the sensor noise calibrated on the healthy record only (values above), sampled at 12 kHz as
    the fault records, the race profiles and ball sizes of `twin.vibration.surface` on (profile RMS
    calibrated on the healthy record, ball-size spread the ISO 3290 G10 default)."""
    rb = 0.5 * CWRU_BALL_DIAMETER_M
    pitch = 0.5 * CWRU_PITCH_DIAMETER_M
    z = 9
    half_chord = 2.0 * pitch * math.sin(math.pi / (2 * z))
    geometry = Geometry(
        ball_radius_m=rb,
        ball_count=z,
        inner_raceway_radius_m=pitch - rb,
        outer_raceway_radius_m=pitch + rb,
        inner_groove_radius_m=0.52 * 2 * rb,
        outer_groove_radius_m=0.52 * 2 * rb,
        cage_element_radius_m=half_chord - rb - _POCKET_CLEARANCE_M,
        cage_mass_kg=0.02 * (pitch / 30.3e-3) ** 3,
        ring_width_m=15.0e-3,
    )
    housing = Housing(
        enabled=True,
        sprung_stiffness_n_m=CWRU_SPRUNG_STIFFNESS_N_M,
        sprung_damping_n_s_m=CWRU_SPRUNG_DAMPING_N_S_M,
        accelerometer=Accelerometer(
            azimuth_deg=180.0,
            sample_rate_hz=12000.0,
            window_s=1.0,
            noise_density_m_s2_rthz=CWRU_NOISE_DENSITY_M_S2_RTHZ,
        ),
    )
    return BearingSpec(
        designation="CWRU-DE",
        kind="deep_groove",
        geometry=geometry,
        mounting=Mounting(diametral_clearance_m=CWRU_DIAMETRAL_CLEARANCE_M, rotor_mass_kg=CWRU_ROTOR_MASS_KG),
        lubricant=Lubricant(),
        housing=housing,
        surface_profile=SurfaceProfile(enabled=True, race_profile_rms_m=CWRU_RACE_PROFILE_RMS_M),
    )


def default_radial_load_n(designation: str) -> float | None:
    """The radial load [N] of the rig a designation stands for (`CWRU-DE`: the estimate above), or
    None for a plain catalog bearing."""
    return _RIG_RADIAL_LOAD_N.get(designation.strip().upper())


def designations() -> list[str]:
    """Every designation the catalog knows, sorted."""
    return sorted(["6208", "7208", "7208AC", "7208C", "CWRU-DE", *_DEEP_GROOVE_MM])


def bearing(
    designation: str = DEFAULT_DESIGNATION,
    *,
    diametral_clearance_m: float = 0.0,
    lubricant: Lubricant | None = None,
    **spec_fields,
) -> BearingSpec:
    """The spec of a catalog bearing with the given mounting clearance [m] and lubricant."""
    key = designation.strip().upper()
    if key == "CWRU-DE":
        spec = _cwru_drive_end()
        if lubricant is not None or diametral_clearance_m != 0.0 or spec_fields:
            data = spec.model_dump()
            if lubricant is not None:
                data["lubricant"] = lubricant.model_dump()
            if diametral_clearance_m != 0.0:
                data["mounting"]["diametral_clearance_m"] = diametral_clearance_m
            data.update({k: (v.model_dump() if hasattr(v, "model_dump") else v) for k, v in spec_fields.items()})
            spec = BearingSpec.model_validate(data)
        return spec
    kind: BearingKind
    if key == "6208":
        geometry, kind = _seed_6208(), "deep_groove"
    elif key in _ANGULAR_7208_DEG:
        geometry, kind = _seed_7208(_ANGULAR_7208_DEG[key]), "angular_contact"
    elif key in _DEEP_GROOVE_MM:
        geometry, kind = _deep_groove(*_DEEP_GROOVE_MM[key]), "deep_groove"
    else:
        raise ValueError(f"designation: unknown bearing {designation!r}; known: {', '.join(designations())}")
    width = _RING_WIDTH_MM.get(key[:4])
    if width is not None and geometry.ring_width_m is None:
        geometry = geometry.model_copy(update={"ring_width_m": width * 1e-3})
    mounting = Mounting(diametral_clearance_m=diametral_clearance_m)
    return BearingSpec(
        designation=key,
        kind=kind,
        geometry=geometry,
        mounting=mounting,
        lubricant=lubricant or Lubricant(),
        **spec_fields,
    )


def lubricant(name: str = "seed-000") -> Lubricant:
    """A named oil: 'seed-000' (eta = 0.04 Pa s at 40 degC) or an ISO VG grade ('ISO VG 68')."""
    key = name.strip().upper().replace("ISO", "").replace("VG", "").replace(" ", "")
    if name.strip().lower() == "seed-000":
        return Lubricant()
    if key.isdigit() and int(key) in _ISO_VG_NU100_MM2_S:
        grade = int(key)
        return Lubricant(
            name=f"ISO VG {grade}",
            kinematic_viscosity_40c_m2_s=grade * 1e-6,
            kinematic_viscosity_100c_m2_s=_ISO_VG_NU100_MM2_S[grade] * 1e-6,
        )
    raise ValueError(
        f"lubricant: unknown {name!r}; use 'seed-000' or 'ISO VG n' with n in {sorted(_ISO_VG_NU100_MM2_S)}"
    )


# ---- load ratings (rating life, twin.life) ---------------------------------------------------
# Basic dynamic load rating C, basic static load rating C0 and fatigue load limit Pu per
# designation, from public catalogues (source named per entry). "7208" is the 40 deg execution
# (7208 B); "7208AC" (25 deg) and "7208C" (15 deg) are its sister executions. Cross-checked in
# tests/life against ISO 281:2007 clause 5.1 (C from the geometry) and ISO 76 (C0 = f0 Z Dw^2
# cos(alpha)): every entry agrees with the twin's own geometry within 10 %.


@dataclass(frozen=True)
class LoadRatings:
    """Catalogue load ratings of one bearing execution (SI)."""

    designation: str
    contact_angle_deg: float  # nominal contact angle of the catalogued execution [deg]
    dynamic_load_rating_n: float  # basic dynamic radial load rating C [N] (ISO 281)
    static_load_rating_n: float  # basic static radial load rating C0 [N] (ISO 76)
    fatigue_load_limit_n: float  # fatigue load limit Pu = Cu of ISO 281:2007 clause 9.3 [N]
    source: str  # where the numbers come from


_SKF_2018 = "SKF Rolling bearings catalogue (PUB BU/P1 17000/1 EN, 2018) and skf.com product page, SKF Explorer"
_SKF_7208B = "SKF General Catalogue 6000/I EN (2008), single row angular contact ball bearing 7208 BEP (40 deg)"
_GB_292 = (
    "GB/T 292 single row angular contact ball bearings as tabulated in Chinese machine-design handbooks "
    "(C, C0); Pu not catalogued there: C0 / 23.5, the C0/Pu ratio of every SKF entry of this table"
)

# designation: (contact angle deg, C kN, C0 kN, Pu kN, source)
_LOAD_RATINGS_KN = {
    "6200": (0.0, 5.4, 2.36, 0.1, _SKF_2018),
    "6201": (0.0, 7.28, 3.1, 0.132, _SKF_2018),
    "6202": (0.0, 8.06, 3.75, 0.16, _SKF_2018),
    "6203": (0.0, 9.95, 4.75, 0.2, _SKF_2018),
    "6204": (0.0, 13.5, 6.55, 0.28, _SKF_2018),
    "6205": (0.0, 14.8, 7.8, 0.335, _SKF_2018),
    "6206": (0.0, 20.3, 11.2, 0.475, _SKF_2018),
    "6207": (0.0, 27.0, 15.3, 0.655, _SKF_2018),
    "6208": (0.0, 32.5, 19.0, 0.8, _SKF_2018),
    "6209": (0.0, 35.1, 21.6, 0.915, _SKF_2018),
    "6210": (0.0, 37.1, 23.2, 0.98, _SKF_2018),
    "7208": (40.0, 34.5, 24.0, 1.02, _SKF_7208B),
    "7208AC": (25.0, 35.2, 24.5, 24.5 / 23.5, _GB_292),
    "7208C": (15.0, 36.8, 25.8, 25.8 / 23.5, _GB_292),
}
_RATING_ALIASES = {"7208B": "7208"}


def load_ratings(designation: str) -> LoadRatings:
    """Catalogue load ratings (C, C0, Pu [N], source) of a designation; '7208 AC' and '7208AC'
    are the same key, '7208B' is '7208'. Raises ValueError naming the known designations."""
    key = designation.strip().upper().replace(" ", "").replace("-", "")
    key = _RATING_ALIASES.get(key, key)
    if key not in _LOAD_RATINGS_KN:
        raise ValueError(
            f"designation: no load ratings for {designation!r}; known: {', '.join(sorted(_LOAD_RATINGS_KN))}"
        )
    angle, c, c0, pu, source = _LOAD_RATINGS_KN[key]
    return LoadRatings(
        designation=key,
        contact_angle_deg=angle,
        dynamic_load_rating_n=c * 1e3,
        static_load_rating_n=c0 * 1e3,
        fatigue_load_limit_n=pu * 1e3,
        source=source,
    )


def rated_designations() -> list[str]:
    """Every designation with catalogue load ratings, sorted."""
    return sorted(_LOAD_RATINGS_KN)


# ---- bearing spec files ------------------------------------------------------------------------
SPEC_FILE_SUFFIXES = (".yaml", ".yml", ".json")


def load_spec_file(path: str) -> BearingSpec:
    """A `BearingSpec` from a YAML or JSON file (the fields of `twin.spec.BearingSpec`: geometry,
    materials, lubricant, mounting, housing, surface profile ...), validated as any spec. Raises
    ValueError naming the file when it cannot be read or parsed, pydantic.ValidationError naming
    the field otherwise."""
    file = Path(path)
    if file.suffix.lower() not in SPEC_FILE_SUFFIXES:
        raise ValueError(f"bearing: spec file {path!r} must end in {', '.join(SPEC_FILE_SUFFIXES)}")
    try:
        text = file.read_text(encoding="utf-8")
    except OSError as exc:
        raise ValueError(f"bearing: cannot read spec file {path!r}: {exc.strerror}") from None
    except UnicodeDecodeError as exc:
        raise ValueError(f"bearing: spec file {path!r} is not UTF-8 text (byte {exc.start})") from None
    try:
        data = json.loads(text) if file.suffix.lower() == ".json" else load_yaml(text)
    except (json.JSONDecodeError, yaml.YAMLError) as exc:
        raise ValueError(
            f"bearing: spec file {path!r} is not valid {file.suffix[1:].upper()}: {str(exc).splitlines()[0]}"
        ) from None
    if not isinstance(data, dict):
        raise ValueError(f"bearing: spec file {path!r} must hold a mapping of BearingSpec fields")
    return BearingSpec.model_validate(data)


def bearing_or_file(name: str) -> BearingSpec:
    """A catalog designation (`bearing`) or, when `name` ends in .yaml, .yml or .json, a spec file
    (`load_spec_file`)."""
    if name.strip().lower().endswith(SPEC_FILE_SUFFIXES):
        return load_spec_file(name.strip())
    return bearing(name)
