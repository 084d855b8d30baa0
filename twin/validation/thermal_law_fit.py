"""The real-time loop's thermal film law, calibrated against the thermal EHL solver (seed 003).

The full solver (twin.ehl_solver) is far too slow for the loop; the loop uses a two-constant
reduced-order law of the same physics:

    dT_inlet = dT_current (seed 003 eq. 10) + dT_shear,
    dT_shear = c_s * 2 eta(theta0 + dT_inlet) u^2 / k'      (seed 003 eq. 6 at the inlet, p -> 0),
    h / h_isothermal = g(dT_inlet)^c_T,   g = (eta/eta0)^0.68 (alpha*/alpha)^0.49 (Roelands, eq. 3)

(twin.physics.thermal). `fit_reduced_order_law` finds c_T and c_s by least squares on ln(h/h_iso)
over the converged cells of the solver's shipped film-reduction table
(twin/ehl_solver/film_reduction_table.json: currents 0-30 A x entrainment speeds 0.832-4.16 m/s
at seed 003's Appendix 2 inputs, the table's provenance names the solver run). The fitted
constants are the defaults of twin.spec.Thermal (`film_temperature_exponent`,
`inlet_shear_heating_factor`); tests/validation/test_thermal_law_fit.py refits and pins them,
so a regenerated table cannot silently disagree with the loop.

Run `python -m twin.validation.thermal_law_fit` to print the fit and its residuals.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from twin.ehl_solver.film_reduction import load_table
from twin.physics.thermal import inlet_shear_heating_temperature_rise_k, thermal_film_factor


@dataclass(frozen=True)
class ReducedOrderFit:
    """Fitted constants of the loop's thermal film law and how well it matches the solver."""

    temperature_exponent: float   # c_T [-]
    shear_factor: float           # c_s [-]
    rms_ln_error: float           # rms of ln(h_law / h_solver) over the cells [-]
    max_reduction_error: float    # max |reduction_law - reduction_solver| (fractions of h_iso) [-]
    cells: int


def law_factor(current_rise_k: float, entrainment_speed_m_s: float, inputs: dict,
               temperature_exponent: float, shear_factor: float) -> float:
    """h / h_isothermal of the loop's law for the solver table's inputs (dict of its provenance)."""
    theta0 = inputs["base_temperature_c"] + 273.15
    shear = inlet_shear_heating_temperature_rise_k(
        entrainment_speed_m_s, inputs["eta0_pa_s"], theta0, inputs["beta_k_inv"],
        inputs["oil_conductivity_w_m_k"], other_rise_k=current_rise_k, shear_factor=shear_factor)
    return thermal_film_factor(current_rise_k + shear, inputs["eta0_pa_s"], theta0, inputs["beta_k_inv"],
                               temperature_exponent)


def _cells(table: dict):
    for i, _ in enumerate(table["currents_a"]):
        for j, u in enumerate(table["entrainment_speeds_m_s"]):
            if table["converged"][i][j] and not table["extrapolated"][i][j]:
                yield table["current_temperature_rise_k"][i][j], u, table["h_min_factor"][i][j]


def fit_reduced_order_law(path: str | None = None) -> ReducedOrderFit:
    """Least-squares fit of (c_T, c_s) to the solver's converged, non-extrapolated cells."""
    from scipy.optimize import least_squares

    table = load_table(path)
    inputs = table["provenance"]["inputs"]
    cells = list(_cells(table))

    def residuals(x):
        return [math.log(law_factor(dt, u, inputs, x[0], x[1])) - math.log(f) for dt, u, f in cells]

    sol = least_squares(residuals, [1.2, 1.5], bounds=([0.3, 0.05], [5.0, 20.0]))
    c_t, c_s = (float(v) for v in sol.x)
    errors = [abs(law_factor(dt, u, inputs, c_t, c_s) - f) for dt, u, f in cells]
    return ReducedOrderFit(temperature_exponent=c_t, shear_factor=c_s,
                           rms_ln_error=float(np.sqrt(np.mean(np.square(sol.fun)))),
                           max_reduction_error=float(max(errors)), cells=len(cells))


def main() -> int:
    fit = fit_reduced_order_law()
    print(f"c_T (film_temperature_exponent)  = {fit.temperature_exponent:.3f}")
    print(f"c_s (inlet_shear_heating_factor) = {fit.shear_factor:.3f}")
    print(f"{fit.cells} solver cells: rms ln error {fit.rms_ln_error:.3f}, "
          f"max reduction error {100 * fit.max_reduction_error:.1f} points")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
