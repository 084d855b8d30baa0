"""`bearing-twin thermal`: the steady state of one operating point (twin.validation.thermal_steady)."""

import json

import pytest

from service.cli import main


def test_bad_ambient_names_the_option_and_its_range(capsys):
    # the ambient / oil-inlet range is the oil temperature's (twin.setpoint: [-30, 150] degC)
    with pytest.raises(SystemExit) as exit_info:
        main(["thermal", "--speed", "1000", "--radial-load", "3000", "--ambient", "500"])
    assert exit_info.value.code == 2
    assert "argument --ambient: must be in [-30, 150] degC, got 500" in capsys.readouterr().err


@pytest.mark.slow
def test_json_steady_state_balances_its_heat(capsys):
    assert (
        main(["thermal", "--bearing", "6208", "--speed", "1000", "--radial-load", "3000", "--ambient", "20", "--json"])
        == 0
    )
    r = json.loads(capsys.readouterr().out)
    assert r["converged"]
    t = r["temperatures_c"]
    assert t["balls"] > t["outer_ring"] > t["housing"] > 20.0
    # the heat by source adds up to the total, friction torque x speed
    assert sum(r["heat_w"].values()) == pytest.approx(r["heat_total_w"], rel=1e-9)
    assert r["heat_total_w"] == pytest.approx(r["friction_torque_n_m"] * 1000.0, rel=1e-9)


def test_a_thermal_runaway_is_said_as_one(capsys):
    """The 6208 at its limiting speed (2073 rad/s) under its static load rating (21.9 kN) makes
    about 2.8 kW of friction heat, more than the sump network can carry away below 400 degC: the
    command says there is no steady state and why, rather than blaming a node temperature no
    option sets."""
    assert main(["thermal", "--bearing", "6208", "--speed", "2073", "--radial-load", "21861"]) == 2
    err = capsys.readouterr().err
    assert "no thermal steady state at this operating point" in err and "thermal runaway" in err
    assert "temperature_c:" not in err and "Traceback" not in err
