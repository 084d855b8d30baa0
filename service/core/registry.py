"""`TwinRegistry`: the twins of one service, their runners, the admission gate and /health.

No transport here: the zenoh bus and the recorders are plugged in from outside through
`Bus` / `Recorder` (service.wiring opens them from the settings):

    create twin -> Twin (warm-started) -> admission by measured capacity (service.core.capacity:
                   calibration, 503 when this host cannot run it in real time beside the others)
                -> TwinRunner (not started, stepped by the registry's SteppingPool) -> SetpointIntake
                -> bus.attach_twin(id, latest, intake) channel as a sink
                -> recorder.add_twin_from(twin), recorder as a sink
                -> alarms.add_twin(id), the alarm hub as a sink -> runner.start()
    delete twin -> runner.stop() -> channel.detach() -> alarms forgotten -> per-twin recording closed
    close       -> every runner stopped (all asked first, then joined) -> channels detached
                -> per-twin recordings closed -> stepping pool closed -> hook `_close_outputs`
                   (service recording, zenoh session)

One `SteppingPool` (service.core.pool) runs every twin's frames on `stepping_threads` threads
(one per core by default), earliest deadline first, and builds their snapshots on its publish
worker.

A twin's own recording (`start_recording`) goes to a path under the recordings directory
(relative, plain names, .rrd), made by `_new_recording(path)`.

The module is longer than the project's 600 lines because it is the one place where a twin's
life is wired (create, admission, delete, close, its recording, health) and each step of that
wiring must be read beside the others; the policies it applies live elsewhere (capacity, pool,
intake, alarm hub).
"""

from __future__ import annotations

import logging
import os
import re
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any, Protocol

from pydantic import ValidationError

from service.core.admission import AdmissionGate
from service.core.alarm_hub import AlarmHub
from service.core.alarms import AlarmEvent
from service.core.capacity import (
    Capacity,
    ServiceOverheadMeter,
    TwinCost,
    calibrate,
    expected_engine_cost,
    mean_engine_cost,
    usable_cores,
)
from service.core.errors import InputError, field_errors, setpoint_field_errors
from service.core.heap import freeze_heap
from service.core.intake import DefectIntake, SetpointIntake, TemperatureIntake
from service.core.measured import MeasuredComparator, MeasuredIntake
from service.core.pool import SteppingPool
from service.core.priority import EGRESS_THREAD_NAMES, ThreadPriority
from service.core.runner import TwinRunner
from service.core.sinks import SnapshotSink
from service.core.thread_cpu import ThreadCpuMeter
from service.keys import TWIN_ID_PATTERN, TWIN_ID_RE
from service.settings import ServiceSettings
from twin import catalog
from twin.engine import Twin
from twin.setpoint import SetpointError, SetpointUpdate
from twin.snapshot import Snapshot
from twin.spec import BearingSpec, Thermal

log = logging.getLogger(__name__)

ID_PATTERN = TWIN_ID_PATTERN
# per-twin recording paths: relative, plain names (no control characters, spaces, '..', hidden
# folders), so a request cannot reach outside the recordings directory or trip the file system
_REC_PATH_RE = re.compile(r"^(?=.{1,256}$)(?:[A-Za-z0-9_][A-Za-z0-9_.-]*/)*[A-Za-z0-9_][A-Za-z0-9_.-]*\.rrd$")


def admission_gate(settings: ServiceSettings) -> AdmissionGate:
    """The service's one admission gate (HTTP and zenoh) from its settings."""
    bus_writes = (
        "authorized" if settings.zenoh.access_control else "closed" if settings.security.token is not None else "open"
    )
    return AdmissionGate(
        token=settings.security.token_value,
        setpoint_rate_hz=settings.security.setpoint_rate_hz or None,
        setpoint_burst=settings.security.setpoint_burst,
        max_payload_bytes=settings.security.max_body_bytes,
        bus_writes=bus_writes,
        read_rate_hz=settings.security.read_rate_hz or None,
        read_burst=settings.security.read_burst,
        error_rate_hz=settings.security.client_error_rate_hz or None,
        error_burst=settings.security.client_error_burst,
    )


class Channel(SnapshotSink, Protocol):
    """A twin's link to the bus."""

    def detach(self) -> None: ...

    # optional: `publish_alarm(event: dict)` puts an alarm event on `bearing/{id}/alarm`


class Bus(Protocol):
    """The message bus the twins are attached to (service.bus.zenoh_bus.ZenohBus)."""

    closed: bool

    def attach_twin(
        self,
        bearing_id: str,
        get_snapshot: Callable[[], Snapshot | None],
        on_setpoint: Callable[[bytes], dict],
        *,
        on_defects: Callable[[bytes], dict] | None = None,
        on_measured: Callable[[bytes], dict] | None = None,
        on_temperature: Callable[[bytes], dict] | None = None,
    ) -> Channel: ...

    def close(self) -> None: ...


class Recorder(SnapshotSink, Protocol):
    """A recording of one or more twins (service.recording.RerunRecorder)."""

    path: Path | None
    rows_logged: int

    def add_twin_from(self, twin: Twin) -> None: ...

    def log_alarm(self, event: AlarmEvent) -> None: ...


@dataclass
class TwinEntry:
    """One twin of the service and what is wired to it."""

    id: str
    twin: Twin
    runner: TwinRunner
    intake: SetpointIntake
    lubricant: str
    measured: MeasuredComparator  # measured vibration beside the twin (service.core.measured)
    channel: Any = None  # the bus channel (a sink)
    recording: Any = None  # this twin's own recording (POST .../recording)
    recording_path: Path | None = None
    created_wall_s: float = field(default_factory=time.time)

    @property
    def designation(self) -> str:
        return self.twin.model.spec.designation

    @property
    def diametral_clearance_m(self) -> float:
        return float(self.twin.model.spec.mounting.diametral_clearance_m)


class TwinRegistry:
    """Owns the twins, the admission gate and the plugged-in bus / recorder of one service."""

    def __init__(self, settings: ServiceSettings, gate: AdmissionGate | None = None):
        self.settings = settings
        self.gate = gate if gate is not None else admission_gate(settings)
        self.bus: Bus | None = None
        self.recorder: Recorder | None = None
        self.started_wall_s = time.monotonic()
        self._twins: dict[str, TwinEntry] = {}
        self._reserved: set[str] = set()  # ids of twins being built
        self._admitting: dict[str, TwinCost] = {}  # costs of twins admitted, not yet running
        threads = settings.runner.stepping_threads or usable_cores()
        self.pool = SteppingPool(threads, name="step")
        self.priority = ThreadPriority(
            self.pool.native_ids,
            settings.runner.io_thread_nice,
            settings.runner.stepping_thread_nice,
            keep_names=EGRESS_THREAD_NAMES,
        )
        self.overhead = ServiceOverheadMeter()
        self.thread_cpu = ThreadCpuMeter()  # the overhead by the job of its threads
        self.capacity = Capacity(
            threads, settings.runner.capacity_core_fraction, reserve_cores=settings.runner.capacity_reserve_cores
        )
        self.last_calibration: TwinCost | None = None
        self._last_calibrated: Twin | None = None  # the twin of last_calibration
        self.over_capacity: str | None = None  # why the configured twin runs over capacity
        self._over_capacity_id: str | None = None
        self._recording_lock = threading.RLock()
        self._lock = threading.RLock()
        self._closed = False
        self.alarms = AlarmHub(settings.alarms)  # every twin's alarms (a sink on each runner)
        self.alarms.subscribe(self._alarm_to_bus)

    def _alarm_to_bus(self, event: AlarmEvent) -> None:
        """Hand an alarm event to the twin's bus channel (`bearing/{id}/alarm`)."""
        entry = self.find(event.bearing_id)
        publish = getattr(entry.channel, "publish_alarm", None) if entry is not None else None
        if publish is not None:
            publish(event.to_dict())

    # ---- outputs: hooks for the wiring ---------------------------------------------------
    def _open_outputs(self) -> None:
        """Open the bus and the service recording (none here)."""

    def _close_outputs(self) -> None:
        """Close the service recording and the bus."""

    def _new_recording(self, path: Path) -> Recorder:
        """A recorder writing one twin to `path` (OSError / RuntimeError / ValueError when it
        cannot)."""
        raise RuntimeError("this service has no recorder")

    # ---- life cycle ------------------------------------------------------------------------
    def open(self, *, default_twin: bool = True) -> TwinRegistry:
        """Open the outputs and start the `default` twin."""
        if sys.getswitchinterval() > self.settings.runner.gil_switch_interval_s:
            sys.setswitchinterval(self.settings.runner.gil_switch_interval_s)  # process-wide, see settings
        try:
            self.pool.start()
            self.priority.start()  # after the pool: its threads keep their nice
            self._open_outputs()
            if default_twin and self.settings.twin.start:
                self.create_twin(id=self.settings.twin.id, over_capacity_ok=True, **self._configured_bearing())
            if self.settings.runner.gc_freeze:
                freeze_heap()
        except BaseException:
            self.close()
            raise
        return self

    def _configured_bearing(self) -> dict[str, Any]:
        """The create_twin options of the configured twin: its designation, or the spec of a
        bearing spec file (`settings.twin.bearing` ending in .yaml, .yml, .json; read on the server by
        its operator), with the housing when `settings.twin.housing`."""
        name, housing = self.settings.twin.bearing, self.settings.twin.housing
        if not name.strip().lower().endswith(catalog.SPEC_FILE_SUFFIXES):
            return {"designation": name, **({"housing": {"enabled": True}} if housing else {})}
        spec = catalog.load_spec_file(name.strip())
        if housing:
            spec = spec.model_copy(update={"housing": spec.housing.model_copy(update={"enabled": True})})
        return {"spec": spec}

    def close(self) -> None:
        """Stop every runner, detach the bus, close recordings (nothing queued is lost), close
        the outputs. Idempotent; never raises."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
            entries = list(self._twins.values())
            self._twins.clear()
        for e in entries:  # ask all to stop first, then join
            e.runner.request_stop()
        for e in entries:
            try:
                e.runner.stop(timeout=5.0)
            except Exception:
                log.exception("stopping twin %s", e.id)
        for e in entries:
            self._unwire(e)
        self.alarms.close()
        self.priority.close()
        if not self.pool.close(timeout=5.0):
            log.error("the stepping pool did not stop within 5 s")
        self._close_outputs()

    def _unwire(self, e: TwinEntry) -> None:
        if e.channel is not None:
            try:
                e.runner.remove_sink(e.channel)
                e.channel.detach()
            except Exception:
                log.exception("detaching twin %s from the bus", e.id)
            e.channel = None
        if self.recorder is not None:
            e.runner.remove_sink(self.recorder)
        e.runner.remove_sink(self.alarms)
        self.alarms.forget(e.id)
        self.stop_recording(e)
        self.gate.forget(e.id)

    # ---- twins -----------------------------------------------------------------------------
    def entries(self) -> list[TwinEntry]:
        with self._lock:
            return list(self._twins.values())

    def get(self, bearing_id: str) -> TwinEntry:
        """The twin (InputError 404 naming the known ones)."""
        with self._lock:
            entry = self._twins.get(bearing_id)
            if entry is None:
                raise self._not_found(bearing_id)
        return entry

    def _not_found(self, bearing_id: str) -> InputError:
        """The 404 naming the known twins (call with the lock held)."""
        known = sorted(self._twins)
        return InputError.one(
            "bearing_id", f"unknown twin {bearing_id!r}; known: {', '.join(known) or 'none'}", known, status_code=404
        )

    def find(self, bearing_id: str) -> TwinEntry | None:
        with self._lock:
            return self._twins.get(bearing_id)

    def _new_id(self, designation: str) -> str:
        stem = re.sub(r"[^A-Za-z0-9_.-]+", "-", designation.strip()).strip("-._")[:48] or "bearing"
        n = 1
        while f"{stem}-{n}" in self._twins or f"{stem}-{n}" in self._reserved:
            n += 1
        return f"{stem}-{n}"

    def build_twin(
        self,
        bearing_id: str,
        designation: str = catalog.DEFAULT_DESIGNATION,
        diametral_clearance_m: float = 0.0,
        lubricant: str = "seed-000",
        setpoint: SetpointUpdate | None = None,
        thermal: Thermal | None = None,
        housing: Any = None,
        spec: BearingSpec | dict | None = None,
    ) -> Twin:
        """A warm-started Twin (InputError naming the field if a value is not valid). `housing`:
        twin.vibration.housing.Housing (or its dict); `{"enabled": true}` puts the outer ring on
        the housing support with the accelerometer. `spec`: a whole bearing spec
        (twin.spec.BearingSpec or its dict, errors named 'spec.<path>') in place of the designation
        and its overrides, which are then ignored."""
        if spec is not None:
            try:
                spec = spec if isinstance(spec, BearingSpec) else BearingSpec.model_validate(spec)
            except ValidationError as exc:
                raise InputError(field_errors(exc.errors(), model=BearingSpec, prefix="spec.")) from None
            try:
                twin = Twin(spec, bearing_id=bearing_id)  # at the bearing's default setpoint
            except (ValueError, ArithmeticError) as exc:  # a valid spec the model cannot compile
                raise InputError.one(
                    "spec", f"bearing {spec.designation!r} cannot be modelled: {' '.join(str(exc).split())[:300]}"
                ) from None
        else:
            twin = Twin(
                self._catalog_spec(designation, diametral_clearance_m, lubricant, thermal, housing),
                bearing_id=bearing_id,
            )
        if setpoint is not None:
            try:
                twin.set_setpoint(setpoint)
            except SetpointError as exc:
                raise InputError(setpoint_field_errors(exc, prefix="setpoint.")) from None
            twin.reset()  # warm start at the requested setpoint
        return twin

    @staticmethod
    def _catalog_spec(
        designation: str, diametral_clearance_m: float, lubricant: str, thermal: Thermal | None, housing: Any
    ) -> BearingSpec:
        """The catalog bearing with its overrides (InputError naming the field)."""
        wanted = designation
        designation = designation.strip().upper()
        if designation not in catalog.designations():
            raise InputError.one("designation", f"unknown bearing {wanted!r}", catalog.designations())
        try:
            lub = catalog.lubricant(lubricant)
        except ValueError as exc:
            raise InputError.one("lubricant", str(exc).removeprefix("lubricant: ")) from None
        try:
            extra = {"thermal": thermal} if thermal else {}
            if housing is not None:
                extra["housing"] = housing
            return catalog.bearing(designation, diametral_clearance_m=diametral_clearance_m, lubricant=lub, **extra)
        except ValidationError as exc:
            raise InputError(field_errors(exc.errors(), model=BearingSpec)) from None

    def create_twin(
        self,
        id: str | None = None,
        designation: str = catalog.DEFAULT_DESIGNATION,
        *,
        over_capacity_ok: bool = False,
        **options: Any,
    ) -> TwinEntry:
        """Create, wire and start a twin (`options`: diametral_clearance_m, lubricant, setpoint,
        thermal, housing; or spec: a whole BearingSpec, whose designation names the twin by default).
        InputError 409 on a duplicate id or at max_twins, 503 when this host cannot run it in real time (admission
        'measured'; `over_capacity_ok`: start it anyway, with a
        warning: the twin of the configuration), 422 for an invalid value."""
        s = self.settings
        with self._lock:
            if self._closed:
                raise InputError.one(None, "the service is shutting down", status_code=503)
            spec = options.get("spec")
            if isinstance(spec, BearingSpec):
                designation = spec.designation
            elif isinstance(spec, dict):
                designation = str(spec.get("designation", "bearing"))
            bearing_id = id or self._new_id(designation.strip().upper())
            if not TWIN_ID_RE.match(bearing_id):
                raise InputError.one(
                    "id",
                    f"{bearing_id!r}: letters, digits, '_', '.', '-' only "
                    "(it is used in URLs and zenoh key expressions)",
                )
            if bearing_id in self._twins or bearing_id in self._reserved:
                raise InputError.one("id", f"a twin named {bearing_id!r} already exists", status_code=409)
            limit = s.runner.twin_limit
            if len(self._twins) + len(self._reserved) >= limit:
                raise InputError.one(
                    None,
                    f"this service already runs {len(self._twins)} twins (max_twins = {limit})",
                    [0, limit],
                    status_code=409,
                )
            # reserve the id while the (slow) model is built outside the lock
            self._reserved.add(bearing_id)
        entry = None
        try:
            twin = self.build_twin(bearing_id, designation, **options)
            cost = self._admit(bearing_id, twin, over_capacity_ok)
            runner = TwinRunner(
                twin,
                fast=s.runner.fast,
                publish_rate_hz=s.runner.publish_rate_hz,
                frame_s=s.runner.frame_s,
                setpoint_frame_s=s.runner.setpoint_frame_s,
                lateness_s=s.runner.lateness_s,
                lead_s=s.runner.frame_lead_s,
                pool=self.pool,
                cost=cost,
            )
            entry = TwinEntry(
                id=bearing_id,
                twin=twin,
                runner=runner,
                intake=SetpointIntake(bearing_id, self.gate, runner),
                lubricant=twin.model.spec.lubricant.name,
                measured=MeasuredComparator(bearing_id, twin.model.spec.geometry, runner),
            )
            if self.bus is not None:
                entry.channel = self.bus.attach_twin(
                    bearing_id,
                    runner.latest_snapshot,
                    entry.intake,
                    on_defects=DefectIntake(bearing_id, self.gate, runner),
                    on_measured=MeasuredIntake(bearing_id, self.gate, entry.measured),
                    on_temperature=TemperatureIntake(bearing_id, self.gate, runner),
                )
                runner.add_sink(entry.channel)
            if self.recorder is not None:
                self.recorder.add_twin_from(twin)
                runner.add_sink(self.recorder)
                if hasattr(self.recorder, "log_measured"):
                    entry.measured.listeners.append(self.recorder.log_measured)
            self.alarms.add_twin(bearing_id)
            runner.add_sink(self.alarms)
            entry.measured.listeners.append(self.alarms.observe_measured)
            runner.start()
        except BaseException:
            with self._lock:
                self._reserved.discard(bearing_id)
                self._admitting.pop(bearing_id, None)
            if entry is not None:
                entry.runner.stop(timeout=2.0)
                self._unwire(entry)
            raise
        with self._lock:
            self._reserved.discard(bearing_id)
            self._admitting.pop(bearing_id, None)
            if self._closed:  # closed while building: do not leak a running twin
                entry.runner.stop(timeout=2.0)
                self._unwire(entry)
                raise InputError.one(None, "the service is shutting down", status_code=503)
            self._twins[bearing_id] = entry
        log.info(
            "twin %s started (%s, Pd = %g m, %s, %s mode)",
            bearing_id,
            entry.designation,
            entry.diametral_clearance_m,
            entry.lubricant,
            runner.mode,
        )
        return entry

    # ---- admission by measured capacity ----------------------------------------------------
    def _admit(self, bearing_id: str, twin: Twin, over_capacity_ok: bool) -> TwinCost | None:
        """Calibrate the new twin and check it against the capacity (service.core.capacity);
        InputError 503 with the reason and the figures when it does not fit. Returns its cost
        (None when admission is off or in fast mode)."""
        s = self.settings
        if s.runner.admission == "off" or s.runner.fast:
            return None
        cost = calibrate(
            twin,
            sim_s=s.runner.calibration_s,
            frame_steps=max(1, round(s.runner.frame_s / twin.model.dt_s)),
            publish_rate_hz=s.runner.publish_rate_hz,
        )
        with self._lock:
            self.last_calibration = cost
            self._last_calibrated = twin
            cost = cost.with_engine(expected_engine_cost(cost.engine_cpu_s_per_sim_s, self._alike_engine(twin)))
            verdict = self.capacity.check(cost, self._running_costs(), self.thread_cpu.overhead_per_twin_cpu_s_per_s)
            if not verdict.admitted:
                if not over_capacity_ok:
                    log.warning("twin %s (%s) refused: %s", bearing_id, twin.model.spec.designation, verdict.reason)
                    raise InputError.one(
                        None,
                        f"twin {bearing_id!r} ({twin.model.spec.designation}) refused: {verdict.reason}",
                        [
                            0.0,
                            round(
                                max(
                                    0.0,
                                    min(
                                        verdict.per_twin_cpu_s_per_s,
                                        verdict.budget_cpu_s_per_s - verdict.used_cpu_s_per_s,
                                    ),
                                ),
                                4,
                            ),
                        ],
                        status_code=503,
                    )
                self.over_capacity = f"twin {bearing_id!r}: {verdict.reason}"
                self._over_capacity_id = bearing_id
                log.warning(
                    "twin %s (%s) started over capacity (it is the configured twin): %s",
                    bearing_id,
                    twin.model.spec.designation,
                    verdict.reason,
                )
            self._admitting[bearing_id] = cost
        return cost

    def _alike_engine(self, twin: Twin | None) -> float | None:
        """The mean measured engine cost of the running twins alike `twin` (the same spec and model
        options) whose engine window has closed [CPU s per simulated s]; None without one (lock
        held)."""
        if twin is None:
            return None
        m = twin.model
        return mean_engine_cost(
            rate
            for e in self._twins.values()
            if (rate := e.runner.engine_cpu.rate) is not None
            and e.twin.model.spec == m.spec
            and e.twin.model.options == m.options
        )

    def _running_costs(self) -> list[TwinCost]:
        """What the twins running (and those admitted, still starting) need (lock held)."""
        costs = [c for c in (e.runner.cost for e in self._twins.values()) if c is not None]
        return costs + list(self._admitting.values())

    def capacity_record(self) -> dict:
        """The /health `capacity` entry: the rule's figures as measured now."""
        with self._lock:
            costs = self._running_costs()
            running = len(self._twins)
            engine_cpu_s = sum(e.runner.engine_cpu.cpu_s for e in self._twins.values())
        overhead = self.overhead.sample(engine_cpu_s, running)
        by_role = self.thread_cpu.sample(engine_cpu_s, running)
        overhead = {**overhead, **by_role} if overhead is not None else (by_role or None)
        per_twin = self.thread_cpu.overhead_per_twin_cpu_s_per_s
        typical = self.last_calibration
        with self._lock:
            alike_engine = self._alike_engine(self._last_calibrated)
        cap = self.capacity
        used = cap.used(costs, per_twin)
        estimate = cap.estimate_max_twins(
            None
            if typical is None
            else typical.with_engine(expected_engine_cost(typical.engine_cpu_s_per_sim_s, alike_engine)),
            running,
            used,
            per_twin,
        )
        if self.settings.runner.max_twins is not None:
            estimate = (
                self.settings.runner.max_twins if estimate is None else min(estimate, self.settings.runner.max_twins)
            )
        return {
            "admission": "off" if self.settings.runner.fast else self.settings.runner.admission,
            "cores": cap.cores,
            "stepping_threads": cap.stepping_threads,
            "core_fraction": cap.core_fraction,
            "reserve_cores": cap.reserve_cores,
            "budget_cpu_s_per_s": cap.budget_cpu_s_per_s,
            "used_cpu_s_per_s": used,
            "over_budget": used > cap.budget_cpu_s_per_s,
            "max_twins": estimate,
            "max_twins_set": self.settings.runner.max_twins,
            "last_calibration": typical.as_dict() if typical is not None else None,
            "alike_engine_cpu_s_per_sim_s": alike_engine,
            "over_capacity": self.over_capacity,
            "service_overhead_per_twin_cpu_s_per_s": per_twin,
            "formula": cap.formula(typical, running, used, per_twin, alike_engine),
            "service_overhead": overhead,
        }

    def delete_twin(self, bearing_id: str) -> TwinEntry:
        with self._lock:
            entry = self._twins.get(bearing_id)
            if entry is None:
                raise self._not_found(bearing_id)
            del self._twins[bearing_id]
            if bearing_id == self._over_capacity_id:
                self.over_capacity = self._over_capacity_id = None
        entry.runner.stop(timeout=5.0)
        self._unwire(entry)
        return entry

    # ---- per-twin recordings ---------------------------------------------------------------
    def recordings_dir(self) -> Path:
        rec = self.settings.recording.path
        return rec.parent if rec is not None else Path("recordings")

    def resolve_recording_path(self, bearing_id: str, path: str | None) -> Path:
        """A path under the recordings directory (relative only, no '..', .rrd)."""
        base = self.recordings_dir()
        if not path:
            stamp = datetime.now(UTC).strftime("%Y%m%dT%H%M%SZ")
            return base / f"{bearing_id}-{stamp}.rrd"
        if not _REC_PATH_RE.match(path):
            raise InputError.one(
                "path",
                "a recording path is a relative path of letters, digits "
                "and '_', '.', '-' (folders separated by '/', none starting with "
                "'.'), ending in .rrd, at most 256 characters",
            )
        p = Path(path)
        if p.is_absolute() or ".." in p.parts:
            raise InputError.one(
                "path", f"{path!r}: give a path relative to the recordings directory {str(base)!r}, without '..'"
            )
        if p.suffix != ".rrd":
            raise InputError.one("path", f"{path!r}: a rerun recording ends in .rrd")
        return base / p

    def start_recording(self, entry: TwinEntry, path: str | None) -> Path:
        target = self.resolve_recording_path(entry.id, path)
        if self.settings.recording.active_path is not None:
            main = Path(self.settings.recording.active_path).resolve()
            t = target.resolve()
            if t == main or (t.parent == main.parent and re.fullmatch(re.escape(main.stem) + r"-\d{4,}\.rrd", t.name)):
                raise InputError.one("path", f"{str(target)!r} is the service-wide recording or one of its segments")
        with self._recording_lock:
            self.stop_recording(entry)
            if target.exists() and not target.is_file():
                raise InputError.one("path", f"{str(target)!r} exists and is not a file")
            try:
                rec = self._new_recording(target)
            except (OSError, RuntimeError, ValueError) as exc:  # e.g. a folder that is a file
                raise InputError.one(
                    "path", f"cannot record to {str(target)!r}: {' '.join(str(exc).split())[:200]}"
                ) from None
            rec.add_twin_from(entry.twin)
            entry.recording, entry.recording_path = rec, target
            entry.runner.add_sink(rec)
        return target

    def stop_recording(self, entry: TwinEntry) -> tuple[Path | None, int]:
        """Finish the twin's own recording (flushed, complete); returns (path, rows written)."""
        with self._recording_lock:
            rec, path = entry.recording, entry.recording_path
            if rec is None:
                return None, 0
            entry.runner.remove_sink(rec)
            entry.recording = None
        try:
            rec.close()
        except Exception:
            log.exception("closing the recording of %s", entry.id)
        return path, int(getattr(rec, "rows_logged", 0))

    # ---- health ----------------------------------------------------------------------------
    def health(self) -> dict:
        twins = [
            e.runner.stats(
                setpoints_refused=e.intake.refused + int(getattr(e.channel, "setpoints_refused_busy", 0)),
                setpoints_rate_limited=self.gate.rate_limited(e.id),
            )
            for e in self.entries()
        ]
        degraded = any((not t["running"]) or t["errors"] for t in twins)
        rec = self.recorder
        return {
            "status": "degraded" if degraded else "ok",
            "capacity": self.capacity_record(),
            "reads_rate_limited": self.gate.reads_limited,
            "thread_priority": self.priority.record(),
            "uptime_s": time.monotonic() - self.started_wall_s,
            "twins": twins,
            "zenoh": self.bus is not None and not getattr(self.bus, "closed", False),
            "zenoh_listen": list(self.settings.zenoh.listen) if self.bus is not None else [],
            "recording": str(rec.path) if rec is not None and getattr(rec, "path", None) else None,
            "recording_rows": int(getattr(rec, "rows_logged", 0)) if rec is not None else 0,
            "pid": os.getpid(),
            "rss_bytes": _own_rss_bytes(),
        }


def _own_rss_bytes() -> int | None:
    """Resident set size of this process from /proc/self/status (None elsewhere)."""
    try:
        with open("/proc/self/status", encoding="ascii") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        return None
    return None
