"""The heat the bearing's friction makes, contact by contact and source by source, and where it goes.

`friction_heat(contacts, z, drive_power_w, ellipse)` reads the per-contact lanes of the engine
(twin.kernels.layout) once per network step:

* rolling: the seed 001 rolling force times the entrainment speed, F_R |u| [W];
* sliding: the tangential force on the ball times the slip velocity, |F . v_s| [W];
* spin: the moment about the contact normal times the relative spin rate, |M_n w_n| [W]
  (the ellipse traction's lanes; 0 with the centre-point friction laws);
* drag and seal: 0 until the engine states them (the friction laws add them; `HeatSources` has
  their fields so that consumers do not change).

The lane estimates split the heat; their total is the drive power, friction torque x shaft speed
(the energy balance of the bearing at steady speed: the shaft's work is all turned into heat),
floored at 0. The heat of a contact goes half to its ring, half to the ball: Blok's partition
for two bodies of the same steel at comparable Peclet numbers (Blok 1937; Harris and Kotzalas,
Advanced Concepts of Bearing Technology, 2007, ch. 7). Drag heats the oil, seal friction the
outer ring.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from twin.kernels import layout as L
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
        s = self.per_contact_w.sum(axis=0)
        return {
            "rolling": float(s[0]),
            "sliding": float(s[1]),
            "spin": float(s[2]),
            "drag": float(self.drag_w),
            "seal": float(self.seal_w),
        }

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


def lane_heat_estimates_w(contacts: np.ndarray, ball_count: int, ellipse: bool) -> np.ndarray:
    """(2Z, 3) rolling, sliding, spin heat of each contact from its lanes [W]."""
    n = 2 * ball_count
    c = contacts[:, :n]
    loaded = c[L.C_LOAD] > 0.0
    rolling = np.abs(c[L.C_ROLLING_FORCE] * c[L.C_ENTRAINMENT])
    sliding = np.abs(c[L.O_FX] * c[L.O_SX] + c[L.O_FY] * c[L.O_SY] + c[L.O_FZ] * c[L.O_SZ])
    spin = np.abs(c[L.E_SPIN_MOMENT] * c[L.E_SPIN_RATE]) if ellipse else np.zeros(n)
    est = np.stack([rolling, sliding, spin], axis=1)
    est[~loaded] = 0.0
    return np.where(np.isfinite(est), est, 0.0)


def friction_heat(contacts: np.ndarray, ball_count: int, drive_power_w: float, ellipse: bool) -> HeatSources:
    """The bearing's friction heat from the engine's lanes, scaled to the drive power [W]."""
    est = lane_heat_estimates_w(contacts, ball_count, ellipse)
    total = est.sum()
    power = max(float(drive_power_w), 0.0) if np.isfinite(drive_power_w) else 0.0
    if total > 0.0:
        est *= power / total
    elif power > 0.0:  # no lane estimate (no loaded contact): rolling at every contact alike
        est[:, 0] = power / est.shape[0]
    return HeatSources(per_contact_w=est)
