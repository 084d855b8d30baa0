"""`--bearing FILE`: a bearing spec file (YAML or JSON of twin.spec.BearingSpec) wherever a command
takes a bearing (simulate, vibration analyse, thermal, serve's configured twin), with errors that
name the file and the field."""

from __future__ import annotations

import json
from pathlib import Path

import httpx
import numpy as np
import yaml

from service.settings import ServiceSettings
from service.tools.cli import main
from twin import catalog

RECORD = Path(__file__).resolve().parents[2] / "data" / "cwru" / "105_DE_5s.npy"


def _own_spec(**geometry) -> dict:
    """A 6205 with 8 balls under a designation of its own (a bearing the catalog does not have)."""
    spec = catalog.bearing("6205").model_dump(mode="json")
    spec["designation"] = "MY-6205-8"
    spec["geometry"].update({"ball_count": 8, **geometry})
    return spec


def test_simulate_runs_the_spec_file(tmp_path, capsys):
    path = tmp_path / "own.json"
    path.write_text(json.dumps(_own_spec()))
    assert (
        main(
            [
                "simulate",
                "--bearing",
                str(path),
                "--speed",
                "300",
                "--radial-load",
                "800",
                "--duration",
                "0.002",
                "--json",
            ]
        )
        == 0
    )
    snap = json.loads(capsys.readouterr().out)
    assert snap["designation"] == "MY-6205-8" and len(snap["balls"]) == 8


def test_a_bad_spec_file_names_the_field(tmp_path, capsys):
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(_own_spec(ball_count=20)))
    assert main(["simulate", "--bearing", str(path), "--duration", "0.001"]) == 2
    err = capsys.readouterr().err
    assert "geometry.ball_count" in err and "16" in err and "Traceback" not in err
    assert main(["thermal", "--bearing", str(tmp_path / "none.yaml"), "--speed", "300", "--radial-load", "800"]) == 2
    assert "cannot read spec file" in capsys.readouterr().err
    binary = tmp_path / "binary.yaml"
    binary.write_bytes(b"\x00\xde\xad\xbe\xef" * 20)
    assert main(["simulate", "--bearing", str(binary), "--duration", "0.001"]) == 2
    err = capsys.readouterr().err
    assert f"spec file {str(binary)!r} is not UTF-8 text" in err and "Traceback" not in err


def test_a_spec_file_takes_numbers_as_yaml_writes_them_and_nothing_else(tmp_path, capsys):
    """In a YAML spec file `1e-5` is a number (YAML 1.2, twin.yaml_numbers; PyYAML's YAML 1.1 reads
    it as text), while `true` or a quoted "2.0" where a number goes is refused naming the field."""
    spec = _own_spec()
    text = yaml.safe_dump(spec).replace(
        f"diametral_clearance_m: {spec['mounting']['diametral_clearance_m']}", "diametral_clearance_m: 1e-5"
    )
    assert "diametral_clearance_m: 1e-5" in text
    path = tmp_path / "own.yaml"
    path.write_text(text)
    assert catalog.load_spec_file(str(path)).mounting.diametral_clearance_m == 1e-5
    for value in ("true", '"2.0"'):
        path.write_text(text.replace(f"rotor_mass_kg: {spec['mounting']['rotor_mass_kg']}", f"rotor_mass_kg: {value}"))
        assert main(["simulate", "--bearing", str(path), "--duration", "0.001"]) == 2
        err = capsys.readouterr().err
        assert "--bearing: mounting.rotor_mass_kg" in err and "Traceback" not in err, err


def test_vibration_analyse_names_the_spec_files_field(tmp_path, capsys):
    """`vibration analyse --bearing FILE` reports a spec file's bad field as the other commands
    do (one line naming the field and its range), not pydantic's whole report."""
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(_own_spec(ball_count=20)))
    argv = ["vibration", "analyse", str(RECORD), "--sample-rate", "12000", "--rpm", "1797", "--bearing", str(path)]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "--bearing" in err and "geometry.ball_count" in err and "16" in err
    assert "errors.pydantic.dev" not in err and "Traceback" not in err


def test_vibration_analyse_takes_the_lines_from_a_spec_file(tmp_path, capsys):
    """The CWRU-DE catalog entry written to a file gives the same analysis as its designation
    (record 105, inner race: BPFI the largest line)."""
    path = tmp_path / "cwru.yaml"
    path.write_text(yaml.safe_dump(catalog.bearing("CWRU-DE").model_dump(mode="json")))
    results = []
    for bearing in ("CWRU-DE", str(path)):
        assert (
            main(
                [
                    "vibration",
                    "analyse",
                    str(RECORD),
                    "--sample-rate",
                    "12000",
                    "--rpm",
                    "1797",
                    "--units",
                    "g",
                    "--bearing",
                    bearing,
                    "--json",
                ]
            )
            == 0
        )
        results.append(json.loads(capsys.readouterr().out))
    assert results[0] == results[1]
    assert results[1]["largest_lines"][0]["label"] == "BPFI"
    assert np.isfinite(results[1]["kurtosis"])


def test_serve_starts_its_twin_from_a_spec_file(tmp_path, support):
    path = tmp_path / "own.yaml"
    path.write_text(yaml.safe_dump(_own_spec()))
    settings = ServiceSettings(enable_zenoh=False, enable_recording=False, admission="off", bearing=str(path))
    with (
        support.ThreadServer(settings, start_timeout_s=60.0, stop_timeout_s=15.0) as srv,
        httpx.Client(base_url=srv.url, timeout=60.0) as c,
    ):
        info = c.get("/v1/bearings/default").json()
    assert info["designation"] == "MY-6205-8" and info["ball_count"] == 8


def test_life_rates_the_spec_file(tmp_path, capsys):
    """A spec file of the catalog 6205 gives the designation's figures; its own clearance is used
    unless --clearance is given."""
    spec = catalog.bearing("6205").model_dump(mode="json")
    spec["mounting"]["diametral_clearance_m"] = 10e-6
    path = tmp_path / "6205.yaml"
    path.write_text(yaml.safe_dump(spec))
    common = ["--radial-load", "1000", "--speed", "300", "--json"]
    results = []
    for args in (["--bearing", "6205", "--clearance", "1e-5"], ["--bearing", str(path)]):
        assert main(["life", *args, *common]) == 0
        results.append(json.loads(capsys.readouterr().out))
    assert results[0] == results[1]
    assert results[1]["diametral_clearance_m"] == 10e-6
