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

import math

import numpy as np
import pytest

from twin.validation import cwru

pytestmark = pytest.mark.slow

# The targets the twin does not meet, each a strict xfail with its evidence (docs/validation.md, "Why
# the fault records are louder than the twin"): a 0.178 mm pit under the 26-37 N ball loads of the
# rotor's weight removes about 8 N of one ball's load for 0.1 ms; through the Sawalhi & Randall
# housing masses (7.6 kg) that rings at ~0.04 g, where the records show 1.5-3.5 g. The mass the
# ball force drives is not pinned by the healthy record (tests/vibration/test_cwru_ring_down.py).
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


@pytest.mark.parametrize(
    "number",
    [
        pytest.param(105, marks=SHORT),
        118,
        pytest.param(130, marks=SHORT),
        pytest.param(144, marks=SHORT),
        pytest.param(156, marks=SHORT),
    ],
)
def test_rms_relative_to_healthy_within_a_factor_two(results, number):
    measured = _ratio(results, number, 0)
    twin = _ratio(results, number, 1)
    assert 0.5 <= twin / measured <= 2.0


@pytest.mark.parametrize("number", [118, 144, 156])
def test_no_strong_line_where_the_record_has_none(results, number):
    m, s = results[number][:2]
    assert s.expected_line_db <= m.expected_line_db + 10.0


def _upper_bound_peak_g(spec, ball_load_n: float) -> float:
    """Peak sensor acceleration [g] of one ball passing CWRU's outer pit with the whole lost load
    (the slice model's lambda Q along the pass, twin.vibration.defects.pit_load_loss) taken off the
    outer ring: the housing's two masses (Sawalhi & Randall 2008 Part I sec. 3, the CWRU-DE values)
    integrated by scipy.signal.lsim at 2 MHz, independently of the engine."""
    from scipy import signal

    from twin.kernels import layout as L
    from twin.model import make_model
    from twin.vibration.defects import pit_load_loss

    model, h, g = make_model(spec), spec.housing, spec.geometry
    k = model.race_params[1, L.R_STIFFNESS]
    delta = (ball_load_n / k) ** (2.0 / 3.0)
    a = model.race_params[1, L.R_SEMI_MAJOR_COEF] * k ** (1.0 / 3.0) * math.sqrt(delta)
    speed = cwru.PUBLISHED_MULTIPLES["FTF"] * 1797.0 * math.pi / 30.0 * g.outer_raceway_radius_m
    t = np.arange(0.0, 0.004, 5e-7)
    lost = np.array(
        [
            pit_load_loss(
                (ti - 5e-4) * speed,
                0.0,
                cwru.FAULT_WIDTH_M / 2,
                cwru.FAULT_WIDTH_M / 2,
                cwru.FAULT_DEPTH_M,
                0.0,
                model.race_params[1, L.R_RX],
                delta,
                a,
            )
            for ti in t
        ]
    )
    mp, kp, cp = h.pedestal_mass_kg, h.radial_stiffness_n_m, h.radial_damping_n_s_m
    mr, kr, cr = h.sprung_mass_kg, h.sprung_stiffness_n_m, h.sprung_damping_n_s_m
    sys_ = (
        np.array(
            [
                [0, 1, 0, 0],
                [-(kp + kr) / mp, -(cp + cr) / mp, kr / mp, cr / mp],
                [0, 0, 0, 1],
                [kr / mr, cr / mr, -kr / mr, -cr / mr],
            ]
        ),
        np.array([[0.0], [1.0 / mp], [0.0], [0.0]]),
        np.array([[kr / mr, cr / mr, -kr / mr, -cr / mr]]),
        np.zeros((1, 1)),
    )
    _, y, _ = signal.lsim(sys_, -lost * ball_load_n, t)
    return float(np.abs(y).max() / cwru.G_M_S2)


def test_outer_pit_response_is_bounded_by_the_whole_lost_load():
    """Independent check of the defect-to-sensor path at 6:00 (record 130's case): the twin alone
    (no floor, no profile) peaks between 0.3 and 1 x the upper bound of `_upper_bound_peak_g` at
    the loaded balls' 26-37 N (0.066 g; the twin 0.037 g: the ball, between two contacts, passes on
    about half of the lost load). Record 130 peaks at 3.5 g: the gap of docs/validation.md is in
    the excitation, not in the engine's dynamics."""
    from twin import catalog
    from twin.spec import BearingSpec
    from twin.validation.vibration_simulation import simulate_vibration

    data = catalog.bearing("CWRU-DE").model_dump()
    data["surface_profile"]["enabled"] = False
    data["housing"]["accelerometer"]["noise_density_m_s2_rthz"] = 0.0
    spec = BearingSpec.model_validate(data)
    bound = max(_upper_bound_peak_g(spec, q) for q in (26.0, 37.0))
    _, x = simulate_vibration(
        spec,
        1797.0 * math.pi / 30.0,
        None,
        defect="outer",
        defect_size_m=cwru.FAULT_WIDTH_M,
        defect_length_m=cwru.FAULT_WIDTH_M,
        defect_depth_m=cwru.FAULT_DEPTH_M,
        duration_s=0.3,
        window_s=0.3,
    )
    peak = float(np.abs(x).max() / cwru.G_M_S2)
    assert 0.3 * bound <= peak <= bound
    _, measured = cwru.measured(BY_NUMBER[130], 1.0)
    assert np.abs(measured).max() / cwru.G_M_S2 > 30.0 * bound  # the gap: 30-50 x the bound
