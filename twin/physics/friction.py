"""Lubrication regime and friction coefficient against the film parameter (seed 000 Table 2)."""

from typing import Literal

from numba import njit

from twin.jit import JIT

REGIME_NO_CONTACT = 0
REGIME_BOUNDARY = 1
REGIME_MIXED = 2
REGIME_FULL_FILM = 3
Regime = Literal["no_contact", "boundary", "mixed", "full_film"]
REGIME_NAMES: tuple[Regime, ...] = ("no_contact", "boundary", "mixed", "full_film")
# seed 000 Table 2: the film parameter Lambda [-] up to which a contact is boundary, then mixed
BOUNDARY_LAMBDA_MAX = 1.0
MIXED_LAMBDA_MAX = 3.0


@njit(**JIT)
def regime_code(film_parameter):
    """Seed 000 Table 2: boundary for Lambda <= 1, mixed for 1 < Lambda <= 3, full film above."""
    if film_parameter <= BOUNDARY_LAMBDA_MAX:
        return REGIME_BOUNDARY
    if film_parameter <= MIXED_LAMBDA_MAX:
        return REGIME_MIXED
    return REGIME_FULL_FILM


@njit(**JIT)
def stribeck_line_mu(film_parameter):
    """mu(Lambda) of seed 000 section 2.3: 0.1 for Lambda <= 1, linear down to 0.01 at
    Lambda = 3, 0.01 above (the 'linear fitting made on the Stribeck curve', Fig. 5)."""
    if film_parameter <= BOUNDARY_LAMBDA_MAX:
        return 0.1
    if film_parameter >= MIXED_LAMBDA_MAX:
        return 0.01
    return 0.1 - 0.045 * (film_parameter - BOUNDARY_LAMBDA_MAX)
