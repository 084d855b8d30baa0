"""`SegmentWriter`: the outputs of one recording, its main file in segments, and its write faults.

Outputs: the main file (in segments), at most one extra file (`start_extra` / `stop_extra`, its
own stream with the same recording id, complete on its own) and a spawned viewer; each has its
own `RecordingStream`, made through the shared `RerunStreams`. Whoever owns the writer fills the
streams (`send_columns`) and then calls `write(rows)`, which writes the files.

Segments. With `segment_s` and/or `segment_bytes` the main file is rotated: once the open segment
is that old [s of wall time] or that large [bytes], after a write, the main stream is pointed at
the next segment `<stem>-NNNN.rrd` (`service.recording.segments`); `on_start(output)` (the
owner) sends the static data and the blueprint into it again. Every row goes to exactly one
segment.

Faults. A write error (disk full, permission, I/O) on the main file is caught: the file is cut
back to its last complete write and closed, the writer becomes degraded with the reason
(`fault`), the rows of that write and of every write until it can write again are counted in
`rows_lost`, and every `retry_s` it tries to open the next segment; once that works it is ok again
and `on_resume(text)` tells the owner what was lost. A failed start (the constructor,
`start_extra`) raises and leaves nothing behind: the file it created is removed and its stream
dropped.
"""

from __future__ import annotations

import logging
import os
import socket
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import rerun as rr

from service.recording.compaction import compact
from service.recording.paths import CreatedFile, RecordingPathError, create_exclusive
from service.recording.retention import Retention
from service.recording.segments import DirectFile, RecordingWriteError, RerunFile, segment_path
from service.recording.streams import RerunStreams

log = logging.getLogger("service.recorder")

_ROTATION_RETRY_S = 10.0  # a failed rotation is retried this often [s], not at every write


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


@dataclass
class Output:
    """One rerun stream and where it goes (a file, a spawned viewer, a live server)."""

    stream: rr.RecordingStream | None
    file: DirectFile | RerunFile | None = None  # None: viewer, or a file that failed
    viewer: bool = False
    viewer_url: str | None = None  # a viewer's gRPC address (reconnected on renew)
    opened_at: float = field(default_factory=time.monotonic)  # monotonic [s]
    rows: int = 0  # snapshots written to this output (to this segment for the main file)
    null_sink: Any = None  # while the main file is degraded: an in-memory sink emptied after each send

    @property
    def path(self) -> Path | None:
        return self.file.path if self.file is not None else None


class SegmentWriter:
    """The outputs of one recording (see module doc): main file in segments, extra file, viewers."""

    def __init__(
        self,
        *,
        application_id: str,
        recording_id: str,
        streams: RerunStreams,
        on_start: Callable[[Output], None],
        on_resume: Callable[[str], None],
        segment_s: float | None = None,
        segment_bytes: int | None = None,
        write_footer: bool = False,
        retention: Retention | None = None,
        retry_s: float = 2.0,
        write_timeout_s: float = 30.0,
        compact_segments: bool = False,
    ):
        self.application_id = application_id
        self.recording_id = recording_id
        self.streams = streams
        self.on_start = on_start
        self.on_resume = on_resume
        self.segment_s = segment_s
        self.segment_bytes = segment_bytes
        self.write_footer = write_footer
        self.retention = retention
        self.retry_s = retry_s
        self.write_timeout_s = write_timeout_s
        self.compact_segments = compact_segments  # rewrite each closed file compacted (service.recording.compaction)
        self._compactions: list[threading.Thread] = []
        self.path: Path | None = None  # the main file's first segment
        self.viewers: list[Output] = []  # spawned viewer, live server
        self.primary: Output | None = None  # the main file's stream (its open segment in .file)
        self.extra: Output | None = None
        self.segments: list[Path] = []
        self.errors = 0
        self.write_errors = 0
        self.rows_lost = 0
        self.fault: str | None = None
        self._fault_since: float | None = None
        self._lost_since_fault = 0
        self._retry_at = 0.0
        self._rotation_failed_at: float | None = None

    # ---- outputs ----------------------------------------------------------------------------
    def new_stream(self) -> rr.RecordingStream:
        return self.streams.new_recording(self.application_id, self.recording_id)

    def outputs(self) -> list[Output]:
        return [o for o in (*self.viewers, self.primary, self.extra) if o is not None]

    def open_viewer(self, port: int) -> Output | None:
        """A stream to a viewer spawned on this machine (its own stream: the file segments rotate,
        the viewer's connection does not), or None (warned) when none can be spawned."""
        if not _display_available():
            log.warning("rerun: no display (DISPLAY/WAYLAND_DISPLAY unset): not spawning a viewer")
            return None
        stream = self.new_stream()
        try:
            stream.spawn(port=port, connect=False)
            if not _port_open(port):
                log.warning("rerun: the spawned viewer does not listen on port %d: continuing without it", port)
                return None
        except Exception as exc:  # noqa: BLE001 - no viewer on PATH, headless, ...: warn, go on
            log.warning(
                "rerun: could not spawn a viewer (%s): continuing without a viewer",
                str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__,
            )
            return None
        url = f"rerun+http://127.0.0.1:{port}/proxy"
        stream.connect_grpc(url)
        out = Output(stream=stream, viewer=True, viewer_url=url)
        self.viewers.append(out)
        return out

    def connect_viewer(self, url: str) -> Output:
        """An output to a running viewer or gRPC proxy at `url` (e.g. `LiveWebViewer.grpc_url`);
        it gets the static data and the blueprint now, and every row from now on."""
        stream = self.new_stream()
        stream.connect_grpc(url)
        out = Output(stream=stream, viewer=True, viewer_url=url)
        self.on_start(out)
        self.viewers.append(out)
        return out

    def _file_writer(self, created: CreatedFile, stream: rr.RecordingStream):
        return (RerunFile if self.write_footer else DirectFile)(created, stream)

    def open_file(self, created: CreatedFile) -> Output:
        """A new stream writing to `created`, which gets the static data and the blueprint and
        is written at once (so that a file that cannot be written fails here). On failure the
        file is removed and the stream dropped; raises RecordingWriteError."""
        stream = self.new_stream()
        out = Output(stream=stream)
        try:
            out.file = self._file_writer(created, stream)
            self.on_start(out)
            out.file.write(self.write_timeout_s)
        except BaseException:
            created.discard()
            out.file = None
            self.close_output(out)
            raise
        if self.retention is not None:
            self.retention.protect(created.path)
        return out

    def open_main(self, created: CreatedFile) -> None:
        self.path = created.path
        self.primary = self.open_file(created)
        self.segments.append(created.path)

    def close_output(self, out: Output, timeout_s: float = 30.0) -> None:
        """Write what is left, close the file, drop the stream (freed by `RerunStreams.reclaim`)."""
        if out.stream is None:
            return
        if out.file is not None:
            try:
                out.file.write(timeout_s)
            except RecordingWriteError as exc:
                self.write_errors += 1
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
            self._finished(out.file.path, background=False)
        out.stream = None

    def _finished(self, path: Path, background: bool) -> None:
        """A file closed complete: compact it (in the background after a rotation, here when
        the recording or a clip stops), then let retention have it."""
        if not self.compact_segments:
            if self.retention is not None:
                self.retention.release(path)
            return

        def run() -> None:
            try:
                compact(path)
            finally:
                if self.retention is not None:
                    self.retention.release(path)

        if not background:
            run()
            return
        self._compactions = [t for t in self._compactions if t.is_alive()]
        t = threading.Thread(target=run, name="rerun-compact", daemon=True)
        t.start()
        self._compactions.append(t)

    def close_all(self) -> None:
        for t in self._compactions:
            t.join()
        self._compactions = []
        for out in self.outputs():
            self.close_output(out)
        self.viewers, self.primary, self.extra = [], None, None

    def stop_extra(self) -> Path | None:
        out, self.extra = self.extra, None
        if out is None:
            return None
        path = out.path
        self.close_output(out)
        return path

    # ---- writing ----------------------------------------------------------------------------
    def write(self, rows: int, timeout_s: float | None = None) -> bool:
        """Write the files after a send of `rows` snapshots; True when they count as recorded
        (written to a file, or sent to a viewer when there is no file)."""
        timeout_s = self.write_timeout_s if timeout_s is None else timeout_s
        written_file = False
        has_file = False
        for out in (self.primary, self.extra):
            if out is None:
                continue
            if out.file is None:
                if out is self.primary:
                    has_file = True
                    self._discard(out)
                    self.rows_lost += rows
                    self._lost_since_fault += rows
                continue
            has_file = True
            try:
                out.file.write(timeout_s)
            except RecordingWriteError as exc:
                if out is self.primary:
                    self._on_write_error(out, exc, rows)
                else:  # a start_file clip: closed where it stands
                    self.write_errors += 1
                    f, out.file = out.file, None
                    log.error("rerun: %s; the file %s is closed", exc, f.path)
                    f.close()
                    self.extra = None
                    self.close_output(out)
                continue
            out.rows += rows
            written_file = True
        for out in self.viewers:
            out.rows += rows
        return written_file or (not has_file and bool(self.viewers))

    # ---- segments ---------------------------------------------------------------------------
    def rotation_due(self) -> bool:
        out = self.primary
        if out is None or out.file is None or out.rows == 0 or (self.segment_s is None and self.segment_bytes is None):
            return False
        now = time.monotonic()
        if self._rotation_failed_at is not None and now - self._rotation_failed_at < _ROTATION_RETRY_S:
            return False
        if self.segment_s is not None and now - out.opened_at >= self.segment_s:
            return True
        return self.segment_bytes is not None and out.file.size() >= self.segment_bytes

    def _next_segment(self) -> CreatedFile:
        assert self.path is not None  # the main file is open (open_main)
        index = len(self.segments)
        return create_exclusive(self.path.parent, segment_path(self.path, index).name, make_dirs=False)

    def rotate(self) -> Path | None:
        """Point the main file's stream at the next segment (the stream is kept: rerun-sdk 0.41
        never frees a stream, see `service.recording.streams`)."""
        out = self.primary
        # the caller checked that the main file is open (rotation_due, Recorder.rotate)
        assert out is not None and out.file is not None and out.stream is not None
        try:
            created = self._next_segment()
        except RecordingPathError as exc:
            self.errors += 1
            self._rotation_failed_at = time.monotonic()
            log.warning("rerun: could not open the next segment (%s): continuing in %s", exc, out.path)
            return None
        self._rotation_failed_at = None
        old = out.file
        try:
            old.write(self.write_timeout_s)  # nothing left, normally: the send wrote it
        except RecordingWriteError as exc:
            created.discard()
            self._on_write_error(out, exc, 0)
            return None
        old_rows = out.rows
        try:
            out.file = self._file_writer(created, out.stream)  # the stream's sink moves to the new file
        except BaseException:
            created.discard()
            raise
        old.close()
        self._finished(old.path, background=True)
        log.info("rerun: segment %s closed (%d snapshots), recording into %s", old.path, old_rows, created.path)
        return self._segment_opened(out, created)

    def _segment_opened(self, out: Output, created: CreatedFile) -> Path | None:
        file = out.file
        assert file is not None  # the caller just opened it
        out.rows, out.opened_at = 0, time.monotonic()
        try:
            self.on_start(out)
            file.write(self.write_timeout_s)
        except RecordingWriteError as exc:
            file.discard()
            self._on_write_error(out, exc, 0, discarded=True)
            return None
        self.segments.append(created.path)
        if self.retention is not None:
            self.retention.protect(created.path)
            try:
                self.retention.apply()
            except Exception:
                log.exception("retention failed")
        return created.path

    # ---- faults -----------------------------------------------------------------------------
    def _on_write_error(self, out: Output, exc: BaseException, rows: int, *, discarded: bool = False) -> None:
        """The main file could not be written: close it (cut back to its last complete write,
        removed if empty), count, degrade, retry later with a new segment."""
        self.write_errors += 1
        self.rows_lost += rows
        if self.fault is None:
            self._fault_since = time.monotonic()
            self._lost_since_fault = 0
        self._lost_since_fault += rows
        self.fault = f"recording write failed: {exc}"
        log.error(
            "rerun: %s; %d snapshots lost so far, retrying every %.0f s", self.fault, self.rows_lost, self.retry_s
        )
        f = out.file
        out.file = None
        if f is not None and not discarded:
            try:
                if f.size() == 0:
                    f.discard()  # this writer's own empty file
                else:
                    f.close()
            except OSError:
                pass
            if self.retention is not None:
                self.retention.release(f.path)
        self._sink_to_nowhere(out)
        self._retry_at = time.monotonic() + self.retry_s

    def _sink_to_nowhere(self, out: Output) -> None:
        """While degraded the stream still gets every send: an in-memory sink that is emptied
        after each send (`_discard`) keeps its memory flat."""
        if out.stream is None:  # a closed output has no sink to replace
            out.null_sink = None
            return
        try:
            out.null_sink = rr.binary_stream(out.stream)  # replaces (and so ends) the failed sink
        except Exception:  # noqa: BLE001
            out.null_sink = None

    def _discard(self, out: Output) -> None:
        storage = out.null_sink
        if storage is not None:
            try:
                storage.read(flush=True, flush_timeout_sec=self.write_timeout_s)
            except Exception:  # noqa: BLE001
                pass

    def retry(self, closed: bool = False) -> None:
        """While degraded and the retry is due: open the next segment of the main file."""
        out = self.primary
        if out is None or out.file is not None or time.monotonic() < self._retry_at or closed:
            return
        assert out.stream is not None  # a degraded main file keeps its stream (_sink_to_nowhere)
        self._retry_at = time.monotonic() + self.retry_s
        try:
            created = self._next_segment()
        except RecordingPathError as exc:
            self.fault = f"recording write failed, and a new segment cannot be created: {exc}"
            return
        self._discard(out)
        out.null_sink = None
        try:
            out.file = self._file_writer(created, out.stream)
        except BaseException as exc:  # noqa: BLE001
            created.discard()
            out.file = None
            self._sink_to_nowhere(out)
            self.fault = f"recording write failed, retry failed: {exc}"
            return
        if self._segment_opened(out, created) is None:
            return  # still failing: _on_write_error ran again
        lost, since = self._lost_since_fault, self._fault_since
        assert since is not None  # set with the fault (_on_write_error)
        log.warning("rerun: recording again into %s after %s (%d snapshots lost)", created.path, self.fault, lost)
        self.on_resume(f"recording resumed after {time.monotonic() - since:.0f} s: {lost} snapshots were not written")
        self.fault = None
        self._fault_since = None

    # ---- fresh streams ----------------------------------------------------------------------
    def renew_streams(self) -> bool:
        """Move every output that can to a fresh stream of the same recording (files written
        directly continue where they are; a viewer is connected again); the old streams are
        dropped for `RerunStreams.reclaim`. Outputs written by rerun's own file sink (footer on),
        keep their stream."""
        renewed = False
        for out in self.outputs():
            if out.stream is None or (out.file is not None and out.file.rebind is None):
                continue
            old = out.stream
            if out.file is not None:
                try:
                    out.file.write(self.write_timeout_s)
                except RecordingWriteError as exc:
                    if out is self.primary:
                        self._on_write_error(out, exc, 0)
                    continue
            stream = self.new_stream()
            if out.file is not None:
                out.file.rebind(stream)
            elif out.viewer:
                stream.connect_grpc(out.viewer_url)
            else:  # degraded main file: a sink emptied after each send
                out.stream = stream
                self._sink_to_nowhere(out)
            out.stream = stream  # (the file and the viewer have the static data)
            try:
                old.disconnect()
            except Exception as exc:  # noqa: BLE001 - only keeps the old stream alive
                log.warning("rerun: disconnect of a replaced stream failed: %s", exc)
            renewed = True
        return renewed
