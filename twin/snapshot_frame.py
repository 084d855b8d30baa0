"""`SnapshotFrame`: one published state of a twin, captured as numbers and turned into the
pydantic `Snapshot` only when someone reads it.

A frame holds the snapshot's `head` (a `Snapshot` whose `balls` are empty: the bearing-level
blocks, a few validated models) and its balls as arrays (twin.snapshot_blocks.BallArrays). The
two costs of a snapshot that grow with the balls (a pydantic model per ball and per contact, and
their validation) are paid only by the consumers that want the tree (`snapshot`: HTTP reads,
OPC UA, a sink that takes snapshots), at their own rate. The state message (`to_json`) is the
head's JSON with the balls' JSON written from the arrays in its place, the same text
`Snapshot.to_json` gives, made once per frame whoever asks for it first.

Every other attribute of a snapshot is read from the head (`frame.time_s`, `frame.vibration`),
so a consumer written for a `Snapshot` reads a frame alike; `balls` builds the tree.
"""

from __future__ import annotations

import threading
from typing import Any

from twin.snapshot import Snapshot
from twin.snapshot_blocks import BallArrays, ball_states, balls_json

_EMPTY_BALLS = '"balls":[]'


class SnapshotFrame:
    """One published state: `head` (a Snapshot without balls) and `ball_arrays` (see the module
    docstring). Immutable; safe to read from any thread (the tree and the JSON are made at most
    once)."""

    __slots__ = ("_json", "_lock", "_snapshot", "ball_arrays", "head")

    def __init__(self, head: Snapshot, ball_arrays: BallArrays):
        if head.balls:
            raise ValueError("a frame's head carries no balls: they are its ball_arrays")
        self.head = head
        self.ball_arrays = ball_arrays
        self._snapshot: Snapshot | None = None
        self._json: str | None = None
        self._lock = threading.Lock()

    def __getattr__(self, name: str) -> Any:
        if name.startswith("_"):
            raise AttributeError(name)
        return getattr(self.head, name)

    def __repr__(self) -> str:
        h = self.head
        return f"SnapshotFrame(bearing_id={h.bearing_id!r}, seq={h.seq}, time_s={h.time_s!r})"

    @property
    def snapshot(self) -> Snapshot:
        """The pydantic `Snapshot` (built on the first read, then the same object)."""
        snap = self._snapshot
        if snap is None:
            with self._lock:
                snap = self._snapshot
                if snap is None:
                    snap = self._snapshot = self.head.model_copy(update={"balls": ball_states(self.ball_arrays)})
        return snap

    @property
    def built(self) -> Snapshot | None:
        """The tree if a reader built it already, else None (builds nothing)."""
        return self._snapshot

    @property
    def balls(self) -> tuple:
        """The balls' tree (`Snapshot.balls`)."""
        return self.snapshot.balls

    def to_json(self) -> str:
        """The state message: `Snapshot.to_json` of this state (made on the first call)."""
        text = self._json
        if text is None:
            head = self.head.to_json()
            text = self._json = head.replace(_EMPTY_BALLS, '"balls":' + balls_json(self.ball_arrays), 1)
        return text

    def to_dict(self) -> dict:
        """Plain dict with the contract's field names (`Snapshot.to_dict`)."""
        return self.snapshot.to_dict()


def as_snapshot(item: Snapshot | SnapshotFrame) -> Snapshot:
    """The `Snapshot` of a frame, or the snapshot itself."""
    return item.snapshot if isinstance(item, SnapshotFrame) else item
