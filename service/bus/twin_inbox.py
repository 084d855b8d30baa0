"""What reaches a twin from the zenoh bus: setpoints, defects, measured accelerometer windows and
temperatures, snapshot and owner queries, each answered (the incoming half of
`service.bus.zenoh_bus.TwinChannel`).

zenoh runs its callbacks on its own threads; those only append to a bounded queue and return.
The inbox's control thread calls the intake (`on_setpoint(payload)`, ...) and publishes what
became of each message on its result key, and answers the queries. Every exception from the
callee is a refusal; nothing kills the thread. Nothing is dropped unanswered: when
`CONTROL_QUEUE_SIZE` items wait, a query is answered "busy" at once and a setpoint is counted and
refused with status 429 on the result key.
"""

from __future__ import annotations

import collections
import contextlib
import logging
import threading
from collections.abc import Callable
from typing import Any

import zenoh

from service.bus.twin_outbox import undeclare
from service.bus.wire import JSON_ENCODING, Bus, dumps, one_line, payload
from service.keys import (
    DEFECTS,
    DEFECTS_RESULT,
    OWNER,
    SETPOINT,
    SETPOINT_RESULT,
    SNAPSHOT,
    TEMPERATURE,
    TEMPERATURE_RESULT,
    VIBRATION_COMPARISON,
    VIBRATION_MEASURED,
    twin_key,
)
from twin.snapshot import Snapshot

log = logging.getLogger(__name__)

CONTROL_QUEUE_SIZE = 256

Handler = Callable[[bytes], dict]


class TwinInbox:
    """The subscribers, queryables and result publishers of one twin, and its control thread."""

    def __init__(
        self,
        bus: Bus,
        bearing_id: str,
        get_snapshot: Callable[[], Snapshot | None],
        on_setpoint: Handler,
        *,
        on_defects: Handler | None = None,
        on_measured: Handler | None = None,
        on_temperature: Handler | None = None,
        known_state: Callable[[Snapshot], str | None] = lambda _s: None,
    ):
        self.bus = bus
        self.bearing_id = bearing_id
        self.prefix = twin_key(bus.prefix, bearing_id)
        self._get_snapshot = get_snapshot
        self._known_state = known_state
        self._on_setpoint = on_setpoint
        self.setpoints_received = 0
        self.writes_received: collections.Counter[str] = collections.Counter()  # defects, measured, temperature
        self.setpoints_refused_busy = 0  # writes refused (429 on their result key): control queue full
        self.queries_answered = 0
        self._busy_pending = 0  # of those, refusals not yet published
        self._busy_marked = 0  # 1 while a ("busy", None) marker waits in the control queue
        self._closed = False
        self._gone = False  # result publishers undeclared
        self._control: collections.deque = collections.deque()
        self._control_cond = threading.Condition()
        session = bus.session
        key = lambda suffix: twin_key(bus.prefix, bearing_id, suffix)  # noqa: E731
        # BLOCK, not DROP: a result is never lost in zenoh's transmission queue (with DROP, 13-18 of
        # 30 000 results of an `attack --record` zenoh flood never arrived); the back-pressure is the
        # control thread's bounded queue, which refuses further setpoints with 429
        self._result_pub = session.declare_publisher(
            key(SETPOINT_RESULT), encoding=JSON_ENCODING, congestion_control=zenoh.CongestionControl.BLOCK
        )
        self._setpoint_sub = session.declare_subscriber(
            key(SETPOINT), lambda sample: self._enqueue(("setpoint", payload(sample)))
        )
        # the writes besides setpoints: defects (service.core.intake.DefectIntake), measured
        # accelerometer windows (service.core.measured: binary frame in, comparison out) and
        # measured temperatures (service.core.intake.TemperatureIntake)
        self._defects_sub, self._defects_result_pub = self._declare_write(
            "defects", DEFECTS, DEFECTS_RESULT, on_defects
        )
        self._measured_sub, self._comparison_pub = self._declare_write(
            "measured", VIBRATION_MEASURED, VIBRATION_COMPARISON, on_measured
        )
        self._temperature_sub, self._temperature_result_pub = self._declare_write(
            "temperature", TEMPERATURE, TEMPERATURE_RESULT, on_temperature
        )
        # kind -> (handler, result publisher)
        self._writes: dict[str, tuple[Handler | None, Any]] = {
            "defects": (on_defects, self._defects_result_pub),
            "measured": (on_measured, self._comparison_pub),
            "temperature": (on_temperature, self._temperature_result_pub),
        }
        self._queryable = session.declare_queryable(key(SNAPSHOT), lambda query: self._enqueue(("query", query)))
        self._owner_queryable = session.declare_queryable(key(OWNER), lambda query: self._enqueue(("owner", query)))
        self._thread = threading.Thread(target=self._loop, name=f"zenoh-ctl-{bearing_id}", daemon=True)
        self._thread.start()

    def _declare_write(self, kind: str, suffix: str, result_suffix: str, handler: Handler | None) -> tuple[Any, Any]:
        """(subscriber, result publisher) of one kind of write (None, None without a handler); the
        result publisher BLOCKs as the setpoint result's does."""
        if handler is None:
            return None, None
        session = self.bus.session
        result_pub = session.declare_publisher(
            twin_key(self.bus.prefix, self.bearing_id, result_suffix),
            encoding=JSON_ENCODING,
            congestion_control=zenoh.CongestionControl.BLOCK,
        )
        sub = session.declare_subscriber(
            twin_key(self.bus.prefix, self.bearing_id, suffix), lambda sample: self._enqueue((kind, payload(sample)))
        )
        return sub, result_pub

    def close_entrances(self) -> None:
        """Stop taking messages: undeclare the subscribers and queryables; what waits is still
        handled until `stop`."""
        with self._control_cond:
            self._closed = True
        for entity in (
            self._setpoint_sub,
            self._defects_sub,
            self._measured_sub,
            self._temperature_sub,
            self._queryable,
            self._owner_queryable,
        ):
            if entity is not None:
                undeclare(entity)

    def stop(self, timeout_s: float) -> None:
        """Answer what waits (queries: "twin detached"), stop the thread, undeclare the result publishers."""
        with self._control_cond:
            self._closed = True
            self._control.append(None)
            self._control_cond.notify()
        if self._thread is not threading.current_thread():  # e.g. detach from inside on_setpoint
            self._thread.join(timeout_s)
        self._gone = True
        for pub in (self._result_pub, self._defects_result_pub, self._comparison_pub, self._temperature_result_pub):
            if pub is not None:
                undeclare(pub)

    # ---- zenoh callbacks: hand off only -----------------------------------------------------
    def _enqueue(self, item: tuple[str, Any]) -> None:
        """Queue a message or query for the control thread (see the module docstring)."""
        with self._control_cond:
            if self._closed:
                finish_query(item, error="twin detached")
                return
            if len(self._control) - self._busy_marked >= CONTROL_QUEUE_SIZE:
                if item[0] == "setpoint":
                    self.setpoints_refused_busy += 1
                    self._busy_pending += 1
                    if not self._busy_marked:  # one marker, beyond the bound
                        self._busy_marked = 1
                        self._control.append(("busy", None))
                        self._control_cond.notify()
                elif item[0] in self._writes:  # rare: refused at once on its result key
                    self.setpoints_refused_busy += 1
                    pub = self._writes[item[0]][1]
                    if not self._gone and pub is not None:
                        with contextlib.suppress(Exception):
                            pub.put(self._busy_refusal("messages"))
                else:
                    finish_query(item, error="busy: too many requests waiting, retry")
                return
            self._control.append(item)
            self._control_cond.notify()

    # ---- control thread ---------------------------------------------------------------------
    def _loop(self) -> None:
        while True:
            with self._control_cond:
                while not self._control:
                    self._control_cond.wait()
                item = self._control.popleft()
            if item is None:
                with self._control_cond:  # answer what is left, then stop
                    rest, self._control = list(self._control), collections.deque()
                for other in rest:
                    finish_query(other, error="twin detached")
                return
            kind, value = item
            try:
                if kind == "busy":
                    self._refuse_busy()
                elif kind == "setpoint":
                    self.setpoints_received += 1
                    self._handle_write(value, self._on_setpoint, self._result_pub)
                elif kind in self._writes:
                    self.writes_received[kind] += 1
                    self._handle_write(value, *self._writes[kind])
                elif kind == "owner":
                    self._handle_owner_query(value)
                else:
                    self._handle_query(value)
            except Exception as exc:  # noqa: BLE001 - nothing kills the control thread
                log.warning("%s: %s handling failed: %s", self.prefix, kind, one_line(exc))

    def _handle_write(self, data: bytes, handler: Handler | None, result_pub: Any) -> None:
        """Call the intake, publish what became of the message on its result key."""
        try:
            if handler is None:
                raise RuntimeError("no handler for this message")
            result = handler(data)
            if not isinstance(result, dict):
                raise TypeError(f"handler returned {type(result).__name__}, not a dict")
            result = dict(result)
            result.setdefault("accepted", False)
            text = dumps({**result, "bearing_id": self.bearing_id})
        except Exception as exc:  # noqa: BLE001 - every failure is a refusal
            text = dumps({"accepted": False, "error": one_line(exc), "bearing_id": self.bearing_id})
        if not self._gone and result_pub is not None:
            result_pub.put(text)

    def _busy_refusal(self, what: str) -> str:
        """The result-key refusal (status 429) of a message of kind `what` (plural) that found
        the control queue full."""
        return dumps(
            {
                "accepted": False,
                "status": 429,
                "retry_after_s": 0.1,
                "error": f"too many {what} waiting for twin {self.bearing_id!r} "
                f"({CONTROL_QUEUE_SIZE} queued, the most this twin queues): refused, retry",
                "bearing_id": self.bearing_id,
            }
        )

    def _refuse_busy(self) -> None:
        """Publish one 429 refusal for each setpoint that found the control queue full."""
        with self._control_cond:
            count, self._busy_pending, self._busy_marked = self._busy_pending, 0, 0
        text = self._busy_refusal("setpoints")
        self.setpoints_received += count
        for _ in range(count):
            if self._gone:
                return
            self._result_pub.put(text)

    def _handle_query(self, query: zenoh.Query) -> None:
        try:
            snapshot = self._get_snapshot()
            if snapshot is None:
                query.reply_err(dumps({"error": "no snapshot yet"}), encoding=JSON_ENCODING)
                return
            text = self._known_state(snapshot) or snapshot.to_json()
            query.reply(twin_key(self.bus.prefix, self.bearing_id, SNAPSHOT), text, encoding=JSON_ENCODING)
            self.queries_answered += 1
        except Exception as exc:  # noqa: BLE001
            with contextlib.suppress(Exception):
                query.reply_err(dumps({"error": one_line(exc)}), encoding=JSON_ENCODING)
        finally:
            with contextlib.suppress(Exception):
                query.drop()

    def _handle_owner_query(self, query: zenoh.Query) -> None:
        try:
            query.reply(
                twin_key(self.bus.prefix, self.bearing_id, OWNER),
                dumps(self.bus.owner(self.bearing_id)),
                encoding=JSON_ENCODING,
            )
        finally:
            with contextlib.suppress(Exception):
                query.drop()


def finish_query(item: Any, error: str) -> None:
    """Answer a queued query with `error` and drop it (other items: nothing to answer)."""
    if item is None or item[0] not in ("query", "owner"):
        return
    query = item[1]
    with contextlib.suppress(Exception):
        query.reply_err(dumps({"error": error}), encoding=JSON_ENCODING)
    with contextlib.suppress(Exception):
        query.drop()
