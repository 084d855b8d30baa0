"""The snapshot captured as a frame (twin.snapshot_frame, twin.snapshot_blocks): the state
message written from the ball arrays is the text the pydantic tree serialises to, the tree holds
the lanes' values, and a value the contract forbids to be null is refused by name."""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest

from twin.engine import Twin
from twin.kernels import layout as L
from twin.snapshot import Snapshot
from twin.snapshot_blocks import (
    B_R,
    CONTACT_FIELDS,
    K_C,
    K_MU,
    K_R,
    ball_arrays,
    ball_json_items,
    ball_states,
    balls_json,
)
from twin.snapshot_frame import SnapshotFrame, as_snapshot


@pytest.fixture(scope="module")
def twin() -> Twin:
    tw = Twin("6208", bearing_id="frame")
    tw.advance(0.01)
    return tw


def test_frame_json_is_the_trees_json(twin):
    frame = twin.frame(0.5, late_fraction=0.25, status="note")
    assert isinstance(frame, SnapshotFrame)
    text = frame.to_json()
    assert text == frame.snapshot.to_json()  # the same text, byte for byte
    data = json.loads(text)
    assert data["late_fraction"] == 0.25 and data["status"] == "note" and data["real_time_factor"] == 0.5
    assert len(data["balls"]) == twin.model.ball_count
    assert frame.to_json() is text  # made once


def test_the_tree_holds_the_lanes_values(twin):
    frame = twin.frame()
    c = twin.state.contacts
    loaded = c[L.C_LOAD] > 0.0
    assert loaded.any() and not loaded.all()  # the 6208 under a radial load: a load zone
    for j, ball in enumerate(frame.balls):
        assert ball.index == j
        for k, contact in ((2 * j, ball.inner), (2 * j + 1, ball.outer)):
            assert contact.load_n == c[L.C_LOAD, k]
            if loaded[k]:
                assert contact.lambda_ == c[L.C_LAMBDA, k]
                assert contact.contact_angle_rad == math.asin(min(1.0, max(-1.0, c[L.G_NZ, k])))
                a, b = c[L.C_SEMI_MAJOR, k], c[L.C_SEMI_MINOR, k]
                assert contact.max_pressure_pa == 1.5 * c[L.C_LOAD, k] / (math.pi * a * b)
            else:  # no film, no friction, no kinematics without a load
                assert (contact.h_min_m, contact.lambda_, contact.regime) == (None, None, "no_contact")
                assert contact.mu == 0.0 and contact.slide_roll_ratio == 0.0


def test_centre_point_friction_publishes_the_lane_coefficient(twin):
    arrays = ball_arrays(twin.model, twin.state, twin.electrical(), effective_mu=False)
    c = twin.state.contacts
    loaded = c[L.C_LOAD] > 0.0
    np.testing.assert_array_equal(arrays.contacts[loaded, K_MU], c[L.C_MU, loaded])
    np.testing.assert_array_equal(arrays.contacts[~loaded, K_MU], 0.0)


def test_ball_messages_and_array_are_the_models_json(twin):
    arrays = ball_arrays(twin.model, twin.state, twin.electrical(), twin._effective_mu)
    tree = ball_states(arrays)
    assert ball_json_items(arrays) == [b.model_dump_json(by_alias=True) for b in tree]
    assert json.loads(balls_json(arrays)) == [b.model_dump(by_alias=True, mode="json") for b in tree]


def test_a_value_that_may_not_be_null_is_refused_by_name(twin):
    state = twin.state.copy()
    state.contacts[L.C_ENTRAINMENT, int(np.argmax(state.contacts[L.C_LOAD]))] = np.nan
    with pytest.raises(ValueError, match="entrainment_speed_m_s"):
        ball_arrays(twin.model, state, twin.electrical(), twin._effective_mu)


def test_a_ball_value_that_may_not_be_null_is_refused_by_ball_and_name(twin):
    state = twin.state.copy()
    state.cage_load_n[4, :] = np.inf
    with pytest.raises(ValueError, match=r"ball 4 cage_load_n = .*inf"):
        ball_arrays(twin.model, state, twin.electrical(), twin._effective_mu)


def test_an_open_circuit_is_null_and_a_closed_one_its_value(twin):
    """The contract: an infinite resistance (no conduction path) is published as null, never as
    a number; the capacitance beside it stays."""
    net = twin.electrical()
    r_contact = net.contact_resistance_ohm.copy()
    r_contact[3] = np.inf
    r_ball = net.ball_resistance_ohm.copy()
    r_ball[1] = np.inf
    open_net = dataclasses.replace(net, contact_resistance_ohm=r_contact, ball_resistance_ohm=r_ball)
    arrays = ball_arrays(twin.model, twin.state, open_net, twin._effective_mu)
    assert np.isnan(arrays.contacts[3, K_R]) and np.isnan(arrays.balls[1, B_R])
    assert arrays.contacts[3, K_C] == net.contact_capacitance_f[3]
    others = np.delete(np.arange(r_contact.size), 3)
    np.testing.assert_array_equal(
        arrays.contacts[others, K_R], np.where(np.isfinite(r_contact[others]), r_contact[others], np.nan)
    )
    tree = ball_states(arrays)
    assert tree[1].resistance_ohm is None and tree[1].outer.resistance_ohm is None
    assert tree[1].outer.capacitance_f == net.contact_capacitance_f[3]


def test_head_attributes_read_alike_and_as_snapshot(twin):
    frame = twin.frame()
    assert frame.time_s == twin.time_s and frame.bearing_id == "frame" and frame.seq == twin.seq
    assert frame.built is None  # nothing built until read
    snap = as_snapshot(frame)
    assert isinstance(snap, Snapshot) and frame.built is snap and as_snapshot(snap) is snap
    with pytest.raises(ValueError, match="no balls"):
        SnapshotFrame(snap, frame.ball_arrays)
    assert len(CONTACT_FIELDS) == frame.ball_arrays.contacts.shape[1]
