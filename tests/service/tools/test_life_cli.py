"""`bearing-twin life`: its JSON keys, ISO 281 numbers, errors that name the field."""

import json
import subprocess
import sys

import pytest

KEYS = {
    "kappa",
    "a_iso",
    "l10_h",
    "l10m_h",
    "l10_contact_loads_h",
    "damage_fraction",
    "remaining_life_h",
    "dynamic_load_rating_n",
    "equivalent_load_n",
}


def _run(*args, timeout=600):
    return subprocess.run(
        [sys.executable, "-m", "service.cli", "life", *args], capture_output=True, text=True, timeout=timeout
    )


def _json(res):
    assert res.returncode == 0, res.stderr
    return json.loads(res.stdout, parse_constant=lambda c: pytest.fail(f"non-finite {c}"))


def test_life_json_keys_and_iso_numbers():
    """6208, 3000 N, 500 rad/s, 40 degC: C = 32.5 kN (SKF), P = Fr, L10 = (32.5/3)^3 10^6 rev =
    4438.1 h (ISO 281:2007 clause 5.3); kappa = 5.59, a_ISO from clause 9.3; the contact-load life
    from the quasi-static equilibrium within 10 % of L10 (zero clearance, pure radial load)."""
    out = _json(_run("--bearing", "6208", "--radial-load", "3000", "--speed", "500", "--json"))
    assert KEYS <= set(out)
    assert out["dynamic_load_rating_n"] == 32500.0 and out["equivalent_load_n"] == 3000.0
    assert out["l10_h"] == pytest.approx(4438.07, abs=0.05)
    assert out["kappa"] == pytest.approx(5.587, abs=0.01)
    assert out["l10m_h"] == pytest.approx(out["a_iso"] * out["l10_h"], rel=1e-12)
    assert out["l10_contact_loads_h"] / out["l10_h"] == pytest.approx(1.0, abs=0.10)
    assert out["damage_fraction"] == 0.0 and out["remaining_life_h"] == pytest.approx(out["l10m_h"])
    assert "quasi-static equilibrium" in out["contact_loads_from"]


def test_life_combined_load_and_table_output():
    """Fa = 1000 N on the 6208: P = 0.56 Fr + Y Fa = 3373 N (ISO 281 Table 3); the human table."""
    out = _json(_run("--bearing", "6208", "--radial-load", "3000", "--axial-load", "1000", "--speed", "500", "--json"))
    assert out["equivalent_load_n"] == pytest.approx(3373.4, abs=0.2)
    res = _run("--bearing", "6208", "--radial-load", "3000", "--speed", "500", "--oil-temperature", "70")
    assert res.returncode == 0, res.stderr
    assert "L10 = 4438 h" in res.stdout and "kappa" in res.stdout


def test_life_refuses_bad_input_by_name():
    res = _run("--bearing", "6208", "--radial-load", "-10", "--speed", "500")
    assert res.returncode == 2 and "radial_load_n" in res.stderr and "Traceback" not in res.stderr
    res = _run("--bearing", "6208", "--radial-load", "3000", "--speed", "3000")
    assert res.returncode == 2 and "shaft_speed_rad_s" in res.stderr and "Traceback" not in res.stderr
    res = _run("--bearing", "9999", "--radial-load", "3000", "--speed", "500")
    assert res.returncode == 2 and "designation" in res.stderr and "Traceback" not in res.stderr
