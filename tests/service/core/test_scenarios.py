"""Scenario format: loading, validation errors that name the field (strict types, the bearing's
own limits, `bearing: 6208` as a designation), the executor's timeline, and `bearing-twin
scenario check` / `scenario run` end to end."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest
import yaml

from service.cli import main
from service.core.scenario_driver import ScenarioExecutor
from service.core.scenario_files import list_scenarios, load_scenario, scenario_from_dict
from service.core.scenarios import ScenarioError
from twin.engine import Twin
from twin.setpoint import Setpoint

SCENARIOS = Path(__file__).resolve().parents[3] / "scenarios"
HAVE_RERUN = importlib.util.find_spec("rerun") is not None


def base(**kw):
    data = {"name": "t", "duration_s": 0.1, "steps": []}
    data.update(kw)
    return data


def test_shipped_scenarios_load():
    found = list_scenarios(SCENARIOS)
    for name in (
        "seed000_startup_steady_slowdown",
        "seed000_load_sweep",
        "seed000_clearance_sweep",
        "seed000_speed_sweep",
        "ev_motor_current_ramp",
        "ev_motor_resistance_temperature",
    ):
        assert name in found
        scenario = load_scenario(found[name])
        assert scenario.name == name
        assert scenario.description


def test_seed000_contents():
    s = load_scenario(SCENARIOS / "seed000_startup_steady_slowdown.yaml")
    run = s.resolved_runs()[0]
    assert run.initial.radial_load_n == 3000.0 and run.initial.shaft_speed_rad_s == 0.0
    assert max(v for _, f, v in run.iter_values() if f == "shaft_speed_rad_s") == 500.0
    loads = [
        v
        for _, f, v in load_scenario(SCENARIOS / "seed000_load_sweep.yaml").resolved_runs()[0].iter_values()
        if f == "radial_load_n"
    ]
    assert min(loads) == 750.0 and max(loads) == 7500.0 and len(set(loads)) == 6
    speeds = {
        v
        for _, f, v in load_scenario(SCENARIOS / "seed000_speed_sweep.yaml").resolved_runs()[0].iter_values()
        if f == "shaft_speed_rad_s"
    }
    assert speeds == set(range(100, 1701, 200))
    runs = load_scenario(SCENARIOS / "seed000_clearance_sweep.yaml").resolved_runs()
    pd = [r.diametral_clearance_m for r in runs]
    assert -12.6e-6 in pd and 0.0 in pd and 12.6e-6 in pd
    assert all(r.initial.radial_load_n == 3000.0 and r.initial.shaft_speed_rad_s == 500.0 for r in runs)


def test_ev_scenario_fits_its_bearing_and_drives_the_current():
    s = load_scenario(SCENARIOS / "ev_motor_current_ramp.yaml")
    run = s.resolved_runs()[0]
    speeds = [v for _, f, v in run.iter_values() if f == "shaft_speed_rad_s"]
    assert min(speeds) == pytest.approx(10000 * 2 * 3.141592653589793 / 60, rel=1e-3)
    assert max(speeds) == pytest.approx(50000 * 2 * 3.141592653589793 / 60, rel=1e-3)
    run.check_limits(Twin(run.bearing, warm=False).limits)  # the 6200 allows 50 000 rpm
    with pytest.raises(ScenarioError) as exc:
        run.check_limits(Twin("6208", warm=False).limits)  # the 6208 does not
    assert "shaft_speed_rad_s" in exc.value.field
    assert max(v for _, f, v in run.iter_values() if f == "shaft_current_a") == 30.0
    assert run.thermal is not None and run.thermal.shear_heating and run.thermal.current_heating


def test_ev_resistance_temperature_scenario_seed003_figs_8_and_10(tmp_path):
    # seed 003 Figs. 8 and 10 through the scenario runner: at 10 A and 20 A the film is thinner
    # with the doubled bearing resistance and with the hotter oil
    pq = pytest.importorskip("pyarrow.parquet")
    out = tmp_path / "ev.parquet"
    path = SCENARIOS / "ev_motor_resistance_temperature.yaml"
    runs = load_scenario(path).resolved_runs()
    assert [r.thermal.equivalent_resistance_ohm for r in runs] == [2.92e-4, 5.84e-4, 2.92e-4, 5.84e-4]
    assert main(["scenario", "run", str(path), "--table", str(out), "--no-progress"]) == 0
    rows = pq.read_table(out).to_pylist()

    def film(run, current):  # last sample of the phase (30 ms after the step)
        phase = [r for r in rows if r["run"] == run and r["setpoint_shaft_current_a"] == current]
        return phase[-1]["electrical_film_thermal_factor"], phase[-1]

    for current in (10.0, 20.0):
        f_low, row = film("rb_292uohm_40c", current)
        f_high, _ = film("rb_584uohm_40c", current)
        f_hot, _ = film("rb_292uohm_80c", current)
        assert f_high < f_low, current
        assert row["electrical_current_temperature_rise_k"] > 0.0
        assert f_hot < 1.0 and f_low < 1.0
    # hotter oil: a thinner film at the same current (the thickest inner film over the balls)

    def thickest_inner_film_m(row):
        return max(v for k, v in row.items() if k.endswith("_inner_h_min_m") and v is not None)

    for current in (10.0, 20.0):
        assert thickest_inner_film_m(film("rb_292uohm_80c", current)[1]) < thickest_inner_film_m(
            film("rb_292uohm_40c", current)[1]
        )


def test_typos_are_errors():
    with pytest.raises(ScenarioError) as exc:
        scenario_from_dict(base(steps=[{"at_s": 0.0, "set": {"radial_lod_n": 100.0}}]))
    assert exc.value.field == "steps[0].set.radial_lod_n"


@pytest.mark.parametrize(
    "data, field",
    [
        (base(steps=[{"at_s": 0.0, "ramp": {"radial_load_n": 1.0}}]), "steps[0]"),  # no over_s
        (
            base(steps=[{"at_s": 0.0, "set": {"radial_load_n": 1.0}, "ramp": {"radial_load_n": 2.0}, "over_s": 0.1}]),
            "steps[0]",
        ),
        (
            base(steps=[{"at_s": 0.05, "ramp": {"radial_load_n": 1.0}, "over_s": 0.1}]),
            "steps[0].over_s",
        ),  # ends after duration
        (
            base(steps=[{"at_s": 0.05, "set": {"radial_load_n": 1.0}}, {"at_s": 0.01, "set": {"radial_load_n": 2.0}}]),
            "steps[1].at_s",
        ),  # out of order
        (base(steps=[{"at_s": -1.0, "set": {"radial_load_n": 1.0}}]), "steps[0].at_s"),
        (base(steps=[{"at_s": 0.0, "set": {"radial_load_n": float("nan")}}]), "steps[0].set.radial_load_n"),
        (base(duration_s=0.0), "duration_s"),
        (base(bearing="9999"), "bearing"),
        (base(lubricant="olive oil"), "lubricant"),
        (base(name="has space"), "name"),
        (base(unknown_key=1), "unknown_key"),
        (base(runs=[{"id": "a"}, {"id": "a"}]), "runs"),
    ],
)
def test_invalid_scenarios_name_the_field(data, field):
    with pytest.raises(ScenarioError) as exc:
        scenario_from_dict(data)
    assert exc.value.field.startswith(field), (exc.value.field, exc.value.message)


def test_invalid_yaml_file(tmp_path):
    p = tmp_path / "bad.yaml"
    p.write_text("name: [unclosed\n")
    with pytest.raises(ScenarioError) as exc:
        load_scenario(p)
    assert "YAML" in exc.value.message
    with pytest.raises(ScenarioError):
        load_scenario(tmp_path / "missing.yaml")


def test_executor_steps_and_ramps():
    s = scenario_from_dict(
        base(
            initial={"radial_load_n": 1000.0},
            steps=[
                {"at_s": 0.0, "ramp": {"shaft_speed_rad_s": 100.0}, "over_s": 0.04},
                {"at_s": 0.02, "set": {"radial_load_n": 2000.0}},
                {"at_s": 0.05, "ramp": {"radial_load_n": 0.0, "oil_temperature_c": 80.0}, "over_s": 0.05},
            ],
        )
    )
    ex = ScenarioExecutor(s.resolved_runs()[0])
    sp = Setpoint(shaft_speed_rad_s=500.0)
    seen = {}
    for k in range(101):
        t = k * 0.001
        sp = ex.updates(t, sp).apply_to(sp)
        seen[k] = sp
        if ex.done(t):
            break
    assert seen[0].radial_load_n == 1000.0 and seen[0].shaft_speed_rad_s == 500.0  # ramp starts from the current value
    assert seen[20].shaft_speed_rad_s == pytest.approx(300.0)
    assert seen[20].radial_load_n == 2000.0
    assert seen[40].shaft_speed_rad_s == 100.0
    assert seen[75].radial_load_n == pytest.approx(1000.0)
    assert seen[75].oil_temperature_c == pytest.approx(60.0)
    assert seen[100].radial_load_n == 0.0 and seen[100].oil_temperature_c == 80.0
    assert ex.done(0.1) and not ex.done(0.099)


def test_runs_and_mounting_check():
    s = load_scenario(SCENARIOS / "seed000_clearance_sweep.yaml")
    runs = {r.id: r for r in s.resolved_runs()}
    runs["pd_0"].check_twin("6208", 0.0, "seed-000")
    with pytest.raises(ScenarioError) as exc:
        runs["pd_minus_12_6um"].check_twin("6208", 0.0, "seed-000")
    assert exc.value.field == "diametral_clearance_m"
    # a scenario that does not name a bearing runs on any twin
    plain = scenario_from_dict(base(initial={"radial_load_n": 10.0})).resolved_runs()[0]
    plain.check_twin("7208", 5e-6, "ISO VG 68")


def _write(tmp_path, data) -> Path:
    p = tmp_path / f"{data['name']}.yaml"
    p.write_text(yaml.safe_dump(data))
    return p


def test_scenario_run_command_writes_the_table(tmp_path, capsys):
    pq = pytest.importorskip("pyarrow.parquet")
    path = _write(
        tmp_path,
        {
            "name": "short",
            "duration_s": 0.02,
            "sample_every_s": 0.002,
            "initial": {"shaft_speed_rad_s": 400.0, "radial_load_n": 2000.0},
            "steps": [
                {"at_s": 0.0, "phase": "up", "ramp": {"radial_load_n": 3000.0}, "over_s": 0.01},
                {"at_s": 0.01, "phase": "hold", "set": {"radial_load_n": 3000.0}},
            ],
        },
    )
    out = tmp_path / "short.parquet"
    assert main(["scenario", "run", str(path), "--table", str(out), "--no-progress"]) == 0
    table = pq.read_table(out).to_pylist()
    assert len(table) == 11  # 0, 2, ..., 20 ms
    assert [r["scenario_time_s"] for r in table] == pytest.approx([0.002 * i for i in range(11)])
    assert table[0]["setpoint_radial_load_n"] == 2000.0 and table[-1]["setpoint_radial_load_n"] == 3000.0
    assert table[0]["phase"] == "up" and table[-1]["phase"] == "hold"
    row = table[-1]
    for col in (
        "time_s",
        "seq",
        "shaft_speed_rad_s",
        "friction_torque_n_m",
        "ball0_azimuth_rad",
        "ball0_inner_load_n",
        "ball0_inner_lambda",
        "ball0_inner_regime",
        "ball8_outer_h_min_m",
        "inner_ring_displacement_x_m",
    ):
        assert col in row, col
    assert max(row[f"ball{i}_inner_load_n"] for i in range(9)) > 0
    assert "done" in capsys.readouterr().out


def test_scenario_table_starts_at_zero_however_late_the_caller(tmp_path, monkeypatch):
    """The runner thread takes the scenario over and samples it at once; a caller thread that
    looks at the twin only later (a busy machine) must not shift the table's scenario time."""
    import time as _time

    import service.tools.offline as offline

    pq = pytest.importorskip("pyarrow.parquet")
    original = offline.TwinRunner.start_scenario

    def slow_caller(self, *args, **kwargs):
        out = original(self, *args, **kwargs)
        _time.sleep(0.3)
        return out

    monkeypatch.setattr(offline.TwinRunner, "start_scenario", slow_caller)
    path = _write(
        tmp_path,
        {
            "name": "late",
            "duration_s": 0.02,
            "sample_every_s": 0.002,
            "initial": {"shaft_speed_rad_s": 400.0, "radial_load_n": 2000.0},
            "steps": [
                {"at_s": 0.0, "phase": "up", "ramp": {"radial_load_n": 3000.0}, "over_s": 0.01},
                {"at_s": 0.01, "phase": "hold", "set": {"radial_load_n": 3000.0}},
            ],
        },
    )
    out = tmp_path / "late.parquet"
    assert main(["scenario", "run", str(path), "--table", str(out), "--no-progress"]) == 0
    table = pq.read_table(out).to_pylist()
    assert [r["scenario_time_s"] for r in table] == pytest.approx([0.002 * i for i in range(11)])
    assert table[0]["phase"] == "up" and table[-1]["phase"] == "hold"


def test_scenario_run_with_runs(tmp_path):
    pq = pytest.importorskip("pyarrow.parquet")
    data = yaml.safe_load((SCENARIOS / "seed000_clearance_sweep.yaml").read_text())
    data.update(name="pd_short", duration_s=0.004, sample_every_s=0.002)
    data["runs"] = data["runs"][:2]
    out = tmp_path / "pd.parquet"
    assert main(["scenario", "run", str(_write(tmp_path, data)), "--table", str(out), "--no-progress"]) == 0
    rows = pq.read_table(out).to_pylist()
    assert [r["run"] for r in rows] == ["pd_minus_12_6um"] * 3 + ["pd_minus_6_3um"] * 3
    assert {r["diametral_clearance_m"] for r in rows} == {-12.6e-6, -6.3e-6}


@pytest.mark.skipif(not HAVE_RERUN, reason="rerun-sdk not installed")
def test_scenario_run_command_writes_a_recording(tmp_path):
    from rerun.chunk import RrdReader

    path = _write(
        tmp_path,
        {"name": "rec", "duration_s": 0.01, "sample_every_s": 0.001, "initial": {"radial_load_n": 2500.0}, "steps": []},
    )
    rrd = tmp_path / "rec.rrd"
    assert main(["scenario", "run", str(path), "--record", str(rrd), "--no-progress"]) == 0
    reader = RrdReader(str(rrd))
    rows: dict[str, int] = {}
    for chunk in reader.stream():
        if not chunk.is_static:
            rows[chunk.entity_path] = rows.get(chunk.entity_path, 0) + chunk.num_rows
    # scenario recordings use the service's recorder options (RerunRecorder.SERVICE_OPTIONS):
    # trends as 0.2 s window means (the 11 samples of 0..10 ms fall in one window), the bearing
    # now every 0.5 s and the contacts every 1 s from the first sample on (one row each here)
    assert rows["/bearing/rec/friction_torque_n_m"] == 1
    assert rows["/bearing/rec/balls"] == 1
    assert rows["/bearing/rec/contacts/load_n"] == 1  # all contacts of a sample in one row


def test_scenario_run_refuses_bad_input(tmp_path, capsys):
    path = _write(
        tmp_path,
        {"name": "fast6208", "duration_s": 0.01, "steps": [{"at_s": 0.0, "set": {"shaft_speed_rad_s": 5000.0}}]},
    )
    assert main(["scenario", "run", str(path), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "shaft_speed_rad_s" in err and "allowed range" in err
    with pytest.raises(SystemExit) as exc:  # refused by the option's type, before the run
        main(["scenario", "run", str(path), "--table", "x.txt", "--no-progress"])
    assert exc.value.code == 2 and "argument --table: must end in .parquet or .pq or .csv" in capsys.readouterr().err
    assert main(["scenario", "check", str(SCENARIOS / "ev_motor_current_ramp.yaml")]) == 0


def test_scenario_check_checks_the_bearing_limits_like_run(tmp_path, capsys):
    """A scenario over the bearing's speed limit (the 6208's 2073.66 rad/s, inside the static
    bound of 1e4) fails `scenario check` as it fails `scenario run`, with the bearing's range."""
    path = _write(
        tmp_path,
        {
            "name": "too_fast",
            "bearing": "6208",
            "duration_s": 0.01,
            "steps": [{"at_s": 0.0, "ramp": {"shaft_speed_rad_s": 3000.0}, "over_s": 0.01}],
        },
    )
    assert main(["scenario", "check", str(path)]) == 2
    err = capsys.readouterr().err
    assert "steps[0].ramp.shaft_speed_rad_s" in err
    assert "outside the allowed range [0, 2073.66] rad/s for bearing 6208" in err
    assert main(["scenario", "run", str(path), "--no-progress"]) == 2
    assert "[0, 2073.66] rad/s" in capsys.readouterr().err
    # the same timeline on a 6200 (a smaller bearing, a higher limit) is fine
    ok = _write(
        tmp_path,
        {
            "name": "fast_6200",
            "bearing": "6200",
            "duration_s": 0.01,
            "steps": [{"at_s": 0.0, "ramp": {"shaft_speed_rad_s": 3000.0}, "over_s": 0.01}],
        },
    )
    assert main(["scenario", "check", str(ok)]) == 0


def test_multi_run_limits_name_the_run():
    s = scenario_from_dict(
        base(
            initial={"radial_load_n": 1000.0},
            runs=[
                {"id": "small", "bearing": "6200"},
                {"id": "big", "bearing": "6208", "steps": [{"at_s": 0.0, "set": {"shaft_speed_rad_s": 2500.0}}]},
            ],
        )
    )
    with pytest.raises(ScenarioError) as exc:
        s.check_bearing_limits()
    assert exc.value.field == "runs[1].steps[0].set.shaft_speed_rad_s"


def test_yaml_integer_designation_and_errors_name_the_field_once(tmp_path):
    path = tmp_path / "int.yaml"
    path.write_text("name: int_bearing\nbearing: 6208\nduration_s: 0.01\nruns:\n  - {id: a, bearing: 6200}\n")
    s = load_scenario(path)
    assert s.bearing == "6208" and s.resolved_runs()[0].bearing == "6200"
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: bad\nbearing: 9999\nduration_s: 0.01\n")
    with pytest.raises(ScenarioError) as exc:
        load_scenario(bad)
    assert exc.value.field == "bearing"
    assert str(exc.value).count("bearing:") == 1 and "unknown bearing '9999'" in str(exc.value)
    for flag in ("true", "yes"):  # a YAML bool is not a designation
        bad.write_text(f"name: bad\nbearing: {flag}\nduration_s: 0.01\n")
        with pytest.raises(ScenarioError):
            load_scenario(bad)


def test_a_binary_file_is_refused_naming_the_file(tmp_path, capsys):
    """A scenario file that is not text (here bytes that are not UTF-8) is a ScenarioError naming
    the file, and `scenario check` ends with status 2 and one line, not a traceback."""
    path = tmp_path / "binary.yaml"
    path.write_bytes(b"\xbb\x00\xff" * 40)
    with pytest.raises(ScenarioError, match="not UTF-8 text"):
        load_scenario(path)
    assert main(["scenario", "check", str(path)]) == 2
    err = capsys.readouterr().err
    assert "binary.yaml" in err and "not UTF-8 text" in err and "Traceback" not in err


@pytest.mark.parametrize("value", ['"3000"', "true"])
def test_yaml_setpoint_values_are_numbers(tmp_path, value):
    path = tmp_path / "s.yaml"
    path.write_text(f"name: s\nduration_s: 0.01\ninitial: {{radial_load_n: {value}}}\n")
    with pytest.raises(ScenarioError) as exc:
        load_scenario(path)
    assert exc.value.field == "initial.radial_load_n" and "valid number" in exc.value.message


def _own_spec(**geometry) -> dict:
    """A 6205 with 8 balls under a designation of its own (a bearing the catalog does not have)."""
    from twin import catalog

    spec = catalog.bearing("6205").model_dump(mode="json")
    spec["designation"] = "MY-6205-8"
    spec["geometry"].update({"ball_count": 8, **geometry})
    return spec


def test_bearing_spec_inline_and_from_a_file_next_to_the_scenario(tmp_path, monkeypatch):
    pq = pytest.importorskip("pyarrow.parquet")
    (tmp_path / "specs").mkdir()
    (tmp_path / "specs" / "own.yaml").write_text(yaml.safe_dump(_own_spec()))
    path = _write(
        tmp_path,
        base(
            name="own",
            duration_s=0.01,
            sample_every_s=0.005,
            bearing="specs/own.yaml",
            initial={"shaft_speed_rad_s": 300.0, "radial_load_n": 800.0},
            runs=[{"id": "file"}, {"id": "inline", "bearing": _own_spec(), "diametral_clearance_m": 10e-6}],
        ),
    )
    monkeypatch.chdir(tmp_path / "specs")  # the path is the scenario file's, not the cwd's
    runs = load_scenario(path).resolved_runs()
    assert [r.designation for r in runs] == ["MY-6205-8", "MY-6205-8"]
    assert [r.spec().geometry.ball_count for r in runs] == [8, 8]
    # a clearance written beside a spec replaces the spec's own
    assert [r.spec().mounting.diametral_clearance_m for r in runs] == [0.0, 10e-6]
    out = tmp_path / "own.parquet"
    assert main(["scenario", "run", str(path), "--table", str(out), "--no-progress"]) == 0
    rows = pq.read_table(out).to_pylist()
    assert {r["bearing"] for r in rows} == {"MY-6205-8"}
    assert {r["run"] for r in rows} == {"file", "inline"}
    assert [r["diametral_clearance_m"] for r in rows if r["run"] == "inline"][0] == 10e-6


def test_bearing_spec_errors_name_the_field(tmp_path):
    bad = _own_spec(ball_count=20)
    with pytest.raises(ScenarioError) as exc:
        scenario_from_dict(base(bearing=bad))
    assert exc.value.field == "bearing.geometry.ball_count" and "16" in str(exc.value)
    with pytest.raises(ScenarioError) as exc:
        scenario_from_dict(base(runs=[{"id": "a", "bearing": bad}]))
    assert exc.value.field == "runs[0].bearing.geometry.ball_count"
    # an inline scenario (the HTTP API's) never names a file
    with pytest.raises(ScenarioError) as exc:
        scenario_from_dict(base(bearing="own.yaml"))
    assert exc.value.field == "bearing" and "mapping of BearingSpec fields" in exc.value.message
    with pytest.raises(ScenarioError) as exc:
        load_scenario(_write(tmp_path, base(name="missing", bearing="nowhere.json")))
    assert exc.value.field == "bearing" and "cannot read spec file" in exc.value.message
    (tmp_path / "bad.yaml").write_text(yaml.safe_dump(bad))
    with pytest.raises(ScenarioError) as exc:
        load_scenario(_write(tmp_path, base(name="badfile", runs=[{"id": "a", "bearing": "bad.yaml"}])))
    assert exc.value.field == "runs[0].bearing.geometry.ball_count" and "bad.yaml" in exc.value.message


def test_limits_are_the_spec_bearings():
    # 400 rad/s is within the catalog 6205's speed range but above this spec's limiting speed
    spec = {**_own_spec(), "limiting_speed_rad_s": 300.0}
    scenario = scenario_from_dict(base(bearing=spec, initial={"shaft_speed_rad_s": 400.0}))
    with pytest.raises(ScenarioError) as exc:
        scenario.check_bearing_limits()
    assert exc.value.field == "initial.shaft_speed_rad_s" and exc.value.allowed[1] == pytest.approx(300.0)
    scenario_from_dict(base(bearing="6205", initial={"shaft_speed_rad_s": 400.0})).check_bearing_limits()


def test_the_run_summary_names_a_torque_at_rest_as_a_holding_torque(capsys):
    # seed 000 Figs. 7-8's start-up, steady run and slow-down ends with the shaft at rest: the summary states the
    # end's time and speed and calls the torque there what it is (the tangential springs' elastic torque, which
    # tests/engine/test_friction_power.py bounds at 3 mN m), not a friction torque
    assert main(["scenario", "run", str(SCENARIOS / "seed000_startup_steady_slowdown.yaml"), "--no-progress"]) == 0
    line = capsys.readouterr().out.strip().splitlines()[-1]
    assert "at the end (0.400 s, 0.0 rad/s)" in line and "holding torque at rest" in line, line
    assert "friction torque" not in line, line
