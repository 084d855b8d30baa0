"""Bearing defect frequencies: FTF, BPFO, BPFI, BSF and 2 x BSF [Hz].

Rigid rolling without slip, outer ring stationary, inner ring at the shaft frequency f_s [Hz]
(Harris & Kotzalas, Rolling Bearing Analysis, 5th ed., Vol. 1 ch. 8 (rolling-element speeds);
Randall & Antoni 2011, "Rolling element bearing diagnostics - A tutorial", MSSP 25, eqs. 1-4):

    gamma = D cos(alpha) / d_m                      (D ball diameter, d_m pitch diameter)
    FTF   = f_s / 2 (1 - gamma)                    cage (fundamental train) frequency   eq. 3
    BPFO  = Z f_s / 2 (1 - gamma) = Z FTF          ball pass frequency, outer race      eq. 1
    BPFI  = Z f_s / 2 (1 + gamma) = Z (f_s - FTF)  ball pass frequency, inner race      eq. 2
    BSF   = d_m / (2 D) f_s (1 - gamma^2)          ball spin frequency (ball relative to
                                                   the cage); a ball defect strikes both
                                                   races once per spin: 2 x BSF         eq. 4

alpha is the LOADED contact angle: under axial load it grows above the nominal one (and under
centrifugal load the inner and outer angles part), so the twin measures it on the contacts
(`loaded_contact_angle_rad`, the mean over loaded balls of each ball's contact angle) and passes
it here. Real bearings slip by 1-2 %, so measured peaks sit slightly below these (Randall &
Antoni 2011, sec. 2.1).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class DefectFrequencies:
    """Kinematic frequencies of one operating point [Hz]."""

    shaft_hz: float
    ftf_hz: float
    bpfo_hz: float
    bpfi_hz: float
    bsf_hz: float
    contact_angle_rad: float

    @property
    def two_bsf_hz(self) -> float:
        """2 x BSF [Hz]: the rate at which a ball defect strikes the races."""
        return 2.0 * self.bsf_hz

    def as_dict(self) -> dict[str, float]:
        """{'ftf', 'bpfo', 'bpfi', 'bsf', 'two_bsf'} in Hz (the CLI JSON `defect_frequencies_hz`)."""
        return {
            "ftf": self.ftf_hz,
            "bpfo": self.bpfo_hz,
            "bpfi": self.bpfi_hz,
            "bsf": self.bsf_hz,
            "two_bsf": self.two_bsf_hz,
        }

    def orders(self) -> dict[str, float]:
        """The same as multiples of the shaft frequency [-] (how catalogues tabulate them)."""
        f = self.shaft_hz
        return {k: v / f for k, v in self.as_dict().items()}


def defect_frequencies(
    ball_diameter_m: float,
    pitch_diameter_m: float,
    ball_count: int,
    shaft_speed_rad_s: float,
    contact_angle_rad: float = 0.0,
) -> DefectFrequencies:
    """FTF, BPFO, BPFI, BSF [Hz] (module docstring; Randall & Antoni 2011 eqs. 1-4).

    ball_diameter_m D [m], pitch_diameter_m d_m [m], ball_count Z, shaft_speed_rad_s [rad/s] (sign
    ignored: the frequencies are rates), contact_angle_rad the loaded contact angle [rad]."""
    if not (ball_diameter_m > 0.0 and pitch_diameter_m > ball_diameter_m):
        raise ValueError(
            f"need 0 < ball_diameter_m < pitch_diameter_m, got {ball_diameter_m:g}, {pitch_diameter_m:g} m"
        )
    if ball_count < 1:
        raise ValueError(f"ball_count = {ball_count}: must be >= 1")
    if not (0.0 <= abs(contact_angle_rad) < 0.5 * math.pi):
        raise ValueError(f"contact_angle_rad = {contact_angle_rad:g}: must be in [0, pi/2)")
    fs = abs(shaft_speed_rad_s) / (2.0 * math.pi)
    gamma = ball_diameter_m * math.cos(contact_angle_rad) / pitch_diameter_m
    ftf = 0.5 * fs * (1.0 - gamma)
    return DefectFrequencies(
        shaft_hz=fs,
        ftf_hz=ftf,
        bpfo_hz=ball_count * ftf,
        bpfi_hz=0.5 * ball_count * fs * (1.0 + gamma),
        bsf_hz=pitch_diameter_m / (2.0 * ball_diameter_m) * fs * (1.0 - gamma * gamma),
        contact_angle_rad=float(contact_angle_rad),
    )


def bearing_defect_frequencies(
    geometry, shaft_speed_rad_s: float, contact_angle_rad: float | None = None
) -> DefectFrequencies:
    """`defect_frequencies` of a `twin.spec.Geometry` (ball radius, pitch radius, ball count);
    contact_angle_rad None -> the nominal (unloaded) contact angle of the geometry."""
    alpha = math.radians(geometry.nominal_contact_angle_deg) if contact_angle_rad is None else contact_angle_rad
    return defect_frequencies(
        2.0 * geometry.ball_radius_m, 2.0 * geometry.pitch_radius_m, geometry.ball_count, shaft_speed_rad_s, alpha
    )


def loaded_contact_angle_rad(normal_z: np.ndarray, load_n: np.ndarray, min_load_fraction: float = 0.01) -> float:
    """Mean contact angle [rad] over the loaded balls.

    normal_z[c], load_n[c]: per ball-raceway contact c = 2 ball + race (race 0 inner, 1 outer; the
    engine's lane order, rows G_NZ and C_LOAD): the axial component of the unit contact normal and
    the contact load [N]. The contact angle of a contact is asin|n_z| (angle of the contact line to
    the radial plane); a ball's angle is the mean of its inner and outer ones; a ball counts as
    loaded when both its contacts carry more than `min_load_fraction` of the largest load.
    Raises ValueError when no ball is loaded (the angle is then undefined)."""
    nz = np.asarray(normal_z, dtype=float)
    q = np.asarray(load_n, dtype=float)
    if nz.shape != q.shape or nz.ndim != 1 or nz.size % 2:
        raise ValueError("normal_z and load_n must be 1-D arrays of equal, even length (2 per ball)")
    qmax = float(np.max(q)) if q.size else 0.0
    if not qmax > 0.0:
        raise ValueError("no loaded contact: the loaded contact angle is undefined")
    angle = np.arcsin(np.clip(np.abs(nz), 0.0, 1.0)).reshape(-1, 2)
    loaded = np.all(q.reshape(-1, 2) > min_load_fraction * qmax, axis=1)
    if not np.any(loaded):
        raise ValueError("no ball is loaded at both raceways: the loaded contact angle is undefined")
    return float(np.mean(angle[loaded].mean(axis=1)))
