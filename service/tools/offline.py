"""Run a scenario offline in fast mode (`bearing-twin scenario run`): a fresh twin per run, the
same `TwinRunner` and scenario executor as the service, a per-sample table (pyarrow: Parquet, or
CSV by extension) and optionally a rerun recording. The alarms of `service.core.alarms` follow
every run as in the service (an `AlarmHub` sink, `AlarmSettings` given or the defaults): their
events are in `RunResult.alarms` and, with a recording, in its `alarms/` and `alarm_states/`
entities.

Table: one row per sample (every `sample_every_s` of simulated time, plus the start and the end
of each run), columns

    run, run_label, bearing, diametral_clearance_m, lubricant, phase, seq, time_s, scenario_time_s,
    status, restarts, setpoint_<field> (the setpoint in force), shaft_speed_rad_s, cage_speed_rad_s,
    inner_ring_displacement_{x,y,z}_m, friction_torque_n_m, viscosity_pa_s,
    ball<i>_<field> (azimuth_rad, spin_rad_s, ...), ball<i>_inner_<field>, ball<i>_outer_<field>
    (load_n, h_min_m, h_c_m, lambda, regime, mu, ...), and whatever else the snapshot carries
    (flattened with '_').
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from service.core.alarm_hub import AlarmHub
from service.core.alarms import AlarmEvent
from service.core.runner import TwinRunner
from service.core.scenarios import ResolvedRun, Scenario
from service.settings import AlarmSettings
from twin.engine import Twin
from twin.snapshot import Snapshot

_SKIP = {"schema", "bearing_id", "designation"}
_XYZ = ("x", "y", "z")


def flatten_snapshot(snapshot: Snapshot) -> dict[str, Any]:
    """The snapshot as one flat row (see the module docstring for the column names)."""
    out: dict[str, Any] = {}

    def walk(prefix: str, value: Any) -> None:
        if isinstance(value, dict):
            for k, v in value.items():
                if k == "balls" and isinstance(v, (list, tuple)):
                    for i, ball in enumerate(v):
                        index = ball.get("index", i) if isinstance(ball, dict) else i
                        walk(
                            f"{prefix}ball{index}_",
                            {bk: bv for bk, bv in ball.items() if bk != "index"} if isinstance(ball, dict) else ball,
                        )
                elif isinstance(v, (list, tuple)) and len(v) == 3 and k.endswith("_m"):
                    for axis, x in zip(_XYZ, v):
                        out[f"{prefix}{k[:-2]}_{axis}_m"] = x
                else:
                    walk(f"{prefix}{k}_", v)
        elif isinstance(value, (list, tuple)):
            for i, v in enumerate(value):
                walk(f"{prefix}{i}_", v)
        else:
            out[prefix[:-1]] = value

    walk("", {k: v for k, v in snapshot.to_dict().items() if k not in _SKIP})
    return out


@dataclass
class RunResult:
    run: ResolvedRun
    rows: int
    wall_s: float
    final: Snapshot | None
    state: str
    error: str | None
    alarms: list[AlarmEvent] = field(default_factory=list)  # the run's alarm events, in order


class TableSink:
    """Collects flattened rows (a plain list append: lossless, never blocks).

    `begin` is called before the runner starts, so every row of a run carries its context. The
    run's scenario time is the snapshot's time minus that of the run's first row: the runner
    publishes its first sample of a scenario run at the frame the scenario takes over
    (`TwinRunner.start(publish_initial=False)`, then a sample at the scenario's start), in its own
    thread; the twin's time read from the caller's thread would race with that thread."""

    def __init__(self) -> None:
        self.rows: list[dict[str, Any]] = []
        self.dropped = 0
        self._context: dict[str, Any] = {}
        self._runner: TwinRunner | None = None
        self._t0: float | None = None

    def begin(self, run: ResolvedRun, runner: TwinRunner, lubricant: str) -> None:
        """A new run on `runner`, whose scenario handle gives each row its phase at publish time."""
        self._context = {
            "run": run.id,
            "run_label": run.label,
            "bearing": run.designation,
            "diametral_clearance_m": run.spec().mounting.diametral_clearance_m,
            "lubricant": lubricant,
        }
        self._runner, self._t0 = runner, None

    def publish(self, snapshot: Snapshot) -> None:
        row = dict(self._context)
        handle = self._runner.scenario if self._runner is not None else None
        row["phase"] = handle.phase if handle is not None else None
        flat = flatten_snapshot(snapshot)
        row["seq"] = flat.pop("seq", None)
        row["time_s"] = flat.pop("time_s", None)
        if self._t0 is None and row["time_s"] is not None:
            self._t0 = row["time_s"]
        row["scenario_time_s"] = (
            round(row["time_s"] - self._t0, 9) if row["time_s"] is not None and self._t0 is not None else None
        )
        row.update(flat)
        self.rows.append(row)

    def close(self) -> None:
        pass


def write_table(rows: list[dict[str, Any]], path: str | Path) -> Path:
    """Write rows (union of their keys, in first-seen order) as Parquet, or CSV for *.csv."""
    import pyarrow as pa

    path = Path(path)
    keys: dict[str, None] = {}
    for row in rows:
        for k in row:
            keys.setdefault(k, None)
    table = pa.table({k: [row.get(k) for row in rows] for k in keys})
    path.parent.mkdir(parents=True, exist_ok=True)
    if path.suffix.lower() == ".csv":
        import pyarrow.csv as pacsv

        pacsv.write_csv(table, str(path))
    else:
        import pyarrow.parquet as pq

        pq.write_table(table, str(path))
    return path


def run_scenario(
    scenario: Scenario,
    *,
    record: str | Path | None = None,
    table: TableSink | None = None,
    frame_s: float = 0.001,
    progress: Callable[[float], None] | None = None,
    timeout_factor: float = 200.0,
    min_timeout_s: float = 120.0,
    on_recording: Callable[[Path], None] | None = None,
    alarms: AlarmSettings | None = None,
) -> list[RunResult]:
    """Run every run of a scenario in fast mode, each on a fresh warm-started twin.

    `progress(simulated seconds done over all runs)` is called about 10 times a second.
    `record`: an .rrd with every run as `bearing/<run id>/...` (lossless queue), alarm events
    included; an existing file of that name is never overwritten (the recorder writes
    `<stem>.run2.rrd` beside it), and `on_recording(path)` is told the file actually written.
    `alarms`: thresholds and delays of the alarms (default `AlarmSettings()`)."""
    table = table if table is not None else TableSink()
    recorder = None
    if record is not None:
        from service.recording import RerunRecorder

        recorder = RerunRecorder(record, queue_size=1_000_000, **RerunRecorder.SERVICE_OPTIONS)
        if on_recording is not None and recorder.path is not None:
            on_recording(recorder.path)
    settings = alarms or AlarmSettings()
    hub = AlarmHub(settings, queue_size=1_000_000)  # lossless: every sample is judged
    if recorder is not None:
        hub.subscribe(recorder.log_alarm)
    scenario.check_bearing_limits()  # every run, before any runs (as `scenario check`)
    runs = scenario.resolved_runs()
    results: list[RunResult] = []
    done_s = 0.0
    try:
        for run in runs:
            bearing_id = scenario.name if len(runs) == 1 else run.id
            spec = run.spec()
            twin = Twin(spec, setpoint=run.initial_setpoint(), bearing_id=bearing_id)
            runner = TwinRunner(
                twin,
                fast=True,
                publish_rate_hz=1.0 / run.sample_every_s,
                frame_s=min(frame_s, run.sample_every_s),
                idle_without_scenario=True,
            )
            runner.add_sink(table)
            hub.add_twin(bearing_id)
            runner.add_sink(hub)
            if recorder is not None:
                recorder.add_twin_from(twin, context=lambda runner=runner: runner.scenario)
                runner.add_sink(recorder)
            t_wall = time.perf_counter()
            table.begin(run, runner, spec.lubricant.name)
            rows_before = len(table.rows)
            runner.start(publish_initial=False)
            handle, _ = runner.start_scenario(run)
            deadline = time.monotonic() + max(min_timeout_s, timeout_factor * run.duration_s)
            try:
                while not handle.wait(0.1):
                    if progress is not None:
                        progress(done_s + handle.scenario_time_s)
                    if runner.failed or not runner.running:
                        break
                    if time.monotonic() > deadline:
                        handle.finish("failed", "timed out")
                        break
            finally:
                runner.stop(timeout=10.0)
                hub.wait_idle(60.0)
            done_s += run.duration_s
            if progress is not None:
                progress(done_s)
            error = handle.error or (runner.last_error if runner.failed else None)
            state = handle.state if not runner.failed else "failed"
            results.append(
                RunResult(
                    run=run,
                    rows=len(table.rows) - rows_before,
                    wall_s=time.perf_counter() - t_wall,
                    final=runner.latest,
                    state=state,
                    error=error,
                    alarms=hub.events(bearing_id),
                )
            )
            hub.forget(bearing_id)
    finally:
        hub.close()
        if recorder is not None:
            recorder.close()
    return results
