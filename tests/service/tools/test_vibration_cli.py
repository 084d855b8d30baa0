"""`bearing-twin vibration`: the issue's JSON keys, BPFO of an outer-race spall from the twin's
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
    bins): the JSON keys of issue 14, FTF / BPFO / BPFI / BSF from the geometry at the loaded contact
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
