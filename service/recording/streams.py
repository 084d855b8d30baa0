"""Making and freeing rerun streams, and sending blueprints without a stream per send.

rerun-sdk 0.41 never frees a `RecordingStream` by itself (rerun issue #2116): the bindings keep
each one, with its batcher threads, in a native list until
`rerun_bindings.flush_and_cleanup_orphaned_recordings()` runs (`rr.init` calls it, nothing else
does). A stream cannot be re-pointed at another recording id, so clips do not share pooled
streams (two clips with one id would merge into one recording in the viewer); every stream is
made through a `RerunStreams` and freed by its `reclaim()` once its file is closed and nothing
refers to it any more.
"""

from __future__ import annotations

import logging
import threading

import rerun as rr
import rerun.blueprint as rrb

log = logging.getLogger("service.recording")


class RerunStreams:
    """Makes the rerun streams of one or more recorders and frees those they have dropped.

    rerun-sdk 0.41 never frees a `RecordingStream` by itself (rerun issue #2116): the bindings
    keep each one, with its batcher threads, in a native list. `reclaim()` calls the bindings'
    `flush_and_cleanup_orphaned_recordings()` (what `rr.init` does), which flushes every stream
    of the process and drops those nothing else refers to (their files must be closed first:
    `flush()` + `disconnect()`). A `TwinService` owns one for all its recorders; a recorder made
    without one makes its own.

    Creation and reclaim are serialised by one lock, and must be: rerun's `new_recording` /
    `new_blueprint` hold the GIL while they wait for the native list the cleanup holds while it
    flushes, and a flush can wait for the GIL (releasing numpy buffers): a stream created on
    another thread during a reclaim deadlocks. So every stream of the recorders sharing one
    `RerunStreams` is made through it, on the caller's thread (constructor, `start_file`), never
    on a worker; recorders on several threads of one process should share one `RerunStreams`."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self.created = 0  # streams made (recordings and blueprints)
        self.reclaims = 0  # successful cleanups
        self.reclaim_errors = 0
        self._warned = False

    def new_recording(self, application_id: str, recording_id: str) -> rr.RecordingStream:
        with self._lock:
            self.created += 1
            return rr.RecordingStream(application_id, recording_id=recording_id)

    def new_blueprint(self, application_id: str) -> rr.RecordingStream:
        import rerun_bindings

        with self._lock:
            self.created += 1
            return rr.RecordingStream._from_native(
                rerun_bindings.new_blueprint(
                    application_id=application_id, make_default=False, make_thread_default=False, default_enabled=True
                )
            )

    def send_blueprint(self, blueprint: rrb.Blueprint, recording: rr.RecordingStream) -> None:
        """rerun's own `send_blueprint` (it makes a blueprint stream per call) under the lock."""
        with self._lock:
            self.created += 1
            recording.send_blueprint(blueprint, make_active=True, make_default=True)

    def reclaim(self) -> bool:
        """Free the streams no recorder refers to any more (threads joined, memory released);
        False (logged once) when the bindings lack the cleanup or it failed (e.g. a sink that
        cannot flush): those streams are then kept, as rerun-sdk would anyway."""
        try:
            import rerun_bindings

            cleanup = rerun_bindings.flush_and_cleanup_orphaned_recordings
        except (ImportError, AttributeError) as exc:
            return self._failed(exc)
        try:
            with self._lock:
                cleanup()
        except Exception as exc:  # noqa: BLE001 - a failed cleanup only keeps the streams
            return self._failed(exc)
        self.reclaims += 1
        return True

    def _failed(self, exc: BaseException) -> bool:
        self.reclaim_errors += 1
        if not self._warned:
            self._warned = True
            log.warning("rerun: could not free closed recording streams (%s): they stay in memory", exc)
        return False


class BlueprintSender:
    """Sends blueprints, each through a blueprint stream of its own that is freed right after.

    A blueprint stream keeps state for every entity path it ever logged, and every blueprint
    logs new ones (each view and container has a fresh id): a stream reused for the
    recorder's lifetime grows with every blueprint sent (a twin created or deleted, a segment
    opened). Here each send makes a blueprint stream through `RerunStreams` (on the caller's
    thread), logs the blueprint into an in-memory sink, hands that storage to the recording
    (what `RecordingStream.send_blueprint` does), drops the stream and reclaims it. Uses rerun
    internals (`rerun_bindings.new_blueprint`, `Blueprint._log_to_stream`); if they are
    missing, falls back to `send_blueprint` (whose stream is reclaimed as well)."""

    def __init__(self, application_id: str, streams: RerunStreams):
        self.application_id = application_id
        self._streams = streams
        self._fallback = False
        self.sent = 0

    def close(self) -> None:
        """Nothing is kept between sends."""

    def send(self, blueprint: rrb.Blueprint, recording: rr.RecordingStream) -> None:
        self.sent += 1
        if not self._fallback:
            try:
                import rerun_bindings

                stream = self._streams.new_blueprint(self.application_id)
                try:
                    storage = stream.memory_recording().storage
                    stream.set_time("blueprint", sequence=0)
                    blueprint.to_blueprint()._log_to_stream(stream)
                    rerun_bindings.send_blueprint(storage, True, True, recording=recording.to_native())
                finally:
                    # the in-memory sink holds the stream (a reference cycle in rerun-sdk 0.41):
                    # disconnect() replaces it, then the stream can be freed
                    stream.disconnect()
                    del stream
                self._streams.reclaim()
                return
            except (ImportError, AttributeError, TypeError) as exc:
                self._fallback = True
                log.warning("rerun: blueprint stream API unavailable (%s): using send_blueprint", exc)
        self._streams.send_blueprint(blueprint, recording)
        self._streams.reclaim()
