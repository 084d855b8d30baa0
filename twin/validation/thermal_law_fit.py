"""The real-time loop's current-heating film law, calibrated against the thermal EHL solver
(seed 003).

The full solver (twin.ehl_solver) is far too slow for the loop; the loop uses a one-constant
reduced-order law of the same physics for the current discharge:

    dT_inlet = dT_current (seed 003 eq. 10),
    h / h_no_current = g(dT_inlet)^c_T,   g = (eta/eta0)^0.68 (alpha*/alpha)^0.49 (Roelands, eq. 3)

(twin.physics.thermal). The shear heating of the inlet is not calibrated here: the loop uses
an established rolling-contact inlet law for it (Murch and Wilson 1975,
twin.physics.thermal.murch_wilson_thermal_factor), because the solver's shear heating is seed 003's
eq. 6, a Hertz-zone temperature. So `fit_reduced_order_law` takes the current-only part of the
solver's shipped film-reduction table (twin/ehl_solver/film_reduction_table.json: currents
5-30 A x entrainment speeds 0.832-4.16 m/s at seed 003's Appendix 2 inputs, the table's
provenance names the solver run): per cell the solver's film with current over its film without
current at the same speed, h(I, u) / h(0, u), and fits c_T by least squares on ln(h/h_iso). The
fitted constant is the default of twin.spec.Thermal (`film_temperature_exponent`);
tests/validation/test_thermal_law_fit.py refits and pins it, so a regenerated table cannot
silently disagree with the loop.

Run `python -m twin.validation.thermal_law_fit` to print the fit and its residuals.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from twin.ehl_solver.film_reduction import load_table
from twin.physics.thermal import murch_wilson_thermal_factor, thermal_film_factor, thermal_loading_parameter


@dataclass(frozen=True)
class ReducedOrderFit:
    """Fitted constant of the loop's current-heating film law and how well it matches the solver."""

    temperature_exponent: float  # c_T [-]
    rms_ln_error: float  # rms of ln(h_law / h_solver) over the cells [-]
    max_reduction_error: float  # max |reduction_law - reduction_solver| (fractions of h_iso) [-]
    cells: int


def current_factor(current_rise_k: float, inputs: dict, temperature_exponent: float) -> float:
    """h(current) / h(no current) of the loop's law for the solver table's inputs (dict of its
    provenance): g(dT)^c_T."""
    theta0 = inputs["base_temperature_c"] + 273.15
    return thermal_film_factor(current_rise_k, inputs["eta0_pa_s"], theta0, inputs["beta_k_inv"], temperature_exponent)


def law_factor(current_rise_k: float, entrainment_speed_m_s: float, inputs: dict, temperature_exponent: float) -> float:
    """h / h_isothermal of the loop's whole law at the solver table's inputs: the current factor
    times the Murch-Wilson inlet shear-heating factor at the speed (both heatings on, as in the
    EV twin). The Murch-Wilson factor takes the oil at the base temperature (the loop evaluates
    it at the current-heated inlet; at the table's small loadings the difference is < 1 %)."""
    loading = thermal_loading_parameter(
        inputs["beta_k_inv"], inputs["eta0_pa_s"], entrainment_speed_m_s, inputs["oil_conductivity_w_m_k"]
    )
    return current_factor(current_rise_k, inputs, temperature_exponent) * murch_wilson_thermal_factor(loading)


def _cells(table: dict):
    """(dT_current, u, h(I, u) / h(0, u)) over the converged, non-extrapolated cells with I > 0."""
    for i, current in enumerate(table["currents_a"]):
        if current <= 0.0:
            continue
        for j, u in enumerate(table["entrainment_speeds_m_s"]):
            if (
                table["converged"][i][j]
                and not table["extrapolated"][i][j]
                and table["converged"][0][j]
                and table["currents_a"][0] == 0.0
            ):
                yield (
                    table["current_temperature_rise_k"][i][j],
                    u,
                    table["h_min_factor"][i][j] / table["h_min_factor"][0][j],
                )


def fit_reduced_order_law(path: str | None = None) -> ReducedOrderFit:
    """Least-squares fit of c_T to the solver's current-only film ratios (closed form: ln h/h0 is
    linear in c_T)."""
    table = load_table(path)
    inputs = table["provenance"]["inputs"]
    cells = list(_cells(table))
    theta0 = inputs["base_temperature_c"] + 273.15
    ln_g = np.array(
        [
            math.log(thermal_film_factor(dt, inputs["eta0_pa_s"], theta0, inputs["beta_k_inv"], 1.0))
            for dt, _, _ in cells
        ]
    )
    ln_f = np.array([math.log(f) for _, _, f in cells])
    c_t = float(np.dot(ln_g, ln_f) / np.dot(ln_g, ln_g))
    residuals = c_t * ln_g - ln_f
    errors = [abs(current_factor(dt, inputs, c_t) - f) for dt, _, f in cells]
    return ReducedOrderFit(
        temperature_exponent=c_t,
        rms_ln_error=float(np.sqrt(np.mean(residuals**2))),
        max_reduction_error=float(max(errors)),
        cells=len(cells),
    )


def main() -> int:
    fit = fit_reduced_order_law()
    print(f"c_T (film_temperature_exponent) = {fit.temperature_exponent:.3f}")
    print(
        f"{fit.cells} solver cells (current-only film ratios): rms ln error {fit.rms_ln_error:.3f}, "
        f"max reduction error {100 * fit.max_reduction_error:.1f} points"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
