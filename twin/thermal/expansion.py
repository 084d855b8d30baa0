"""Thermal expansion of the rings and balls and the operating clearance it leaves.

A ring or ball of steel grows by alpha dT times its radius (linear expansion, alpha of 52100,
twin.thermal.materials). The inner raceway moves out by alpha dT_i r_i, the outer raceway out by
alpha dT_o r_o, each ball's radius grows by alpha dT_b R_b; the diametral clearance changes by
dP_d = 2 (alpha dT_o r_o - alpha dT_i r_i - 2 alpha dT_b R_b) (Harris and Kotzalas, Essential
Concepts of Bearing Technology, 2007, ch. 2 'operating clearance'; the rings unconstrained by
their fits). The engine sees it in the contacts' groove-centre radii and groove clearances.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from twin.kernels import layout as L
from twin.thermal.materials import STEEL_EXPANSION_K_INV


@dataclass(frozen=True)
class Expansion:
    """Growth of each body over its reference temperature [m]."""

    inner_raceway_m: float  # radial growth of the inner raceway
    outer_raceway_m: float  # radial growth of the outer raceway
    ball_radius_m: float  # growth of a ball's radius

    @property
    def diametral_clearance_change_m(self) -> float:
        """dP_d [m]: > 0 the clearance opens, < 0 it closes."""
        return 2.0 * (self.outer_raceway_m - self.inner_raceway_m - 2.0 * self.ball_radius_m)


def expansion(
    inner_rise_k: float,
    outer_rise_k: float,
    ball_rise_k: float,
    inner_raceway_radius_m: float,
    outer_raceway_radius_m: float,
    ball_radius_m: float,
    alpha_k_inv: float = STEEL_EXPANSION_K_INV,
) -> Expansion:
    """The growths of the raceways and the balls for temperature rises over the reference [m]."""
    return Expansion(
        alpha_k_inv * inner_rise_k * inner_raceway_radius_m,
        alpha_k_inv * outer_rise_k * outer_raceway_radius_m,
        alpha_k_inv * ball_rise_k * ball_radius_m,
    )


def write_groove_lanes(
    contacts: np.ndarray, base: tuple[np.ndarray, np.ndarray], growth: Expansion, ball_count: int
) -> None:
    """Write the growths into the engine's contact lanes (twin.kernels.layout): the groove-centre
    radius of each inner contact (even lanes) grows with the inner raceway, of each outer contact
    (odd lanes, and the pad lanes, which copy the last outer contact) with the outer raceway; the
    groove clearance (groove radius - ball radius) of every lane shrinks with the ball. `base`:
    the lanes' groove-centre radii and groove clearances at the start temperatures."""
    radius, clearance = base
    z2 = 2 * ball_count
    contacts[L.M_GROOVE_CENTRE_RADIUS] = radius + growth.outer_raceway_m
    contacts[L.M_GROOVE_CENTRE_RADIUS, 0:z2:2] = radius[0:z2:2] + growth.inner_raceway_m
    contacts[L.M_GROOVE_CLEARANCE] = clearance - growth.ball_radius_m
