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


class WaveformSink(Protocol):
    """A sink that also takes the accelerometer samples: `twin.vibration.sensor.WaveformBlock`s
    (float32 [m/s^2], t0_s [s], sample_rate_hz [Hz]), handed over after the snapshot they came
    with; the same rules (never block, drop-oldest, count)."""

    def publish_waveform(self, bearing_id: str, blocks: list, seq: int | None = None) -> None:
        """Hand the blocks over without blocking (`seq`: the snapshot they came with)."""
