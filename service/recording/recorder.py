"""`RerunRecorder`: a `SnapshotSink` that records one or more twins into one rerun recording.

The runner thread calls `publish(snapshot)`, which only appends to a bounded queue (drop-oldest,
counted in `dropped`) and returns. A background thread drains the queue into rows of plain
numbers and, every `flush_interval_s` (1 s by default), sends what it buffered with
`send_columns`: one call, hence one rerun chunk, per entity and send, all rows of that second in
it (`service.recording.layout` lists the entities; the per-contact series go out every
`slow_interval_s`). Then it writes the file (`service.recording.segments.DirectFile`).

Outputs: the file given to the constructor (in segments) and/or a spawned viewer (each its own
`RecordingStream`), plus at most one extra file opened with `start_file` and closed with
`stop_file` (its own stream with the same recording id, complete on its own). Nothing listens on
the network unless `spawn_viewer=True` (and then only the spawned viewer does).

Append-only. Every file is created here, exclusively and without following links
(`service.recording.paths`); a main path that exists already (an earlier run, e.g. one killed
with kill -9) is left untouched and this run records under the next free name
`<stem>.runN.rrd` (`path` is the name actually used). Nothing here deletes a recording except a
file this recorder created itself and could not write a single byte to, and `Retention` (the
only thing that deletes recordings, by its settings).

Segments. With `segment_s` and/or `segment_bytes` the main file is rotated: once the open segment
is that old [s of wall time] or that large [bytes], after a send, the recorder points its stream
at the next segment `<stem>-NNNN.rrd` (`service.recording.segments`), which starts with the
static data and the blueprint again. Every row goes to exactly one segment; `close()` (the
service's SIGTERM path) closes the open one. Read a segmented recording with
`read_recording(recording_segments(path))`.

Faults. A write error (disk full, permission, I/O) on the main file is caught: the file is cut
back to its last complete write and closed, the recorder becomes `degraded` with the reason
(`fault`, `health()`), the rows of that send and of every send until it can write again are
counted in `rows_lost` (never in `rows_logged`), and every `retry_s` it tries to open the next
segment; once that works it is `ok` again (with a log row saying how many rows were lost). The
twin never notices: `publish` never blocks or raises. A failed start (the constructor,
`start_file`) raises and leaves nothing behind: the file it created is removed, its streams and
thread are freed.

Memory and streams: see `service.recording.streams` (rerun-sdk 0.41 keeps every stream until
`RerunStreams.reclaim`) and the footer note of `service.recording.segments`.
"""

from __future__ import annotations

import logging
import math
import os
import socket
import sys
import threading
import time
import uuid
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Self

import numpy as np
import rerun as rr

from service.recording import columns as C
from service.recording.layout import TwinLayout, blueprint, send_static
from service.recording.paths import CreatedFile, RecordingPathError, create_exclusive, create_recording
from service.recording.retention import Retention
from service.recording.segments import (
    DirectFile,
    RecordingWriteError,
    RerunFile,
    is_segment_of,
    segment_path,
)
from service.recording.streams import BlueprintSender, RerunStreams

log = logging.getLogger("service.recorder")

_MAX_ENDED = 1024           # remembered end times of removed twins (a re-created id continues after them)
_NEW_RUN_GAP_S = 1.0        # simulated seconds between a removed twin's last row and its re-creation


def _display_available() -> bool:
    if not sys.platform.startswith("linux"):
        return True
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY") or os.environ.get("WAYLAND_SOCKET"))


def _port_open(port: int, timeout_s: float = 0.5) -> bool:
    try:
        with socket.create_connection(("127.0.0.1", port), timeout=timeout_s):
            return True
    except OSError:
        return False


def _scenario_text(handle) -> str | None:
    """"scenario NAME: STATE, phase PHASE" of a scenario handle (duck-typed), or None."""
    if handle is None:
        return None
    name = getattr(handle, "name", None) or "?"
    state = getattr(handle, "state", None) or "?"
    phase = getattr(handle, "phase", None)
    text = f"scenario {name}: {state}"
    if phase and state == "running":
        text += f", phase {phase}"
    error = getattr(handle, "error", None)
    if error and state in ("failed", "cancelled"):
        text += f" ({error})"
    return text


@dataclass
class _Twin(TwinLayout):
    rows: list = field(default_factory=list)          # rows not sent yet
    slow_rows: list = field(default_factory=list)     # rows whose per-contact series are not sent yet
    slow_since: float = field(default_factory=time.monotonic)
    last_time_s: float = -math.inf                    # simulated time of the last row kept
    last_seq: int | None = None                       # seq of the last snapshot seen
    slow_prev_time_s: float | None = None             # time of the row before slow_rows[0]
    prev_time_s: float | None = None                  # time of the row before rows[0]
    time_offset_s: float = 0.0                        # added to sim_time (a re-created twin)
    continue_after_s: float | None = None             # where the previous run of this id ended
    note: str | None = None                           # logged (with a line break) before the next row
    alarm_rows: list = field(default_factory=list)    # alarm events not sent yet (columns.AlarmRow)
    alarm_states: dict = field(default_factory=dict)  # alarm id -> latest state seen (ALARM_STATES)
    alarm_carry: dict = field(default_factory=dict)   # a new output: the active states to log again
    wave_rows: list = field(default_factory=list)     # accelerometer samples not sent yet (columns.WaveRow)


@dataclass
class _Output:
    stream: rr.RecordingStream | None
    file: DirectFile | RerunFile | None = None        # None: viewer, or a file that failed
    viewer: bool = False
    opened_at: float = field(default_factory=time.monotonic)   # monotonic [s]
    rows: int = 0                # snapshots written to this output (to this segment for the main file)
    null_sink: Any = None        # while the main file is degraded: an in-memory sink emptied after each send

    @property
    def path(self) -> Path | None:
        return self.file.path if self.file is not None else None


class RerunRecorder:
    """Records the snapshots of one or more twins into one rerun recording (see module doc).

    Usage::

        rec = RerunRecorder("run.rrd")
        rec.add_twin_from(twin)            # or add_twin("a", designation=..., pitch_radius_m=..., ...)
        rec.publish(twin.snapshot())       # never blocks
        rec.start_file("clip.rrd"); ...; rec.stop_file()
        rec.close()                        # drains, sends, writes, closes
    """

    def __init__(self, path: str | Path | CreatedFile | None = None, *, spawn_viewer: bool = False,
                 application_id: str = "bearing-twin", flush_interval_s: float = 1.0,
                 slow_interval_s: float = 5.0, queue_size: int = 512, viewer_port: int = 9876,
                 series_window_s: float | None = 10.0, min_interval_s: float = 0.0,
                 segment_s: float | None = None, segment_bytes: int | None = None,
                 write_footer: bool = False, streams: RerunStreams | None = None,
                 rename_existing: bool = True, retention: Retention | None = None,
                 retry_s: float = 2.0, write_timeout_s: float = 30.0):
        """`path`: the main file (None: none); taken -> `<stem>.runN.rrd` with `rename_existing`,
        else RecordingPathError; or a `CreatedFile` made by the caller (`create_exclusive`), which
        the recorder then owns (removed again if the start fails). `flush_interval_s` [s]: send (one chunk per entity) and write
        this often; `slow_interval_s` [s]: the same for the per-contact series. `segment_s` [s of
        wall time] / `segment_bytes` [bytes]: rotate the main file (None or 0 = never).
        `write_footer`: end every file with rerun's footer (rerun's own file sink writes it;
        memory grows with the open segment). `streams`: makes and frees this recorder's rerun
        streams (shared by the recorders of a service). `retention`: applied after each new
        segment. `retry_s` [s]: after a write error, try a new segment this often."""
        if not (flush_interval_s > 0.0 and math.isfinite(flush_interval_s)):
            raise ValueError(f"flush_interval_s = {flush_interval_s!r}: must be finite and > 0")
        if not (slow_interval_s > 0.0 and math.isfinite(slow_interval_s)):
            raise ValueError(f"slow_interval_s = {slow_interval_s!r}: must be finite and > 0")
        if queue_size < 1:
            raise ValueError(f"queue_size = {queue_size!r}: must be >= 1")
        if segment_s is not None and not (segment_s >= 0.0 and math.isfinite(segment_s)):
            raise ValueError(f"segment_s = {segment_s!r}: must be finite and >= 0 (0 = no rotation by age)")
        if segment_bytes is not None and segment_bytes < 0:
            raise ValueError(f"segment_bytes = {segment_bytes!r}: must be >= 0 (0 = no rotation by size)")
        self.segment_s = float(segment_s) if segment_s else None
        self.segment_bytes = int(segment_bytes) if segment_bytes else None
        self.write_footer = bool(write_footer)
        self.application_id = application_id
        self.recording_id = uuid.uuid4().hex
        self.flush_interval_s = float(flush_interval_s)
        self.slow_interval_s = max(float(slow_interval_s), self.flush_interval_s)
        self.queue_size = int(queue_size)
        self.series_window_s = series_window_s
        self.viewer_port = viewer_port
        self.min_interval_s = float(min_interval_s)
        self.retry_s = float(retry_s)
        self.write_timeout_s = float(write_timeout_s)
        self.retention = retention
        self._streams = streams if streams is not None else RerunStreams()

        self._queue: deque = deque()
        self._alarm_queue: deque = deque()
        self._wave_queue: deque = deque()
        self._waveform_dropped = 0
        self._alarms_dropped = 0
        self._alarms_logged = 0
        self._qlock = threading.Lock()
        self._io_lock = threading.RLock()
        self._wake = threading.Event()
        self._stop = threading.Event()
        self._wake_at = max(1, self.queue_size // 2)
        self._closed = False
        self._dropped = 0
        self._rows_logged = 0
        self._errors = 0
        self._skipped = 0
        self._write_errors = 0
        self._rows_lost = 0
        self._fault: str | None = None
        self._fault_since: float | None = None
        self._lost_since_fault = 0
        self._retry_at = 0.0
        self._twins: dict[str, _Twin] = {}
        self._context: dict[str, Callable[[], Any]] = {}
        self._ended: dict[str, float] = {}
        self._viewer: _Output | None = None
        self._primary: _Output | None = None    # the main file's stream (its open segment in .file)
        self._extra: _Output | None = None
        self._blueprint_dirty = False
        self._segments: list[Path] = []
        self._segment_index = 0
        self._rotation_failed_at: float | None = None
        self._thread: threading.Thread | None = None
        self._blueprints = BlueprintSender(application_id, self._streams)

        self.path: Path | None = None
        try:
            self._viewer = self._open_viewer(spawn_viewer)
            if isinstance(path, CreatedFile):
                created = path
                self.path = created.path
                self._primary = self._open_file(created)
                self._segments.append(created.path)
            elif path is not None:
                created = create_recording(path, rename=rename_existing)
                if created.path != Path(path):
                    log.warning("rerun: %s exists (an earlier run): recording beside it to %s", path, created.path)
                self.path = created.path
                self._primary = self._open_file(created)
                self._segments.append(created.path)
        except BaseException:
            self._abandon()
            raise
        self._thread = threading.Thread(target=self._run, name="rerun-recorder", daemon=True)
        self._thread.start()

    def _abandon(self) -> None:
        """Free everything a failed constructor made (its files are already removed)."""
        self._closed = True
        for out in self._outputs():
            self._close_output(out)
        self._viewer = self._primary = self._extra = None
        self._blueprints.close()
        self._streams.reclaim()

    # ---- outputs ----------------------------------------------------------------------------
    def _new_stream(self) -> rr.RecordingStream:
        return self._streams.new_recording(self.application_id, self.recording_id)

    def _open_viewer(self, spawn_viewer: bool) -> _Output | None:
        """A stream to a spawned viewer (its own stream: the file segments rotate, the viewer's
        connection does not), or None."""
        if not spawn_viewer:
            return None
        if not _display_available():
            log.warning("rerun: no display (DISPLAY/WAYLAND_DISPLAY unset): not spawning a viewer")
            return None
        stream = self._new_stream()
        try:
            stream.spawn(port=self.viewer_port, connect=False)
            if not _port_open(self.viewer_port):
                log.warning("rerun: the spawned viewer does not listen on port %d: continuing without it",
                            self.viewer_port)
                return None
        except Exception as exc:  # noqa: BLE001 - no viewer on PATH, headless, ...: warn, go on
            log.warning("rerun: could not spawn a viewer (%s): continuing without a viewer",
                        str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__)
            return None
        stream.connect_grpc(f"rerun+http://127.0.0.1:{self.viewer_port}/proxy")
        return _Output(stream=stream, viewer=True)

    def _writer(self, created: CreatedFile, stream: rr.RecordingStream):
        return (RerunFile if self.write_footer else DirectFile)(created, stream)

    def _open_file(self, created: CreatedFile) -> _Output:
        """A new stream writing to `created`, which gets the static data and the blueprint and
        is written at once (so that a file that cannot be written fails here). On failure the
        file is removed and the stream dropped; raises RecordingWriteError."""
        stream = self._new_stream()
        out = _Output(stream=stream)
        try:
            out.file = self._writer(created, stream)
            self._start_output(out)
            out.file.write(self.write_timeout_s)
        except BaseException:
            created.discard()
            out.file = None
            self._close_output(out)
            raise
        if self.retention is not None:
            self.retention.protect(created.path)
        return out

    def _start_output(self, out: _Output) -> None:
        """Static data of every twin, event state reset, blueprint (if there are twins)."""
        for tw in self._twins.values():
            send_static(out.stream, tw)
            tw.last.clear()
            tw.alarm_carry = {k: v for k, v in tw.alarm_states.items() if v != "inactive"}
        self._send_blueprint([out])

    def _outputs(self) -> list[_Output]:
        return [o for o in (self._viewer, self._primary, self._extra) if o is not None]

    def _close_output(self, out: _Output, timeout_s: float = 30.0) -> None:
        """Write what is left, close the file, drop the stream (freed by `RerunStreams.reclaim`)."""
        if out.stream is None:
            return
        if out.file is not None:
            try:
                out.file.write(timeout_s)
            except RecordingWriteError as exc:
                self._write_errors += 1
                log.warning("rerun: closing %s: %s", out.file.path, exc)
        else:
            try:
                out.stream.flush(timeout_sec=timeout_s)
            except Exception as exc:  # noqa: BLE001 - a sink's failure must not stop the others
                log.warning("rerun: flush of %s failed: %s", "viewer" if out.viewer else "stream", exc)
        try:
            out.stream.disconnect()
        except Exception as exc:  # noqa: BLE001
            log.warning("rerun: disconnect failed: %s", exc)
        if out.file is not None:
            out.file.close()
            if self.retention is not None:
                self.retention.release(out.file.path)
        out.stream = None

    def start_file(self, path: str | Path) -> Path:
        """Start recording into a further .rrd file while running (static geometry and blueprint
        first, then every snapshot published from now on). Replaces (and completes) a file started
        earlier with `start_file`. Returns the path. The file is created exclusively (an existing
        name, or a link, raises RecordingPathError) and gets a new stream with the recorder's
        recording id, freed again when the file is stopped."""
        path = Path(path)
        if self._closed:
            raise RuntimeError("recorder is closed")
        if self.path is not None and is_segment_of(self.path, path):
            raise RecordingPathError(f"{path} is the recorder's main file (or one of its segments)")
        with self._io_lock:
            self._drain_locked()
            self._send_locked(force_slow=True)   # rows published before start_file go to the old outputs only
            replaced = self._extra is not None
            if replaced:
                self._stop_file_locked()
            created = create_recording(path, rename=False)
            try:
                self._extra = self._open_file(created)
            except RecordingWriteError as exc:
                self._streams.reclaim()
                raise RecordingPathError(f"cannot record to {path}: {exc}") from None
        if replaced:
            self._streams.reclaim()
        return created.path

    def stop_file(self) -> Path | None:
        """Finish the file started with `start_file` (everything published so far is in it,
        written and closed). Returns its path, or None if no file was being recorded."""
        with self._io_lock:
            if self._extra is None:
                return None
            self._drain_locked()
            self._send_locked(force_slow=True)
            path = self._stop_file_locked()
        self._streams.reclaim()             # outside the lock: it flushes every stream
        return path

    def _stop_file_locked(self) -> Path | None:
        out, self._extra = self._extra, None
        path = out.path
        self._close_output(out)
        return path

    @property
    def recording_file(self) -> Path | None:
        """The file being recorded with `start_file`, if any."""
        out = self._extra
        return out.path if out is not None else None

    @property
    def segments(self) -> list[Path]:
        """The segments of the main file opened so far, in order (the last one is being written
        unless the recorder is closed or degraded); [] without a main file."""
        return list(self._segments)

    @property
    def current_path(self) -> Path | None:
        """The segment of the main file being written (None without a main file, once closed,
        or while degraded)."""
        out = self._primary
        return out.path if out is not None else None

    def rotate(self) -> Path | None:
        """Close the open segment of the main file now (everything published so far is in it) and
        open the next one; returns the new segment's path (None without a main file, or if it
        could not be opened)."""
        with self._io_lock:
            if self._closed or self._primary is None or self._primary.file is None:
                return None
            self._drain_locked()
            self._send_locked(force_slow=True)
            if self._primary.file is None:        # the send just failed
                return None
            return self._rotate_locked()

    def _rotation_due(self) -> bool:
        out = self._primary
        if out is None or out.file is None or out.rows == 0 or (self.segment_s is None and self.segment_bytes is None):
            return False
        now = time.monotonic()
        if self._rotation_failed_at is not None and now - self._rotation_failed_at < 10.0:
            return False          # a failed rotation is retried every 10 s, not at every send
        if self.segment_s is not None and now - out.opened_at >= self.segment_s:
            return True
        return self.segment_bytes is not None and out.file.size() >= self.segment_bytes

    def _next_segment(self) -> CreatedFile:
        index = len(self._segments)
        return create_exclusive(self.path.parent, segment_path(self.path, index).name, make_dirs=False)

    def _rotate_locked(self) -> Path | None:
        """Point the main file's stream at the next segment (the stream is kept: rerun-sdk 0.41
        never frees a stream, see `service.recording.streams`)."""
        out = self._primary
        try:
            created = self._next_segment()
        except RecordingPathError as exc:
            self._errors += 1
            self._rotation_failed_at = time.monotonic()
            log.warning("rerun: could not open the next segment (%s): continuing in %s", exc, out.path)
            return None
        self._rotation_failed_at = None
        old = out.file
        try:
            old.write(self.write_timeout_s)     # nothing left, normally: the send wrote it
        except RecordingWriteError as exc:
            created.discard()
            self._on_write_error(out, exc, 0)
            return None
        old_rows = out.rows
        try:
            out.file = self._writer(created, out.stream)     # the stream's sink moves to the new file
        except BaseException:
            created.discard()
            raise
        old.close()
        if self.retention is not None:
            self.retention.release(old.path)
        log.info("rerun: segment %s closed (%d snapshots), recording into %s", old.path, old_rows, created.path)
        return self._segment_opened(out, created)

    def _segment_opened(self, out: _Output, created: CreatedFile) -> Path | None:
        out.rows, out.opened_at = 0, time.monotonic()
        try:
            self._start_output(out)
            out.file.write(self.write_timeout_s)
        except RecordingWriteError as exc:
            out.file.discard()
            self._on_write_error(out, exc, 0, discarded=True)
            return None
        self._segments.append(created.path)
        if self.retention is not None:
            self.retention.protect(created.path)
            self._apply_retention()
        return created.path

    def _apply_retention(self) -> None:
        try:
            self.retention.apply()
        except Exception:
            log.exception("retention failed")

    # ---- faults -----------------------------------------------------------------------------
    def _on_write_error(self, out: _Output, exc: BaseException, rows: int, *, discarded: bool = False) -> None:
        """The main file could not be written: close it (cut back to its last complete write,
        removed if empty), count, degrade, retry later with a new segment."""
        self._write_errors += 1
        self._rows_lost += rows
        if self._fault is None:
            self._fault_since = time.monotonic()
            self._lost_since_fault = 0
        self._lost_since_fault += rows
        self._fault = f"recording write failed: {exc}"
        log.error("rerun: %s; %d snapshots lost so far, retrying every %.0f s", self._fault, self._rows_lost, self.retry_s)
        f = out.file
        out.file = None
        if f is not None and not discarded:
            try:
                if f.size() == 0:
                    f.discard()              # this recorder's own empty file
                else:
                    f.close()
            except OSError:
                pass
            if self.retention is not None:
                self.retention.release(f.path)
        self._sink_to_nowhere(out)
        self._retry_at = time.monotonic() + self.retry_s

    def _sink_to_nowhere(self, out: _Output) -> None:
        """While degraded the stream still gets every send: an in-memory sink that is emptied
        after each send (`_discard`) keeps its memory flat."""
        try:
            out.null_sink = out.stream.binary_stream()      # replaces (and so ends) the failed sink
        except Exception:  # noqa: BLE001
            out.null_sink = None

    def _discard(self, out: _Output) -> None:
        storage = out.null_sink
        if storage is not None:
            try:
                storage.read(flush=True, flush_timeout_sec=self.write_timeout_s)
            except Exception:  # noqa: BLE001
                pass

    def _retry_locked(self) -> None:
        out = self._primary
        if out is None or out.file is not None or time.monotonic() < self._retry_at or self._closed:
            return
        self._retry_at = time.monotonic() + self.retry_s
        try:
            created = self._next_segment()
        except RecordingPathError as exc:
            self._fault = f"recording write failed, and a new segment cannot be created: {exc}"
            return
        self._discard(out)
        out.null_sink = None
        try:
            out.file = self._writer(created, out.stream)
        except BaseException as exc:  # noqa: BLE001
            created.discard()
            out.file = None
            self._sink_to_nowhere(out)
            self._fault = f"recording write failed, retry failed: {exc}"
            return
        if self._segment_opened(out, created) is None:
            return                                    # still failing: _on_write_error ran again
        lost, since = self._lost_since_fault, self._fault_since
        log.warning("rerun: recording again into %s after %s (%d snapshots lost)", created.path, self._fault, lost)
        for tw in self._twins.values():
            tw.note = (f"recording resumed after {time.monotonic() - since:.0f} s: {lost} snapshots were "
                       "not written")
        self._fault = None
        self._fault_since = None

    @property
    def fault(self) -> str | None:
        """Why the main file is not being written now (None when it is)."""
        return self._fault

    @property
    def status(self) -> str:
        return "degraded" if self._fault is not None else "ok"

    @property
    def write_errors(self) -> int:
        """Writes (or flushes) of a recording file that failed."""
        return self._write_errors

    @property
    def rows_lost(self) -> int:
        """Snapshots that were sent but could not be written to the main file."""
        return self._rows_lost

    def health(self) -> dict:
        return {"status": self.status, "error": self._fault, "path": str(self.path) if self.path else None,
                "current": str(self.current_path) if self.current_path else None,
                "rows": self._rows_logged, "rows_lost": self._rows_lost, "write_errors": self._write_errors,
                "dropped": self._dropped, "segments": len(self._segments)}

    # ---- twins ------------------------------------------------------------------------------
    def add_twin(self, bearing_id: str, *, designation: str, pitch_radius_m: float,
                 ball_radius_m: float, inner_raceway_radius_m: float,
                 outer_raceway_radius_m: float, ball_count: int,
                 load_scale_m_per_n: float | None = None, context: Callable[[], Any] | None = None,
                 vibration: bool = False) -> None:
        """Register a twin: its static geometry goes out now, the blueprint with the next send.
        `load_scale_m_per_n`: arrow length per newton of contact load; by default the largest load
        of the first loaded snapshot is drawn one ball diameter long. `context`: called with each
        `publish` (on the publishing thread) for the twin's scenario handle (name, state, phase),
        whose changes are logged as events."""
        tw = _Twin(bearing_id=str(bearing_id), designation=str(designation), ball_count=int(ball_count),
                   pitch_radius_m=float(pitch_radius_m), ball_radius_m=float(ball_radius_m),
                   inner_raceway_radius_m=float(inner_raceway_radius_m),
                   outer_raceway_radius_m=float(outer_raceway_radius_m),
                   load_scale_m_per_n=load_scale_m_per_n, vibration=bool(vibration))
        self._register(tw, context)

    def _register(self, tw: _Twin, context) -> None:
        with self._io_lock:
            old = self._twins.get(tw.bearing_id)
            if old is not None:        # the same twin again (new geometry): keep its rows and state
                tw.rows, tw.slow_rows, tw.last = old.rows, old.slow_rows, old.last
                tw.last_time_s, tw.last_seq, tw.time_offset_s = old.last_time_s, old.last_seq, old.time_offset_s
                tw.prev_time_s, tw.slow_prev_time_s = old.prev_time_s, old.slow_prev_time_s
                tw.alarm_rows, tw.alarm_states = old.alarm_rows, old.alarm_states
                tw.wave_rows = old.wave_rows
            else:
                tw.continue_after_s = self._ended.pop(tw.bearing_id, None)
            self._twins[tw.bearing_id] = tw
            if context is not None:
                self._context[tw.bearing_id] = context
            for out in self._outputs():
                send_static(out.stream, tw)
            self._blueprint_dirty = True

    def add_twin_from(self, twin, bearing_id: str | None = None, *, context: Callable[[], Any] | None = None) -> None:
        """`add_twin` with the geometry of a `twin.engine.Twin`."""
        m = twin.model
        g = m.spec.geometry
        self.add_twin(bearing_id or twin.bearing_id, designation=m.spec.designation,
                      pitch_radius_m=m.pitch_radius_m, ball_radius_m=m.ball_radius_m,
                      inner_raceway_radius_m=g.inner_raceway_radius_m,
                      outer_raceway_radius_m=g.outer_raceway_radius_m, ball_count=m.ball_count,
                      context=context, vibration=bool(getattr(m, "housing_on", False)))

    def remove_twin(self, bearing_id: str) -> bool:
        """Forget a twin (its runner has stopped): what it published is sent and written first,
        then its entry, context and buffers are dropped, and the outputs move to fresh rerun
        streams (rerun-sdk keeps state for every entity path a stream has seen: the old streams,
        and that state, are freed). A twin created later under the same id continues on
        `sim_time` after this one (1 s later), with a line break. Returns whether it was known."""
        with self._io_lock:
            self._context.pop(bearing_id, None)
            if bearing_id not in self._twins:
                return False
            if not self._closed:
                self._drain_locked()
                self._send_locked(force_slow=True)
            tw = self._twins.pop(bearing_id)
            if math.isfinite(tw.last_time_s):
                self._ended[bearing_id] = tw.last_time_s + tw.time_offset_s
                while len(self._ended) > _MAX_ENDED:
                    self._ended.pop(next(iter(self._ended)))
            self._blueprint_dirty = bool(self._twins)
            renewed = not self._closed and self._renew_streams_locked()
        if renewed:
            self._streams.reclaim()
        return True

    def _renew_streams_locked(self) -> bool:
        """Move every output that can to a fresh stream of the same recording (files written
        directly continue where they are; a viewer is connected again); the old streams are
        dropped for `RerunStreams.reclaim`. Outputs written by rerun's own file sink (footer on)
        keep their stream."""
        renewed = False
        for out in self._outputs():
            if out.stream is None or (out.file is not None and out.file.rebind is None):
                continue
            old = out.stream
            if out.file is not None:
                try:
                    out.file.write(self.write_timeout_s)
                except RecordingWriteError as exc:
                    if out is self._primary:
                        self._on_write_error(out, exc, 0)
                    continue
            stream = self._new_stream()
            if out.file is not None:
                out.file.rebind(stream)
            elif out.viewer:
                stream.connect_grpc(f"rerun+http://127.0.0.1:{self.viewer_port}/proxy")
            else:                     # degraded main file: a sink emptied after each send
                out.stream = stream
                self._sink_to_nowhere(out)
            out.stream = stream                  # (the file and the viewer have the static data)
            try:
                old.disconnect()
            except Exception as exc:  # noqa: BLE001 - only keeps the old stream alive
                log.warning("rerun: disconnect of a replaced stream failed: %s", exc)
            renewed = True
        return renewed

    @property
    def bearing_ids(self) -> list[str]:
        return list(self._twins)

    # ---- blueprint --------------------------------------------------------------------------
    def blueprint(self):
        """The default layout (`service.recording.layout.blueprint`)."""
        return blueprint(list(self._twins.values()), self.series_window_s)

    def _send_blueprint(self, outs: list[_Output]) -> None:
        if not outs or not self._twins:
            return
        bp = self.blueprint()
        for out in outs:
            self._blueprints.send(bp, out.stream)

    # ---- the sink ---------------------------------------------------------------------------
    def publish(self, snapshot, positions_m: Any = None) -> None:
        """Queue a snapshot (and optionally the ball centres, shape (Z, 3) [m]); never blocks.
        When the queue is full the oldest queued snapshot is dropped and counted."""
        if self._closed:
            with self._qlock:
                self._dropped += 1
            return
        pos = None
        if positions_m is not None:
            try:
                pos = np.array(positions_m, dtype=float).reshape(-1, 3)
            except (TypeError, ValueError) as exc:   # never raise into the runner: draw from azimuth
                log.warning("rerun recorder: positions_m ignored: %s", exc)
        context = None
        ctx = self._context.get(getattr(snapshot, "bearing_id", None))
        if ctx is not None:
            try:
                context = _scenario_text(ctx())
            except Exception:  # noqa: BLE001 - never raise into the runner
                context = None
        with self._qlock:
            if len(self._queue) >= self.queue_size:
                self._queue.popleft()
                self._dropped += 1
            self._queue.append((snapshot, pos, context))
            n = len(self._queue)
        if n >= self._wake_at:
            self._wake.set()

    def log_alarm(self, event) -> None:
        """Queue an alarm event (`service.core.alarms.AlarmEvent`, or its dict) for the twin's
        `alarms/{alarm_id}` and `alarm_states/{alarm_id}` entities (`service.recording.layout`);
        never blocks or raises (an alarm-hub subscriber). Events of a twin this recorder does not
        record are left out; when `queue_size` events wait, the oldest is dropped and counted."""
        if self._closed:
            return
        try:
            row = C.AlarmRow.of(event)
        except Exception as exc:  # noqa: BLE001 - never raise into the alarm hub
            self._errors += 1
            log.warning("rerun recorder: alarm event skipped: %s", exc)
            return
        with self._qlock:
            if len(self._alarm_queue) >= self.queue_size:
                self._alarm_queue.popleft()
                self._alarms_dropped += 1
            self._alarm_queue.append(row)

    def publish_waveform(self, bearing_id: str, blocks: list, seq: int | None = None) -> None:
        """Queue accelerometer blocks (twin.vibration.sensor.WaveformBlock) of a twin for
        `vibration/acceleration_m_s2`, at the `seq` of the snapshot they came with (by default
        the last one queued); never blocks or raises. When `queue_size` batches wait, the oldest
        is dropped and counted (`waveform_dropped`)."""
        if self._closed:
            return
        try:
            rows = [C.WaveRow(seq=-1 if seq is None else int(seq), t0_s=float(b.t0_s),
                              sample_rate_hz=float(b.sample_rate_hz), samples=np.asarray(b.samples, dtype=np.float32))
                    for b in blocks]
        except Exception as exc:  # noqa: BLE001 - never raise into the publisher
            self._errors += 1
            log.warning("rerun recorder: waveform skipped: %s", exc)
            return
        with self._qlock:
            if len(self._wave_queue) >= self.queue_size:
                self._wave_queue.popleft()
                self._waveform_dropped += 1
            self._wave_queue.append((str(bearing_id), rows))

    @property
    def waveform_dropped(self) -> int:
        """Batches of accelerometer samples dropped because their queue was full."""
        return self._waveform_dropped

    @property
    def alarms_logged(self) -> int:
        """Alarm events sent to the outputs."""
        return self._alarms_logged

    @property
    def alarms_dropped(self) -> int:
        """Alarm events dropped because their queue was full."""
        return self._alarms_dropped

    @property
    def dropped(self) -> int:
        """Snapshots dropped because the queue was full (or published after close)."""
        return self._dropped

    @property
    def rows_logged(self) -> int:
        """Snapshots written: to a file when the recorder has one (never counting those a write
        error lost), else sent to the viewer."""
        return self._rows_logged

    @property
    def errors(self) -> int:
        """Snapshots, sends, writes or rotations that failed (logged, never raised into the physics)."""
        return self._errors + self._write_errors

    @property
    def skipped(self) -> int:
        """Snapshots left out on purpose: closer than `min_interval_s` of simulated time to the
        previous recorded one of the same twin, or published while there was no output."""
        return self._skipped

    @property
    def queued(self) -> int:
        return len(self._queue)

    @property
    def closed(self) -> bool:
        return self._closed

    def flush(self, timeout_s: float = 30.0) -> None:
        """Send and write everything queued or buffered now (the per-contact series too); then
        rotate the main file if its segment is due, or retry a failed one."""
        with self._io_lock:
            self._drain_locked()
            self._send_locked(force_slow=True, timeout_s=timeout_s)
            if not self._closed:
                if self._rotation_due():
                    self._rotate_locked()
                self._retry_locked()

    def close(self) -> None:
        """Drain the queue, send and write the rest, close every output (idempotent)."""
        with self._qlock:
            if self._closed:
                return
            self._closed = True
        self._stop.set()
        self._wake.set()
        if self._thread is not None and self._thread.is_alive() and threading.current_thread() is not self._thread:
            self._thread.join()
        with self._io_lock:
            self._drain_locked()
            self._send_locked(force_slow=True)
            for out in self._outputs():
                self._close_output(out)
            self._viewer = self._primary = self._extra = None
            self._blueprints.close()
            self._twins.clear()
            self._context.clear()
        self._streams.reclaim()             # free this recorder's streams (service.recording.streams)

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # ---- worker -----------------------------------------------------------------------------
    def _run(self) -> None:
        next_send = time.monotonic() + self.flush_interval_s
        while not self._stop.is_set():
            self._wake.wait(timeout=max(0.0, next_send - time.monotonic()))
            self._wake.clear()
            if self._stop.is_set():
                break
            try:
                with self._io_lock:
                    self._drain_locked()
                    if time.monotonic() >= next_send:
                        self._send_locked()
                        if self._rotation_due():
                            self._rotate_locked()
                        self._retry_locked()
                        next_send = time.monotonic() + self.flush_interval_s
            except Exception:  # never let the worker die
                self._errors += 1
                log.exception("rerun recorder: send failed")

    def _drain_locked(self) -> None:
        with self._qlock:
            items = list(self._queue)
            self._queue.clear()
            alarms = list(self._alarm_queue)
            self._alarm_queue.clear()
            waves = list(self._wave_queue)
            self._wave_queue.clear()
        for bearing_id, wave_rows in waves:
            tw = self._twins.get(bearing_id)
            if tw is not None:
                for w in wave_rows:
                    if w.seq < 0:          # no seq given: the snapshot it came with is the last one seen
                        w.seq = tw.last_seq if tw.last_seq is not None else 0
                tw.wave_rows.extend(wave_rows)
        for row in alarms:
            tw = self._twins.get(row.bearing_id)
            if tw is not None:
                tw.alarm_rows.append(row)
                tw.alarm_states[row.alarm_id] = row.state
        if not items:
            return
        if not self._outputs():        # nowhere to write (no file, no viewer): nothing to convert
            self._skipped += len(items)
            return
        for snapshot, pos, context in items:
            try:
                tw = self._twins.get(snapshot.bearing_id)
                if tw is None:
                    tw = self._auto_register(snapshot)
                seq = int(snapshot.seq)
                gap = None
                if tw.last_seq is not None and seq != tw.last_seq + 1:
                    missing = seq - tw.last_seq - 1
                    gap = (f"{missing} snapshots not recorded (seq {tw.last_seq + 1}..{seq - 1})" if missing > 0
                           else f"seq went back from {tw.last_seq} to {seq}")
                tw.last_seq = seq
                t = float(snapshot.time_s)
                if self.min_interval_s > 0.0 and tw.last_time_s <= t < tw.last_time_s + self.min_interval_s:
                    self._skipped += 1
                    continue
                if len(snapshot.balls) != tw.ball_count:
                    raise ValueError(f"{len(snapshot.balls)} balls in the snapshot, {tw.ball_count} registered")
                if pos is not None and pos.shape != (tw.ball_count, 3):
                    raise ValueError(f"positions_m has shape {pos.shape}, expected ({tw.ball_count}, 3)")
                row = C.extract(snapshot, pos, context)
                if tw.continue_after_s is not None:      # a new run of a removed twin's id
                    start = tw.continue_after_s + _NEW_RUN_GAP_S
                    tw.time_offset_s = max(0.0, start - t)
                    gap = (f"new run of twin {tw.bearing_id}: its simulated time {t:g} s is shown at "
                           f"{t + tw.time_offset_s:g} s (after the previous run)")
                    tw.continue_after_s = None
                elif t < tw.last_time_s:
                    gap = gap or f"simulated time went back from {tw.last_time_s:g} s to {t:g} s"
                if tw.note is not None:
                    gap, tw.note = (f"{tw.note}; {gap}" if gap else tw.note), None
                row.gap_before = gap
                tw.last_time_s = t
                tw.rows.append(row)
            except Exception as exc:  # noqa: BLE001 - a bad snapshot is skipped and counted
                self._errors += 1
                log.warning("rerun recorder: snapshot %s/%s skipped: %s",
                            getattr(snapshot, "bearing_id", "?"), getattr(snapshot, "seq", "?"), exc)

    def _auto_register(self, snapshot) -> _Twin:
        log.warning("rerun recorder: twin %r was not added with add_twin: recording its series without geometry",
                    snapshot.bearing_id)
        tw = _Twin(bearing_id=str(snapshot.bearing_id), designation=str(snapshot.designation),
                   ball_count=len(snapshot.balls))
        self._register(tw, None)
        return tw

    def _send_locked(self, force_slow: bool = False, timeout_s: float | None = None) -> None:
        """Send the buffered rows of every twin (and the blueprint if due) to every output, then
        write the files; count what was written."""
        outs = self._outputs()
        timeout_s = self.write_timeout_s if timeout_s is None else timeout_s
        now = time.monotonic()
        sent = 0
        for tw in self._twins.values():
            rows, tw.rows = tw.rows, []
            alarm_rows, tw.alarm_rows = tw.alarm_rows, []
            wave_rows, tw.wave_rows = tw.wave_rows, []
            if not outs:
                continue
            triples: list = []
            try:
                if tw.alarm_carry and (rows or alarm_rows):
                    first = rows[0] if rows else None
                    carry, tw.alarm_carry = tw.alarm_carry, {}
                    triples += C.alarm_states_in_force(
                        tw, carry, first.time_s if first else alarm_rows[0].time_s,
                        first.seq if first else alarm_rows[0].seq, tw.time_offset_s)
                if alarm_rows:
                    triples += C.alarm_columns(tw, alarm_rows, tw.time_offset_s)
                if wave_rows:
                    triples += C.waveform_columns(tw, wave_rows, tw.time_offset_s)
                if rows:
                    batch = C.Batch.of(rows, tw.time_offset_s)
                    C.fast_columns(tw, batch)
                    C.events(tw, batch)
                    C.vibration_columns(tw, batch)
                    batch.breaks(C.scalar_paths(tw, slow=False), tw.time_offset_s, tw.prev_time_s)
                    triples += batch.out
                    tw.prev_time_s = rows[-1].time_s
                    if not tw.slow_rows:
                        tw.slow_since = now
                    tw.slow_rows.extend(rows)
                if tw.slow_rows and (force_slow or now - tw.slow_since >= self.slow_interval_s):
                    slow, tw.slow_rows = tw.slow_rows, []
                    batch = C.Batch.of(slow, tw.time_offset_s)
                    C.slow_columns(tw, batch)
                    batch.breaks(C.scalar_paths(tw, slow=True), tw.time_offset_s, tw.slow_prev_time_s)
                    tw.slow_prev_time_s = slow[-1].time_s
                    triples += batch.out
                for path, indexes, columns in triples:
                    for out in outs:
                        out.stream.send_columns(path, indexes=indexes, columns=columns)
                sent += len(rows)
                self._alarms_logged += len(alarm_rows)
            except Exception:
                self._errors += len(rows)
                log.exception("rerun recorder: %d rows of %s lost", len(rows), tw.bearing_id)
        if self._blueprint_dirty and outs:
            self._blueprint_dirty = False
            self._send_blueprint(outs)
        if not outs:
            return
        self._write_locked(sent, timeout_s)

    def _write_locked(self, rows: int, timeout_s: float) -> None:
        written_file = False
        has_file = False
        for out in (self._primary, self._extra):
            if out is None:
                continue
            if out.file is None:
                if out is self._primary:
                    has_file = True
                    self._discard(out)
                    self._rows_lost += rows
                    self._lost_since_fault += rows
                continue
            has_file = True
            try:
                out.file.write(timeout_s)
            except RecordingWriteError as exc:
                if out is self._primary:
                    self._on_write_error(out, exc, rows)
                else:                       # a start_file clip: closed where it stands
                    self._write_errors += 1
                    f, out.file = out.file, None
                    log.error("rerun: %s; the file %s is closed", exc, f.path)
                    f.close()
                    self._extra = None
                    self._close_output(out)
                continue
            out.rows += rows
            written_file = True
        if self._viewer is not None:
            self._viewer.rows += rows
        if written_file or (not has_file and self._viewer is not None):
            self._rows_logged += rows
