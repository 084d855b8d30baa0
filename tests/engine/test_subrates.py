"""The tribology sub-rates of the DEM step: the default periods of the tribology refresh
and of the strip traction solve, chosen by the convergence study twin.validation.subrate_study,
hold the outputs within the study's tolerances on representative cases."""

import math

import pytest
from pydantic import ValidationError

from twin import catalog
from twin.kernels import layout as L
from twin.model import make_model
from twin.spec import ModelOptions
from twin.validation import subrate_study, timestep_study


def test_defaults_are_the_studys_choice():
    options = ModelOptions()
    assert (options.tribology_period_s, options.traction_period_s) == subrate_study.CHOSEN
    assert subrate_study.CHOSEN in subrate_study.PERIODS  # a candidate the study measured


@pytest.mark.parametrize("dt", [1e-6, "auto", 4e-6])
def test_traction_period_is_a_whole_number_of_refreshes(dt):
    model = make_model(catalog.bearing("6208"), ModelOptions(time_step_s=dt))
    refresh_s = model.params[L.P_SUBSTEPS] * model.dt_s
    every = int(model.params[L.P_TRACTION_EVERY])
    assert every >= 1
    assert abs(every * refresh_s - ModelOptions().traction_period_s) <= 0.5 * refresh_s
    # shorter than a refresh: every refresh
    fast = make_model(catalog.bearing("6208"), ModelOptions(time_step_s=dt, traction_period_s=1e-6))
    assert fast.params[L.P_TRACTION_EVERY] == 1


@pytest.mark.parametrize(
    "field, value",
    [
        ("traction_period_s", 0.0),
        ("traction_period_s", 2e-3),
        ("traction_period_s", math.nan),
        ("tribology_period_s", 1e-3),
        ("tribology_period_s", -1e-5),
    ],
)
def test_bad_sub_rate_refused_with_field_and_range(field, value):
    with pytest.raises(ValidationError) as err:
        ModelOptions(**{field: value})
    assert field in str(err.value)


def test_chosen_sub_rates_within_tolerance_on_representative_cases():
    # the default periods against the study's reference sub-rates (subrate_study.REFERENCE:
    # tribology 10 us, traction 200 us) at the auto step, and against seed 000's 1 us step, over
    # whole cage revolutions: loads, films, Lambda, mu and speeds within 0.5 %, torque and
    # electrical values within 2 %
    # (timestep_study.TOLERANCES). Cases: 6208 at the serve default, 6208 at 1700 rad/s and 7500 N,
    # 7208 B at Fr = Fa = 3000 N, 6208 with a 5 A shaft current.
    cases = subrate_study.representative_cases()
    assert {c.id for c in cases} == {"6208-serve", "6208-1700rad-7.5kN", "7208-500rad-3kN+3kN", "6208-5A"}
    rows = subrate_study.run_study(cases, (subrate_study.CHOSEN,), against_1us=True)
    assert len(rows) == len(cases)
    tol = timestep_study.TOLERANCES
    assert tol["ball_load"] == 0.005 and tol["lambda"] == 0.005 and tol["friction_torque"] == 0.02
    for r in rows:
        assert r["status"] == "ok" and r["restarts"] == 0, r["id"]
        for key in ("deviation", "deviation_from_1us"):
            for q, limit in tol.items():
                dev = r[key][q]
                assert math.isnan(dev) or dev <= limit, (r["id"], key, q, dev)
            for q in ("ball_load", "lambda", "h_min", "mu", "cage_speed", "friction_torque", "impedance"):
                assert not math.isnan(r[key][q]), (r["id"], key, q)  # compared, not skipped
        assert r["within_tolerance"] and r["within_tolerance_of_1us"], r["id"]
    current = next(r for r in rows if r["shaft_current_a"] > 0.0)
    assert not math.isnan(current["deviation"]["current_heating"])
