"""`RerunRecorder`: a `SnapshotSink` that records one or more twins into one rerun recording.

The runner thread calls `publish(snapshot)`, which only appends to a bounded queue (drop-oldest,
counted in `dropped`) and returns. A background thread drains the queue, converts snapshots to
plain numbers and, every `flush_interval_s`, sends what it buffered with `send_columns` (one call
per entity, all buffered rows at once: per-row `log` is orders of magnitude dearer).

Entities (per twin `bearing/{id}/...`, timelines `sim_time` (duration, seconds from
`snapshot.time_s`) and `seq` (sequence, `snapshot.seq`)):

```
geometry/inner_raceway, geometry/outer_raceway, geometry/pitch_circle   LineStrips3D, static
geometry/load_line                                Arrows3D, static (azimuth 0 = radial load line)
balls                  Points3D at the ball centres, radius = ball radius, colour = inner regime
loads/inner, loads/outer       Arrows3D from the ball centre towards the raceway, length ~ load
ball/{i}/inner/load_n, .../inner/lambda, .../inner/mu, same for outer          Scalars
ball/{i}/inner/resistance_ohm, .../capacitance_f, ball/{i}/resistance_ohm, ...  Scalars, when the
                                                                        snapshot carries them
electrical/{field}     Scalars from `snapshot.electrical` (numeric fields), when present
electrical/discharge_risk  TextLog "risk: reason", one row whenever it changes
friction_torque_n_m, cage_speed_rad_s                                           Scalars
status                 TextLog, one row whenever the status text changes
```

A value that is null (Lambda without contact, electrical fields not yet modelled) is simply not
logged for that row, so a series has one row per snapshot where it is defined.

Outputs: the file given to the constructor (in segments, below) and/or a spawned viewer (each its
own `RecordingStream`), plus at most one extra file opened with `start_file` and closed with
`stop_file` (its own `RecordingStream` with the same recording id, so it is complete on its own:
static geometry, blueprint, and every row published while it was open). Nothing listens on the
network unless `spawn_viewer=True` (and then only the spawned viewer does); `serve_grpc` is never
called.

Segments. With `segment_s` and/or `segment_bytes` the main file is rotated: once the open segment
is that old [s of wall time] or that large [bytes on disk], after a send, the recorder flushes its
stream and points it at the next segment (the old file sink writes its end and closes the file;
the stream itself is kept, rerun-sdk never frees one), so every segment is complete on its
own (static geometry, series styles and blueprint first, then its rows; the same application and
recording id, so `rerun name.rrd name-0001.rrd ...` shows one recording). Segment 0 is the path
given (`name.rrd`), then `name-0001.rrd`, `name-0002.rrd`, ... in the same folder (`segment_path`,
`recording_segments`; when rotation is on, stale `name-NNNN.rrd` files of an earlier recording
to the same name are removed when the recorder opens, as `name.rrd` itself is overwritten). Every row goes to exactly
one segment: nothing is lost or doubled at a rotation, and `close()` (the service's SIGTERM path)
closes the open one. Read a segmented recording with `read_recording(recording_segments(path))`
(every reader here takes a path or a list of paths).

Memory. rerun-sdk 0.41's file sink keeps an entry of the RRD footer (the chunk manifest) in native
memory for every chunk written until the file is closed (about 1 kB per chunk, nearly as much as
the file grows; one chunk per entity per send: 128 per send for one 6208 twin with its electrical
series, 1280 chunks/s at `flush_interval_s` 0.1, about 1 MB/s): that is the growth of rerun issue
#12623. `write_footer=False` writes no footer and the
memory stays flat (the file is a valid RRD stream: the viewer and `RrdReader.stream()` read it,
`rerun rrd optimize` adds the footer afterwards); with the footer, segments bound the memory to
that of one segment (freed when it closes).

Freeing streams. rerun-sdk 0.41 keeps every `RecordingStream` (and its 2 threads, ~1-2 MB) in
a native list until `rerun_bindings.flush_and_cleanup_orphaned_recordings()` runs (rerun issue
#2116; `rr.init` calls it, nothing else does), so a stream per output would leak on a service
where clips are started and stopped for weeks. A stream cannot be re-pointed at another
recording id (the id is fixed at creation), so clips do not share pooled streams: two clips
with one id would merge into one recording in the viewer. Instead every stream is made through
a `RerunStreams` (one per service, or one per recorder) and, once its file is closed (flushed,
`disconnect()` writes the footer) and the recorder has dropped it, `RerunStreams.reclaim()`
runs that cleanup: the stream's threads are joined and its memory freed. The cleanup flushes
every stream of the process (blocking) and clears rerun's global data recording (unused here).
The main file's stream still survives its rotations (`save()` to the next segment).

rerun-sdk 0.41 notes: an explicit `rr.RecordingStream` per output; `flush()` then `disconnect()`
before the file is read back; read it with `read_recording` (`rerun.chunk.RrdReader`).
"""

from __future__ import annotations

import colorsys
import logging
import math
import os
import re
import socket
import sys
import threading
import time
import uuid
import warnings
from collections import deque
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Self

import numpy as np

# The service writes footerless segments on purpose (module doc: the footer grows in memory until
# the file closes); rerun warns about that once per file. Quiet that one target unless the user
# set RUST_LOG themselves.
os.environ.setdefault("RUST_LOG", "warn,re_log_encoding::rrd::file_sink=error")

import rerun as rr  # noqa: E402 - after the RUST_LOG default
import rerun.blueprint as rrb  # noqa: E402

log = logging.getLogger(__name__)

SIM_TIME = "sim_time"
SEQ = "seq"

# Contact fields extracted per ball and side, in this order (getattr with a None default, so the
# electrical fields are logged as soon as the snapshot schema carries them).
_CONTACT_FIELDS = ("load_n", "lambda_", "mu", "contact_angle_rad", "resistance_ohm", "capacitance_f")
_K = len(_CONTACT_FIELDS)
_F_LOAD, _F_LAMBDA, _F_MU, _F_ANGLE, _F_R, _F_C = range(_K)
# (field index, entity leaf) of the per-contact scalar series
_CONTACT_SERIES = ((_F_LOAD, "load_n"), (_F_LAMBDA, "lambda"), (_F_MU, "mu"),
                   (_F_R, "resistance_ohm"), (_F_C, "capacitance_f"))
_BALL_ELECTRICAL = ("resistance_ohm", "capacitance_f")
_SIDES = ("inner", "outer")

_REGIME_CODE = {"no_contact": 0, "boundary": 1, "mixed": 2, "full_film": 3}
_REGIME_RGBA = np.array([[150, 150, 150, 255],   # no_contact: grey
                         [220, 40, 40, 255],     # boundary: red
                         [255, 150, 0, 255],     # mixed: orange
                         [40, 180, 70, 255]],    # full_film: green
                        dtype=np.uint8)
_INNER_ARROW_RGBA = (60, 120, 255, 255)
_OUTER_ARROW_RGBA = (200, 80, 255, 255)
_RACEWAY_RGBA = (170, 170, 180, 255)
_PITCH_RGBA = (90, 90, 100, 255)


def _circle(radius_m: float, n: int = 181) -> np.ndarray:
    a = np.linspace(0.0, 2.0 * math.pi, n)
    return np.column_stack([radius_m * np.cos(a), radius_m * np.sin(a), np.zeros(n)])


def _ball_rgb(i: int, count: int, side: int) -> tuple[int, int, int]:
    r, g, b = colorsys.hsv_to_rgb(i / max(count, 1), 0.75 if side == 0 else 0.55, 0.95 if side == 0 else 0.7)
    return int(r * 255), int(g * 255), int(b * 255)


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
class _Twin:
    bearing_id: str
    designation: str
    ball_count: int
    pitch_radius_m: float | None = None
    ball_radius_m: float | None = None
    inner_raceway_radius_m: float | None = None
    outer_raceway_radius_m: float | None = None
    load_scale_m_per_n: float | None = None
    has_electrical: bool = False
    last_status: str | None = None
    last_discharge: str | None = None
    last_time_s: float = -math.inf
    rows: list = field(default_factory=list)

    @property
    def has_geometry(self) -> bool:
        return self.pitch_radius_m is not None

    @property
    def root(self) -> str:
        return f"bearing/{self.bearing_id}"


@dataclass
class _Row:
    time_s: float
    seq: int
    friction_torque_n_m: float
    cage_speed_rad_s: float
    status: str
    contacts: list          # Z * 2 * _K floats (ball, side, field), NaN for null
    regimes: list           # Z ints, inner-contact regime code
    azimuth_rad: list       # Z floats
    ball_electrical: list   # Z * 2 floats (resistance, capacitance), NaN for null
    electrical: dict | None  # bearing-level numeric electrical fields
    discharge: str | None    # "risk: reason" when the snapshot carries electrical.discharge_risk
    positions_m: np.ndarray | None


_FIELD_CACHE: dict = {}


def _present(obj, names: tuple[str, ...]) -> tuple[str | None, ...]:
    """`names` with None for those `obj` does not have. Cached per pydantic model class (a
    getattr that misses on a pydantic model costs microseconds: it raises inside __getattr__)."""
    cls = type(obj)
    key = (cls, names)
    found = _FIELD_CACHE.get(key)
    if found is None:
        declared = getattr(cls, "model_fields", None)
        if not isinstance(declared, dict):   # duck-typed object: look at this instance
            return tuple(n if hasattr(obj, n) else None for n in names)
        found = tuple(n if n in declared else None for n in names)
        _FIELD_CACHE[key] = found
    return found


def _values(obj, fields: tuple[str | None, ...], out: list) -> None:
    for f in fields:
        v = getattr(obj, f) if f is not None else None
        out.append(math.nan if v is None else v)


def _extract(snapshot, positions_m: np.ndarray | None) -> _Row:
    balls = snapshot.balls
    contacts: list = []
    ball_el: list = []
    if balls:
        cf = _present(balls[0].inner, _CONTACT_FIELDS)
        bf = _present(balls[0], _BALL_ELECTRICAL)
        for b in balls:
            _values(b.inner, cf, contacts)
            _values(b.outer, cf, contacts)
            _values(b, bf, ball_el)
    electrical = None
    discharge = None
    el = getattr(snapshot, "electrical", None) if _present(snapshot, ("electrical",))[0] else None
    if el is not None:
        if isinstance(el, Mapping):
            items = dict(el)
        else:
            names = getattr(type(el), "model_fields", None)
            items = {k: getattr(el, k) for k in names} if isinstance(names, dict) else dict(vars(el))
        electrical = {k: float(v) for k, v in items.items()
                      if isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)}
        risk = items.get("discharge_risk")
        if isinstance(risk, str):
            reason = items.get("reason")
            discharge = f"{risk}: {reason}" if isinstance(reason, str) and reason else risk
    return _Row(time_s=float(snapshot.time_s), seq=int(snapshot.seq),
                friction_torque_n_m=float(snapshot.friction_torque_n_m),
                cage_speed_rad_s=float(snapshot.cage_speed_rad_s), status=str(snapshot.status),
                contacts=contacts, regimes=[_REGIME_CODE.get(b.inner.regime, 0) for b in balls],
                azimuth_rad=[b.azimuth_rad for b in balls],
                ball_electrical=ball_el, electrical=electrical, discharge=discharge,
                positions_m=positions_m)


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
        self.created = 0           # streams made (recordings and blueprints)
        self.reclaims = 0          # successful cleanups
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
            return rr.RecordingStream._from_native(rerun_bindings.new_blueprint(
                application_id=application_id, make_default=False, make_thread_default=False,
                default_enabled=True))

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


@dataclass
class _Output:
    stream: rr.RecordingStream | None
    path: Path | None
    viewer: bool = False
    opened_at: float = field(default_factory=time.monotonic)   # monotonic [s]
    rows: int = 0               # snapshots written to this output (to this segment for the main file)


class _BlueprintSender:
    """Sends blueprints through ONE blueprint stream for the recorder's lifetime.

    `RecordingStream.send_blueprint` creates a new blueprint `RecordingStream` per call, and
    rerun-sdk 0.41 never frees one (its threads keep running, rerun issue #2116): once per segment
    that would grow without bound. Here the blueprint is logged again into the same blueprint
    stream, behind a fresh in-memory sink, and that storage is sent (what `send_blueprint` does
    with its throw-away stream). Uses rerun internals (`rerun_bindings.new_blueprint`,
    `Blueprint._log_to_stream`): if they are missing, falls back to `send_blueprint`."""

    def __init__(self, application_id: str, streams: RerunStreams):
        self.application_id = application_id
        self._streams = streams
        self._stream: rr.RecordingStream | None = None
        self._fallback = False
        try:     # made now, on the caller's thread (see `RerunStreams`), not on the worker
            self._stream = streams.new_blueprint(application_id)
        except (ImportError, AttributeError, TypeError) as exc:
            self._fallback = True
            log.warning("rerun: blueprint stream reuse unavailable (%s): using send_blueprint", exc)

    def close(self) -> None:
        """Drop the blueprint stream (freed by the next `RerunStreams.reclaim`). Its in-memory
        sink holds the stream itself (a reference cycle in rerun-sdk 0.41): `disconnect()`
        replaces that sink first, or the stream could never be freed."""
        stream, self._stream = self._stream, None
        if stream is not None:
            try:
                stream.disconnect()
            except Exception as exc:  # noqa: BLE001 - only keeps the stream alive
                log.warning("rerun: disconnect of the blueprint stream failed: %s", exc)

    def send(self, blueprint: rrb.Blueprint, recording: rr.RecordingStream) -> None:
        if not self._fallback:
            try:
                import rerun_bindings

                if self._stream is None:
                    raise AttributeError("the blueprint stream is closed")
                storage = self._stream.memory_recording().storage
                self._stream.set_time("blueprint", sequence=0)
                blueprint.to_blueprint()._log_to_stream(self._stream)
                rerun_bindings.send_blueprint(storage, True, True, recording=recording.to_native())
                return
            except (ImportError, AttributeError, TypeError) as exc:
                self._fallback = True
                log.warning("rerun: blueprint stream reuse unavailable (%s): using send_blueprint", exc)
        self._streams.send_blueprint(blueprint, recording)


def segment_path(path: str | Path, index: int) -> Path:
    """Path of segment `index` of the recording `path`: the path itself for 0, else
    `<stem>-<index:04d><suffix>` in the same folder (run.rrd, run-0001.rrd, run-0002.rrd, ...)."""
    path = Path(path)
    if index < 0:
        raise ValueError(f"segment index {index}: must be >= 0")
    return path if index == 0 else path.with_name(f"{path.stem}-{index:04d}{path.suffix}")


def _numbered_segments(path: Path) -> dict[int, Path]:
    pattern = re.compile(re.escape(path.stem) + r"-(\d{4,})" + re.escape(path.suffix) + "$")
    found: dict[int, Path] = {}
    try:
        siblings = list(path.parent.iterdir())
    except OSError:
        return found
    for p in siblings:
        m = pattern.match(p.name)
        if m and int(m.group(1)) > 0 and p.is_file():
            found[int(m.group(1))] = p
    return found


def recording_segments(path: str | Path) -> list[Path]:
    """The segments of the recording `path` in order: `path` itself, then `<stem>-0001<suffix>`,
    `<stem>-0002<suffix>`, ... as long as they follow each other (see the module doc). Empty when
    `path` does not exist."""
    path = Path(path)
    if not path.is_file():
        return []
    numbered = _numbered_segments(path)
    out = [path]
    i = 1
    while i in numbered:
        out.append(numbered[i])
        i += 1
    return out


class RerunRecorder:
    """Records the snapshots of one or more twins into one rerun recording (see module doc).

    Usage::

        rec = RerunRecorder("run.rrd")
        rec.add_twin_from(twin)            # or add_twin("a", designation=..., pitch_radius_m=..., ...)
        rec.publish(twin.snapshot())       # never blocks
        rec.start_file("clip.rrd"); ...; rec.stop_file()
        rec.close()                        # drains, sends, flushes, disconnects
    """

    def __init__(self, path: str | Path | None = None, *, spawn_viewer: bool = False,
                 application_id: str = "bearing-twin", flush_interval_s: float = 0.1,
                 queue_size: int = 256, viewer_port: int = 9876,
                 series_window_s: float | None = 5.0, min_interval_s: float = 0.0,
                 segment_s: float | None = None, segment_bytes: int | None = None,
                 write_footer: bool = True, streams: RerunStreams | None = None):
        """`segment_s` [s of wall time] / `segment_bytes` [bytes]: rotate the main file once its
        open segment is that old / that large (None or 0 = never; see the module doc).
        `write_footer`: end every file (segments, `start_file` files) with rerun's footer (chunk
        manifest); False keeps the memory flat on long runs (module doc).
        `streams`: makes and frees this recorder's rerun streams (shared by the recorders of a
        service); by default the recorder has its own."""
        if not (flush_interval_s > 0.0 and math.isfinite(flush_interval_s)):
            raise ValueError(f"flush_interval_s = {flush_interval_s!r}: must be finite and > 0")
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
        self.queue_size = int(queue_size)
        self.series_window_s = series_window_s
        self.viewer_port = viewer_port
        self.min_interval_s = float(min_interval_s)
        self._streams = streams if streams is not None else RerunStreams()

        self._queue: deque = deque()
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
        self._twins: dict[str, _Twin] = {}
        self._viewer: _Output | None = None
        self._primary: _Output | None = None    # the open segment of the main file
        self._extra: _Output | None = None
        self._blueprint_dirty = False   # (re)sent by the next send, once for many add_twin calls
        self._segments: list[Path] = []
        self._rotation_failed_at: float | None = None
        self._blueprints = _BlueprintSender(application_id, self._streams)

        self.path = Path(path) if path is not None else None
        self._viewer = self._open_viewer(spawn_viewer)
        if self.path is not None:
            if self.segment_s is not None or self.segment_bytes is not None:
                self._remove_stale_segments(self.path)
            self._primary = self._open_file(self.path)
            self._segments.append(self.path)

        self._thread = threading.Thread(target=self._run, name="rerun-recorder", daemon=True)
        self._thread.start()

    # ---- outputs ----------------------------------------------------------------------------
    def _new_stream(self) -> rr.RecordingStream:
        return self._streams.new_recording(self.application_id, self.recording_id)

    def _open_viewer(self, spawn_viewer: bool) -> _Output | None:
        """A stream to a spawned viewer (its own stream: the file segments rotate, the viewer's
        connection does not), or None."""
        if not spawn_viewer:
            return None
        where = f", recording to {self.path}" if self.path else ""
        if not _display_available():
            log.warning("rerun: no display (DISPLAY/WAYLAND_DISPLAY unset): not spawning a viewer%s", where)
            return None
        stream = self._new_stream()
        try:
            stream.spawn(port=self.viewer_port, connect=False)
            if not _port_open(self.viewer_port):
                log.warning("rerun: the spawned viewer does not listen on port %d: continuing without it",
                            self.viewer_port)
                return None
        except Exception as exc:  # noqa: BLE001 - no viewer on PATH, headless, ...: warn, go on
            log.warning("rerun: could not spawn a viewer (%s): continuing%s",
                        str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__,
                        f" with the file sink {self.path}" if self.path else " without a viewer")
            return None
        stream.connect_grpc(f"rerun+http://127.0.0.1:{self.viewer_port}/proxy")
        return _Output(stream=stream, path=None, viewer=True)

    def _open_file(self, path: Path) -> _Output:
        path.parent.mkdir(parents=True, exist_ok=True)
        stream = self._new_stream()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            stream.save(str(path), write_footer=self.write_footer)
        return _Output(stream=stream, path=path)

    @staticmethod
    def _remove_stale_segments(path: Path) -> None:
        for p in _numbered_segments(path).values():
            try:
                p.unlink()
                log.warning("rerun: removed %s, a segment of an earlier recording to %s", p, path)
            except OSError as exc:
                log.warning("rerun: could not remove the stale segment %s: %s", p, exc)

    def _outputs(self) -> list[_Output]:
        return [o for o in (self._viewer, self._primary, self._extra) if o is not None]

    @staticmethod
    def _close_output(out: _Output, timeout_s: float = 30.0) -> None:
        try:
            out.stream.flush(timeout_sec=timeout_s)
        except Exception as exc:  # noqa: BLE001 - a sink's failure must not stop the others
            log.warning("rerun: flush of %s failed: %s", out.path or "viewer", exc)
        try:
            out.stream.disconnect()
        except Exception as exc:  # noqa: BLE001
            log.warning("rerun: disconnect of %s failed: %s", out.path or "viewer", exc)
        out.stream = None       # the file is closed: the stream can be freed (`RerunStreams.reclaim`)

    def start_file(self, path: str | Path) -> Path:
        """Start recording into a further .rrd file while running (static geometry and blueprint
        first, then every snapshot published from now on). Replaces (and completes) a file started
        earlier with `start_file`. Returns the path. The file gets a new stream (with the
        recorder's recording id), freed again when the file is stopped."""
        path = Path(path)
        if self._closed:
            raise RuntimeError("recorder is closed")
        if self.path is not None and path.resolve() in {p.resolve() for p in self._segments}:
            raise ValueError(f"{path} is the recorder's main file (or one of its segments)")
        with self._io_lock:
            self._drain_locked()
            self._send_locked()        # rows published before start_file go to the old outputs only
            replaced = self._extra is not None
            if replaced:
                self._stop_file_locked()
            out = self._open_file(path)
            for tw in self._twins.values():
                self._send_static(out, tw)
            self._send_blueprint([out])         # the others get theirs at the next send if due
            self._extra = out
        if replaced:
            self._streams.reclaim()
        return path

    def stop_file(self) -> Path | None:
        """Finish the file started with `start_file` (everything published so far is in it,
        flushed and closed). Returns its path, or None if no file was being recorded."""
        with self._io_lock:
            if self._extra is None:
                return None
            self._drain_locked()
            self._send_locked()
            path = self._stop_file_locked()
        self._streams.reclaim()             # outside the lock: it flushes every stream
        return path

    def _stop_file_locked(self) -> Path | None:
        out, self._extra = self._extra, None
        self._close_output(out)
        return out.path

    @property
    def recording_file(self) -> Path | None:
        """The file being recorded with `start_file`, if any."""
        out = self._extra
        return out.path if out is not None else None

    @property
    def segments(self) -> list[Path]:
        """The segments of the main file opened so far, in order (the last one is being written
        unless the recorder is closed); [] without a main file."""
        return list(self._segments)

    @property
    def current_path(self) -> Path | None:
        """The segment of the main file being written (None without a main file or once closed)."""
        out = self._primary
        return out.path if out is not None else None

    def rotate(self) -> Path | None:
        """Close the open segment of the main file now (everything published so far is in it) and
        open the next one; returns the new segment's path (None without a main file)."""
        with self._io_lock:
            if self._closed or self._primary is None:
                return None
            self._drain_locked()
            self._send_locked()
            return self._rotate_locked()

    def _rotation_due(self) -> bool:
        out = self._primary
        if out is None or out.rows == 0 or (self.segment_s is None and self.segment_bytes is None):
            return False
        now = time.monotonic()
        if self._rotation_failed_at is not None and now - self._rotation_failed_at < 10.0:
            return False          # a failed rotation is retried every 10 s, not at every send
        if self.segment_s is not None and now - out.opened_at >= self.segment_s:
            return True
        if self.segment_bytes is not None:
            try:
                return out.path.stat().st_size >= self.segment_bytes
            except OSError:
                return False
        return False

    def _rotate_locked(self) -> Path | None:
        """Point the main file's stream at the next segment. The stream is kept (rerun-sdk 0.41
        never frees a `RecordingStream` nor its threads, rerun issue #2116: a new stream per
        segment would leak about 2 MB and 4 threads per rotation); `save()` replaces its file
        sink, and the old sink, dropped, writes its end (and footer) and closes the file."""
        out = self._primary
        path = segment_path(self.path, len(self._segments))
        try:
            out.stream.flush(timeout_sec=30.0)      # every row sent so far goes to the old segment
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                out.stream.save(str(path), write_footer=self.write_footer)
        except Exception as exc:  # noqa: BLE001 - the old sink stays: keep writing the open segment
            self._errors += 1
            self._rotation_failed_at = time.monotonic()
            log.warning("rerun: could not open the next segment %s (%s): continuing in %s", path, exc, out.path)
            return None
        self._rotation_failed_at = None
        old_path, old_rows = out.path, out.rows
        out.path, out.rows, out.opened_at = path, 0, time.monotonic()
        self._segments.append(path)
        for tw in self._twins.values():             # the new segment is complete on its own
            self._send_static(out, tw)
            tw.last_status = tw.last_discharge = None  # its first rows log the status and risk again
        self._send_blueprint([out])
        log.info("rerun: segment %s closed (%d snapshots), recording into %s", old_path, old_rows, path)
        return path

    # ---- twins ------------------------------------------------------------------------------
    def add_twin(self, bearing_id: str, *, designation: str, pitch_radius_m: float,
                 ball_radius_m: float, inner_raceway_radius_m: float,
                 outer_raceway_radius_m: float, ball_count: int,
                 load_scale_m_per_n: float | None = None) -> None:
        """Register a twin: log its static geometry and (re)send the blueprint.
        `load_scale_m_per_n`: arrow length per newton of contact load; by default the largest load
        of the first loaded snapshot is drawn one ball diameter long."""
        tw = _Twin(bearing_id=str(bearing_id), designation=str(designation), ball_count=int(ball_count),
                   pitch_radius_m=float(pitch_radius_m), ball_radius_m=float(ball_radius_m),
                   inner_raceway_radius_m=float(inner_raceway_radius_m),
                   outer_raceway_radius_m=float(outer_raceway_radius_m),
                   load_scale_m_per_n=load_scale_m_per_n)
        with self._io_lock:
            old = self._twins.get(tw.bearing_id)
            if old is not None:
                tw.rows, tw.has_electrical, tw.last_status = old.rows, old.has_electrical, old.last_status
            self._twins[tw.bearing_id] = tw
            outs = self._outputs()
            for out in outs:
                self._send_static(out, tw)
            self._blueprint_dirty = True

    def add_twin_from(self, twin, bearing_id: str | None = None) -> None:
        """`add_twin` with the geometry of a `twin.engine.Twin`."""
        m = twin.model
        g = m.spec.geometry
        self.add_twin(bearing_id or twin.bearing_id, designation=m.spec.designation,
                      pitch_radius_m=m.pitch_radius_m, ball_radius_m=m.ball_radius_m,
                      inner_raceway_radius_m=g.inner_raceway_radius_m,
                      outer_raceway_radius_m=g.outer_raceway_radius_m, ball_count=m.ball_count)

    @property
    def bearing_ids(self) -> list[str]:
        return list(self._twins)

    def _send_static(self, out: _Output, tw: _Twin) -> None:
        s = out.stream
        root = tw.root
        if tw.has_geometry:
            rb = tw.ball_radius_m
            line = rr.components.Radius.ui_points(1.5)
            s.log(f"{root}/geometry/inner_raceway",
                  rr.LineStrips3D([_circle(tw.inner_raceway_radius_m)], radii=line, colors=_RACEWAY_RGBA),
                  static=True)
            s.log(f"{root}/geometry/outer_raceway",
                  rr.LineStrips3D([_circle(tw.outer_raceway_radius_m)], radii=line, colors=_RACEWAY_RGBA),
                  static=True)
            s.log(f"{root}/geometry/pitch_circle",
                  rr.LineStrips3D([_circle(tw.pitch_radius_m)], radii=rr.components.Radius.ui_points(0.5),
                                  colors=_PITCH_RGBA),
                  static=True)
            s.log(f"{root}/geometry/load_line",
                  rr.Arrows3D(origins=[[0.0, 0.0, 0.0]], vectors=[[tw.inner_raceway_radius_m * 0.8, 0.0, 0.0]],
                              colors=[(230, 230, 230, 255)], labels=["radial load"],
                              radii=rr.components.Radius.ui_points(1.0)),
                  static=True)
            s.log(f"{root}/balls", rr.Points3D.from_fields(radii=[rb]), static=True)
            s.log(f"{root}/loads/inner",
                  rr.Arrows3D.from_fields(colors=[_INNER_ARROW_RGBA], radii=[0.08 * rb]), static=True)
            s.log(f"{root}/loads/outer",
                  rr.Arrows3D.from_fields(colors=[_OUTER_ARROW_RGBA], radii=[0.08 * rb]), static=True)
        self._send_series_styles(out, tw)

    def _send_series_styles(self, out: _Output, tw: _Twin) -> None:
        s = out.stream
        root = tw.root
        z = tw.ball_count
        leaves = ["load_n", "lambda", "mu"] + (["resistance_ohm", "capacitance_f"] if tw.has_electrical else [])
        for i in range(z):
            for side, name in enumerate(_SIDES):
                color = _ball_rgb(i, z, side)
                for leaf in leaves:
                    s.log(f"{root}/ball/{i}/{name}/{leaf}",
                          rr.SeriesLines(names=f"ball {i} {name}", colors=[color]), static=True)
            if tw.has_electrical:
                for leaf in _BALL_ELECTRICAL:
                    s.log(f"{root}/ball/{i}/{leaf}",
                          rr.SeriesLines(names=f"ball {i}", colors=[_ball_rgb(i, z, 0)]), static=True)
        s.log(f"{root}/friction_torque_n_m",
              rr.SeriesLines(names=f"{tw.bearing_id} friction torque", colors=[(255, 200, 0)]), static=True)
        s.log(f"{root}/cage_speed_rad_s",
              rr.SeriesLines(names=f"{tw.bearing_id} cage speed", colors=[(0, 200, 255)]), static=True)

    # ---- blueprint --------------------------------------------------------------------------
    def _twin_layout(self, tw: _Twin) -> rrb.Container:
        root = f"/{tw.root}"
        z = tw.ball_count
        window = None
        if self.series_window_s:
            window = rrb.VisibleTimeRange(
                SIM_TIME, start=rrb.TimeRangeBoundary.cursor_relative(seconds=-float(self.series_window_s)),
                end=rrb.TimeRangeBoundary.cursor_relative())

        def series(title: str, leaf: str, sides=_SIDES) -> rrb.TimeSeriesView:
            contents = [f"+ {root}/ball/{i}/{side}/{leaf}" for side in sides for i in range(z)]
            return rrb.TimeSeriesView(name=f"{tw.bearing_id}: {title}", origin=root, contents=contents,
                                      time_ranges=window, plot_legend=rrb.PlotLegend(visible=False))

        plots: list = [series("contact load [N]", "load_n"), series("film parameter Lambda [-]", "lambda"),
                       series("friction coefficient mu [-]", "mu")]
        shares = [2.0, 2.0, 2.0]
        if tw.has_electrical:
            plots.append(rrb.Tabs(series("contact resistance R [ohm]", "resistance_ohm"),
                                  series("contact capacitance C [F]", "capacitance_f")))
            shares.append(2.0)
        plots.append(rrb.Horizontal(
            rrb.TimeSeriesView(name=f"{tw.bearing_id}: friction torque [N m]", origin=root,
                               contents=[f"+ {root}/friction_torque_n_m"], time_ranges=window),
            rrb.TimeSeriesView(name=f"{tw.bearing_id}: cage speed [rad/s]", origin=root,
                               contents=[f"+ {root}/cage_speed_rad_s"], time_ranges=window)))
        shares.append(2.0)
        plots.append(rrb.TextLogView(name=f"{tw.bearing_id}: status", origin=root,
                                     contents=[f"+ {root}/status", f"+ {root}/electrical/discharge_risk"]))
        shares.append(1.0)
        if not tw.has_geometry:
            return rrb.Vertical(*plots, row_shares=shares, name=tw.bearing_id)
        distance = 3.0 * tw.outer_raceway_radius_m
        view3d = rrb.Spatial3DView(
            name=f"{tw.bearing_id} ({tw.designation})", origin=root,
            contents=[f"+ {root}/geometry/**", f"+ {root}/balls", f"+ {root}/loads/**"],
            # look along the axis (-z) with the radial load line (+x, azimuth 0) pointing down
            eye_controls=rrb.EyeControls3D(position=[0.0, 0.0, distance], look_target=[0.0, 0.0, 0.0],
                                           eye_up=[-1.0, 0.0, 0.0]),
            line_grid=False)
        return rrb.Horizontal(view3d, rrb.Vertical(*plots, row_shares=shares), column_shares=[1.0, 1.0], name=tw.bearing_id)

    def blueprint(self) -> rrb.Blueprint:
        """The default layout: per twin, the 3D bearing on the left and its time series on the
        right (one tab per twin when there are several)."""
        layouts = [self._twin_layout(tw) for tw in self._twins.values()]
        if not layouts:
            body = rrb.Vertical()
        elif len(layouts) == 1:
            body = layouts[0]
        else:
            body = rrb.Tabs(*layouts)
        return rrb.Blueprint(body, rrb.TimePanel(timeline=SIM_TIME, play_state="following"))

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
        with self._qlock:
            if len(self._queue) >= self.queue_size:
                self._queue.popleft()
                self._dropped += 1
            self._queue.append((snapshot, pos))
            n = len(self._queue)
        if n >= self._wake_at:
            self._wake.set()

    @property
    def dropped(self) -> int:
        """Snapshots dropped because the queue was full (or published after close)."""
        return self._dropped

    @property
    def rows_logged(self) -> int:
        """Snapshots written to the recording (to at least one output)."""
        return self._rows_logged

    @property
    def errors(self) -> int:
        """Snapshots or flushes that failed (logged, never raised into the physics)."""
        return self._errors

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
        """Send everything queued or buffered now and wait until the outputs have written it;
        then rotate the main file if its segment is due (old or large enough)."""
        with self._io_lock:
            self._drain_locked()
            self._send_locked()
            for out in self._outputs():
                try:
                    out.stream.flush(timeout_sec=timeout_s)
                except Exception as exc:  # noqa: BLE001
                    log.warning("rerun: flush of %s failed: %s", out.path or "viewer", exc)
            if not self._closed and self._rotation_due():
                self._rotate_locked()

    def close(self) -> None:
        """Drain the queue, send the rest, flush and disconnect every output (idempotent)."""
        with self._qlock:
            if self._closed:
                return
            self._closed = True
        self._stop.set()
        self._wake.set()
        if self._thread.is_alive() and threading.current_thread() is not self._thread:
            self._thread.join()
        with self._io_lock:
            self._drain_locked()
            self._send_locked()
            for out in self._outputs():
                self._close_output(out)
            self._viewer = None
            self._primary = None
            self._extra = None
            self._blueprints.close()
        self._streams.reclaim()             # free this recorder's streams (module doc)

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
                        next_send = time.monotonic() + self.flush_interval_s
            except Exception:  # never let the worker die
                self._errors += 1
                log.exception("rerun recorder: send failed")

    def _drain_locked(self) -> None:
        with self._qlock:
            items = list(self._queue)
            self._queue.clear()
        if not items:
            return
        if not self._outputs():        # nowhere to write (no file, no viewer): nothing to convert
            self._skipped += len(items)
            return
        for snapshot, pos in items:
            try:
                tw = self._twins.get(snapshot.bearing_id)
                if tw is None:
                    tw = self._auto_register(snapshot)
                t = float(snapshot.time_s)
                if self.min_interval_s > 0.0 and tw.last_time_s <= t < tw.last_time_s + self.min_interval_s:
                    self._skipped += 1
                    continue
                tw.last_time_s = t
                if len(snapshot.balls) != tw.ball_count:
                    raise ValueError(f"{len(snapshot.balls)} balls in the snapshot, {tw.ball_count} registered")
                if pos is not None and pos.shape != (tw.ball_count, 3):
                    raise ValueError(f"positions_m has shape {pos.shape}, expected ({tw.ball_count}, 3)")
                tw.rows.append(_extract(snapshot, pos))
            except Exception as exc:  # noqa: BLE001 - a bad snapshot is skipped and counted
                self._errors += 1
                log.warning("rerun recorder: snapshot %s/%s skipped: %s",
                            getattr(snapshot, "bearing_id", "?"), getattr(snapshot, "seq", "?"), exc)

    def _auto_register(self, snapshot) -> _Twin:
        log.warning("rerun recorder: twin %r was not added with add_twin: recording its series without geometry",
                    snapshot.bearing_id)
        tw = _Twin(bearing_id=str(snapshot.bearing_id), designation=str(snapshot.designation),
                   ball_count=len(snapshot.balls))
        self._twins[tw.bearing_id] = tw
        outs = self._outputs()
        for out in outs:
            self._send_static(out, tw)
        self._blueprint_dirty = True
        return tw

    def _send_locked(self) -> None:
        outs = self._outputs()
        for tw in self._twins.values():
            rows, tw.rows = tw.rows, []
            if not rows or not outs:
                continue
            try:
                batch = self._columns(tw, rows, outs)
                for path, indexes, columns in batch:
                    for out in outs:
                        out.stream.send_columns(path, indexes=indexes, columns=columns)
                self._rows_logged += len(rows)
                for out in outs:
                    out.rows += len(rows)
            except Exception:
                self._errors += len(rows)
                log.exception("rerun recorder: %d rows of %s lost", len(rows), tw.bearing_id)
        if self._blueprint_dirty and outs:
            self._blueprint_dirty = False
            self._send_blueprint(outs)

    def _columns(self, tw: _Twin, rows: list[_Row], outs: list[_Output]) -> list[tuple]:
        """Turn buffered rows into (entity path, index columns, component columns) triples."""
        n = len(rows)
        z = tw.ball_count
        root = tw.root
        # integer nanoseconds, rounded (rerun truncates float seconds: 0.002 s would become 1999999 ns)
        t = np.round(np.fromiter((r.time_s for r in rows), dtype=np.float64, count=n) * 1e9
                     ).astype(np.int64).astype("timedelta64[ns]")
        seq = np.fromiter((r.seq for r in rows), dtype=np.int64, count=n)
        idx_all = [rr.TimeColumn(SIM_TIME, duration=t), rr.TimeColumn(SEQ, sequence=seq)]
        out: list[tuple] = []

        def scalars(path: str, values: np.ndarray) -> None:
            ok = np.isfinite(values)
            if ok.all():
                out.append((path, idx_all, rr.Scalars.columns(scalars=values)))
            elif ok.any():
                idx = [rr.TimeColumn(SIM_TIME, duration=t[ok]), rr.TimeColumn(SEQ, sequence=seq[ok])]
                out.append((path, idx, rr.Scalars.columns(scalars=values[ok])))

        c = np.array([r.contacts for r in rows], dtype=np.float64).reshape(n, z, 2, _K)
        be = np.array([r.ball_electrical for r in rows], dtype=np.float64).reshape(n, z, 2)
        electrical_now = bool(np.isfinite(c[..., _F_R:]).any() or np.isfinite(be).any())
        if electrical_now and not tw.has_electrical:
            tw.has_electrical = True
            for o in outs:
                self._send_series_styles(o, tw)
            self._blueprint_dirty = True

        for i in range(z):
            for side, name in enumerate(_SIDES):
                base = f"{root}/ball/{i}/{name}"
                for k, leaf in _CONTACT_SERIES:
                    if k in (_F_R, _F_C) and not tw.has_electrical:
                        continue
                    scalars(f"{base}/{leaf}", c[:, i, side, k])
            if tw.has_electrical:
                for e, leaf in enumerate(_BALL_ELECTRICAL):
                    scalars(f"{root}/ball/{i}/{leaf}", be[:, i, e])
        scalars(f"{root}/friction_torque_n_m", np.fromiter((r.friction_torque_n_m for r in rows), np.float64, n))
        scalars(f"{root}/cage_speed_rad_s", np.fromiter((r.cage_speed_rad_s for r in rows), np.float64, n))

        keys = sorted({k for r in rows if r.electrical for k in r.electrical})
        for key in keys:
            scalars(f"{root}/electrical/{key}",
                    np.array([(r.electrical or {}).get(key, math.nan) for r in rows], dtype=np.float64))

        # status and discharge risk: one text row whenever they change
        def text_changes(path: str, attr: str, last: str, level) -> None:
            changed = []
            for j, r in enumerate(rows):
                value = getattr(r, attr)
                if value is not None and value != getattr(tw, last):
                    changed.append(j)
                    setattr(tw, last, value)
            if changed:
                sel = np.array(changed)
                texts = [getattr(rows[j], attr) for j in changed]
                out.append((path, [rr.TimeColumn(SIM_TIME, duration=t[sel]), rr.TimeColumn(SEQ, sequence=seq[sel])],
                            rr.TextLog.columns(text=texts, level=[level(x) for x in texts])))

        text_changes(f"{root}/status", "status", "last_status", lambda x: "INFO" if x == "ok" else "WARN")
        text_changes(f"{root}/electrical/discharge_risk", "discharge", "last_discharge",
                     lambda x: "ERROR" if x.startswith("likely") else "WARN" if x.startswith("possible") else "INFO")

        if tw.has_geometry:
            az = np.array([r.azimuth_rad for r in rows], dtype=np.float64)          # (n, z)
            cos_az, sin_az = np.cos(az), np.sin(az)
            rp = tw.pitch_radius_m
            pos = np.stack([rp * cos_az, rp * sin_az, np.zeros_like(az)], axis=-1)  # (n, z, 3)
            for j, r in enumerate(rows):
                if r.positions_m is not None:
                    pos[j] = r.positions_m
            flat = pos.reshape(-1, 3)
            colors = _REGIME_RGBA[np.array([r.regimes for r in rows], dtype=np.intp).reshape(-1)]
            lengths = np.full(n, z)
            out.append((f"{root}/balls", idx_all,
                        rr.Points3D.columns(positions=flat, colors=colors).partition(lengths)))
            load = c[..., _F_LOAD]                                                   # (n, z, 2)
            if tw.load_scale_m_per_n is None:
                peak = float(np.nanmax(load)) if load.size else 0.0
                if peak > 0.0:
                    tw.load_scale_m_per_n = 2.0 * tw.ball_radius_m / peak
            scale = tw.load_scale_m_per_n or 0.0
            angle = c[..., _F_ANGLE]
            for side, name in enumerate(_SIDES):
                a = np.nan_to_num(angle[:, :, side])
                radial = -1.0 if side == 0 else 1.0        # towards the inner / outer raceway
                length = np.nan_to_num(load[:, :, side]) * scale
                vec = np.stack([radial * np.cos(a) * cos_az, radial * np.cos(a) * sin_az, np.sin(a)],
                               axis=-1) * length[..., None]
                out.append((f"{root}/loads/{name}", idx_all,
                            rr.Arrows3D.columns(origins=flat, vectors=vec.reshape(-1, 3)).partition(lengths)))
        return out


# ---- reading a recording back -----------------------------------------------------------------
PathOrPaths = str | Path | Iterable[str | Path]


def _paths(path: PathOrPaths) -> list[Path]:
    if isinstance(path, (str, Path)):
        return [Path(path)]
    return [Path(p) for p in path]


def _reader(path: Path):
    """`RrdReader` of one file; the "no footer" warning of a file written with
    `write_footer=False` is expected here and silenced."""
    from rerun.chunk import RrdReader

    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=".*no footer.*")
        return RrdReader(str(path))


def describe_recording(path: PathOrPaths) -> dict:
    """What an .rrd (or the segments of one recording, given as a list of paths) holds, read
    with `rerun.chunk.RrdReader`:

    {"application_id", "recording_id", "blueprints": number of blueprint stores,
     "segments": number of files read,
     "entities": {entity path (no leading slash): {"rows": temporal rows, "static_rows": n,
                  "components": [...], "timelines": [...]}}}

    Application and recording id are those of the first file; a later file of another recording
    raises ValueError (segments of one recording share them).
    """
    info: dict = {"application_id": None, "recording_id": None, "blueprints": 0, "segments": 0, "entities": {}}
    entities: dict = info["entities"]
    for p in _paths(path):
        reader = _reader(p)
        recordings = reader.recordings()
        info["segments"] += 1
        info["blueprints"] += len(reader.blueprints())
        if not recordings:
            continue
        ids = (recordings[0].application_id, recordings[0].recording_id)
        if info["recording_id"] is None:
            info["application_id"], info["recording_id"] = ids
        elif ids != (info["application_id"], info["recording_id"]):
            raise ValueError(f"{p} holds recording {ids}, not {(info['application_id'], info['recording_id'])}")
        for chunk in reader.stream(store=recordings[0]):
            entity = chunk.entity_path.lstrip("/")
            e = entities.setdefault(entity, {"rows": 0, "static_rows": 0, "components": set(), "timelines": set()})
            if chunk.is_static:
                e["static_rows"] += chunk.num_rows
            else:
                e["rows"] += chunk.num_rows
                e["timelines"].update(chunk.timeline_names)
            schema = chunk.to_record_batch().schema
            for f in schema:
                meta = f.metadata or {}
                comp = meta.get(b"rerun:component") or meta.get(b"rerun.component")
                if comp is not None:
                    e["components"].add(comp.decode())
    for e in entities.values():
        e["components"] = sorted(e["components"])
        e["timelines"] = sorted(e["timelines"])
    return info


def read_recording(path: PathOrPaths) -> dict[str, int]:
    """{entity path (no leading slash, e.g. "bearing/a/friction_torque_n_m"): number of temporal
    rows} of the first recording in an .rrd, or summed over the segments of one recording given
    as a list (`read_recording(recording_segments(path))`); entities with static data only map to
    0; rerun's own `__properties` entity is left out. Flush and disconnect (close the recorder)
    first."""
    return {k: v["rows"] for k, v in describe_recording(path)["entities"].items()
            if not k.startswith("__")}


def read_column(path: PathOrPaths, entity: str, column: str) -> list:
    """The values of one column (a timeline such as "seq", or a component such as
    "Points3D:positions" / "Scalars:scalars") over the temporal rows of one entity, in the order
    the rows were written (file after file for a list of segments), one item per row (a list for
    components, an int for "seq", integer nanoseconds for "sim_time")."""
    import pyarrow as pa

    want = "/" + entity.lstrip("/")
    values: list = []
    for p in _paths(path):
        for chunk in _reader(p).stream():
            if chunk.entity_path == want and not chunk.is_static:
                batch = chunk.to_record_batch()
                col = batch.column(batch.schema.get_field_index(column))
                if pa.types.is_duration(col.type) or pa.types.is_timestamp(col.type):
                    col = col.cast(pa.int64())
                values.extend(col.to_pylist())
    return values


def read_index(path: PathOrPaths, entity: str, timeline: str = SEQ) -> np.ndarray:
    """Sorted values of one timeline ("seq", or "sim_time" in integer nanoseconds) over the
    temporal rows of one entity, e.g. the `seq` numbers that made it into the file(s)."""
    return np.sort(np.array(read_column(path, entity, timeline), dtype=np.int64))
