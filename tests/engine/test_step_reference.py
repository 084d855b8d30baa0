"""The optimised step reproduces the reference step kept in twin.validation.step_reference.

tests/engine/data/step_reference.json holds the outputs of the reference engine, the step written
law by law without reciprocals, series or fused passes (commit 5454e19:
`python -m twin.validation.step_reference` on that tree): window means over
10 ms after 10 ms from the warm start of every contact's load and Lambda, the friction torque,
the cage speed and the ring displacement, for the default twin (6208, 3000 N, 500 rad/s) at the
auto step and at 1 us, the 7208 under Fr = Fa = 3000 N and the 6208 at 1700 rad/s and 7500 N.
The optimisations change operations (reciprocals, series, fused passes), not the model, so the
outputs agree to rounding: measured within 2e-10 of the largest load and 5e-11 in Lambda after
20 ms (the trajectory's own sensitivity amplifies the last-bit differences). The tolerances
below (1e-6 of the largest load, of the largest Lambda and of the ring displacement, 1e-6 in cage
speed, 1e-5 in torque) are four orders above that and far below any model change (a changed sub-rate or
law moves these figures by 1e-4 or more).
"""

import json
from pathlib import Path

import numpy as np
import pytest

from twin.validation.step_reference import CASES, reference_outputs

REFERENCE = json.loads((Path(__file__).parent / "data" / "step_reference.json").read_text())


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_step_reproduces_reference(case):
    ref = REFERENCE[case[0]]
    out = reference_outputs(case)
    assert out["status"] == ref["status"] == "ok"
    assert out["time_step_s"] == pytest.approx(ref["time_step_s"], rel=1e-15)
    load, load_ref = np.array(out["load_n"]), np.array(ref["load_n"])
    assert np.abs(load - load_ref).max() <= 1e-6 * load_ref.max()
    lam, lam_ref = np.array(out["lambda"]), np.array(ref["lambda"])
    assert np.abs(lam - lam_ref).max() <= 1e-6 * np.abs(lam_ref).max()
    assert out["torque_n_m"] == pytest.approx(ref["torque_n_m"], rel=1e-5)
    assert out["cage_speed_rad_s"] == pytest.approx(ref["cage_speed_rad_s"], rel=1e-6)
    ring, ring_ref = np.array(out["ring_displacement_m"]), np.array(ref["ring_displacement_m"])
    assert np.abs(ring - ring_ref).max() <= 1e-6 * np.abs(ring_ref).max()
