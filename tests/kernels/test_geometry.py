"""The vectorised raceway geometry equals the scalar torus-groove penetration (seed 000 Fig. 3)."""

import numpy as np
import pytest

from twin import catalog
from twin.kernels import layout as L
from twin.kernels.contacts import groove_penetration, raceway_geometry
from twin.model import make_model
from twin.state import make_state


def test_vector_geometry_matches_scalar():
    model = make_model(catalog.bearing("7208"))
    state = make_state(model)
    z = model.ball_count
    rows = state.lanes.reshape(L.N_ROWS, L.CW)
    rng = np.random.default_rng(3)
    az = rng.uniform(-np.pi, np.pi, 2 * z)
    rho = model.pitch_radius_m + rng.uniform(-30e-6, 30e-6, 2 * z)
    rows[L.K_PX, : 2 * z] = rho * np.cos(az)
    rows[L.K_PY, : 2 * z] = rho * np.sin(az)
    rows[L.K_PZ, : 2 * z] = rng.uniform(-30e-6, 30e-6, 2 * z)
    raceway_geometry(state.lanes, 2 * z)
    rb = model.ball_radius_m
    for c in range(2 * z):
        race = model.race_params[c % 2]
        delta, nx, ny, nz = groove_penetration(
            rows[L.K_PX, c],
            rows[L.K_PY, c],
            rows[L.K_PZ, c],
            race[L.R_GROOVE_CENTRE_RADIUS],
            race[L.R_GROOVE_CENTRE_Z],
            race[L.R_GROOVE_RADIUS],
            rb,
        )
        assert rows[L.G_DELTA, c] == pytest.approx(delta, abs=1e-15)
        assert rows[L.G_NX : L.G_NZ + 1, c] == pytest.approx([nx, ny, nz], abs=1e-12)
        # delta rounds differently in the two forms (1e-18 m), hence rel 1e-9 on the load
        assert rows[L.G_LOAD, c] == pytest.approx(race[L.R_STIFFNESS] * max(delta, 0) ** 1.5, rel=1e-9)
