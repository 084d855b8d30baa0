"""The vibration the twin itself produces: outer ring on the housing, local defects in
the contact geometry, the accelerometer sampled in the kernel, the indicators of each window.

Every run is one engine window (the snapshot's `vibration` block, twin.accelerometer) of a twin
started at its quasi-static equilibrium: the Sawalhi & Randall 2008 housing (twin.vibration.housing
defaults), 51.2 kHz, and a background of NOISE m/s^2/sqrt(Hz) (1 mg/sqrt(Hz): about ten times a
general-purpose ICP accelerometer's own noise, standing for the machine's background vibration,
which a real healthy bearing's signal is dominated by; noiseless, the model's healthy signal is
deterministic: README, Vibration). Defects are pits WIDTH wide along the rolling direction,
0.6 ball radius long across it (3.8 mm: a pit shorter across than the contact ellipse is bridged
by the conforming groove), 50 um deep, sharp edges.

The 6208 runs at SPEED = 523 rad/s under 3000 N: a 0.5 s window holds 148 BPFO, 226 BPFI, 191
2 x BSF and 16 FTF periods (bins of 2 Hz: 0.7 % of BPFO). At 523 rad/s the rotor's radial mode
(seed 000's 0.5 kg inner ring on the ball contacts, ~3.1 kHz, ~0.5 % damping) lies between two
BPFO harmonics; at 500 rad/s the 11th harmonic sits on it and a spall drives it resonantly, which
flattens the broadband kurtosis (README, Vibration limits).

Frequencies come from the geometry (twin.vibration.defect_frequencies with the window's mean
shaft speed and loaded contact angle), never typed in. A line is "present" when its envelope
amplitude exceeds SIGNIFICANCE (4) x the envelope noise floor (median), the criterion of
twin.vibration.indicators (1.5e-5 false alarms per bin for Gaussian noise).
"""

import math

import numpy as np
import pytest
from pydantic import ValidationError

from twin import catalog
from twin.engine import Twin
from twin.kernels import layout as L
from twin.kernels.step import step_n
from twin.setpoint import Setpoint
from twin.spec import BearingSpec, ModelOptions
from twin.vibration.defect_frequencies import bearing_defect_frequencies
from twin.vibration.indicators import SIGNIFICANCE

NOISE = 0.01  # m/s^2/sqrt(Hz)
SPEED = 523.0  # rad/s
WINDOW = 0.5  # s
WIDTH = 0.5e-3  # m


def _spec(designation="6208", *, noise=NOISE, window=WINDOW, enabled=True):
    data = catalog.bearing(designation).model_dump()
    data["housing"]["enabled"] = enabled
    data["housing"]["accelerometer"].update(noise_density_m_s2_rthz=noise, window_s=window, noise_seed=14)
    return BearingSpec.model_validate(data)


def _pit(kind, width=WIDTH, designation="6208"):
    rb = catalog.bearing(designation).geometry.ball_radius_m
    return {"kind": kind, "width_m": width, "length_m": 0.6 * rb, "depth_m": 50e-6}


def _window(defects=(), designation="6208", radial=3000.0, axial=0.0, window=WINDOW):
    """One engine window after the start: (twin, snapshot vibration block)."""
    twin = Twin(
        _spec(designation, window=window),
        setpoint=Setpoint(shaft_speed_rad_s=SPEED, radial_load_n=radial, axial_load_n=axial),
    )
    twin.set_defects(list(defects))
    twin.advance(window + 0.003)  # + the decimator's start-up (K - 1 outputs, ~1 ms)
    assert twin.status == "ok"
    v = twin.snapshot().vibration
    assert v is not None and v.window_s == pytest.approx(window)
    return twin, v


@pytest.fixture(scope="module")
def runs():
    """Lazily computed, shared windows: healthy, outer 0.25 / 0.5 mm, inner, ball."""
    cache = {}

    def get(name):
        if name not in cache:
            defects = {
                "healthy": (),
                "outer_small": (_pit("outer", 0.25e-3),),
                "outer": (_pit("outer"),),
                "inner": (_pit("inner"),),
                "ball": (_pit("ball"),),
            }[name]
            cache[name] = _window(defects)
        return cache[name]

    return get


def _floor(v):
    return v.envelope_noise_floor_m_s2


def _check_frequencies_from_geometry(twin, v):
    f = bearing_defect_frequencies(twin.model.spec.geometry, v.shaft_speed_rad_s, v.contact_angle_rad)
    got = v.defect_frequencies_hz
    for name, want in (("ftf", f.ftf_hz), ("bpfo", f.bpfo_hz), ("bpfi", f.bpfi_hz), ("bsf", f.bsf_hz)):
        assert getattr(got, name) == pytest.approx(want, rel=1e-12)
    assert v.shaft_speed_rad_s == pytest.approx(SPEED, rel=1e-9)


def test_outer_race_spall_envelope_peak_is_bpfo_with_harmonics(runs):
    """Outer-race spall at the centre of the load zone: the largest envelope peak within 1 % of BPFO
    (Randall & Antoni 2011 eq. 1), its 2nd and 3rd harmonics present."""
    twin, v = runs("outer")
    _check_frequencies_from_geometry(twin, v)
    bpfo = v.defect_frequencies_hz.bpfo
    assert v.envelope_peaks_hz[0].frequency_hz == pytest.approx(bpfo, rel=0.01)
    assert all(a > SIGNIFICANCE * _floor(v) for a in v.envelope_lines["bpfo"].harmonics)
    assert [p.frequency_hz / bpfo for p in v.envelope_peaks_hz[:3]] == pytest.approx([1.0, 2.0, 3.0], rel=0.01)
    assert twin.snapshot().defects[0].kind == "outer"


def test_outer_race_spall_full_spectra_of_the_window(runs):
    """The window's full spectra (VibrationState.envelope_spectrum / amplitude_spectrum, left out
    of the snapshot's JSON). Envelope: 0 Hz to the peak search's limit min(half the envelope band,
    5 x max(BPFI, 2 x BSF)) at 1 / window = 2 Hz; its largest bin within one bin of BPFO; at each
    of the five published peaks, the parabola through its own bin and the two beside it (vertex
    d = (a - c) / (2 (a - 2 b + c)) bins, height b - (a - c) d / 4) gives the published frequency and
    amplitude (rel 1e-9).
    Acceleration: 0 - fs/2 in at most 2000 power-summed bins; Parseval (Oppenheim & Schafer Table
    8.2, one-sided): sum A^2 / 2 = rms_m_s2^2 (rel 1e-9: the same samples, rounding only)."""
    twin, v = runs("outer")
    env, acc = v.envelope_spectrum, v.amplitude_spectrum
    assert "envelope_spectrum" not in v.model_dump() and "amplitude_spectrum" not in twin.snapshot().to_json()
    f = v.defect_frequencies_hz
    lo, hi = v.envelope_band_hz
    limit = min(0.5 * (hi - lo), 5.0 * max(f.bpfi, f.two_bsf))
    assert env.start_hz == 0.0 and env.step_hz == pytest.approx(1.0 / WINDOW, rel=1e-9)
    assert env.max_hz <= limit < env.max_hz + env.step_hz
    freqs, amp = env.frequencies_hz, np.array(env.amplitude_m_s2)
    assert abs(freqs[np.argmax(amp)] - f.bpfo) <= env.step_hz
    for peak in v.envelope_peaks_hz:
        i = int(np.rint((peak.frequency_hz - env.start_hz) / env.step_hz))
        i = max((i - 1, i, i + 1), key=lambda k: amp[k])  # the local maximum it was refined from
        a, b, c = amp[i - 1], amp[i], amp[i + 1]
        d = 0.5 * (a - c) / (a - 2.0 * b + c)
        got_f, got_a = freqs[i] + d * (freqs[1] - freqs[0]), b - 0.25 * (a - c) * d
        assert (got_f, got_a) == pytest.approx((peak.frequency_hz, peak.amplitude), rel=1e-9)
    fs = v.sample_rate_hz
    assert acc.start_hz == pytest.approx(0.5 * (acc.step_hz * WINDOW - 1.0) / WINDOW, rel=1e-9)
    assert (
        len(acc.amplitude_m_s2) <= 2000 and acc.max_hz - 0.5 * acc.step_hz < 0.5 * fs <= acc.max_hz + 0.5 * acc.step_hz
    )
    assert np.sum(np.square(acc.amplitude_m_s2)) / 2.0 == pytest.approx(v.rms_m_s2**2, rel=1e-9)


def test_inner_race_spall_bpfi_with_shaft_sidebands(runs):
    """Inner-race spall (turning with the shaft through the load zone): the largest envelope peak
    within 1 % of BPFI (eq. 2), sidebands at BPFI -+ the shaft frequency present (load-zone
    modulation, Randall & Antoni 2011 sec. 2.1)."""
    twin, v = runs("inner")
    _check_frequencies_from_geometry(twin, v)
    assert v.envelope_peaks_hz[0].frequency_hz == pytest.approx(v.defect_frequencies_hz.bpfi, rel=0.01)
    lower, upper = v.envelope_lines["bpfi"].sidebands
    assert lower > SIGNIFICANCE * _floor(v) and upper > SIGNIFICANCE * _floor(v)
    shaft = v.shaft_speed_rad_s / (2.0 * math.pi)
    peaks = [p.frequency_hz for p in v.envelope_peaks_hz]
    assert any(abs(f - (v.defect_frequencies_hz.bpfi - shaft)) < 0.01 * v.defect_frequencies_hz.bpfi for f in peaks)


def test_ball_defect_two_bsf_with_cage_sidebands(runs):
    """Ball defect (tracked by the ball's unit quaternion): it strikes the races alternately at
    2 x BSF (eq. 4), and the defective ball goes round the load zone with the cage, so the 2 x BSF
    line (within 1 %) comes with sidebands at -+ FTF of about its own size, and FTF harmonics appear
    in the envelope (Randall & Antoni 2011 sec. 2.1). Asserted: 2 x BSF and both sidebands present,
    the 2 x BSF line at least half the largest peak above 4 FTF, and every one of the five largest
    peaks above 4 FTF within 1 % of a harmonic of BSF up to 4 x BSF or their FTF sidebands, the
    2 x BSF line above the 1 x BSF one. The defect strikes the inner and the outer race once each per
    spin; the two strikes are not equal, so the pulse train also carries BSF itself (measured with the
    default, shear-heated inlet: 1 x BSF 2.2 m/s^2 against 3.2 at 2 x BSF; with seed 000's isothermal
    inlet the fifth peak is 4 x BSF, 2.4)."""
    twin, v = runs("ball")
    _check_frequencies_from_geometry(twin, v)
    f = v.defect_frequencies_hz
    family = [k * f.bsf + m * f.ftf for k in (1, 2, 4) for m in (-1, 0, 1)]
    above = [p for p in v.envelope_peaks_hz if p.frequency_hz > 4.0 * f.ftf]
    assert len(above) >= 3
    for p in above:  # every large peak above the cage modulation: BSF, 2 x BSF, 4 x BSF and their FTF sidebands
        assert min(abs(p.frequency_hz / x - 1.0) for x in family) < 0.01, p
    line = v.envelope_lines["two_bsf"].harmonics[0]
    assert line > SIGNIFICANCE * _floor(v) and line > 0.5 * above[0].amplitude
    bsf = [p.amplitude for p in above if abs(p.frequency_hz / f.bsf - 1.0) < 0.01]
    assert all(a < line for a in bsf)
    lower, upper = v.envelope_lines["two_bsf"].sidebands
    assert lower > SIGNIFICANCE * _floor(v) and upper > SIGNIFICANCE * _floor(v)
    q = twin.state.ball_orientation
    assert np.allclose(np.sum(q * q, axis=1), 1.0, atol=1e-12)
    assert not np.allclose(q[0], (1.0, 0.0, 0.0, 0.0))  # the defective ball's orientation was integrated


def test_healthy_bearing_is_gaussian_without_defect_lines(runs):
    """Healthy: kurtosis within 3 +- 0.5, and none of FTF, BPFO, BPFI, BSF, 2 x BSF, their 2nd
    and 3rd harmonics or sidebands above SIGNIFICANCE x the envelope noise floor."""
    twin, v = runs("healthy")
    assert twin.defects == ()
    assert v.kurtosis == pytest.approx(3.0, abs=0.5)
    assert v.band_kurtosis == pytest.approx(3.0, abs=0.5)
    amps = []
    for line in v.envelope_lines.values():
        amps += list(line.harmonics) + list(line.sidebands or ())
    assert max(amps) < SIGNIFICANCE * _floor(v)


def test_indicators_rise_with_spall_size(runs):
    """Outer spall 0 (healthy) -> 0.25 mm -> 0.5 mm wide: the kurtosis, the band kurtosis and the
    BPFO envelope amplitude rise strictly (impacts harder as the ball drops deeper; the drop at the
    spall centre is 1.0 um at 0.25 mm, 4.1 um at 0.5 mm)."""
    sizes = [runs(n)[1] for n in ("healthy", "outer_small", "outer")]
    for key in ("kurtosis", "band_kurtosis"):
        values = [getattr(v, key) for v in sizes]
        assert values[0] < values[1] < values[2], (key, values)
    env = [v.envelope_lines["bpfo"].harmonics[0] for v in sizes]
    assert env[0] < env[1] < env[2]
    assert env[1] > SIGNIFICANCE * _floor(sizes[1])


def test_angular_contact_frequencies_follow_the_loaded_contact_angle():
    """7208C (15 deg nominal, seed 004 geometry, conformity B = 0.14) under Fr = 1000 N, Fa = 6000 N:
    the loaded contact angle measured on the lanes is above 17 deg, and the outer-spall envelope
    peak sits on BPFO at that angle, not at the nominal one (they differ by ~0.45 %): within a
    quarter of their difference of the loaded BPFO (a 1 s window, 1 Hz bins)."""
    twin, v = _window((_pit("outer", designation="7208C"),), "7208C", radial=1000.0, axial=6000.0, window=1.0)
    g = twin.model.spec.geometry
    nominal = bearing_defect_frequencies(g, v.shaft_speed_rad_s)
    loaded = bearing_defect_frequencies(g, v.shaft_speed_rad_s, v.contact_angle_rad)
    assert math.degrees(v.contact_angle_rad) > g.nominal_contact_angle_deg + 2.0
    assert v.defect_frequencies_hz.bpfo == pytest.approx(loaded.bpfo_hz, rel=1e-12)
    gap = abs(loaded.bpfo_hz - nominal.bpfo_hz)
    assert gap > 0.003 * loaded.bpfo_hz
    peak = v.envelope_peaks_hz[0].frequency_hz
    assert abs(peak - loaded.bpfo_hz) < 0.25 * gap
    assert abs(peak - nominal.bpfo_hz) > 0.75 * gap


# ---- engine plumbing (short runs) ------------------------------------------------------------------
def test_housing_warm_start_and_snapped_step():
    """The warm start puts the housing at its static equilibrium under the load (x = Fr / k_p), the
    balls and inner ring with it (the bearing's own deflection as with the rigid ring); the step is
    1 / (R x 51.2 kHz), R an integer, at most the auto step; the housing stays at equilibrium."""
    twin = Twin(_spec(noise=0.0))
    rigid = Twin(_spec(noise=0.0, enabled=False))
    h = twin.model.spec.housing
    s = twin.snapshot()
    assert s.outer_ring_displacement_m[0] == pytest.approx(3000.0 / h.radial_stiffness_n_m, rel=1e-12)
    assert s.inner_ring_displacement_m == pytest.approx(rigid.snapshot().inner_ring_displacement_m, abs=1e-12)
    ratio = 1.0 / (twin.model.dt_s * h.accelerometer.sample_rate_hz)
    assert ratio == pytest.approx(round(ratio), abs=1e-9) and twin.model.decimator.ratio == round(ratio)
    assert twin.model.dt_s <= rigid.model.dt_s == rigid.model.time_step.auto_time_step_s
    twin.advance(0.01)
    assert twin.snapshot().outer_ring_displacement_m[0] == pytest.approx(3000.0 / h.radial_stiffness_n_m, rel=0.02)


def test_rigid_outer_ring_has_no_signal():
    twin = Twin(_spec(enabled=False))
    twin.advance(0.003)
    assert not twin.model.housing_on and twin.drain_waveform() == []
    s = twin.snapshot()
    assert s.vibration is None and s.outer_ring_displacement_m == (0.0, 0.0, 0.0)


def test_waveform_blocks_are_contiguous_float32():
    """drain_waveform: float32 samples at the accelerometer rate, the next block starting one
    sample period after the last one ended; the group delay is taken out (t0 < the time of the first
    filter input + the delay)."""
    twin = Twin(_spec(noise=0.0))
    fs = twin.model.sample_rate_hz
    twin.advance(0.01)
    first = twin.drain_waveform()
    twin.advance(0.01)
    second = twin.drain_waveform()
    assert len(first) == 1 and len(second) == 1
    a, b = first[0], second[0]
    assert a.samples.dtype == np.float32 and a.sample_rate_hz == fs
    assert b.t0_s == pytest.approx(a.t0_s + a.samples.size / fs, abs=1e-9)
    assert a.samples.size + b.samples.size == pytest.approx(0.02 * fs - (twin.model.decimator.ring - 1), abs=2)
    assert b.t0_s + b.samples.size / fs <= twin.time_s
    assert np.all(np.isfinite(a.samples)) and np.std(b.samples) > 0.0


def test_a_frozen_copys_snapshot_leaves_the_live_waveform_intact():
    """The service builds snapshots from `Twin.frozen()` copies in its publishing thread while the
    twin steps on (service.core.publishing). A copy's snapshot must not drain the live
    accelerometer reader with the copy's older sample ring: it once moved the reader's cursor back
    (samples read twice; a CI run published a waveform chunk at t0 = 0.0005 s right after one
    ending at 0.1695 s). Here the copy's snapshot runs after the live twin moved on and drained
    part of it (the race, made deterministic): the live samples are exactly those of the same run
    without the copy (noise off, so bit for bit), and the copy carries the window of its moment."""

    def run(with_copy: bool):
        twin = Twin(_spec(noise=0.0, window=0.05))
        twin.advance(0.06)
        (a,) = twin.drain_waveform()
        frozen = twin.frozen()
        twin.advance(0.053)  # ends between two drains of the reader (DRAIN_EVERY_S)
        snap = frozen.snapshot() if with_copy else None
        (b,) = twin.drain_waveform()
        return twin, frozen, snap, a, b

    twin, frozen, snap, a, b = run(True)
    _, _, _, a_ref, b_ref = run(False)
    fs = twin.model.sample_rate_hz
    assert b.t0_s == pytest.approx(a.t0_s + a.samples.size / fs, abs=1e-9)
    assert b.samples.size == b_ref.samples.size and np.array_equal(b.samples, b_ref.samples)
    assert snap.vibration is not None and snap.vibration.window_end_s <= frozen.time_s < twin.time_s
    assert frozen.drain_waveform() == []
    assert twin.snapshot().vibration.window_end_s > snap.vibration.window_end_s


def test_defects_set_and_cleared_without_recompiling():
    """set_defects / clear_defects while the twin runs: the kernel is not compiled again (same numba
    signatures), the snapshot lists the active defects, the contact lanes' drop row follows."""
    twin = Twin(_spec(noise=0.0))
    twin.advance(0.002)
    compiled = len(step_n.signatures)
    twin.set_defects([_pit("outer"), _pit("ball")])
    twin.advance(0.01)
    assert [d.kind for d in twin.snapshot().defects] == ["outer", "ball"]
    twin.clear_defects()
    twin.advance(0.002)
    assert twin.snapshot().defects == () and not twin.state.contacts[L.G_DEFECT_DROP].any()
    assert len(step_n.signatures) == compiled


@pytest.mark.parametrize(
    "defect, field, bound",
    [
        ({"kind": "outer", "width_m": 0.04, "length_m": 3e-3, "depth_m": 5e-5}, "width_m", "0.0255"),
        ({"kind": "inner", "width_m": 1e-3, "length_m": 3e-3, "depth_m": -5e-5}, "depth_m", "greater than 0"),
        ({"kind": "ball", "width_m": 1e-3, "length_m": 3e-3, "depth_m": 5e-5, "ball_index": 9}, "ball_index", "[0, 8]"),
        ({"kind": "ball", "width_m": 7e-3, "length_m": 3e-3, "depth_m": 5e-5}, "width_m", "0.0063"),
    ],
)
def test_bad_defects_name_the_field_and_the_bearings_range(defect, field, bound):
    twin = Twin(_spec(noise=0.0, enabled=False))
    with pytest.raises(ValidationError) as info:
        twin.set_defects([defect])
    text = str(info.value)
    assert field in text and bound in text
    assert twin.defects == ()
    with pytest.raises(ValueError, match="at most 8"):
        twin.set_defects([_pit("outer")] * 9)


def test_explicit_step_is_snapped_too():
    twin = Twin(_spec(noise=0.0), options=ModelOptions(time_step_s=1e-6))
    assert twin.model.dt_s == pytest.approx(1.0 / (20 * 51200.0), rel=1e-12)
