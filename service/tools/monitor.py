"""`bearing-twin monitor`: a live table of every twin seen on the zenoh bus.

    bearing-twin monitor                                   # connects to tcp/127.0.0.1:7447
    bearing-twin monitor --connect tcp/router.plant1:7447 --prefix 'plant1/**'   # a whole fleet
    bearing-twin monitor --duration 10 'bearing/pump-*/state'

The monitor is a zenoh client of the endpoint it connects to (a service or a router; with
--listen it is a peer instead; multicast scouting off), subscribes to the state key expression
`{prefix}/*/state` and to the liveliness tokens `{prefix}/*/alive`, and renders one row per twin
with rich: the twin's key without the prefix when the prefix is concrete (`default`), its whole
key under a pattern (`plant1/line2/motor7/de`). A twin whose liveliness token goes (its service
stopped or lost) is shown gone, and dropped after --forget-after seconds. zenoh credentials
come from the environment (BEARING_TWIN_ZENOH_USER / _PASSWORD, or _TLS_*). Alarm events
`{prefix}/*/alarm` fill the `alarms` column (the active alarms seen since the monitor started,
`id:severity`; GET /v1/bearings/{id}/alarms lists them all).
"""

from __future__ import annotations

import argparse
import contextlib
import queue
import sys
import time
from typing import Any, Literal

from service.core.json_numbers import finite_number
from service.keys import ALIVE, DEFAULT_PREFIX, STATE, all_twins
from service.tools.arg_types import positive_float
from service.tools.client import strict_json
from twin.snapshot import LAMBDA_KEY

DEFAULT_CONNECT = ["tcp/127.0.0.1:7447"]


def twin_keys(prefix: str) -> tuple[str, str]:
    """(state, liveliness) key expressions of the twins under `prefix` (canonical form)."""
    import zenoh

    return (
        str(zenoh.KeyExpr.autocanonize(all_twins(prefix, STATE))),
        str(zenoh.KeyExpr.autocanonize(all_twins(prefix, ALIVE))),
    )


_REFRESH_S = 0.25
_ONCE_SETTLE_S = 0.5


def twin_name(key: str, prefix: str = DEFAULT_PREFIX) -> str | None:
    """The twin of a `.../{id}/state` or `.../{id}/alive` key: its id when the key is under the
    concrete `prefix`, else its whole key (`plant1/line2/motor7/de`)."""
    head, sep, _last = key.rpartition("/")
    if not sep or not head:
        return None
    if "*" not in prefix and head.startswith(prefix + "/") and "/" not in head[len(prefix) + 1 :]:
        return head[len(prefix) + 1 :]
    return head


class TwinTable:
    """Aggregates state messages and liveliness events into one row per twin."""

    def __init__(self, prefix: str = DEFAULT_PREFIX, forget_gone_s: float | None = None) -> None:
        self.prefix = prefix
        self.forget_gone_s = forget_gone_s  # drop a gone twin's row after this long [s]
        self.rows: dict[str, dict[str, Any]] = {}
        self.invalid = 0  # messages that were not contract JSON objects
        self.departed: dict[str, float] = {}  # forgotten twins: late messages do not revive them

    def _row(self, bearing_id: str) -> dict[str, Any]:
        row = self.rows.get(bearing_id)
        if row is None:
            row = self.rows[bearing_id] = {
                "bearing_id": bearing_id,
                "designation": None,
                "time_s": None,
                "status": None,
                "shaft_speed_rad_s": None,
                "min_lambda": None,
                "regimes": {},
                "friction_torque_n_m": None,
                "discharge_risk": None,
                "seq": None,
                "gaps": 0,
                "missing": 0,
                "messages": 0,
                "alive": None,
                "last_seen": None,
                "key": None,
                "gone_at": None,
                "alarms": {},
            }
        return row

    def on_state(self, key: str, payload: bytes) -> None:
        try:
            data = strict_json(payload)
        except (ValueError, UnicodeDecodeError):
            data = None
        if not isinstance(data, dict):
            self.invalid += 1
            return
        if "balls" not in data:  # a ball or result message matched by a wide key expression
            return
        # the key names the twin (as its liveliness token does); the payload is the fallback
        bearing_id = twin_name(key, self.prefix) or str(data.get("bearing_id") or key)
        row = self.rows.get(bearing_id)
        if bearing_id in self.departed or (row is not None and row["alive"] is False):
            return  # a late message of a twin that is gone (its last snapshots follow its token)
        row = self._row(bearing_id)
        row["messages"] += 1
        row["key"] = key
        row["last_seen"] = time.time()
        if row["alive"] is None:
            row["alive"] = True
        for field in ("designation", "status"):
            if data.get(field) is not None:
                row[field] = data[field]
        for field in ("time_s", "shaft_speed_rad_s", "friction_torque_n_m"):
            row[field] = finite_number(data.get(field))
        seq = data.get("seq")
        if isinstance(seq, int) and not isinstance(seq, bool):
            last = row["seq"]
            if last is not None and seq > last + 1:
                row["gaps"] += 1
                row["missing"] += seq - last - 1
            row["seq"] = seq  # seq <= last: the twin (or service) restarted; follow it
        lambdas: list[float] = []
        regimes: dict[str, int] = {}
        for ball in data.get("balls") or []:
            if not isinstance(ball, dict):
                continue
            for side in ("inner", "outer"):
                contact = ball.get(side)
                if not isinstance(contact, dict):
                    continue
                lam = finite_number(contact.get(LAMBDA_KEY))
                if lam is not None:
                    lambdas.append(lam)
                regime = contact.get("regime")
                if isinstance(regime, str):
                    regimes[regime] = regimes.get(regime, 0) + 1
        row["min_lambda"] = min(lambdas) if lambdas else None
        row["regimes"] = regimes
        electrical = data.get("electrical")
        risk = electrical.get("discharge_risk") if isinstance(electrical, dict) else None
        row["discharge_risk"] = risk if isinstance(risk, (str, int, float)) and not isinstance(risk, bool) else None

    def on_alarm(self, key: str, payload: bytes) -> None:
        """An alarm event (schema bearing-twin/alarm/1): keep the twin's active alarms."""
        try:
            data = strict_json(payload)
        except (ValueError, UnicodeDecodeError):
            data = None
        alarm_id = data.get("alarm_id") if isinstance(data, dict) else None
        if not isinstance(alarm_id, str):
            self.invalid += 1
            return
        alarms = self._row(twin_name(key, self.prefix) or str(data.get("bearing_id") or key))["alarms"]
        if data.get("active") is True:
            alarms[alarm_id] = str(data.get("severity") or "?")
        else:
            alarms.pop(alarm_id, None)

    def on_alive(self, key: str, alive: bool) -> None:
        bearing_id = twin_name(key, self.prefix)
        if bearing_id:
            if alive:
                self.departed.pop(bearing_id, None)
            elif bearing_id in self.departed:
                return
            row = self._row(bearing_id)
            row["alive"] = alive
            row["gone_at"] = None if alive else time.monotonic()

    def forget_gone(self, now: float | None = None) -> list[str]:
        """Drop the rows of twins gone for longer than `forget_gone_s`; returns their names."""
        if self.forget_gone_s is None:
            return []
        now = time.monotonic() if now is None else now
        gone = [
            k
            for k, r in self.rows.items()
            if r["alive"] is False and r["gone_at"] is not None and now - r["gone_at"] >= self.forget_gone_s
        ]
        for k in gone:
            self.departed[k] = self.rows.pop(k)["gone_at"]
        return gone

    def snapshot(self) -> dict[str, dict[str, Any]]:
        return {
            k: {**v, "regimes": dict(v["regimes"]), "alarms": dict(v["alarms"])} for k, v in sorted(self.rows.items())
        }

    def render(self, title: str = "bearing-twin monitor"):
        from rich.table import Table

        table = Table(
            title=title,
            caption=f"{len(self.rows)} twin(s)" + (f", {self.invalid} invalid message(s)" if self.invalid else ""),
        )
        columns: tuple[tuple[str, Literal["left", "right"]], ...] = (
            ("bearing", "left"),
            ("designation", "left"),
            ("alive", "left"),
            ("time s", "right"),
            ("status", "left"),
            ("shaft rad/s", "right"),
            ("min Lambda", "right"),
            ("regimes", "left"),
            ("torque mN m", "right"),
            ("discharge", "right"),
            ("alarms", "left"),
            ("seq", "right"),
            ("gaps", "right"),
        )
        for col, justify in columns:
            table.add_column(col, justify=justify)
        for bearing_id, r in sorted(self.rows.items()):
            alive = {True: "[green]alive[/]", False: "[red]gone[/]", None: "?"}[r["alive"]]
            risk = r["discharge_risk"]
            risk_text = "-" if risk is None else (f"{risk:.3g}" if isinstance(risk, (int, float)) else str(risk))
            status = r["status"] or "-"
            table.add_row(
                bearing_id,
                r["designation"] or "-",
                alive,
                _fmt(r["time_s"], "{:.3f}"),
                status if status == "ok" else f"[yellow]{status}[/]",
                _fmt(r["shaft_speed_rad_s"], "{:.1f}"),
                _fmt(r["min_lambda"], "{:.2f}"),
                " ".join(f"{name}:{n}" for name, n in sorted(r["regimes"].items())) or "-",
                _fmt(None if r["friction_torque_n_m"] is None else r["friction_torque_n_m"] * 1e3, "{:.2f}"),
                risk_text,
                _alarms_text(r["alarms"]),
                "-" if r["seq"] is None else str(r["seq"]),
                str(r["gaps"]) if not r["gaps"] else f"[red]{r['gaps']}[/] ({r['missing']} lost)",
            )
        return table


def _alarms_text(alarms: dict[str, str]) -> str:
    colour = {"critical": "red", "warning": "yellow"}
    return (
        " ".join(f"[{colour.get(sev, 'white')}]{alarm_id}:{sev}[/]" for alarm_id, sev in sorted(alarms.items())) or "-"
    )


def _fmt(value: float | None, spec: str) -> str:
    return "-" if value is None else spec.format(value)


def run_monitor(
    connect: list[str] | None,
    listen: list[str] | None = None,
    keyexpr: str | None = None,
    duration_s: float | None = None,
    once: bool = False,
    out: Any = None,
    *,
    prefix: str = DEFAULT_PREFIX,
    forget_gone_s: float | None = None,
    access: Any = None,
    on_update: Any = None,
    stop: Any = None,
) -> dict[str, dict[str, Any]]:
    """Watch the bus and render a live table; return the final rows {twin: {...}}.

    connect: endpoints to connect to (None or [] -> tcp/127.0.0.1:7447 unless `listen` is given);
    listen: endpoints to listen on (default none: the monitor is a zenoh client); keyexpr: the
    state key expression (default {prefix}/*/state); prefix: the twins' key prefix or a pattern
    (`plant1/**`); duration_s: stop after this many seconds (None: until Ctrl-C); once: print one
    table as soon as a twin has been seen (plus a short settle time) and stop; forget_gone_s:
    drop gone twins after this long (None: keep them, marked gone); access: zenoh credentials
    (service.bus.access.ZenohAccess; default from the environment); on_update(rows): called
    from the monitor's thread after each batch of messages (tests); stop: a threading.Event that
    ends the watch when set; out: a rich Console or a text file (default stdout).
    """
    import zenoh
    from rich.console import Console
    from rich.live import Live

    from service.bus.zenoh_bus import client_config

    state_key, alive_key = twin_keys(prefix)
    keyexpr = keyexpr or state_key
    connect = list(connect or [])
    listen = list(listen or [])
    if not connect and not listen:
        connect = list(DEFAULT_CONNECT)
    if isinstance(out, Console):
        console = out
    else:
        stream = out if out is not None else sys.stdout
        interactive = bool(getattr(stream, "isatty", lambda: False)())
        console = Console(file=stream, width=None if interactive else 160)
    table = TwinTable(prefix, forget_gone_s)
    inbox: queue.SimpleQueue = queue.SimpleQueue()  # zenoh callbacks only push; this thread parses and renders

    def on_sample(sample: zenoh.Sample) -> None:  # zenoh thread: hand off only
        with contextlib.suppress(Exception):
            inbox.put(("state", str(sample.key_expr), sample.payload.to_bytes()))

    def on_alarm(sample: zenoh.Sample) -> None:
        with contextlib.suppress(Exception):
            inbox.put(("alarm", str(sample.key_expr), sample.payload.to_bytes()))

    def on_alive(sample: zenoh.Sample) -> None:
        with contextlib.suppress(Exception):
            inbox.put(("alive", str(sample.key_expr), sample.kind == zenoh.SampleKind.PUT))

    def drain(timeout: float) -> int:
        n = 0
        try:
            item = inbox.get(timeout=max(timeout, 0.0))
            while True:
                kind, key, value = item
                if kind == "state":
                    table.on_state(key, value)
                elif kind == "alarm":
                    table.on_alarm(key, value)
                else:
                    table.on_alive(key, value)
                n += 1
                item = inbox.get_nowait()
        except queue.Empty:
            pass
        table.forget_gone()
        if on_update is not None:
            on_update(table.snapshot())
        return n

    title = f"bearing-twin monitor: {keyexpr} via {', '.join(connect) or 'listen ' + ', '.join(listen)}"
    session = zenoh.open(client_config(connect, listen=listen, access=access, prefix=prefix))
    subscribers = []  # keep references: undeclared when dropped or at the end
    try:
        subscribers.append(session.declare_subscriber(keyexpr, on_sample))
        subscribers.append(session.declare_subscriber(alive_key.replace("/alive", "/alarm"), on_alarm))
        subscribers.append(session.liveliness().declare_subscriber(alive_key, on_alive, history=True))
        start = time.monotonic()
        deadline = None if duration_s is None else start + duration_s
        if once:
            first_seen = None
            while deadline is None or time.monotonic() < deadline:
                drain(0.05)
                if first_seen is None and any(r["messages"] for r in table.rows.values()):
                    first_seen = time.monotonic()
                if first_seen is not None and time.monotonic() - first_seen >= _ONCE_SETTLE_S:
                    break
            console.print(table.render(title))
        else:
            try:
                with Live(table.render(title), console=console, auto_refresh=False, transient=False) as live:
                    next_refresh = 0.0
                    while (deadline is None or time.monotonic() < deadline) and not (stop and stop.is_set()):
                        now = time.monotonic()
                        wait = _REFRESH_S if deadline is None else min(_REFRESH_S, deadline - now)
                        drain(wait)
                        if time.monotonic() >= next_refresh:
                            live.update(table.render(title), refresh=True)
                            next_refresh = time.monotonic() + _REFRESH_S
                    drain(0.0)
                    live.update(table.render(title), refresh=True)
            except KeyboardInterrupt:
                pass
            if not console.is_terminal:
                console.line()  # Live leaves the cursor after the last line of a file
    finally:
        for sub in subscribers:
            with contextlib.suppress(Exception):
                sub.undeclare()
        session.close()
    return table.snapshot()


def _cmd_monitor(args: argparse.Namespace) -> int:
    from pydantic import ValidationError

    from service.settings import ZenohAccessSettings

    try:
        given: dict[str, Any] = {"zenoh": {"prefix": args.prefix}} if args.prefix else {}
        env = ZenohAccessSettings(**given)
    except ValidationError as exc:
        print(
            "error: monitor: " + "; ".join(str(e["msg"]).removeprefix("Value error, ") for e in exc.errors()),
            file=sys.stderr,
        )
        return 2
    try:
        from service.bus.access import ZenohAccess

        run_monitor(
            args.connect,
            args.listen,
            args.keyexpr,
            duration_s=args.duration,
            once=args.once,
            prefix=env.zenoh.prefix,
            forget_gone_s=args.forget_after,
            access=ZenohAccess.from_settings(env.zenoh),
        )
    except KeyboardInterrupt:
        return 0
    except Exception as exc:  # noqa: BLE001 - bad endpoint, port in use, ...
        print(f"error: monitor: {' '.join(str(exc).split())}", file=sys.stderr)
        return 2
    return 0


def add_monitor_command(subparsers: Any) -> argparse.ArgumentParser:
    """Register `monitor` on an argparse subparsers object; its `func(args)` returns an exit code."""
    p = subparsers.add_parser(
        "monitor",
        help="live table of the twins on the zenoh bus",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "keyexpr", nargs="?", default=None, help="state key expression to subscribe to (default {prefix}/*/state)"
    )
    p.add_argument(
        "--prefix",
        default=None,
        help="key prefix of the twins, or a pattern for a fleet: plant1/** (default "
        "$BEARING_TWIN_ZENOH_PREFIX, else bearing)",
    )
    p.add_argument(
        "--forget-after",
        type=positive_float,
        default=10.0,
        metavar="SECONDS",
        help="drop a gone twin's row after this long (default 10)",
    )
    p.add_argument(
        "--connect",
        metavar="ENDPOINT",
        action="append",
        default=None,
        help="zenoh endpoint to connect to (repeatable; default tcp/127.0.0.1:7447)",
    )
    p.add_argument(
        "--listen",
        metavar="ENDPOINT",
        action="append",
        default=None,
        help="zenoh endpoint to listen on (repeatable; default: none)",
    )
    p.add_argument(
        "--duration",
        type=positive_float,
        default=None,
        metavar="SECONDS",
        help="stop after this many seconds (default: until Ctrl-C)",
    )
    p.add_argument("--once", action="store_true", help="print one table once a twin is seen, then exit")
    p.set_defaults(func=_cmd_monitor)
    return p


build_parser = add_monitor_command  # alias
