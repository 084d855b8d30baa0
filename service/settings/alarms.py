"""The `alarms` settings group: thresholds and timing of the alarms (service.core.alarms;
docs/service.md "Alarms")."""

from __future__ import annotations

from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from service.settings.flat import details


class AlarmSettings(BaseModel):
    """Alarm thresholds and timing (service.core.alarms; docs/service.md "Alarms"). Times are simulated
    seconds (the twin's clock). Give them in the environment as JSON,
    `BEARING_TWIN_ALARMS='{"machine_group": 1, "support": "flexible"}'`, or one by one,
    `BEARING_TWIN_ALARMS__MACHINE_GROUP=1`."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    machine_group: Literal[1, 2] = Field(
        default=2,
        json_schema_extra=details("Large machines: 300 kW to 50 MW; medium machines: 15 kW to 300 kW."),
        description="ISO 20816-3 machine group [1 | 2]: 1 = large machines "
        "(Table A.1), 2 = medium machines (Table A.2).",
    )
    support: Literal["rigid", "flexible"] = Field(
        default="rigid", description="ISO 20816-3 support class [rigid | flexible] (clause 4.4)."
    )
    clear_ratio: float = Field(
        default=0.9,
        gt=0.0,
        lt=1.0,
        json_schema_extra=details("The 'below' alarms clear above T / clear_ratio."),
        description="Hysteresis of the 'above' alarms: an alarm raised "
        "at threshold T clears below clear_ratio x T [-].",
    )
    clear_hold_s: float = Field(
        default=1.0,
        ge=0.0,
        le=3600.0,
        description="Time on the clear side of the clear threshold before "
        "an alarm clears or steps down [s of simulated time].",
    )
    vibration_delay_s: float = Field(
        default=0.0,
        ge=0.0,
        le=3600.0,
        description="A vibration zone alarm rises after the velocity RMS stays in zone C or D this long [s].",
    )
    lubrication_delay_s: float = Field(
        default=1.0,
        ge=0.0,
        le=3600.0,
        json_schema_extra=details(
            "The conditions: kappa < kappa_threshold, or a loaded contact in the boundary regime."
        ),
        description="Time a lubrication condition lasts before its alarm rises [s of simulated time].",
    )
    kappa_threshold: float = Field(
        default=1.0,
        gt=0.0,
        le=10.0,
        description="Viscosity ratio kappa = nu / nu1 (ISO 281:2007 clause 9.3) below which the "
        "lubrication alarm rises [-].",
    )
    boundary_lambda: float = Field(
        default=1.0,
        gt=0.0,
        le=10.0,
        description="Film parameter at or below which a contact is in the boundary regime (seed "
        "000 Table 2: Lambda <= 1) [-].",
    )
    loaded_contact_fraction: float = Field(
        default=0.1,
        ge=0.0,
        le=1.0,
        description="A contact is loaded when it carries this fraction of "
        "the snapshot's largest contact load, or more [-].",
    )
    discharge_delay_s: float = Field(
        default=0.0,
        ge=0.0,
        le=3600.0,
        description="Time the discharge risk stays 'possible' or 'likely' "
        "before the electrical alarm rises [s of simulated time].",
    )
    defect_amplitude_m_s2: float = Field(
        default=0.5,
        gt=0.0,
        le=1e4,
        json_schema_extra=details(
            "When the envelope noise floor is known, the line must also stand defect_significance x the floor above it."
        ),
        description="Envelope amplitude of a defect line (FTF, BPFO, BPFI, BSF) above which its alarm rises [m/s^2].",
    )
    defect_significance: float = Field(
        default=4.0,
        ge=1.0,
        le=100.0,
        json_schema_extra=details("The default is twin.vibration.indicators.SIGNIFICANCE."),
        description="Times the envelope noise floor (median) a defect line must exceed [-].",
    )
    defect_delay_s: float = Field(
        default=0.0,
        ge=0.0,
        le=3600.0,
        description="A defect alarm rises after its line stays above the threshold this long [s of simulated time].",
    )
    life_used_warning: float = Field(
        default=0.5,
        gt=0.0,
        le=10.0,
        description="Palmgren-Miner damage fraction above which the life alarm is a warning [-].",
    )
    life_used_critical: float = Field(
        default=0.9, gt=0.0, le=10.0, description="Damage fraction above which the life alarm is critical [-]."
    )
    temperature_warning_c: float = Field(
        default=82.0,
        gt=-30.0,
        le=300.0,
        json_schema_extra=details(
            "82 degC is the oil sump limit of ISO 13709 / API 610 for ring-oil and splash lubricated bearings."
        ),
        description="Outer-ring temperature above which the temperature alarm is a warning [degC].",
    )
    temperature_critical_c: float = Field(
        default=95.0,
        gt=-30.0,
        le=300.0,
        description="Outer-ring temperature above which the temperature alarm is critical [degC].",
    )
    temperature_rate_warning_k_per_min: float = Field(
        default=5.0,
        gt=0.0,
        le=1000.0,
        description="Rise rate of the outer ring (over a minute of thermal "
        "time) above which the rate alarm warns [K/min].",
    )
    temperature_rate_critical_k_per_min: float = Field(
        default=10.0, gt=0.0, le=1000.0, description="Rate of rise above which the rate alarm is critical [K/min]."
    )
    temperature_delay_s: float = Field(
        default=0.0,
        ge=0.0,
        le=3600.0,
        description="A temperature alarm rises after its value stays beyond the threshold this long [s of simulated "
        "time].",
    )
    history: int = Field(
        default=200, ge=1, le=100000, description="Alarm events kept per twin for GET .../alarms [count]."
    )

    @field_validator("machine_group", mode="before")
    @classmethod
    def _group_from_text(cls, value: Any) -> Any:
        """The environment gives text (`BEARING_TWIN_ALARMS__MACHINE_GROUP=1`): "1" and "2" are the groups."""
        return int(value) if isinstance(value, str) and value.strip() in ("1", "2") else value

    @model_validator(mode="after")
    def _ordered(self) -> AlarmSettings:
        if self.life_used_critical < self.life_used_warning:
            raise ValueError(
                f"life_used_critical = {self.life_used_critical:g} must be >= "
                f"life_used_warning = {self.life_used_warning:g}"
            )
        return self
