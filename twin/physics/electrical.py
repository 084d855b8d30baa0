"""Electrical RC-equivalent of a lubricated ball-raceway contact (seed 000 end of section 2.2:
asperity contacts are resistive, the film is capacitive, the apparent contact is a parallel RC
whose dissipative properties follow the regime; seed 004 conclusion; seed 003 eq. 2 density).

Scalar laws, SI in and out, never NaN for non-negative inputs; the capacitance of the bearing's
geometry (ball-raceway gap, ring lands) is integrated once per model (numpy).
"""

import math

import numpy as np
from numba import njit

from twin.jit import JIT

VACUUM_PERMITTIVITY_F_M = 8.8541878128e-12


@njit(**JIT)
def dowson_higginson_density_ratio(pressure_pa):
    """rho / rho_0 = 1 + 0.6e-9 p / (1 + 1.7e-9 p) (seed 003 eq. 2, isothermal part)."""
    p = max(pressure_pa, 0.0)
    return 1.0 + 0.6e-9 * p / (1.0 + 1.7e-9 * p)


@njit(**JIT)
def clausius_mossotti_permittivity(relative_permittivity_0, density_ratio):
    """Relative permittivity of the compressed oil: (eps - 1)/(eps + 2) proportional to density
    (Clausius-Mossotti), so (eps - 1)/(eps + 2) = rho/rho_0 (eps_0r - 1)/(eps_0r + 2)."""
    k = density_ratio * (relative_permittivity_0 - 1.0) / (relative_permittivity_0 + 2.0)
    return (1.0 + 2.0 * k) / (1.0 - k)


@njit(**JIT)
def hertz_zone_capacitance_f(relative_permittivity, semi_major_m, semi_minor_m, central_film_m):
    """Plate capacitor over the Hertz ellipse on the central film: eps0 eps_r pi a b / h_c [F]."""
    if central_film_m <= 0.0:
        return 0.0
    return VACUUM_PERMITTIVITY_F_M * relative_permittivity * math.pi * semi_major_m * semi_minor_m / central_film_m


@njit(**JIT)
def outer_zone_capacitance_f(relative_permittivity_0, rx_m, ry_m, gap_m, gap_limit_m):
    """Oil-filled gap around the contact: the gap grows from `gap_m` like x^2/(2 Rx) + y^2/(2 Ry);
    with s that increment, dA = 2 pi sqrt(Rx Ry) ds, so
    C = eps0 eps_r0 2 pi sqrt(Rx Ry) ln((gap + gap_limit) / gap) [F], integrated out to where the
    gap has grown by gap_limit (the oil meniscus). Finite for any gap > 0; the log keeps the
    result insensitive to the exact limit."""
    if gap_m <= 0.0:
        return 0.0
    return (
        VACUUM_PERMITTIVITY_F_M
        * relative_permittivity_0
        * 2.0
        * math.pi
        * math.sqrt(rx_m * ry_m)
        * math.log((gap_m + gap_limit_m) / gap_m)
    )


@njit(**JIT)
def asperity_resistance_ohm(full_contact_resistance_ohm, asperity_share):
    """Metallic conduction through the asperities: the fully metallic contact's resistance divided
    by the share of the load they carry (seed 001 eq. A2); infinite without asperity contact."""
    if asperity_share <= 0.0:
        return math.inf
    return full_contact_resistance_ohm / asperity_share


@njit(**JIT)
def oil_film_resistance_ohm(resistivity_ohm_m, central_film_m, semi_major_m, semi_minor_m):
    """Leakage through the oil film over the Hertz ellipse: rho_e h_c / (pi a b) [ohm]."""
    area = math.pi * semi_major_m * semi_minor_m
    if area <= 0.0:
        return math.inf
    return resistivity_ohm_m * max(central_film_m, 0.0) / area


@njit(**JIT)
def parallel_resistance_ohm(r1, r2):
    """R1 || R2 with infinities allowed."""
    if math.isinf(r1):
        return r2
    if math.isinf(r2):
        return r1
    return r1 * r2 / (r1 + r2)


# ---- capacitance of the bearing's geometry (model build, numpy) ---------------------------


def ball_raceway_gap_integral_m(
    ball_radius_m: float,
    groove_radius_m: float,
    groove_centre_radius_m: float,
    contact_angle_rad: float,
    inner: bool,
    land_radius_m: float,
    ring_width_m: float | None,
    central_gap_m: float,
    polar_steps: int = 300,
    azimuth_steps: int = 90,
) -> float:
    """Integral of dA / gap over the half of the ball that faces a raceway [m]: C = eps0 eps_r
    times it is the ball-raceway capacitance when the oil fills the gap (local parallel-plate
    reading, as in the bearing-capacitance models of the literature, e.g. Jablonka, Glovnea and
    Bongaerts 2012, J. Phys. D 45, 385301: Hertz zone plus the gap around it).

    Exact geometry of the unloaded surfaces: the ball (centre on the pitch circle, `central_gap_m`
    off the raceway along the contact normal) and the groove, a torus of minor radius
    `groove_radius_m` about the circle of radius `groove_centre_radius_m`, up to its shoulders,
    where the ring's land (a cylinder of radius `land_radius_m`, width `ring_width_m`, None:
    unbounded) takes over. The gap is measured along the ball's normal (ray from its centre);
    graded polar grid (geometric from 1e-5 rad) around the contact normal: 300 x 90 rays are
    converged to 0.1 %."""
    rb, rg = ball_radius_m, groove_radius_m
    offset = rg - rb
    ca, sa = math.cos(contact_angle_rad), math.sin(contact_angle_rad)
    # contact normal (from the ball centre to the contact point) in the meridional x-z plane
    nrm = np.array([-ca, 0.0, -sa]) if inner else np.array([ca, 0.0, sa])
    z_g = offset * sa if inner else -offset * sa
    centre = np.array([groove_centre_radius_m, 0.0, z_g]) + (offset - central_gap_m) * nrm
    e_roll = np.array([0.0, 1.0, 0.0])
    e_cross = np.cross(nrm, e_roll)
    edges = np.concatenate([[0.0], np.geomspace(1e-5, 0.5 * math.pi, polar_steps)])
    theta = 0.5 * (edges[1:] + edges[:-1])
    phi = (np.arange(azimuth_steps) + 0.5) * 2.0 * math.pi / azimuth_steps
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    ray = (
        np.cos(th)[..., None] * nrm
        + (np.sin(th) * np.cos(ph))[..., None] * e_roll
        + (np.sin(th) * np.sin(ph))[..., None] * e_cross
    )

    def torus(t):
        x = centre + t[..., None] * ray
        return (np.hypot(x[..., 0], x[..., 1]) - groove_centre_radius_m) ** 2 + (x[..., 2] - z_g) ** 2 - rg * rg

    lo = np.zeros(th.shape)
    hi = np.full(th.shape, 3.0 * rg)  # the ball centre lies inside the torus tube: one crossing
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        inside = torus(mid) < 0.0
        lo = np.where(inside, mid, lo)
        hi = np.where(inside, hi, mid)
    t_groove = 0.5 * (lo + hi)
    hit = centre + t_groove[..., None] * ray
    rho = np.hypot(hit[..., 0], hit[..., 1])
    in_groove = rho <= land_radius_m if inner else rho >= land_radius_m
    # beyond the shoulder: the land cylinder |x_xy| = land radius along the same ray
    a2 = ray[..., 0] ** 2 + ray[..., 1] ** 2
    b2 = 2.0 * (centre[0] * ray[..., 0] + centre[1] * ray[..., 1])
    c2 = centre[0] ** 2 + centre[1] ** 2 - land_radius_m**2
    disc = b2 * b2 - 4.0 * a2 * c2
    root = np.sqrt(np.clip(disc, 0.0, None))
    with np.errstate(divide="ignore", invalid="ignore"):
        s_land = np.where(inner, (-b2 - root) / (2.0 * a2), (-b2 + root) / (2.0 * a2))
    z_land = centre[2] + s_land * ray[..., 2]
    on_land = (disc > 0.0) & (s_land > rb)
    if ring_width_m is not None:
        on_land &= np.abs(z_land) <= 0.5 * ring_width_m
    distance = np.where(in_groove, t_groove, np.where(on_land, s_land, np.inf))
    gap = distance - rb
    area = rb * rb * np.sin(th) * np.diff(edges)[:, None] * (2.0 * math.pi / azimuth_steps)
    ok = np.isfinite(gap) & (gap > 0.0)
    return float(np.sum(np.where(ok, area / np.where(ok, gap, 1.0), 0.0)))


def equivalent_gap_limit_m(gap_integral_m: float, rx_m: float, ry_m: float, central_gap_m: float) -> float:
    """The gap limit g of outer_zone_capacitance_f that reproduces an exact gap integral at the
    central gap h: 2 pi sqrt(Rx Ry) ln((h + g) / h) = integral -> g = h (exp(integral /
    (2 pi sqrt(Rx Ry))) - 1) [m]. For the 6208 the geometric integral gives g = 0.31 mm, nearly
    the same from 0.1 to 10 um of gap (310-323 um), so the paraboloid law with it follows the
    exact geometry within 3 % over the gaps of loaded and open contacts."""
    return central_gap_m * math.expm1(gap_integral_m / (2.0 * math.pi * math.sqrt(rx_m * ry_m)))


def coaxial_capacitance_f(
    relative_permittivity: float, length_m: float, inner_radius_m: float, outer_radius_m: float
) -> float:
    """C = 2 pi eps0 eps_r L / ln(r_out / r_in) [F]: two coaxial cylinders (the rings' lands facing
    each other across the annulus)."""
    if length_m <= 0.0 or outer_radius_m <= inner_radius_m:
        return 0.0
    return (
        2.0
        * math.pi
        * VACUUM_PERMITTIVITY_F_M
        * relative_permittivity
        * length_m
        / math.log(outer_radius_m / inner_radius_m)
    )
