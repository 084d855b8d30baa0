"""Interfaces between the runner (one thread per twin, sole writer of its state) and the outside
world. The runner calls sinks from its own thread; a sink must never block the physics: it copies
what it needs into a bounded queue (drop-oldest, counted) and does its I/O on its own thread."""

from __future__ import annotations

from typing import Protocol

from twin.snapshot import Snapshot


class SnapshotSink(Protocol):
    """Receives every published snapshot of the twins it is attached to."""

    def publish(self, snapshot: Snapshot) -> None:
        """Hand a snapshot over without blocking (drop the oldest queued one if full)."""

    @property
    def dropped(self) -> int:
        """Snapshots dropped so far because the queue was full."""

    def close(self) -> None:
        """Flush what is queued and release resources (idempotent)."""
