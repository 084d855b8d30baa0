"""Steady point-contact EHL solver with shear and current-discharge heating (seed 003).

- `solve_point_contact(...) -> EHLResult` (solver.py): isothermal or thermal (eqs. 6 + 10),
  FAS multigrid on a uniform grid, influence coefficients applied by FFT (elastic.py), Roelands
  and Dowson-Higginson (kernels.py); defaults and their provenance in params.py.
- `film_reduction_factor(current_a, entrainment_speed_m_s)` (film_reduction.py): the thermal/current
  film-reduction factor for the real-time loop, interpolated from the shipped
  film_reduction_table.json (`bearing-twin ehl calibrate` regenerates it).
"""

from twin.ehl_solver.film_reduction import film_reduction_factor
from twin.ehl_solver.result import EHLResult
from twin.ehl_solver.solver import solve_point_contact

__all__ = ["EHLResult", "film_reduction_factor", "solve_point_contact"]
