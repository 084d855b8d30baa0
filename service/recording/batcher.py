"""`RowBatcher`: the twins of a recording, the queues the publishers fill, and their rows.

The runner thread calls `publish(snapshot)` (alarm hub: `log_alarm`; vibration publisher:
`publish_waveform`), which only appends to a bounded queue (drop-oldest, counted) and returns.
The recorder's worker calls `drain()`, which turns the queued snapshots into rows of plain
numbers per twin (`service.recording.columns`), and `send(outputs)`, which turns each twin's
buffered rows into columns and sends them with `send_columns`: one call, hence one rerun chunk,
per entity and send (the per-contact series every `slow_interval_s`).
"""

from __future__ import annotations

import logging
import math
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from service.core.alarm_rules import ALARM_IDS
from service.recording import alarm_columns as A
from service.recording import columns as C
from service.recording import trends
from service.recording import vibration_columns as V
from service.recording.archive import WaveformArchive, is_spectrum
from service.recording.layout import TwinLayout, send_static

log = logging.getLogger("service.recorder")

_MAX_ENDED = 1024  # remembered end times of removed twins (a re-created id continues after them)
_NEW_RUN_GAP_S = 1.0  # simulated seconds between a removed twin's last row and its re-creation


def scenario_text(handle) -> str | None:
    """ "scenario NAME: STATE, phase PHASE" of a scenario handle (duck-typed), or None."""
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
class TwinRows(TwinLayout):
    """A recorded twin: its layout, and its rows not sent yet."""

    rows: list = field(default_factory=list)  # rows not sent yet
    slow_rows: list = field(default_factory=list)  # rows whose per-contact series are not sent yet
    slow_since: float = field(default_factory=time.monotonic)
    last_time_s: float = -math.inf  # simulated time of the last row kept
    last_seq: int | None = None  # seq of the last snapshot seen
    slow_prev_time_s: float | None = None  # time of the row before slow_rows[0]
    prev_time_s: float | None = None  # time of the row before rows[0]
    time_offset_s: float = 0.0  # added to sim_time (a re-created twin)
    continue_after_s: float | None = None  # where the previous run of this id ended
    note: str | None = None  # logged (with a line break) before the next row
    alarm_rows: list = field(default_factory=list)  # alarm events not sent yet (alarm_columns.AlarmRow)
    alarm_states: dict = field(default_factory=dict)  # alarm id -> latest state seen (ALARM_STATES)
    alarm_carry: dict = field(default_factory=dict)  # a new output: the states to log again
    wave_rows: list = field(default_factory=list)  # accelerometer samples not sent yet (vibration_columns.WaveRow)
    measured_rows: list = field(default_factory=list)  # measured-window comparisons not sent yet (dicts)
    trend_rows: list = field(default_factory=list)  # rows of the trend window still open (sent: not yet)
    wave_events_s: list = field(default_factory=list)  # simulated times of recent events (WaveformArchive)
    wave_defects: tuple = ()  # the defects of the last row seen
    spectrum_filed_s: float = -math.inf  # simulated time of the last spectra sent to the files

    def keep_state_of(self, old: TwinRows) -> None:
        """The same twin registered again (new geometry): keep its rows and state."""
        self.rows, self.slow_rows, self.last = old.rows, old.slow_rows, old.last
        self.last_time_s, self.last_seq, self.time_offset_s = old.last_time_s, old.last_seq, old.time_offset_s
        self.prev_time_s, self.slow_prev_time_s = old.prev_time_s, old.slow_prev_time_s
        self.alarm_rows, self.alarm_states = old.alarm_rows, old.alarm_states
        self.wave_rows, self.trend_rows = old.wave_rows, old.trend_rows


class RowBatcher:
    """Queues of snapshots, alarm events and waveforms; rows per twin; columns per send."""

    def __init__(
        self,
        *,
        queue_size: int,
        slow_interval_s: float,
        min_interval_s: float,
        wake: threading.Event,
        trend_window_s: float | None = None,
        now_interval_s: float = 0.0,
        waveform_archive: WaveformArchive | None = None,
        contacts_interval_s: float = 0.0,
    ):
        """`trend_window_s` [s of simulated time]: a trend row per window (`service.recording.
        trends`; None: a row per snapshot, no min / max); `now_interval_s` [s of simulated
        time]: the 3D, load-zone and per-contact entities get the first snapshot of each such
        interval (0: every snapshot), the per-contact series of each `contacts_interval_s`.
        `waveform_archive`: which accelerometer samples and spectra the files get (None: all;
        viewers always get all)."""
        self.waveform_archive = waveform_archive
        self.contacts_interval_s = float(contacts_interval_s)
        self.trend_window_s = trend_window_s
        self.now_interval_s = float(now_interval_s)
        self.queue_size = int(queue_size)
        self.slow_interval_s = float(slow_interval_s)
        self.min_interval_s = float(min_interval_s)
        self.wake = wake
        self.wake_at = max(1, self.queue_size // 2)
        self.qlock = threading.Lock()
        self.twins: dict[str, TwinRows] = {}
        self.context: dict[str, Callable[[], Any]] = {}
        self.ended: dict[str, float] = {}
        self._queue: deque = deque()
        self._alarm_queue: deque = deque()
        self._measured_queue: deque = deque()
        self._wave_queue: deque = deque()
        self.dropped = 0
        self.waveform_dropped = 0
        self.alarms_dropped = 0
        self.alarms_logged = 0
        self.errors = 0
        self.skipped = 0

    @property
    def queued(self) -> int:
        return len(self._queue)

    # ---- the publishers' side ---------------------------------------------------------------
    def publish(self, snapshot, positions_m: Any = None) -> None:
        pos = None
        if positions_m is not None:
            try:
                pos = np.array(positions_m, dtype=float).reshape(-1, 3)
            except (TypeError, ValueError) as exc:  # never raise into the runner: draw from azimuth
                log.warning("rerun recorder: positions_m ignored: %s", exc)
        context = None
        ctx = self.context.get(str(getattr(snapshot, "bearing_id", "")))
        if ctx is not None:
            try:
                context = scenario_text(ctx())
            except Exception:  # noqa: BLE001 - never raise into the runner
                context = None
        with self.qlock:
            if len(self._queue) >= self.queue_size:
                self._queue.popleft()
                self.dropped += 1
            self._queue.append((snapshot, pos, context))
            n = len(self._queue)
        if n >= self.wake_at:
            self.wake.set()

    def log_alarm(self, event) -> None:
        try:
            row = A.AlarmRow.of(event)
        except Exception as exc:  # noqa: BLE001 - never raise into the alarm hub
            self.errors += 1
            log.warning("rerun recorder: alarm event skipped: %s", exc)
            return
        with self.qlock:
            if len(self._alarm_queue) >= self.queue_size:
                self._alarm_queue.popleft()
                self.alarms_dropped += 1
            self._alarm_queue.append(row)

    def log_measured(self, comparison: dict) -> None:
        """Queue a measured-window comparison (service.core.measured); drops the oldest when
        `queue_size` wait."""
        with self.qlock:
            if len(self._measured_queue) >= self.queue_size:
                self._measured_queue.popleft()
            self._measured_queue.append(comparison)

    def publish_waveform(self, bearing_id: str, blocks: list, seq: int | None = None) -> None:
        try:
            rows = [
                V.WaveRow(
                    seq=-1 if seq is None else int(seq),
                    t0_s=float(b.t0_s),
                    sample_rate_hz=float(b.sample_rate_hz),
                    samples=np.asarray(b.samples, dtype=np.float32),
                )
                for b in blocks
            ]
        except Exception as exc:  # noqa: BLE001 - never raise into the publisher
            self.errors += 1
            log.warning("rerun recorder: waveform skipped: %s", exc)
            return
        with self.qlock:
            if len(self._wave_queue) >= self.queue_size:
                self._wave_queue.popleft()
                self.waveform_dropped += 1
            self._wave_queue.append((str(bearing_id), rows))

    # ---- twins ------------------------------------------------------------------------------
    def register(self, tw: TwinRows, context, outputs: list) -> None:
        old = self.twins.get(tw.bearing_id)
        if old is not None:
            tw.keep_state_of(old)
        else:
            tw.continue_after_s = self.ended.pop(tw.bearing_id, None)
            tw.alarm_carry = dict.fromkeys(ALARM_IDS, "inactive")  # the state timelines start with it
        self.twins[tw.bearing_id] = tw
        if context is not None:
            self.context[tw.bearing_id] = context
        for out in outputs:
            send_static(out.stream, tw)

    def forget(self, bearing_id: str) -> None:
        """Drop a twin (sent already); a later twin of the same id continues after its end."""
        tw = self.twins.pop(bearing_id)
        if math.isfinite(tw.last_time_s):
            self.ended[bearing_id] = tw.last_time_s + tw.time_offset_s
            while len(self.ended) > _MAX_ENDED:
                self.ended.pop(next(iter(self.ended)))

    def start_output(self, stream) -> None:
        """A new output (file, segment, viewer): the static data of every twin, event state reset."""
        for tw in self.twins.values():
            send_static(stream, tw)
            tw.last.clear()
            # every alarm's state from the first row on (the state timeline shows "inactive" too)
            tw.alarm_carry = {a: tw.alarm_states.get(a, "inactive") for a in ALARM_IDS}

    def note_all(self, text: str) -> None:
        for tw in self.twins.values():
            tw.note = text

    # ---- the worker's side ------------------------------------------------------------------
    def drain(self, has_outputs: bool) -> None:
        """Queued items to rows of their twin (skipped and counted when there is no output)."""
        with self.qlock:
            items = list(self._queue)
            self._queue.clear()
            alarms = list(self._alarm_queue)
            self._alarm_queue.clear()
            measured = list(self._measured_queue)
            self._measured_queue.clear()
            waves = list(self._wave_queue)
            self._wave_queue.clear()
        for bearing_id, wave_rows in waves:
            tw = self.twins.get(bearing_id)
            if tw is not None:
                for w in wave_rows:
                    if w.seq < 0:  # no seq given: the snapshot it came with is the last one seen
                        w.seq = tw.last_seq if tw.last_seq is not None else 0
                tw.wave_rows.extend(wave_rows)
        for comparison in measured:
            tw = self.twins.get(str(comparison.get("bearing_id")))
            if tw is not None:
                tw.measured_rows.append(comparison)
        for row in alarms:
            tw = self.twins.get(row.bearing_id)
            if tw is not None:
                tw.alarm_rows.append(row)
                tw.alarm_states[row.alarm_id] = row.state
        if not items:
            return
        if not has_outputs:  # nowhere to write (no file, no viewer): nothing to convert
            self.skipped += len(items)
            return
        for snapshot, pos, context in items:
            try:
                self._row_of(snapshot, pos, context)
            except Exception as exc:  # noqa: BLE001 - a bad snapshot is skipped and counted
                self.errors += 1
                log.warning(
                    "rerun recorder: snapshot %s/%s skipped: %s",
                    getattr(snapshot, "bearing_id", "?"),
                    getattr(snapshot, "seq", "?"),
                    exc,
                )

    def _row_of(self, snapshot, pos, context) -> None:
        tw = self.twins.get(snapshot.bearing_id)
        if tw is None:
            tw = self._auto_register(snapshot)
        seq = int(snapshot.seq)
        gap = None
        if tw.last_seq is not None and seq != tw.last_seq + 1:
            missing = seq - tw.last_seq - 1
            gap = (
                f"{missing} snapshots not recorded (seq {tw.last_seq + 1}..{seq - 1})"
                if missing > 0
                else f"seq went back from {tw.last_seq} to {seq}"
            )
        tw.last_seq = seq
        t = float(snapshot.time_s)
        if self.min_interval_s > 0.0 and tw.last_time_s <= t < tw.last_time_s + self.min_interval_s:
            self.skipped += 1
            return
        balls = C.ball_count(snapshot)
        if balls != tw.ball_count:
            raise ValueError(f"{balls} balls in the snapshot, {tw.ball_count} registered")
        if pos is not None and pos.shape != (tw.ball_count, 3):
            raise ValueError(f"positions_m has shape {pos.shape}, expected ({tw.ball_count}, 3)")
        row = C.extract(snapshot, pos, context)
        if tw.continue_after_s is not None:  # a new run of a removed twin's id
            start = tw.continue_after_s + _NEW_RUN_GAP_S
            tw.time_offset_s = max(0.0, start - t)
            gap = (
                f"new run of twin {tw.bearing_id}: its simulated time {t:g} s is shown at "
                f"{t + tw.time_offset_s:g} s (after the previous run)"
            )
            tw.continue_after_s = None
        elif t < tw.last_time_s:
            gap = gap or f"simulated time went back from {tw.last_time_s:g} s to {t:g} s"
        if tw.note is not None:
            gap, tw.note = (f"{tw.note}; {gap}" if gap else tw.note), None
        row.gap_before = gap
        tw.last_time_s = t
        tw.rows.append(row)

    def _auto_register(self, snapshot) -> TwinRows:
        log.warning(
            "rerun recorder: twin %r was not added with add_twin: recording its series without geometry",
            snapshot.bearing_id,
        )
        tw = TwinRows(
            bearing_id=str(snapshot.bearing_id),
            designation=str(snapshot.designation),
            ball_count=C.ball_count(snapshot),
        )
        self.register(tw, None, [])
        return tw

    def send(self, outputs: list, force_slow: bool = False) -> int:
        """Send the buffered rows of every twin to every output (one `send_columns` per entity);
        returns the snapshots sent."""
        now = time.monotonic()
        sent = 0
        for tw in self.twins.values():
            rows, tw.rows = tw.rows, []
            alarm_rows, tw.alarm_rows = tw.alarm_rows, []
            wave_rows, tw.wave_rows = tw.wave_rows, []
            measured_rows, tw.measured_rows = tw.measured_rows, []
            if not outputs:
                continue
            try:
                triples = self._columns(tw, rows, alarm_rows, now, force_slow)
                if measured_rows:
                    triples += A.measured_columns(tw, measured_rows, tw.time_offset_s)
                for path, indexes, columns in triples:
                    for out in self._audience(tw, path, rows, outputs):
                        out.stream.send_columns(path, indexes=indexes, columns=columns)
                self._send_waveform(tw, rows, alarm_rows, wave_rows, outputs)
                sent += len(rows)
                self.alarms_logged += len(alarm_rows)
            except Exception:
                self.errors += len(rows)
                log.exception("rerun recorder: %d rows of %s lost", len(rows), tw.bearing_id)
        return sent

    def _audience(self, tw: TwinRows, path: str, rows: list, outputs: list) -> list:
        """Every output, except the files for a spectrum sent less than `spectrum_every_s` after
        the last one they got (with a `waveform_archive`)."""
        archive = self.waveform_archive
        if archive is None or not is_spectrum(path) or not rows:
            return outputs
        t = rows[-1].time_s
        if t >= tw.spectrum_filed_s + archive.spectrum_every_s or t < tw.spectrum_filed_s:
            if path.endswith("/vibration/spectrum_envelope_band"):  # the last of a window's spectra
                tw.spectrum_filed_s = t
            return outputs
        return [o for o in outputs if o.viewer]

    def _send_waveform(self, tw: TwinRows, rows: list, alarm_rows: list, wave_rows: list, outputs: list) -> None:
        """Every sample to the viewers; to the files all of them, or what `waveform_archive` keeps."""
        archive = self.waveform_archive
        if archive is not None and tw.vibration:
            for r in rows:
                defects = tuple(r.defects or ())
                if r.defects is not None and defects != tw.wave_defects:
                    tw.wave_events_s.append(r.time_s)
                    tw.wave_defects = defects
            tw.wave_events_s += [a.time_s for a in alarm_rows if a.transition in ("raised", "escalated")]
        if not wave_rows:
            return
        files = [o for o in outputs if not o.viewer]
        viewers = [o for o in outputs if o.viewer]
        if archive is None:
            groups = [(outputs, wave_rows)]
        else:
            newest = max(w.t0_s for w in wave_rows)
            tw.wave_events_s = [t for t in tw.wave_events_s if t + archive.after_event_s >= newest - 60.0]
            groups = [(viewers, wave_rows), (files, archive.keep(wave_rows, tw.wave_events_s))]
        for k, (outs, part) in enumerate(groups):
            if not outs or not part:
                continue
            triples = V.waveform_columns(tw, part, tw.time_offset_s)
            if k:  # the archive: a line break before every burst
                triples += V.waveform_breaks(tw, part, tw.time_offset_s)
            for path, indexes, columns in triples:
                for out in outs:
                    out.stream.send_columns(path, indexes=indexes, columns=columns)

    @staticmethod
    def _sample(rows: list, tw: TwinRows, key: str, interval_s: float) -> list:
        """The first row of each `interval_s` of simulated time (and every row after a gap)."""
        if interval_s <= 0.0:
            return rows
        last = tw.last
        out = []
        for r in rows:
            k = math.floor(r.time_s / interval_s)
            if last.get(key) != k or r.gap_before is not None:
                out.append(r)
                last[key] = k
        return out

    def _columns(self, tw: TwinRows, rows: list, alarm_rows: list, now_s: float, force_slow: bool) -> list:
        triples: list = []
        if tw.alarm_carry and (rows or alarm_rows):
            first = rows[0] if rows else None
            carry, tw.alarm_carry = tw.alarm_carry, {}
            triples += A.alarm_states_in_force(
                tw,
                carry,
                first.time_s if first else alarm_rows[0].time_s,
                first.seq if first else alarm_rows[0].seq,
                tw.time_offset_s,
            )
        if alarm_rows:
            triples += A.alarm_columns(tw, alarm_rows, tw.time_offset_s)
        if rows:
            batch = C.Batch.of(rows, tw.time_offset_s)
            now = self._sample(rows, tw, "now_interval", self.now_interval_s)
            if now:
                now_batch = C.Batch.of(now, tw.time_offset_s)
                C.now_columns(tw, now_batch)
                triples += now_batch.out
            C.events(tw, batch)
            V.vibration_columns(tw, batch)
            batch.breaks(C.scalar_paths(tw, slow=False), tw.time_offset_s, tw.prev_time_s)
            triples += batch.out
            tw.prev_time_s = rows[-1].time_s
            slow_rows = self._sample(rows, tw, "contacts_interval", self.contacts_interval_s)
            if slow_rows and not tw.slow_rows:
                tw.slow_since = now_s
            tw.slow_rows.extend(slow_rows)
        if rows or (force_slow and tw.trend_rows):
            if self.trend_window_s is None:
                triples += trends.trend_columns(tw, [[r] for r in rows], tw.time_offset_s, bands=False)
            else:
                windows, tw.trend_rows = trends.split_windows(
                    tw.trend_rows + rows, self.trend_window_s, final=force_slow
                )
                triples += trends.trend_columns(tw, windows, tw.time_offset_s)
        if tw.slow_rows and (force_slow or now_s - tw.slow_since >= self.slow_interval_s):
            slow, tw.slow_rows = tw.slow_rows, []
            batch = C.Batch.of(slow, tw.time_offset_s)
            C.slow_columns(tw, batch)
            batch.breaks(C.scalar_paths(tw, slow=True), tw.time_offset_s, tw.slow_prev_time_s)
            tw.slow_prev_time_s = slow[-1].time_s
            triples += batch.out
        return triples
