"""The `CWRU-DE` twin against the measured CWRU drive-end records (Case Western Reserve University
Bearing Data Center, engineering.case.edu/bearingdatacenter; 5 s excerpts in tests/data/cwru,
0 hp, 0.007 in EDM faults). Every fault record is a prediction: the only rig values calibrated
are the housing resonance and the sensor noise, on the healthy record 97 (twin.catalog).

Tolerances are the acceptance targets: healthy kurtosis in [2.5, 3.5]; inner race and outer
race at 6:00: the expected line (BPFI, BPFO) the largest envelope line within 1.5 % of the
published multiple, its height within 10 dB of the measured one, kurtosis within 40 %; every
fault: RMS relative to healthy within a factor 2 of the measured ratio; ball and outer race at
3:00 and 12:00: no line claimed more than 10 dB above what the record shows. Both sides go
through `twin.validation.cwru.analyse` over the same duration.
"""

import pytest

from twin.validation import cwru

pytestmark = [pytest.mark.slow,
              pytest.mark.xfail(reason="the twin's CWRU figures are not verified yet against these targets "
                                "(docs/validation.md: the twin's side of the table is to be run)", strict=False)]

DURATION_S = 1.0
BY_NUMBER = {r.number: r for r in cwru.RECORDS}


@pytest.fixture(scope="module")
def results():
    out = {}
    for rec in cwru.RECORDS:
        m, _ = cwru.measured(rec, DURATION_S)
        s, _ = cwru.simulated(rec, DURATION_S)
        out[rec.number] = (m, s)
    return out


def _ratio(results, number, side):
    return results[number][side].rms_g / results[97][side].rms_g


def test_healthy_kurtosis_is_near_gaussian(results):
    assert 2.5 <= results[97][1].kurtosis <= 3.5


@pytest.mark.parametrize("number", [105, 130])
def test_expected_line_is_the_largest_and_as_high_as_measured(results, number):
    m, s = results[number]
    rec = BY_NUMBER[number]
    shaft = rec.rpm / 60.0
    assert s.largest_line_name == rec.expected
    assert s.largest_line_hz / shaft == pytest.approx(cwru.PUBLISHED_MULTIPLES[rec.expected], rel=0.015)
    assert abs(s.expected_line_db - m.expected_line_db) <= 10.0
    assert s.kurtosis == pytest.approx(m.kurtosis, rel=0.4)


@pytest.mark.parametrize("number", [105, 118, 130, 144, 156])
def test_rms_relative_to_healthy_within_a_factor_two(results, number):
    measured = _ratio(results, number, 0)
    twin = _ratio(results, number, 1)
    assert 0.5 <= twin / measured <= 2.0


@pytest.mark.parametrize("number", [118, 144, 156])
def test_no_strong_line_where_the_record_has_none(results, number):
    m, s = results[number]
    assert s.expected_line_db <= m.expected_line_db + 10.0
