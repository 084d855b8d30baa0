"""The heat the bearing's friction makes, contact by contact and source by source, and where it goes.

`friction_heat(rolling_w, sliding_w, spin_w, drive_power_w, drag_w, seal_w)` takes the power of
every ball-raceway contact by source, as the engine's friction powers compute it from the lanes of
the last step
(twin.friction_power.contact_powers_w: rolling, sliding, spin, the one reading of those sources
that the snapshot's `friction_power_w` also gives), once per network step.

That split is instantaneous; its total is scaled to the mean drive power over the network's
period, the contacts' share of friction torque x shaft speed (the energy balance of the bearing
at steady speed: the shaft's work is all turned into heat), floored at 0. The heat of a contact
goes half to its ring, half to the ball: Blok's partition for two bodies of the same steel at
comparable Peclet numbers (Blok 1937; Harris and Kotzalas, Advanced Concepts of Bearing
Technology, 2007, ch. 7). Drag heats the oil, seal friction the outer ring.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from twin.thermal.network import BALLS, INNER_RING, N_NODES, OIL, OUTER_RING

SOURCE_NAMES = ("rolling", "sliding", "spin", "drag", "seal")
RING_SHARE = 0.5  # Blok's partition of a contact's heat to the ring, equal steels and Peclet numbers [-]


@dataclass(frozen=True)
class HeatSources:
    """Friction heat [W]: per contact (rows: ball j inner 2j, outer 2j+1; columns SOURCE_NAMES
    rolling, sliding, spin) and per non-contact source."""

    per_contact_w: np.ndarray  # (2Z, 3) [W]
    drag_w: float = 0.0
    seal_w: float = 0.0

    @property
    def by_source_w(self) -> dict[str, float]:
        """Total heat of each source [W]."""
        contacts = self.per_contact_w.sum(axis=0)
        return dict(zip(SOURCE_NAMES, (*map(float, contacts), float(self.drag_w), float(self.seal_w)), strict=True))

    @property
    def total_w(self) -> float:
        """All the friction heat [W]."""
        return float(self.per_contact_w.sum() + self.drag_w + self.seal_w)

    def node_heat_w(self) -> np.ndarray:
        """The heat into each network node [W] (twin.thermal.network.NODE_NAMES)."""
        q = np.zeros(N_NODES)
        per = self.per_contact_w.sum(axis=1)
        inner, outer = float(per[0::2].sum()), float(per[1::2].sum())
        q[INNER_RING] += RING_SHARE * inner
        q[OUTER_RING] += RING_SHARE * outer + self.seal_w
        q[BALLS] += (1.0 - RING_SHARE) * (inner + outer)
        q[OIL] += self.drag_w
        return q


def friction_heat(
    rolling_w: np.ndarray,
    sliding_w: np.ndarray,
    spin_w: np.ndarray,
    drive_power_w: float,
    drag_w: float = 0.0,
    seal_w: float = 0.0,
) -> HeatSources:
    """The friction heat [W]: the contacts' rolling, sliding and spin power, each (Z, 2) with
    column 0 the inner, 1 the outer contact of each ball (twin.friction_power.contact_powers_w),
    scaled so that their total is `drive_power_w` (floored at 0; rolling at every contact alike
    when no contact has power), beside the balls' drag and the seals' rubbing."""
    split = np.stack((np.ravel(rolling_w), np.ravel(sliding_w), np.ravel(spin_w)), axis=1)  # row 2j + side
    est = np.where(np.isfinite(split), split, 0.0)
    total = est.sum()
    power = max(float(drive_power_w), 0.0) if np.isfinite(drive_power_w) else 0.0
    if total > 0.0:
        est = est * (power / total)
    elif power > 0.0:  # no contact power (no loaded contact): rolling at every contact alike
        est = np.zeros_like(est)
        est[:, 0] = power / est.shape[0]
    return HeatSources(per_contact_w=est, drag_w=drag_w, seal_w=seal_w)
