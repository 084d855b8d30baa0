"""Friction of the rubbing seals of a sealed bearing (SKF model for the frictional moment, SKF
Rolling bearings catalogue PUB BU/P1 10000/2 EN, 2016, 'Frictional moment of seals'; the same in
the General Catalogue 6000 EN, 2003):

    M_seal = K_S1 d_s^beta + K_S2                                                      [N mm]

for both seals of a bearing together, d_s [mm] the seal counterface diameter (the
inner-ring shoulder diameter d1 of the product tables), with the catalogue's table 'Seal
frictional moment: exponent and constants' for deep-groove ball bearings. Shields (2Z) do not
touch the inner ring: M_seal = 0. The torque acts whenever the shaft turns and is independent of
speed; its power is M_seal omega.
"""

from __future__ import annotations

# (largest outside diameter D [mm], beta, K_S1, K_S2) of 2RS1 contact seals on deep-groove ball
# bearings, rows in order of D (SKF catalogue table 'Seal frictional moment: exponent and
# constants', deep-groove ball bearings, RS1 seals: D <= 62, 62-80, 80-100, over 100 mm; the same
# rows, beta = 2.25 in every one, in the transcription of github.com/JRaposo-m/SKF-Bearing-Selection-Tool,
# skf_model/friction_model/seal_friction/seal_frictional_moment.csv)
RS1_CONSTANTS = (
    (62.0, 2.25, 0.023, 2.0),
    (80.0, 2.25, 0.018, 20.0),
    (100.0, 2.25, 0.018, 15.0),
    (1e9, 2.25, 0.018, 0.0),
)


def seal_constants(seal: str, outside_diameter_m: float) -> tuple[float, float, float]:
    """(beta, K_S1, K_S2) of a seal execution ('open', '2Z', '2RS') for a bearing of outside
    diameter D [m]; zeros for 'open' and '2Z' (no rubbing contact)."""
    if seal in ("open", "2Z"):
        return 0.0, 0.0, 0.0
    if seal != "2RS":
        raise ValueError(f"seal = {seal!r}: one of 'open', '2Z', '2RS'")
    d_mm = outside_diameter_m * 1e3
    for limit, beta, k1, k2 in RS1_CONSTANTS:
        if d_mm <= limit:
            return beta, k1, k2
    raise AssertionError("unreachable: the last row has no upper bound")


def seal_moment_n_m(seal: str, counterface_diameter_m: float, outside_diameter_m: float) -> float:
    """M_seal = K_S1 d_s^beta + K_S2 [N m] of both seals of a bearing (module docstring)."""
    beta, k1, k2 = seal_constants(seal, outside_diameter_m)
    if k1 == 0.0 and k2 == 0.0:
        return 0.0
    return (k1 * (counterface_diameter_m * 1e3) ** beta + k2) * 1e-3
