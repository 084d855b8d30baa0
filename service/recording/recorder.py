"""`RerunRecorder`: a `SnapshotSink` that records one or more twins into one rerun recording.

One module for one facade: its length is this contract and the one-line properties that forward to
the two parts doing the work, so a split would scatter one public surface.

A thin facade over two parts: `service.recording.batcher.RowBatcher` (the queues the publishers
fill, drop-oldest, and the rows per twin) and `service.recording.writer.SegmentWriter` (the
outputs, segment rotation, write faults and retry). The runner thread calls `publish(snapshot)`,
which only appends to a bounded queue and returns. A background thread drains the queue into rows
of plain numbers and, every `flush_interval_s` (1 s by default), sends what it buffered with
`send_columns`: one call, hence one rerun chunk, per entity and send, all rows of that interval
in it (`service.recording.layout` lists the entities; the per-contact series go out every
`slow_interval_s`). Then it writes the file (`service.recording.segments.DirectFile`).

Outputs: the file given to the constructor (in segments) and/or a spawned viewer (each its own
`RecordingStream`), plus at most one extra file opened with `start_file` and closed with
`stop_file` (its own stream with the same recording id, complete on its own), plus viewers it
sends to (`connect_viewer`, e.g. the live web viewer of `service.recording.live`). Nothing here
listens on the network; a spawned viewer, or rerun's web viewer server, listens in its own process.

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
import threading
import time
import uuid
from collections.abc import Callable
from pathlib import Path
from typing import Any, Self

from service.recording.archive import WaveformArchive
from service.recording.batcher import RowBatcher, TwinRows
from service.recording.blueprint import blueprint
from service.recording.paths import CreatedFile, RecordingPathError, create_recording
from service.recording.retention import Retention
from service.recording.segments import RecordingWriteError, is_segment_of
from service.recording.streams import BlueprintSender, RerunStreams
from service.recording.writer import Output, SegmentWriter

log = logging.getLogger("service.recorder")


class RerunRecorder:
    """Records the snapshots of one or more twins into one rerun recording (see module doc).

    Usage::

        rec = RerunRecorder("run.rrd")
        rec.add_twin_from(twin)            # or add_twin("a", designation=..., pitch_radius_m=..., ...)
        rec.publish(twin.snapshot())       # never blocks
        rec.start_file("clip.rrd"); ...; rec.stop_file()
        rec.close()                        # drains, sends, writes, closes
    """

    # what the service's recordings keep (`service.wiring.recorder_options`, the offline scenario
    # runner): a trend row per 0.2 s of simulated time (mean, min, max of its 10 snapshots at
    # 50 Hz), the bearing now (3D, load zone) every 0.5 s, the per-contact series every 1 s, the
    # accelerometer's samples in bursts and around events and the spectra every 30 s
    # (`service.recording.archive`), each closed file compacted
    SERVICE_OPTIONS: dict[str, Any] = {
        "trend_window_s": 0.2,
        "now_interval_s": 0.5,
        "contacts_interval_s": 1.0,
        "waveform_archive": WaveformArchive(),
        "compact_segments": True,
    }

    def __init__(
        self,
        path: str | Path | CreatedFile | None = None,
        *,
        spawn_viewer: bool = False,
        application_id: str = "bearing-twin",
        flush_interval_s: float = 1.0,
        slow_interval_s: float = 5.0,
        queue_size: int = 512,
        viewer_port: int = 9876,
        series_window_s: float | None = None,
        min_interval_s: float = 0.0,
        segment_s: float | None = None,
        segment_bytes: int | None = None,
        write_footer: bool = False,
        streams: RerunStreams | None = None,
        rename_existing: bool = True,
        retention: Retention | None = None,
        retry_s: float = 2.0,
        write_timeout_s: float = 30.0,
        trend_window_s: float | None = None,
        now_interval_s: float = 0.0,
        waveform_archive: WaveformArchive | None = None,
        compact_segments: bool = False,
        contacts_interval_s: float = 0.0,
    ):
        """`path`: the main file (None: none); taken -> `<stem>.runN.rrd` with `rename_existing`,
        else RecordingPathError; or a `CreatedFile` made by the caller (`create_exclusive`), which
        the recorder then owns (removed again if the start fails). `flush_interval_s` [s]: send
        (one chunk per entity) and write this often; `slow_interval_s` [s]: the same for the
        per-contact series. `series_window_s` [s of simulated time]: the span the trend views
        show (None: the whole run). `segment_s` [s of wall time] / `segment_bytes` [bytes]: rotate
        the main file (None or 0 = never). `write_footer`: end every file with rerun's footer
        (rerun's own file sink writes it; memory grows with the open segment). `streams`: makes
        and frees this recorder's rerun streams (shared by the recorders of a service).
        `retention`: applied after each new segment. `retry_s` [s]: after a write error, try a new
        segment this often. `trend_window_s` [s of simulated time]: the trends are a row per such
        window (mean, min, max: `service.recording.trends`; None: a row per snapshot, no bands);
        `now_interval_s` [s of simulated time]: the 3D, load-zone and per-contact entities get
        one snapshot per such interval (0: every snapshot), the per-contact series one per
        `contacts_interval_s` [s of simulated time]. `waveform_archive`: which
        accelerometer samples the files keep (`service.recording.archive`; None: all, viewers
        always get all). `compact_segments`: rewrite every file once closed with fewer, larger
        chunks and rerun's footer (`service.recording.compaction`). The service records with all
        four (`SERVICE_OPTIONS`); the defaults keep every snapshot and sample, as sent."""
        if trend_window_s is not None and not (trend_window_s > 0.0 and math.isfinite(trend_window_s)):
            raise ValueError(f"trend_window_s = {trend_window_s!r}: must be finite and > 0")
        for name, value in (("now_interval_s", now_interval_s), ("contacts_interval_s", contacts_interval_s)):
            if not (value >= 0.0 and math.isfinite(value)):
                raise ValueError(f"{name} = {value!r}: must be finite and >= 0")
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
        self.application_id = application_id
        self.recording_id = uuid.uuid4().hex
        self.flush_interval_s = float(flush_interval_s)
        self.queue_size = int(queue_size)
        self.series_window_s = series_window_s
        self.viewer_port = viewer_port
        self._streams = streams if streams is not None else RerunStreams()
        self._io_lock = threading.RLock()
        self._wake = threading.Event()
        self._stop = threading.Event()
        self._closed = False
        self._rows_logged = 0
        self._errors = 0
        self._blueprint_dirty = False
        self._thread: threading.Thread | None = None
        self._blueprints = BlueprintSender(application_id, self._streams)
        self._rows = RowBatcher(
            queue_size=self.queue_size,
            slow_interval_s=max(float(slow_interval_s), self.flush_interval_s),
            min_interval_s=float(min_interval_s),
            wake=self._wake,
            trend_window_s=trend_window_s,
            now_interval_s=float(now_interval_s),
            waveform_archive=waveform_archive,
            contacts_interval_s=float(contacts_interval_s),
        )
        self._out = SegmentWriter(
            application_id=application_id,
            recording_id=self.recording_id,
            streams=self._streams,
            on_start=self._start_output,
            on_resume=self._rows.note_all,
            segment_s=float(segment_s) if segment_s else None,
            segment_bytes=int(segment_bytes) if segment_bytes else None,
            write_footer=bool(write_footer),
            retention=retention,
            retry_s=float(retry_s),
            write_timeout_s=float(write_timeout_s),
            compact_segments=bool(compact_segments),
        )
        try:
            if spawn_viewer:
                self._out.open_viewer(self.viewer_port)
            if isinstance(path, CreatedFile):
                self._out.open_main(path)
            elif path is not None:
                created = create_recording(path, rename=rename_existing)
                if created.path != Path(path):
                    log.warning("rerun: %s exists (an earlier run): recording beside it to %s", path, created.path)
                self._out.open_main(created)
        except BaseException:
            self._abandon()
            raise
        self._thread = threading.Thread(target=self._run, name="rerun-recorder", daemon=True)
        self._thread.start()

    def _abandon(self) -> None:
        """Free everything a failed constructor made (its files are already removed)."""
        self._closed = True
        self._out.close_all()
        self._blueprints.close()
        self._streams.reclaim()

    # ---- settings, read back ----------------------------------------------------------------
    @property
    def path(self) -> Path | None:
        """The main file (its first segment); None without one."""
        return self._out.path

    @property
    def segment_s(self) -> float | None:
        return self._out.segment_s

    @property
    def segment_bytes(self) -> int | None:
        return self._out.segment_bytes

    @property
    def write_footer(self) -> bool:
        return self._out.write_footer

    @property
    def retention(self) -> Retention | None:
        return self._out.retention

    @property
    def slow_interval_s(self) -> float:
        return self._rows.slow_interval_s

    @property
    def min_interval_s(self) -> float:
        return self._rows.min_interval_s

    @property
    def retry_s(self) -> float:
        return self._out.retry_s

    @property
    def write_timeout_s(self) -> float:
        return self._out.write_timeout_s

    @property
    def _context(self) -> dict[str, Callable[[], Any]]:
        return self._rows.context

    # ---- outputs ----------------------------------------------------------------------------
    def _start_output(self, out: Output) -> None:
        """Static data of every twin, event state reset, blueprint (if there are twins)."""
        self._rows.start_output(out.stream)
        self._send_blueprint([out])

    def connect_viewer(self, url: str) -> None:
        """Also send everything from now on to the viewer or gRPC proxy at `url` (e.g. the live
        web viewer's, `service.recording.live`); it gets the static data and the blueprint first."""
        with self._io_lock:
            self._drain_locked()
            self._send_locked(force_slow=True)
            self._out.connect_viewer(url)

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
            self._send_locked(force_slow=True)  # rows published before start_file go to the old outputs only
            replaced = self._out.extra is not None
            if replaced:
                self._out.stop_extra()
            created = create_recording(path, rename=False)
            try:
                self._out.extra = self._out.open_file(created)
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
            if self._out.extra is None:
                return None
            self._drain_locked()
            self._send_locked(force_slow=True)
            path = self._out.stop_extra()
        self._streams.reclaim()  # outside the lock: it flushes every stream
        return path

    @property
    def recording_file(self) -> Path | None:
        """The file being recorded with `start_file`, if any."""
        out = self._out.extra
        return out.path if out is not None else None

    @property
    def segments(self) -> list[Path]:
        """The segments of the main file opened so far, in order (the last one is being written
        unless the recorder is closed or degraded); [] without a main file."""
        return list(self._out.segments)

    @property
    def current_path(self) -> Path | None:
        """The segment of the main file being written (None without a main file, once closed,
        or while degraded)."""
        out = self._out.primary
        return out.path if out is not None else None

    def rotate(self) -> Path | None:
        """Close the open segment of the main file now (everything published so far is in it) and
        open the next one; returns the new segment's path (None without a main file, or if it
        could not be opened)."""
        with self._io_lock:
            primary = self._out.primary
            if self._closed or primary is None or primary.file is None:
                return None
            self._drain_locked()
            self._send_locked(force_slow=True)
            if primary.file is None:  # the send just failed
                return None
            return self._out.rotate()

    # ---- the sink ---------------------------------------------------------------------------
    accepts_frames = True  # rows are read from a frame's arrays (service.recording.columns.extract)

    def publish(self, snapshot, positions_m: Any = None) -> None:
        """Queue a snapshot (and optionally the ball centres, shape (Z, 3) [m]); never blocks.
        When the queue is full the oldest queued snapshot is dropped and counted."""
        if self._closed:
            with self._rows.qlock:
                self._rows.dropped += 1
            return
        self._rows.publish(snapshot, positions_m)

    def log_alarm(self, event) -> None:
        """Queue an alarm event (`service.core.alarms.AlarmEvent`, or its dict) for the twin's
        `alarms/{alarm_id}` and `alarm_states/{alarm_id}` entities (`service.recording.layout`);
        never blocks or raises (an alarm-hub subscriber). Events of a twin this recorder does not
        record are left out; when `queue_size` events wait, the oldest is dropped and counted."""
        if not self._closed:
            self._rows.log_alarm(event)

    def log_measured(self, comparison: dict) -> None:
        """Queue a measured-window comparison (service.core.measured) for the twin's
        `vibration/measured/...` entities (`alarm_columns.measured_columns`); never blocks or raises.
        When `queue_size` wait, the oldest is dropped."""
        if not self._closed and isinstance(comparison, dict):
            self._rows.log_measured(comparison)

    def publish_waveform(self, bearing_id: str, blocks: list, seq: int | None = None) -> None:
        """Queue accelerometer blocks (twin.accelerometer.WaveformBlock) of a twin for
        `vibration/acceleration_m_s2`, at the `seq` of the snapshot they came with (by default
        the last one queued); never blocks or raises. When `queue_size` batches wait, the oldest
        is dropped and counted (`waveform_dropped`)."""
        if not self._closed:
            self._rows.publish_waveform(bearing_id, blocks, seq)

    # ---- counters and health ----------------------------------------------------------------
    @property
    def waveform_dropped(self) -> int:
        """Batches of accelerometer samples dropped because their queue was full."""
        return self._rows.waveform_dropped

    @property
    def alarms_logged(self) -> int:
        """Alarm events sent to the outputs."""
        return self._rows.alarms_logged

    @property
    def alarms_dropped(self) -> int:
        """Alarm events dropped because their queue was full."""
        return self._rows.alarms_dropped

    @property
    def dropped(self) -> int:
        """Snapshots dropped because the queue was full (or published after close)."""
        return self._rows.dropped

    @property
    def rows_logged(self) -> int:
        """Snapshots written: to a file when the recorder has one (never counting those a write
        error lost), else sent to the viewer."""
        return self._rows_logged

    @property
    def errors(self) -> int:
        """Snapshots, sends, writes or rotations that failed (logged, never raised into the physics)."""
        return self._errors + self._rows.errors + self._out.errors + self._out.write_errors

    @property
    def skipped(self) -> int:
        """Snapshots left out on purpose: closer than `min_interval_s` of simulated time to the
        previous recorded one of the same twin, or published while there was no output."""
        return self._rows.skipped

    @property
    def queued(self) -> int:
        return self._rows.queued

    @property
    def closed(self) -> bool:
        return self._closed

    @property
    def fault(self) -> str | None:
        """Why the main file is not being written now (None when it is)."""
        return self._out.fault

    @property
    def status(self) -> str:
        return "degraded" if self._out.fault is not None else "ok"

    @property
    def write_errors(self) -> int:
        """Writes (or flushes) of a recording file that failed."""
        return self._out.write_errors

    @property
    def rows_lost(self) -> int:
        """Snapshots that were sent but could not be written to the main file."""
        return self._out.rows_lost

    def health(self) -> dict:
        return {
            "status": self.status,
            "error": self.fault,
            "path": str(self.path) if self.path else None,
            "current": str(self.current_path) if self.current_path else None,
            "rows": self._rows_logged,
            "rows_lost": self.rows_lost,
            "write_errors": self.write_errors,
            "dropped": self.dropped,
            "segments": len(self._out.segments),
        }

    # ---- flushing and closing ---------------------------------------------------------------
    def flush(self, timeout_s: float = 30.0) -> None:
        """Send and write everything queued or buffered now (the per-contact series too); then
        rotate the main file if its segment is due, or retry a failed one."""
        with self._io_lock:
            self._drain_locked()
            self._send_locked(force_slow=True, timeout_s=timeout_s)
            if not self._closed:
                self._rotate_if_due_locked()
                self._out.retry(self._closed)

    def close(self) -> None:
        """Drain the queue, send and write the rest, close every output (idempotent)."""
        with self._rows.qlock:
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
            self._out.close_all()
            self._blueprints.close()
            self._rows.twins.clear()
            self._rows.context.clear()
        self._streams.reclaim()  # free this recorder's streams (service.recording.streams)

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
                        self._rotate_if_due_locked()
                        self._out.retry(self._closed)
                        next_send = time.monotonic() + self.flush_interval_s
            except Exception:  # never let the worker die
                self._errors += 1
                log.exception("rerun recorder: send failed")

    def _rotate_if_due_locked(self) -> None:
        """Rotate the main file if its segment is due and a twin is registered: a segment opened
        with no twin would hold neither static geometry nor blueprint (after the last twin is
        removed, as at shutdown, the open segment stays the last one)."""
        if self._rows.twins and self._out.rotation_due():
            self._out.rotate()

    def _drain_locked(self) -> None:
        self._rows.drain(bool(self._out.outputs()))

    def _send_locked(self, force_slow: bool = False, timeout_s: float | None = None) -> None:
        """Send the buffered rows of every twin (and the blueprint if due) to every output, then
        write the files; count what was written."""
        outs = self._out.outputs()
        sent = self._rows.send(outs, force_slow)
        if self._blueprint_dirty and outs:
            self._blueprint_dirty = False
            self._send_blueprint(outs)
        if not outs:
            return
        if self._out.write(sent, timeout_s):
            self._rows_logged += sent

    # ---- twins ------------------------------------------------------------------------------
    def add_twin(
        self,
        bearing_id: str,
        *,
        designation: str,
        pitch_radius_m: float,
        ball_radius_m: float,
        inner_raceway_radius_m: float,
        outer_raceway_radius_m: float,
        ball_count: int,
        load_scale_m_per_n: float | None = None,
        context: Callable[[], Any] | None = None,
        vibration: bool = False,
    ) -> None:
        """Register a twin: its static geometry goes out now, the blueprint with the next send.
        `load_scale_m_per_n`: arrow length per newton of contact load; by default the largest load
        of the first loaded snapshot is drawn one ball diameter long. `context`: called with each
        `publish` (on the publishing thread) for the twin's scenario handle (name, state, phase),
        whose changes are logged as events."""
        tw = TwinRows(
            bearing_id=str(bearing_id),
            designation=str(designation),
            ball_count=int(ball_count),
            pitch_radius_m=float(pitch_radius_m),
            ball_radius_m=float(ball_radius_m),
            inner_raceway_radius_m=float(inner_raceway_radius_m),
            outer_raceway_radius_m=float(outer_raceway_radius_m),
            load_scale_m_per_n=load_scale_m_per_n,
            vibration=bool(vibration),
        )
        with self._io_lock:
            self._rows.register(tw, context, self._out.outputs())
            self._blueprint_dirty = True

    def add_twin_from(self, twin, bearing_id: str | None = None, *, context: Callable[[], Any] | None = None) -> None:
        """`add_twin` with the geometry of a `twin.engine.Twin`."""
        m = twin.model
        g = m.spec.geometry
        self.add_twin(
            bearing_id or twin.bearing_id,
            designation=m.spec.designation,
            pitch_radius_m=m.pitch_radius_m,
            ball_radius_m=m.ball_radius_m,
            inner_raceway_radius_m=g.inner_raceway_radius_m,
            outer_raceway_radius_m=g.outer_raceway_radius_m,
            ball_count=m.ball_count,
            context=context,
            vibration=bool(getattr(m, "housing_on", False)),
        )

    def remove_twin(self, bearing_id: str) -> bool:
        """Forget a twin (its runner has stopped): what it published is sent and written first,
        then its entry, context and buffers are dropped, and the outputs move to fresh rerun
        streams (rerun-sdk keeps state for every entity path a stream has seen: the old streams,
        and that state, are freed). A twin created later under the same id continues on
        `sim_time` after this one (1 s later), with a line break. Returns whether it was known."""
        with self._io_lock:
            self._rows.context.pop(bearing_id, None)
            if bearing_id not in self._rows.twins:
                return False
            if not self._closed:
                self._drain_locked()
                self._send_locked(force_slow=True)
            self._rows.forget(bearing_id)
            self._blueprint_dirty = bool(self._rows.twins)
            renewed = not self._closed and self._out.renew_streams()
        if renewed:
            self._streams.reclaim()
        return True

    @property
    def bearing_ids(self) -> list[str]:
        return list(self._rows.twins)

    # ---- blueprint --------------------------------------------------------------------------
    def blueprint(self, live: bool = False):
        """The default layout (`service.recording.blueprint.blueprint`); `live`: for a viewer (the
        time cursor follows the newest data), else for a file."""
        return blueprint(list(self._rows.twins.values()), self.series_window_s, live=live)

    def _send_blueprint(self, outs: list[Output]) -> None:
        if not outs or not self._rows.twins:
            return
        layouts: dict[bool, Any] = {}
        for out in outs:
            if out.stream is None:  # a closed output
                continue
            if out.viewer not in layouts:
                layouts[out.viewer] = self.blueprint(live=out.viewer)
            self._blueprints.send(layouts[out.viewer], out.stream)
