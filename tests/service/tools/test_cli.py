"""The console script: simulate prints the contract as JSON, report writes Markdown and plots;
numbers in scientific notation, a closed pipe and a busy zenoh port are handled cleanly."""

import json
import os
import socket
import subprocess
import sys

import pytest


def _run(*args, timeout=300):
    return subprocess.run([sys.executable, "-m", "service.cli", *args], capture_output=True, text=True, timeout=timeout)


def test_simulate_json_is_the_contract():
    res = _run(
        "simulate", "--bearing", "6208", "--radial-load", "3000", "--speed", "500", "--duration", "0.005", "--json"
    )
    assert res.returncode == 0, res.stderr
    snap = json.loads(res.stdout, parse_constant=lambda c: pytest.fail(f"non-finite {c}"))
    assert snap["schema"] == "bearing-twin/state/1"
    assert snap["time_s"] == pytest.approx(0.005)
    assert len(snap["balls"]) == 9
    ball = snap["balls"][0]
    assert set(ball["inner"]) >= {
        "load_n",
        "entrainment_speed_m_s",
        "slide_roll_ratio",
        "h_min_m",
        "lambda",
        "regime",
        "mu",
    }
    assert snap["setpoint"]["radial_load_n"] == 3000.0


def test_simulate_refuses_bad_input_by_name():
    """The error names the option typed and the model's field, with the bearing's range (6208:
    C0 = 21.86 kN is the radial limit, twin.setpoint; the clearance -50..200 um, twin.spec)."""
    res = _run("simulate", "--radial-load", "-10", "--duration", "0.001")
    assert res.returncode == 2 and "Traceback" not in res.stderr
    assert (
        res.stderr.strip()
        == "error: --radial-load: radial_load_n = -10 N is outside the allowed range [0, 21861.8] N for bearing 6208"
    )
    res = _run("simulate", "--clearance", "0.01", "--duration", "0.001")
    assert res.returncode == 2 and "--clearance: mounting.diametral_clearance_m" in res.stderr
    assert "allowed range [-5e-05, 0.0002] m" in res.stderr
    res = _run("simulate", "--duration", "-1")
    assert res.returncode == 2 and "--duration" in res.stderr and "Traceback" not in res.stderr
    res = _run("simulate", "--bearing", "nosuch", "--duration", "0.001")
    assert res.returncode == 2 and res.stderr.startswith("error: --bearing: designation: unknown bearing 'nosuch'")
    res = _run("simulate", "--duration", "1e6")  # a typo would run for days: refused with the range
    assert res.returncode == 2 and "argument --duration: must be in [0, 3600] s, got 1e6" in res.stderr


def test_simulate_table_fits_80_columns_uncut():
    """The table of a fast, loaded 6208 (spin above 1000 rad/s, regimes no_contact and full_film)
    in an 80-column terminal: every value whole, no line longer than 80 characters."""
    env = {**os.environ, "COLUMNS": "80"}
    cmd = [sys.executable, "-m", "service.cli", "simulate", "--speed", "2000", "--radial-load", "20000"]
    res = subprocess.run([*cmd, "--duration", "0.005"], capture_output=True, text=True, timeout=300, env=env)
    assert res.returncode == 0, res.stderr
    assert "\u2026" not in res.stdout and max(len(line) for line in res.stdout.splitlines()) <= 80, res.stdout
    assert "no_contact" in res.stdout and "full_film" in res.stdout


def test_a_spec_file_error_is_named_as_the_bearing_option(tmp_path):
    """A field of a `--bearing` spec file is led by `--bearing` (twin.spec.Geometry: 3 to 16 balls)."""
    from service.tools.messages import SPEC_PARTS
    from twin import catalog
    from twin.spec import BearingSpec

    assert set(SPEC_PARTS) == set(BearingSpec.model_fields) - {"designation"}
    spec = catalog.bearing("6208").model_dump(mode="json")
    spec["geometry"]["ball_count"] = 99
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(spec))
    res = _run("simulate", "--bearing", str(path), "--duration", "0.001")
    assert res.returncode == 2
    assert res.stderr.strip() == (
        "error: --bearing: geometry.ball_count: Input should be less than or equal to 16; allowed range [3, 16]"
    )


def test_other_commands_name_the_option_and_the_range():
    """vibration, thermal and life: the option, the field and both sides of its range (twin.vibration.defects:
    width_m in (0, 0.05] m; the accelerometer's noise density in [0, 1] m/s^2/sqrt(Hz), twin.vibration.housing)."""
    vib = ("vibration", "--speed", "100", "--radial-load", "1000")
    res = _run(*vib, "--defect", "outer", "--defect-size", "1")
    assert res.returncode == 2 and "Traceback" not in res.stderr
    assert res.stderr.strip().startswith("error: --defect-size: [0].outer.width_m: "), res.stderr
    assert res.stderr.strip().endswith("allowed range (0, 0.05] m"), res.stderr
    res = _run(*vib, "--noise-density", "1e9")
    assert res.returncode == 2 and res.stderr.strip().endswith("allowed range [0, 1] m/s^2/sqrt(Hz)"), res.stderr
    assert "--noise-density: " in res.stderr
    res = _run(*vib, "--duration", "0")
    assert res.returncode == 2 and "argument --duration: must be in (0, 600] s, got 0" in res.stderr
    res = _run("thermal", "--speed", "100", "--radial-load", "1000", "--ambient", "900")
    assert res.returncode == 2 and "argument --ambient: must be in [-30, 150] degC, got 900" in res.stderr
    res = _run("thermal", "--speed", "1e5", "--radial-load", "1000")
    assert res.returncode == 2 and "error: --speed: shaft_speed_rad_s = 100000 rad/s is outside" in res.stderr
    res = _run("life", "--speed", "100", "--radial-load", "1000", "--oil-temperature", "900")
    assert res.returncode == 2 and "error: --oil-temperature: oil_temperature_c = 900 degC" in res.stderr


def test_report_quick(tmp_path):
    res = _run("report", "--out", str(tmp_path), "--quick", timeout=600)
    assert res.returncode == 0, res.stderr
    text = (tmp_path / "report.md").read_text()
    for png in (
        "lambda_azimuth_500.png",
        "lambda_speed.png",
        "lambda_load.png",
        "lambda_clearance.png",
        "startup.png",
        "seed001_torque.png",
        "seed003_reduction.png",
        "seed003_fig7_speed.png",
        "seed003_temperature_resistance.png",
        "ehl_centre_line_isothermal.png",
        "ehl_centre_line_current.png",
        "ehl_film_vs_speed.png",
        "angular_contact_jones.png",
        "cwru_comparison.png",
    ):
        assert (tmp_path / png).stat().st_size > 10_000
        assert png in text
    assert "0.6797" in text and "-0.0727" in text
    # the EV section (seed 003): Figs. 2/4 band, Fig. 7's thickest-film speed rising with current
    assert "## EV motor bearing under shaft current (seed 003)" in text
    assert "57.6-84.8 %" in text and "speed of the thickest film" in text
    # the 7208 family against Jones' quasi-static solution (service/reports/angular_contact.py)
    assert "## Angular-contact 7208 family against Jones' quasi-static solution" in text
    assert "| 7208AC | 3000 / 3000 |" in text
    # the CWRU records beside the twin (service/reports/cwru.py): every record's row
    assert "## Vibration against the CWRU records" in text
    assert all(f"| {n} | " in text for n in (97, 105, 118, 130, 144, 156))
    # the time-step study's table (bearing-twin timestep-study)
    assert "## Time step: the auto step against 1 us" in text and "| 6208-serve | auto |" in text


def test_negative_numbers_in_scientific_notation_are_values():
    """`--clearance -1e-5` (a preload) is the option's value, not an unknown option (Python
    3.11's argparse only knows -1 and -1.5 as numbers); `--clearance=-1e-5` too."""
    for args in (("--clearance", "-1e-5"), ("--clearance=-1e-5",)):
        res = _run("simulate", *args, "--duration", "0.001", "--json")
        assert res.returncode == 0, res.stderr
        assert json.loads(res.stdout)["status"] == "ok"
    res = _run("simulate", "--clear", "0", "--duration", "0.001")  # no abbreviations
    assert res.returncode == 2 and "unrecognized arguments" in res.stderr


def test_a_closed_pipe_ends_quietly():
    """`simulate --json | head -c 100`: the reader goes away; no BrokenPipeError traceback."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "service.cli", "simulate", "--duration", "0.001", "--json"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    proc.stdout.close()  # nothing reads: the first write fails with EPIPE
    _out, err = proc.communicate(timeout=300)
    assert proc.returncode == 141, err
    assert b"Traceback" not in err and b"BrokenPipeError" not in err


def test_a_document_goes_out_in_one_write(monkeypatch):
    """README ("Units"): a command's JSON document that fits the pipe's buffer is in the pipe
    before a reader that takes only its start (`simulate --json | head -c 200`) can go, so the
    command ends with status 0: the document and its newline leave in one write to the OS
    (`print` writes a document larger than the stream's 8 KiB buffer and its newline apart)."""
    import io

    from service.tools.stdout import print_document

    class Raw(io.RawIOBase):
        def __init__(self):
            self.writes: list[bytes] = []

        def writable(self):
            return True

        def write(self, b):
            self.writes.append(bytes(b))
            return len(b)

    raw = Raw()
    monkeypatch.setattr(sys, "stdout", io.TextIOWrapper(io.BufferedWriter(raw), encoding="utf-8"))
    document = json.dumps({"balls": ["x" * 100] * 110})  # 11 kB, a snapshot's size
    print_document(document)
    assert raw.writes == [(document + "\n").encode()]


def test_a_busy_zenoh_port_is_a_one_line_error(tmp_path):
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        res = subprocess.run(
            [
                sys.executable,
                "-m",
                "service.cli",
                "serve",
                "--port",
                "0",
                "--no-record",
                "--zenoh-listen",
                f"tcp/127.0.0.1:{port}",
            ],
            capture_output=True,
            text=True,
            timeout=300,
            cwd=tmp_path,
        )
    assert res.returncode == 2
    lines = [line for line in res.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: zenoh") and "already in use" in lines[0], res.stderr
    assert ".rs:" not in lines[0]


def test_scenario_run_names_the_recording_it_wrote(tmp_path):
    """A --record name that is taken is never overwritten: the run records beside it as
    <stem>.run2.rrd and prints the name it wrote, not the one it was given."""
    pytest.importorskip("rerun")
    scenario = tmp_path / "tiny.yaml"
    scenario.write_text(
        'name: tiny\nbearing: "6208"\ninitial: {shaft_speed_rad_s: 300.0, radial_load_n: 3000.0}\n'
        "duration_s: 0.01\nsample_every_s: 0.005\nsteps:\n  - at_s: 0.0\n"
        "    set: {shaft_speed_rad_s: 300.0}\n"
    )
    taken = tmp_path / "x.rrd"
    taken.write_bytes(b"an earlier run")
    res = subprocess.run(
        [
            sys.executable,
            "-m",
            "service.cli",
            "scenario",
            "run",
            str(scenario),
            "--record",
            str(taken),
            "--no-progress",
        ],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=tmp_path,
    )
    assert res.returncode == 0, res.stdout + res.stderr
    written = tmp_path / "x.run2.rrd"
    assert f"recording: {written}" in res.stdout, res.stdout
    assert written.stat().st_size > 0 and taken.read_bytes() == b"an earlier run"


def test_an_output_file_that_cannot_be_written_is_refused_before_the_run(tmp_path):
    """`vibration --waveform/--plot` and `scenario run --record/--table` check the file they will
    write before simulating (its suffix, and that it can be created: /proc takes no new file), and
    name the option; the run, which would otherwise end in a traceback after it, never starts."""
    from service.tools.arg_types import output_file

    scenario = os.path.join(
        os.path.dirname(__file__), "..", "..", "..", "scenarios", "seed000_startup_steady_slowdown.yaml"
    )
    cases = [
        (["vibration", "--waveform", "/proc/nope.npy"], "--waveform", "cannot write /proc/nope.npy"),
        (["vibration", "--waveform", str(tmp_path / "w.txt")], "--waveform", "must end in .npy"),
        (["vibration", "--plot", str(tmp_path / "p.txt")], "--plot", "must end in .png or .pdf"),
        (["vibration", "--plot", "/proc/x.png"], "--plot", "cannot write /proc/x.png"),
        (["scenario", "run", scenario, "--table", "/proc/nope/x.parquet"], "--table", "cannot write"),
        (["scenario", "run", scenario, "--record", "/proc/nope/x.rrd"], "--record", "cannot write"),
    ]
    for argv, flag, says in cases:
        res = _run(*argv, timeout=120)
        assert res.returncode == 2, (argv, res.stderr)
        assert f"argument {flag}: {says}" in res.stderr and "Traceback" not in res.stderr, res.stderr
    assert not (tmp_path / "w.txt").exists() and not (tmp_path / "p.txt").exists()
    ok = tmp_path / "new" / "w.npy"  # a missing folder is made; the file is not left behind
    assert output_file(".npy")(str(ok)) == str(ok) and ok.parent.is_dir() and not ok.exists()


def test_defect_flags_without_a_defect_are_refused():
    """`vibration --defect-size ...` without `--defect`: the defect's description would be dropped
    without a word and a healthy bearing simulated; it is refused naming the flag."""
    res = _run("vibration", "--speed", "500", "--radial-load", "3000", "--defect-angle", "90", timeout=120)
    assert res.returncode == 2 and "--defect-angle: describes a defect; give --defect" in res.stderr
    res = _run("vibration", "analyse", "x.wav", "--full-scale", "0", "--rpm", "1797", "--sample-rate", "12000")
    assert res.returncode == 2 and "argument --full-scale: must be a finite number > 0" in res.stderr


def test_a_vibration_run_too_short_to_analyse_names_the_duration_it_needs():
    """The analysis takes windows of at least 1024 samples: at the CWRU-DE's 12 kHz a 0.05 s run
    has 600; the command says so before simulating, with the least duration at that rate."""
    res = _run("vibration", "--bearing", "CWRU-DE", "--speed", "188", "--duration", "0.05", timeout=120)
    assert res.returncode == 2 and "Traceback" not in res.stderr
    assert "--duration: duration_s = 0.05 s: 600 samples at 12000 Hz" in res.stderr
    assert "at least 0.08533 s" in res.stderr
