"""How the twin rates its life: the inputs of ISO 281:2007 clause 9.3 and the damage basis."""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field

ContaminationLevel = Literal[
    "extreme_cleanliness",
    "high_cleanliness",
    "normal_cleanliness",
    "slight_to_typical_contamination",
    "severe_contamination",
    "very_severe_contamination",
]


class LifeSettings(BaseModel):
    """How the twin rates its life (ISO 281:2007 clause 9.3 inputs and the damage basis)."""

    model_config = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False)

    contamination: ContaminationLevel = Field(
        default="normal_cleanliness",
        description="Contamination level (ISO 281:2007 Table 13 names; e_C from the Annex A formula of the level).",
    )
    lubrication: Literal["oil", "grease"] = Field(
        default="oil", description="Annex A formula set: oil without filtering or with off-line filters, or grease."
    )
    contamination_factor: float | None = Field(
        default=None, ge=0.0, le=1.0, description="e_C [-] given directly (overrides `contamination`)."
    )
    damage_basis: Literal["iso_281", "contact_loads"] = Field(
        default="iso_281",
        description="Life the damage accrues against: the modified rating life L10m = a_ISO L10 (ISO 281), or "
        "a_ISO times the contact-load life (the twin's own ball loads, ISO/TS 16281 spirit).",
    )
    initial_damage_fraction: float = Field(
        default=0.0, ge=0.0, le=1.0, description="Damage already accumulated when the twin starts [-] (0: new bearing)."
    )
    refresh_s: float = Field(
        default=0.01, gt=0.0, le=1.0, description="Simulated time between two life evaluations in the engine [s]."
    )
    averaging_s: float = Field(
        default=0.05,
        gt=0.0,
        le=10.0,
        description="Time constant of the running mean of the contact-load damage rate over the ball passages [s].",
    )
