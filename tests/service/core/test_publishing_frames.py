"""The publisher hands frames (twin.snapshot_frame.SnapshotFrame) to the sinks that take them
and snapshots to the others; the alarm inputs and the recording rows read from a frame's arrays
are those read from its pydantic tree."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from service.core.alarm_inputs import inputs_from_snapshot
from service.core.publishing import Publisher
from service.recording.columns import ball_count, extract
from service.settings import AlarmSettings
from twin.engine import Twin
from twin.snapshot import Snapshot
from twin.snapshot_frame import SnapshotFrame


class Sink:
    def __init__(self, frames: bool):
        self.accepts_frames = frames
        self.got: list = []
        self.dropped = 0

    def publish(self, item) -> None:
        self.got.append(item)


@pytest.fixture(scope="module")
def twin() -> Twin:
    tw = Twin("6208", bearing_id="pub")
    tw.advance(0.01)
    return tw


def test_frames_to_the_sinks_that_take_them_snapshots_to_the_others(twin):
    framed, plain = Sink(True), Sink(False)
    pub = Publisher("pub", [framed, plain])
    pub.capture(twin, 1.0, 0.0)  # no worker: built and delivered here
    (frame,), (snap,) = framed.got, plain.got
    assert isinstance(frame, SnapshotFrame) and isinstance(snap, Snapshot)
    assert frame.built is snap  # one tree, built for the sink that wanted it
    assert pub.latest is snap and pub.latest_json() == frame.to_json().encode()


def test_the_latest_tree_is_built_on_read(twin):
    framed = Sink(True)
    pub = Publisher("pub", [framed])
    pub.capture(twin, 1.0)
    (frame,) = framed.got
    assert frame.built is None  # no sink asked for the tree
    assert pub.latest is frame.built and pub.latest is not None


def test_alarm_inputs_from_a_frame_are_those_from_its_tree(twin):
    frame = twin.frame()
    settings = AlarmSettings()
    a, b = inputs_from_snapshot(frame, settings), inputs_from_snapshot(frame.snapshot, settings)
    assert a == b and a.min_loaded_lambda is not None  # the 6208's loaded zone has a film
    assert inputs_from_snapshot(frame.snapshot.to_dict(), settings) == b  # the dict of a message too


def test_recording_rows_from_a_frame_are_those_from_its_tree(twin):
    frame = twin.frame()
    a = extract(frame)
    assert frame.built is None  # read from the arrays
    b = extract(frame.snapshot)
    assert ball_count(frame) == ball_count(frame.snapshot) == twin.model.ball_count
    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(x, np.ndarray):
            np.testing.assert_array_equal(x, y)  # NaN where null, on both
        else:
            assert x == y, f.name
