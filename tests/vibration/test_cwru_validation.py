"""The `CWRU-DE` twin against the measured CWRU drive-end records (Case Western Reserve University
Bearing Data Center, engineering.case.edu/bearingdatacenter; 5 s excerpts in tests/data/cwru,
0 hp, 0.007 in EDM faults). Every fault record is a prediction: the only rig values calibrated
are the housing resonance, the sensor floor and the bound on the race profile, on the healthy
record 97 (twin.catalog).

Tolerances are the acceptance targets: healthy kurtosis in [2.5, 3.5]; inner race and outer
race at 6:00: the expected line (BPFI, BPFO) the largest envelope line within 1.5 % of the
published multiple, its height within 10 dB of the measured one, kurtosis within 40 %; every
fault: RMS relative to healthy within a factor 2 of the measured ratio; ball and outer race at
3:00 and 12:00: no line claimed more than 10 dB above what the record shows. Both sides go
through `twin.validation.cwru.analyse` over the same duration.
"""

import numpy as np
import pytest

from twin.validation import cwru

pytestmark = pytest.mark.slow

# The targets the twin does not meet, each a strict xfail with its evidence (docs/validation.md, "Why
# the fault records are louder than the twin"): a 0.178 mm pit under the 26-37 N ball loads of the
# rotor's weight removes 5-10 N of one ball's load for 0.1 ms; through the housing path whose
# healthy lines near 3.2 kHz match record 97's, that rings at ~0.04 g, where the records show 1.5-3.5 g.
SHORT = pytest.mark.xfail(strict=True, reason="fault excitation 30-100 x below the records' (docs/validation.md)")

DURATION_S = 1.0
BY_NUMBER = {r.number: r for r in cwru.RECORDS}


@pytest.fixture(scope="module")
def results():
    out = {}
    for rec in cwru.RECORDS:
        m, xm = cwru.measured(rec, DURATION_S)
        s, xs = cwru.simulated(rec, DURATION_S)
        out[rec.number] = (m, s, xm, xs)
    return out


def _largest_line_g(x, band_hz=(3000.0, 3500.0)):
    """Largest line [g] of the Hann-windowed amplitude spectrum in the band."""
    n = len(x)
    amp = np.abs(np.fft.rfft(x * np.hanning(n))) / n * 4.0 / cwru.G_M_S2
    f = np.fft.rfftfreq(n, 1.0 / cwru.SAMPLE_RATE_HZ)
    return float(amp[(f >= band_hz[0]) & (f < band_hz[1])].max())


def test_healthy_lines_at_the_resonance_are_as_high_as_measured(results):
    """The healthy bearing's ball-pass lines at the 3.2 kHz housing resonance (record 97: 4.0e-3 g at
    3205 Hz; the twin: 3.3e-3 g) agree within a factor 2: the housing path carries the bearing's
    own forces at the measured gain (its resonance and damping are calibrated on record 97, its
    masses are Sawalhi & Randall's), so the fault levels below are the excitation's, not the path's."""
    _, _, xm, xs = results[97]
    assert 0.5 <= _largest_line_g(xs) / _largest_line_g(xm) <= 2.0


def _ratio(results, number, side):
    return results[number][side].rms_g / results[97][side].rms_g


def test_healthy_kurtosis_is_near_gaussian(results):
    assert 2.5 <= results[97][1].kurtosis <= 3.5


@pytest.mark.parametrize("number", [pytest.param(105, marks=SHORT), pytest.param(130, marks=SHORT)])
def test_expected_line_is_the_largest_and_as_high_as_measured(results, number):
    m, s = results[number][:2]
    rec = BY_NUMBER[number]
    shaft = rec.rpm / 60.0
    assert s.largest_line_name == rec.expected
    assert s.largest_line_hz / shaft == pytest.approx(cwru.PUBLISHED_MULTIPLES[rec.expected], rel=0.015)
    assert abs(s.expected_line_db - m.expected_line_db) <= 10.0
    assert s.kurtosis == pytest.approx(m.kurtosis, rel=0.4)


@pytest.mark.parametrize("number", [pytest.param(105, marks=SHORT), 118, pytest.param(130, marks=SHORT),
                                    pytest.param(144, marks=SHORT), pytest.param(156, marks=SHORT)])
def test_rms_relative_to_healthy_within_a_factor_two(results, number):
    measured = _ratio(results, number, 0)
    twin = _ratio(results, number, 1)
    assert 0.5 <= twin / measured <= 2.0


@pytest.mark.parametrize("number", [118, 144, 156])
def test_no_strong_line_where_the_record_has_none(results, number):
    m, s = results[number][:2]
    assert s.expected_line_db <= m.expected_line_db + 10.0
