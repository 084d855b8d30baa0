"""`bearing-twin vibration`: its JSON keys, BPFO of an outer-race spall from the twin's
own signal, the figure, errors that name the field and the bearing's range."""

import json
import subprocess
import sys

import pytest

from twin import catalog
from twin.vibration.defect_frequencies import bearing_defect_frequencies

KEYS = {"sample_rate_hz", "defect_frequencies_hz", "envelope_peaks_hz", "kurtosis", "rms_m_s2", "velocity_rms_mm_s"}


def _run(*args, timeout=900):
    return subprocess.run(
        [sys.executable, "-m", "service.cli", "vibration", *args], capture_output=True, text=True, timeout=timeout
    )


def test_outer_spall_json_and_plot(tmp_path):
    """6208, 523 rad/s, 3000 N, a 0.5 mm outer-race spall, 0.3 s analysed (87 BPFO periods, 3.3 Hz
    bins): the JSON keys (KEYS), FTF / BPFO / BPFI / BSF from the geometry at the loaded contact
    angle (0 for the 6208 under a radial load, to 0.01 deg), the largest of the five envelope
    peaks within 1 % of BPFO; --plot writes a PNG."""
    png = tmp_path / "vib.png"
    res = _run(
        "--bearing",
        "6208",
        "--speed",
        "523",
        "--radial-load",
        "3000",
        "--defect",
        "outer",
        "--defect-size",
        "0.5e-3",
        "--duration",
        "0.3",
        "--json",
        "--plot",
        str(png),
    )
    assert res.returncode == 0, res.stderr
    out = json.loads(res.stdout, parse_constant=lambda c: pytest.fail(f"non-finite {c}"))
    assert KEYS <= set(out)
    assert out["sample_rate_hz"] == 51200.0
    assert {"ftf", "bpfo", "bpfi", "bsf"} <= set(out["defect_frequencies_hz"])
    assert abs(out["contact_angle_deg"]) < 0.01
    f = bearing_defect_frequencies(
        catalog.bearing("6208").geometry, out["shaft_speed_rad_s"], out["contact_angle_deg"] * 3.141592653589793 / 180.0
    )
    assert out["defect_frequencies_hz"]["bpfo"] == pytest.approx(f.bpfo_hz, rel=1e-12)
    peaks = out["envelope_peaks_hz"]
    assert len(peaks) == 5 and set(peaks[0]) == {"frequency_hz", "amplitude"}
    assert peaks[0]["frequency_hz"] == pytest.approx(f.bpfo_hz, rel=0.01)
    assert out["kurtosis"] > 3.5 and out["rms_m_s2"] > 0 and out["velocity_rms_mm_s"] > 0
    assert out["defect"]["kind"] == "outer" and out["status"] == "ok"
    assert png.stat().st_size > 20_000 and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_refuses_bad_input_by_name():
    res = _run(
        "--bearing",
        "6208",
        "--speed",
        "523",
        "--radial-load",
        "3000",
        "--defect",
        "outer",
        "--defect-size",
        "0.05",
        "--duration",
        "0.05",
    )
    assert res.returncode == 2 and "width_m" in res.stderr and "0.0255" in res.stderr
    assert "Traceback" not in res.stderr
    res = _run(
        "--bearing",
        "6208",
        "--speed",
        "523",
        "--radial-load",
        "3000",
        "--defect",
        "ball",
        "--defect-depth=-1e-5",
        "--duration",
        "0.05",
    )
    assert res.returncode == 2 and "depth_m" in res.stderr and "Traceback" not in res.stderr
    res = _run("--bearing", "6208", "--speed", "523", "--radial-load=-5", "--duration", "0.05")
    assert res.returncode == 2 and "radial_load_n" in res.stderr and "Traceback" not in res.stderr


def test_the_mounted_clearance_reaches_the_twin_and_bad_values_name_the_field():
    """`--clearance` replaces the spec's mounted diametral clearance (twin.spec.Mounting, range
    -50 .. 200 um); the CWRU rig's drive end with a 2 um preload instead of its CN 12.5 um: the
    JSON states the clearance it ran with, and a clearance out of range names the field and its
    bounds before any simulation."""
    res = _run("--bearing", "CWRU-DE", "--speed", "188.1", "--clearance", "-2e-6", "--duration", "0.1", "--json")
    assert res.returncode == 0, res.stderr
    out = json.loads(res.stdout)
    assert out["diametral_clearance_m"] == -2e-6 and out["status"] == "ok"
    bad = _run("--bearing", "CWRU-DE", "--speed", "188.1", "--clearance", "1e-3", "--json", timeout=120)
    assert bad.returncode == 2 and "Traceback" not in bad.stderr
    assert "mounting.diametral_clearance_m" in bad.stderr and "[-5e-05, 0.0002] m" in bad.stderr, bad.stderr


def test_a_preload_loads_every_ball_of_the_cwru_rig():
    """Seed 000 Appendix A (clearance and preload) / Harris and Kotzalas' load zone: at the CWRU
    rig's 1797 rpm under its rotor's 36.8 N (twin.catalog.default_radial_load_n), with the CN
    clearance (12.5 um) only the balls about the load line carry load; with a 2 um preload every
    ball does, the one opposite the load at least 1 N (the ring's shift under 36.8 N stays below
    the preload's interference)."""
    from twin.engine import Twin
    from twin.setpoint import Setpoint
    from twin.spec import Mounting

    def inner_loads_n(clearance_m: float) -> list[float]:
        spec = catalog.bearing("CWRU-DE")
        mounting = Mounting(diametral_clearance_m=clearance_m, rotor_mass_kg=spec.mounting.rotor_mass_kg)
        load = catalog.default_radial_load_n("CWRU-DE")
        assert load == 36.8
        twin = Twin(
            spec.model_copy(update={"mounting": mounting}),
            setpoint=Setpoint(shaft_speed_rad_s=188.1, radial_load_n=load),
        )
        twin.advance(0.01)
        return [ball.inner.load_n for ball in twin.snapshot().balls]

    assert sum(q > 0.0 for q in inner_loads_n(12.5e-6)) <= 4
    assert min(inner_loads_n(-2e-6)) >= 1.0
