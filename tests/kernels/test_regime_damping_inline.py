"""raceway_forces inlines seed 000 Table 2's C_n(Lambda) branch-free (so the lane loop vectorises);
this pins the inline copy to the law twin.physics.damping.regime_damping_n_s_m."""

import numpy as np
import pytest

from twin.kernels import layout as L
from twin.kernels.contacts import raceway_forces
from twin.physics.damping import regime_damping_n_s_m

CASES = [(lam, c_fluid) for lam in (0.0, 0.5, 1.0, 1.0001, 2.0, 3.0, 3.0001, 5.0) for c_fluid in (0.0, 40.0, 400.0)]


def test_inline_table2_damping_equals_the_law():
    # seed 000 Table 2 / eqs. 4-5: boundary C_hyst, mixed series C_hyst C_fluid / (C_hyst + C_fluid),
    # full film C_fluid; a contact closing at 0.01 m/s along its normal (x), no tangential motion
    alpha_e, q_el, rate = 0.08, 500.0, 0.01
    nc = len(CASES)
    w = np.zeros(L.N_ROWS * L.CW)
    for c, (lam, c_fluid) in enumerate(CASES):
        w[L.G_DELTA * L.CW + c] = 1e-6
        w[L.G_NX * L.CW + c] = 1.0
        w[L.G_LOAD * L.CW + c] = q_el
        w[L.K_VX * L.CW + c] = rate
        w[L.C_LAMBDA * L.CW + c] = lam
        w[L.C_FLUID_DAMPING * L.CW + c] = c_fluid
    raceway_forces(w, nc, 6.35e-3, 1e-6, 0.0, alpha_e)
    for c, (lam, c_fluid) in enumerate(CASES):
        c_n = regime_damping_n_s_m(lam, 1.5 * alpha_e * q_el, c_fluid)
        fn = max(q_el + c_n * rate, 0.0)
        assert abs(w[L.O_FX * L.CW + c]) == pytest.approx(fn, rel=1e-12), (lam, c_fluid)
