"""The vectorised raceway geometry equals the scalar torus-groove penetration (seed 000 Fig. 3)."""

import numpy as np
import pytest

from twin import catalog
from twin.kernels import layout as L
from twin.kernels.contacts import groove_penetration, raceway_geometry
from twin.model import make_model


def test_vector_geometry_matches_scalar():
    model = make_model(catalog.bearing("7208"))
    z = model.ball_count
    rng = np.random.default_rng(3)
    rel = np.empty((3, 2 * z))
    az = rng.uniform(-np.pi, np.pi, 2 * z)
    rho = model.pitch_radius_m + rng.uniform(-30e-6, 30e-6, 2 * z)
    rel[0], rel[1], rel[2] = rho * np.cos(az), rho * np.sin(az), rng.uniform(-30e-6, 30e-6, 2 * z)
    geo = np.empty((6, 2 * z))
    raceway_geometry(rel, model.contact_groove, geo)
    rb = model.ball_radius_m
    for c in range(2 * z):
        r = c % 2
        race = model.race_params[r]
        delta, nx, ny, nz = groove_penetration(*rel[:, c], race[L.R_GROOVE_CENTRE_RADIUS],
                                               race[L.R_GROOVE_CENTRE_Z], race[L.R_GROOVE_RADIUS], rb)
        assert geo[0, c] == pytest.approx(delta, abs=1e-15)
        assert geo[1:4, c] == pytest.approx([nx, ny, nz], abs=1e-12)
        assert geo[5, c] == pytest.approx(race[L.R_STIFFNESS] * max(delta, 0) ** 1.5, rel=1e-9)  # delta rounds differently (1e-18 m)
