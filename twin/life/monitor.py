"""The twin's live rating life: Palmgren-Miner damage along its history.

dD/dt = 1 / life(current conditions) [1/s], accumulated by `LifeMonitor` between frames;
remaining life = (1 - D) x life at the current conditions.
"""

from __future__ import annotations

import math

import numpy as np

from twin.life.contact_loads import RacewayGeometry, contact_load_damage_per_mrev, contact_loads_from_state
from twin.life.iso281 import SECONDS_PER_HOUR, BearingRatings, IsoLife, iso_life, life_hours, ratings_for
from twin.life.settings import LifeSettings


def _finite(value: float | None) -> float | None:
    return float(value) if value is not None and math.isfinite(value) else None


def damage_rate_per_s(life_h: float) -> float:
    """Palmgren-Miner: the fraction of life used per second at a life of `life_h` hours [1/s]
    (0 for an unbounded life)."""
    return 0.0 if not math.isfinite(life_h) or life_h <= 0.0 else 1.0 / (life_h * SECONDS_PER_HOUR)


def life_block(iso: IsoLife, contact_life_h: float, settings: LifeSettings, damage_fraction: float) -> dict:
    """The published `life` block (twin.snapshot.LifeState fields): hours, fractions, nulls where
    undefined, one `reason` string for the nulls and caveats."""
    basis_h = (
        iso.a_iso_for_damage * iso.l10_h
        if settings.damage_basis == "iso_281"
        else iso.a_iso_for_damage * contact_life_h
    )
    rate = damage_rate_per_s(basis_h)
    remaining = max(0.0, 1.0 - damage_fraction) * basis_h if math.isfinite(basis_h) else None
    return {
        "kappa": _finite(iso.kappa),
        "a_iso": _finite(iso.a_iso),
        "l10_h": _finite(iso.l10_h),
        "l10m_h": _finite(iso.l10m_h),
        "l10_contact_loads_h": _finite(contact_life_h),
        "damage_fraction": float(damage_fraction),
        "damage_rate_per_s": float(rate),
        "remaining_life_h": _finite(remaining),
        "dynamic_load_rating_n": float(iso.dynamic_load_rating_n),
        "equivalent_load_n": float(iso.equivalent_load_n),
        "contamination_factor": float(iso.contamination_factor),
        "viscosity_m2_s": float(iso.viscosity_m2_s),
        "rated_viscosity_m2_s": _finite(iso.rated_viscosity_m2_s),
        "damage_basis": settings.damage_basis,
        "reason": "; ".join(iso.reasons) if iso.reasons else None,
    }


# ---- the engine's accumulator ------------------------------------------------------------------
class DamageAccumulator:
    """Palmgren-Miner sum D = sum (dt / life) with a piecewise-constant rate: `set_rate` at time t
    closes the interval since the last call at the old rate and starts one at the new rate;
    `damage_at(t)` reads D without changing it (exact for a rate constant over each interval). A
    clock that goes back (a restarted scenario) starts a new interval without adding damage."""

    def __init__(self, initial_damage: float = 0.0):
        self.damage = float(initial_damage)
        self.rate_per_s = 0.0
        self.time_s: float | None = None

    def damage_at(self, time_s: float) -> float:
        """D at `time_s` [-] (the damage so far plus the open interval at the current rate)."""
        if self.time_s is None or time_s <= self.time_s:
            return self.damage
        return self.damage + self.rate_per_s * (time_s - self.time_s)

    def set_rate(self, time_s: float, rate_per_s: float) -> None:
        """Close the open interval at `time_s` and continue at `rate_per_s` [1/s]."""
        self.damage = self.damage_at(time_s)
        self.time_s = time_s
        self.rate_per_s = max(0.0, float(rate_per_s))


class LifeMonitor:
    """The twin's live rating life: the engine calls `update` after every frame (cheap: it
    re-evaluates every `settings.refresh_s` of simulated time) and `block` for the snapshot.

    The ISO part follows the setpoint loads, the current shaft speed and the oil's kinematic
    viscosity the engine passes in (the inlet viscosity at the oil temperature plus the inlet's
    current and shear heating). The contact-load part reads the DEM's ball loads and contact
    angles; its damage rate per revolution is a running mean (time constant `averaging_s`) over
    the ball passages. Damage accrues against `settings.damage_basis`. Errors never escape into
    the frame loop: they leave the life undefined with the reason."""

    def __init__(self, model, settings: LifeSettings | None = None):
        self.settings = settings or LifeSettings()
        self.spec = model.spec
        self.geometry = RacewayGeometry.of(model.spec.geometry)
        self.accumulator = DamageAccumulator(self.settings.initial_damage_fraction)
        self.error: str | None = None
        self.ratings: BearingRatings | None
        try:
            self.ratings = ratings_for(model.spec)
        except ValueError as exc:
            self.ratings, self.error = None, f"no load ratings: {exc}"
        self._iso: IsoLife | None = None
        self._contact_damage_per_mrev: float | None = None
        self._contact_life_h = math.inf
        self._last_eval_s: float | None = None

    def due(self, time_s: float) -> bool:
        """Whether `update` would re-evaluate at `time_s` (refresh_s passed, or a new clock)."""
        last = self._last_eval_s
        return self.ratings is not None and (last is None or not last <= time_s < last + self.settings.refresh_s)

    def update(
        self,
        time_s: float,
        shaft_speed_rad_s: float,
        radial_load_n: float,
        axial_load_n: float,
        kinematic_viscosity_m2_s: float,
        contacts: np.ndarray,
        force: bool = False,
    ) -> None:
        """Re-evaluate if `refresh_s` has passed (or `force`), and restart the damage interval at
        the new rate."""
        if self.ratings is None or not (force or self.due(time_s)):
            return
        last = self._last_eval_s
        try:
            self._iso = iso_life(
                self.spec,
                self.ratings,
                self.settings,
                radial_load_n,
                axial_load_n,
                shaft_speed_rad_s,
                kinematic_viscosity_m2_s,
            )
            d = contact_load_damage_per_mrev(self.geometry, *contact_loads_from_state(contacts))
            prev = self._contact_damage_per_mrev
            if prev is None or last is None or time_s <= last:
                mean = d
            else:
                w = 1.0 - math.exp(-(time_s - last) / self.settings.averaging_s)
                mean = prev + w * (d - prev)
            self._contact_damage_per_mrev = mean
            self._contact_life_h = life_hours(math.inf if mean <= 0.0 else 1.0 / mean, shaft_speed_rad_s)
            self.error = None
        except (ValueError, ZeroDivisionError, OverflowError, FloatingPointError) as exc:
            self._iso, self.error = None, f"life not evaluated: {exc}"
        self._last_eval_s = time_s
        rate = 0.0
        if self._iso is not None:
            basis_h = self._iso.a_iso_for_damage * (
                self._iso.l10_h if self.settings.damage_basis == "iso_281" else self._contact_life_h
            )
            rate = damage_rate_per_s(basis_h)
        self.accumulator.set_rate(time_s, rate)

    def block(self, time_s: float) -> dict | None:
        """The snapshot's `life` fields at `time_s`, or None before the first evaluation."""
        damage = self.accumulator.damage_at(time_s)
        if self._iso is None:
            if self.error is None:
                return None
            return {"damage_fraction": float(damage), "reason": self.error}
        block = life_block(self._iso, self._contact_life_h, self.settings, damage)
        if self.error:
            block["reason"] = self.error
        return block
