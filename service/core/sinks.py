"""Interfaces between the runner (one thread per twin, sole writer of its state) and the outside
world. The runner calls sinks from its own thread; a sink must never block the physics: it copies
what it needs into a bounded queue (drop-oldest, counted) and does its I/O on its own thread."""

from __future__ import annotations

from typing import Protocol

from twin.snapshot import Snapshot


class SnapshotSink(Protocol):
    """Receives every published snapshot of the twins it is attached to.

    A sink whose class sets `accepts_frames = True` is handed each state as the
    twin.snapshot_frame.SnapshotFrame the publisher captured (its balls as arrays; every
    snapshot attribute reads alike, `snapshot` builds the pydantic tree); any other sink gets the
    `Snapshot` (its tree built for it)."""

    def publish(self, snapshot: Snapshot) -> None:
        """Hand a snapshot over without blocking (drop the oldest queued one if full)."""

    @property
    def dropped(self) -> int:
        """Snapshots dropped so far because the queue was full."""

    def close(self) -> None:
        """Flush what is queued and release resources (idempotent)."""
