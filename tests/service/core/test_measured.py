"""service.core.measured without a service: the binary frame round trip, the twin's prediction
from its vibration window, and the alarms against it. Window: 1 s of CWRU record 105 (inner race
0.007 in, 0 hp; tests/data/cwru, Case Western Reserve University Bearing Data Center)."""

import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from service.core.errors import InputError
from service.core.measured import (
    HEADER,
    MeasuredComparator,
    encode_frame,
    window_from_float32,
    window_from_frame,
    window_from_json,
)
from twin import catalog

DATA = Path(__file__).resolve().parents[2] / "data" / "cwru"
WINDOW_G = np.load(DATA / "105_DE_5s.npy")[:12000]
SHAFT_RAD_S = 1797.0 * 2.0 * math.pi / 60.0


def _snapshot(vibration=None):
    return SimpleNamespace(shaft_speed_rad_s=SHAFT_RAD_S, time_s=1.5, seq=42, vibration=vibration)


def _vibration(kurtosis: float, bpfi_over_floor: float):
    lines = {k: SimpleNamespace(harmonics=(1.0, 0.5, 0.2)) for k in ("bpfo", "two_bsf")}
    lines["bpfi"] = SimpleNamespace(harmonics=(bpfi_over_floor, 1.0, 1.0))
    return SimpleNamespace(
        envelope_noise_floor_m_s2=1.0, envelope_lines=lines, rms_m_s2=2.0, kurtosis=kurtosis, crest_factor=5.0
    )


def test_frame_round_trip():
    """encode_frame / window_from_frame: a 32-byte header, the samples to float32 precision, g to
    m/s2 by 9.80665, shaft 0 -> the twin's."""
    frame = encode_frame(WINDOW_G, 12000.0, "g")
    assert HEADER.size == 32 and len(frame) == 32 + 4 * WINDOW_G.size
    w = window_from_frame(frame)
    assert w.sample_rate_hz == 12000.0 and w.units == "g" and w.shaft_hz is None
    assert np.allclose(w.samples_m_s2, WINDOW_G.astype(np.float32) * 9.80665, rtol=1e-7)
    with pytest.raises(InputError) as err:
        window_from_frame(b"XXXX" + frame[4:])
    assert err.value.errors[0].field == "header"


@pytest.mark.parametrize(
    "make, field",
    [
        (lambda: window_from_json({"sample_rate_hz": 12000.0, "samples": [0.0] * 2000, "speed": 1}), "speed"),
        (lambda: window_from_json({"samples": [0.0] * 2000}), "sample_rate_hz"),
        (lambda: window_from_json({"sample_rate_hz": 12000.0, "samples": ["a"] * 2000}), "samples"),
        (lambda: window_from_float32(b"\0" * 4098, 12000.0), "samples"),
        (lambda: window_from_float32(b"\0" * 8192, float("nan")), "sample_rate_hz"),
        # a JSON list or object for the units (unhashable: once a 500), text and true for numbers
        (lambda: window_from_json({"sample_rate_hz": 12000.0, "units": ["g"], "samples": [0.0] * 2000}), "units"),
        (lambda: window_from_json({"sample_rate_hz": 12000.0, "units": {}, "samples": [0.0] * 2000}), "units"),
        (lambda: window_from_json({"sample_rate_hz": "12000", "samples": [0.0] * 2000}), "sample_rate_hz"),
        (lambda: window_from_json({"sample_rate_hz": True, "samples": [0.0] * 2000}), "sample_rate_hz"),
        (lambda: window_from_json({"sample_rate_hz": 12000.0, "samples": [0.0] * 2000, "shaft_hz": "30"}), "shaft_hz"),
        (lambda: window_from_json({"sample_rate_hz": 12000.0, "samples": [0.0] * 2000, "shaft_hz": True}), "shaft_hz"),
        (lambda: window_from_float32(b"\0" * 8192, 12000.0, shaft_hz=True), "shaft_hz"),
    ],
)
def test_bad_windows_name_the_field(make, field):
    with pytest.raises(InputError) as err:
        make()
    assert err.value.status_code == 422 and err.value.errors[0].field == field


def test_a_window_beyond_any_accelerometer_is_refused_naming_samples():
    """Finite samples of 1e160 m/s2 (a corrupt record, or wrong units) would overflow the
    statistics into null indicators; the analysis refuses samples beyond 1e6 m/s2 (about 1e5 g,
    twin.vibration.analysis.MAX_ABS_SIGNAL_M_S2) with a 422 on `samples` naming the range."""
    comparator = MeasuredComparator("b", catalog.bearing("CWRU-DE").geometry)
    window = window_from_json(
        {"sample_rate_hz": 12000.0, "units": "g", "samples": (WINDOW_G.astype(float) * 1e160).tolist()}
    )
    with pytest.raises(InputError) as err:
        comparator.compare(window, _snapshot(), ())
    assert err.value.status_code == 422 and err.value.errors[0].field == "samples"
    assert "allowed [-1e+06, 1e+06] m/s2" in err.value.errors[0].message


def test_twin_with_matching_defect_and_vibration_window_explains_the_measurement():
    """A twin with the inner-race defect whose own window has kurtosis 5 (measured 5.6): no alarm;
    the residual is measured - predicted; the twin's BPFI height is 20 log10(line / floor)."""
    c = MeasuredComparator("t", catalog.bearing("6205").geometry)
    w = window_from_float32(WINDOW_G.astype("<f4").tobytes(), 12000.0, "g")
    out = c.compare(w, _snapshot(_vibration(5.0, 100.0)), ({"kind": "inner"},))
    assert out["alarm"] is False
    assert out["predicted"]["line_height_db"]["BPFI"] == pytest.approx(40.0)
    assert out["residual"]["kurtosis"] == pytest.approx(out["measured"]["kurtosis"] - 5.0)
    assert out["twin_seq"] == 42 and out["twin_time_s"] == 1.5


def test_kurtosis_well_above_the_twins_raises_its_alarm():
    """The same twin whose window reads a Gaussian-like kurtosis 3.1: `kurtosis_above_twin` (margin
    1.5), and no line alarm (the inner defect explains BPFI)."""
    c = MeasuredComparator("t", catalog.bearing("6205").geometry)
    w = window_from_float32(WINDOW_G.astype("<f4").tobytes(), 12000.0, "g")
    out = c.compare(w, _snapshot(_vibration(3.1, 100.0)), ({"kind": "inner"},))
    assert [a["code"] for a in out["alarms"]] == ["kurtosis_above_twin"]


def test_a_rate_too_low_for_the_twins_shaft_names_the_rate():
    """A window sampled at 500 Hz beside a twin turning at 1797 rpm (30 Hz, more than fs / 20): the
    refusal names `sample_rate_hz` and the least rate, not a `shaft_hz` the window did not give."""
    comparator = MeasuredComparator("b", catalog.bearing("CWRU-DE").geometry)
    window = window_from_json({"sample_rate_hz": 500.0, "samples": [0.0] * 2000})
    with pytest.raises(InputError) as err:
        comparator.compare(window, _snapshot(), ())
    e = err.value.errors[0]
    assert e.field == "sample_rate_hz" and "at least 599 Hz" in e.message, e


def test_standing_twin_needs_a_shaft_frequency():
    c = MeasuredComparator("t", catalog.bearing("6205").geometry)
    w = window_from_float32(WINDOW_G.astype("<f4").tobytes(), 12000.0, "g")
    with pytest.raises(InputError) as err:
        c.compare(w, SimpleNamespace(shaft_speed_rad_s=0.0, time_s=0.0, seq=0, vibration=None), ())
    assert err.value.errors[0].field == "shaft_hz"
