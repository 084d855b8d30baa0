"""Segments of a recording and the files they are written to.

Naming (`service.recording.names`). Segment 0 of the recording `name.rrd` is `name.rrd` itself, then
`name-0001.rrd`, `name-0002.rrd`, ... in the same folder (`segment_path`, `recording_segments`). Every
segment is a complete recording on its own (static data, series styles and blueprint first, then its rows;
the same application and recording id, so `rerun name.rrd name-0001.rrd ...` shows one
recording).

Files. A segment is written by one of two writers, both on a file this process created
exclusively (`service.recording.paths.create_exclusive`):

* `DirectFile` (the default, no RRD footer): the rerun stream's sink is an in-memory binary
  stream; after every send the recorder reads its bytes and writes them itself with `os.write`,
  so a write error (disk full, permission, I/O) is an `OSError` at once, the rows of that send are
  known not to be written, and the file is cut back to the end of the last complete write (it
  stays a valid RRD stream). rerun-sdk 0.41 encodes every read of a binary stream as a complete
  RRD stream (stream header, messages, an End message carrying that read's RRD footer, stream
  footer); the file keeps the stream header of the first read and, of every read, the messages
  up to the End message: one footerless stream, byte for byte what rerun's own file sink writes
  with `write_footer=False` (`_RrdFraming`). No writer thread.
* `RerunFile` (`write_footer=True`): rerun's own file sink writes the file, opened through
  `/proc/self/fd/<fd>` (the very file created here, not whatever the name points at later), and
  writes the footer (chunk manifest) when the segment closes. A write error stops rerun's writer
  thread; the recorder sees it as a failed flush.
"""

from __future__ import annotations

import logging
import os
import struct
import sys
import warnings

from service.recording.names import is_segment_of, numbered_segments, recording_segments, segment_path
from service.recording.paths import CreatedFile

__all__ = [
    "DirectFile",
    "RecordingWriteError",
    "RerunFile",
    "is_segment_of",
    "numbered_segments",
    "recording_segments",
    "segment_path",
]

log = logging.getLogger("service.recording")


class RecordingWriteError(OSError):
    """Writing a recording failed (the message names the file and the reason)."""


# ---- RRD framing (rerun-sdk 0.41, re_log_encoding rrd::frames) ----------------------------------
_FOURCC = b"RRF2"
_STREAM_HEADER = 12  # fourcc, version, encoding options
_MESSAGE_HEADER = struct.Struct("<QQ")  # kind, payload length
_KIND_END = 0


class _RrdFraming:
    """Turns the complete RRD streams that every binary-stream read yields into one footerless
    stream: the first read keeps its stream header, every read keeps its messages up to (not
    including) the End message; the End message (it carries the read's RRD footer) and the
    stream footer are left out. A read that does not look like that (another rerun version) is
    written as it is (a concatenation of complete streams, which rerun's streaming decoders
    read too) and this is logged once."""

    _warned = False

    def payload(self, data: bytes, first: bool) -> memoryview:
        view = memoryview(data)
        if len(data) < _STREAM_HEADER or data[:4] != _FOURCC:
            return self._raw(view, "no RRD stream header")
        off = _STREAM_HEADER
        n = len(data)
        while off + _MESSAGE_HEADER.size <= n:
            kind, length = _MESSAGE_HEADER.unpack_from(data, off)
            if kind == _KIND_END:
                return view[:off] if first else view[_STREAM_HEADER:off]
            off += _MESSAGE_HEADER.size + length
            if off > n:
                return self._raw(view, "a message runs past the end of the read")
        return self._raw(view, "no End message")

    def _raw(self, view: memoryview, why: str) -> memoryview:
        if not _RrdFraming._warned:
            _RrdFraming._warned = True
            log.warning(
                "rerun: unexpected RRD framing (%s): writing complete streams one after "
                "the other (readable by the viewer, not by RrdReader)",
                why,
            )
        return view


def _write_all(fd: int, data: memoryview) -> None:
    while data:
        n = os.write(fd, data)
        data = data[n:]


class DirectFile:
    """One segment written from the stream's in-memory binary sink (module doc)."""

    footer = False

    def __init__(self, created: CreatedFile, stream) -> None:
        self.created = created
        self.path = created.path
        self.bytes = 0
        self._framing = _RrdFraming()
        self._storage = stream.binary_stream()  # the stream's sink from now on

    def write(self, timeout_s: float) -> int:
        """Write what the stream sent since the last call; returns bytes written. Raises
        RecordingWriteError (the file is cut back to its last complete write)."""
        try:
            data = self._storage.read(flush=True, flush_timeout_sec=timeout_s)
        except Exception as exc:  # noqa: BLE001 - rerun raises RuntimeError on a flush timeout
            raise RecordingWriteError(f"rerun did not hand over the data for {self.path}: {exc}") from None
        if not data:
            return 0
        payload = self._framing.payload(data, first=self.bytes == 0)
        good = self.bytes
        try:
            _write_all(self.created.fd, payload)
        except OSError as exc:
            try:
                os.ftruncate(self.created.fd, good)
            except OSError:
                pass
            raise RecordingWriteError(exc.errno, f"{exc.strerror or exc} (writing {self.path})") from None
        self.bytes += len(payload)
        return len(payload)

    def size(self) -> int:
        return self.bytes

    def rebind(self, stream) -> None:
        """Continue this file from another stream of the same recording (write everything sent
        to the old one first): its sink is a new binary stream whose first read starts with a
        stream header (left out: the file has one) and the store info (kept)."""
        self._storage = stream.binary_stream()

    def detach(self, stream) -> None:
        """Nothing to hand back: the next writer (or `disconnect`) replaces the sink; bytes
        left in this one belong to nothing any more (everything sent was written)."""

    def close(self) -> None:
        try:
            if self.created.fd >= 0:
                os.fsync(self.created.fd)
        except OSError:
            pass
        self.created.close()

    def discard(self) -> None:
        self.created.discard()


class RerunFile:
    """One segment written by rerun's own file sink, with the RRD footer (module doc)."""

    footer = True
    rebind = None  # rerun's file sink cannot continue a file from another stream

    def __init__(self, created: CreatedFile, stream) -> None:
        self.created = created
        self.path = created.path
        target = f"/proc/self/fd/{created.fd}" if sys.platform.startswith("linux") else str(created.path)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            stream.save(target, write_footer=True)
        self._stream = stream

    def write(self, timeout_s: float) -> int:
        before = self.size()
        try:
            self._stream.flush(timeout_sec=timeout_s)
        except Exception as exc:  # noqa: BLE001 - a dead writer thread shows as a flush timeout
            raise RecordingWriteError(f"rerun could not write {self.path}: {exc}") from None
        return self.size() - before

    def size(self) -> int:
        try:
            return os.fstat(self.created.fd).st_size
        except OSError:
            return 0

    def detach(self, stream) -> None:
        """The sink is replaced by the next `save()` / `disconnect()`, which writes the footer
        and closes rerun's own descriptor."""

    def close(self) -> None:
        self.created.close()

    def discard(self) -> None:
        self.created.discard()
