"""Settings of the thermal network: the bearing's surroundings and the oil supply (strict pydantic).

What the geometry of a `BearingSpec` does not say: the housing, the shaft, the oil sump or the
circulating supply. Defaults describe a bearing in a cast-iron pillow-block housing with an oil
bath, in still air at the setpoint's ambient temperature.
"""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field


class ThermalNetworkSettings(BaseModel):
    """The bearing's surroundings for the thermal network (twin.thermal.network)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    dissipation: Literal["housing", "iso_15312"] = Field(
        default="housing",
        description="'housing': the rings lose heat through the shaft, the housing and the oil (correlations); "
        "'iso_15312': through the rings' seating surfaces at the standard's reference heat flow, q_r A_r per 50 K "
        "(ISO 15312:2018 clauses 4-5), the shaft and housing nodes left out.",
    )
    oil_supply: Literal["sump", "circulating"] = Field(
        default="sump",
        description="'sump': an oil bath that keeps its oil; 'circulating': oil enters at the setpoint's oil "
        "temperature at `oil_flow_m3_s` and leaves at the oil node's temperature.",
    )
    oil_flow_m3_s: float = Field(
        default=0.0, ge=0.0, le=1e-3, description="Circulating oil flow [m^3/s] (oil_supply = circulating)."
    )
    oil_volume_m3: float | None = Field(
        default=None,
        gt=0.0,
        le=0.1,
        description="Oil in the bearing and its sump [m^3]; None: the bearing's free volume plus a sump of twice it.",
    )
    housing_mass_kg: float | None = Field(
        default=None,
        gt=0.0,
        le=1e4,
        description="Housing mass [kg]; None: a cast-iron ring of outside diameter 2 D and width 2 B (a pillow block).",
    )
    housing_emissivity: float = Field(
        default=0.8,
        ge=0.0,
        le=1.0,
        description="Emissivity of the painted housing [-] (Incropera and DeWitt Table A.11).",
    )
    housing_frame_conductance_w_k: float = Field(
        default=1.0,
        ge=0.0,
        le=1e4,
        description="Conduction from the housing into the machine frame at ambient temperature [W/K]: the uncertain "
        "part of the dissipation that the estimator (twin.thermal.estimator) corrects from a measured temperature.",
    )
    fit_conductance_w_m2_k: float = Field(
        default=1.0e4,
        gt=0.0,
        le=1e6,
        description="Contact conductance of a ring's seat (shaft / housing fit, steel on steel, moderate pressure) "
        "[W/(m^2 K)] (Madhusudana, Thermal Contact Conductance, 2nd ed. 2014, ch. 2 range 1e3-1e5).",
    )
    shaft_length_m: float | None = Field(
        default=None, gt=0.0, le=10.0, description="Exposed shaft length either side [m]; None: 4 ring widths."
    )
    shaft_frame_conductance_w_k: float = Field(
        default=0.5,
        ge=0.0,
        le=1e4,
        description="Conduction along the shaft into the machine (motor, coupling) at ambient temperature [W/K].",
    )
    heat_capacity_scale: float = Field(
        default=1.0,
        gt=0.0,
        le=1.0,
        description="Factor on every heat capacity [-]; < 1 is the accelerated mode: a study reaches its steady state "
        "1 / scale times sooner in simulated time, with the same steady state; outputs flag it.",
    )
