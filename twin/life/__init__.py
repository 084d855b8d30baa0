"""Rating life of a ball bearing: ISO 281:2007 basic and modified rating life (`iso281`), a life
from the contact loads in the spirit of ISO/TS 16281 (`contact_loads`), and Palmgren-Miner damage
accumulation along the twin's history (`monitor`); `settings` holds what a user chooses.

Pure functions of SI inputs (plain Python, evaluated between frames, never in the hot loop).
The drivers that build a model or a `twin.engine.Twin` to rate one operating point live above
the engine, in `twin.validation.life_rating`.
"""

from twin.life.contact_loads import (
    RacewayGeometry,
    contact_load_damage_per_mrev,
    contact_load_life_mrev,
    contact_loads_from_equilibrium,
    contact_loads_from_state,
    equilibrium_contact_life_mrev,
)
from twin.life.iso281 import (
    A_ISO_CAP,
    B_M_RADIAL_BALL,
    KAPPA_MAX,
    KAPPA_MIN,
    LIFE_EXPONENT_BALL,
    LP_CONSTANT_N_MM,
    LP_REDUCTION,
    PU_CONTACT_STRESS_RATIO,
    SECONDS_PER_HOUR,
    BearingRatings,
    IsoLife,
    LoadFactors,
    basic_dynamic_load_rating_n,
    basic_rating_life_mrev,
    basic_static_load_rating_n,
    contamination_factor,
    equivalent_dynamic_load_n,
    iso_life,
    life_hours,
    life_modification_factor,
    load_factors,
    raceway_load_rating_n,
    rad_s_to_rpm,
    rated_viscosity_m2_s,
    ratings_for,
    static_load_factor_f0,
    viscosity_ratio,
)
from twin.life.monitor import DamageAccumulator, LifeMonitor, damage_rate_per_s, life_block
from twin.life.settings import ContaminationLevel, LifeSettings

__all__ = [
    "A_ISO_CAP",
    "B_M_RADIAL_BALL",
    "BearingRatings",
    "ContaminationLevel",
    "DamageAccumulator",
    "IsoLife",
    "KAPPA_MAX",
    "KAPPA_MIN",
    "LIFE_EXPONENT_BALL",
    "LP_CONSTANT_N_MM",
    "LP_REDUCTION",
    "LifeMonitor",
    "LifeSettings",
    "LoadFactors",
    "PU_CONTACT_STRESS_RATIO",
    "RacewayGeometry",
    "SECONDS_PER_HOUR",
    "basic_dynamic_load_rating_n",
    "basic_rating_life_mrev",
    "basic_static_load_rating_n",
    "contact_load_damage_per_mrev",
    "contact_load_life_mrev",
    "contact_loads_from_equilibrium",
    "contact_loads_from_state",
    "contamination_factor",
    "damage_rate_per_s",
    "equilibrium_contact_life_mrev",
    "equivalent_dynamic_load_n",
    "iso_life",
    "life_block",
    "life_hours",
    "life_modification_factor",
    "load_factors",
    "raceway_load_rating_n",
    "rad_s_to_rpm",
    "rated_viscosity_m2_s",
    "ratings_for",
    "static_load_factor_f0",
    "viscosity_ratio",
]
