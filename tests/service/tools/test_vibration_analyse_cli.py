"""`bearing-twin vibration analyse FILE`: a measured record (.npy, .csv, .wav) analysed by
twin.vibration.analysis, the same JSON as `analyse_signal`, errors that name the option and its
range. Data: the CWRU inner-race excerpt (tests/data/cwru, Case Western Reserve University
Bearing Data Center record 105, 0.007 in, 0 hp; published BPFI 5.4152 x shaft)."""

import json
from pathlib import Path

import numpy as np
import pytest
import scipy.io
import scipy.io.wavfile

from service.tools.cli import main
from twin.vibration.analysis import analyse_signal

RECORD = Path(__file__).resolve().parents[2] / "data" / "cwru" / "105_DE_5s.npy"
G = 9.80665
LINES = ["--line", "BPFI=5.4152", "--line", "BPFO=3.5848", "--line", "2xBSF=4.7135", "--line", "FTF=0.39828"]
MULTIPLES = {"BPFI": 5.4152, "BPFO": 3.5848, "2xBSF": 4.7135, "FTF": 0.39828}


def _run(capsys, *args):
    code = main(["vibration", "analyse", *map(str, args)])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_npy_json_is_the_analysis(capsys):
    """The JSON is `analyse_signal(...).to_dict()` of the record in m/s2 plus the `input` block; BPFI
    is the largest envelope line, within 1.5 % of the published multiple."""
    code, out, err = _run(capsys, RECORD, "--sample-rate", 12000, "--rpm", 1797, "--units", "g", *LINES, "--json")
    assert code == 0, err
    result = json.loads(out, parse_constant=lambda c: pytest.fail(f"non-finite {c}"))
    x = np.load(RECORD).astype(float) * G
    expected = analyse_signal(x, 12000.0, 1797 / 60.0, MULTIPLES).to_dict()
    assert {k: v for k, v in result.items() if k != "input"} == json.loads(json.dumps(expected))
    assert result["input"]["units"] == "g" and result["input"]["line_multiples"] == MULTIPLES
    assert result["largest_lines"][0]["label"] == "BPFI"
    bpfi = next(d for d in result["defect_lines"] if d["name"] == "BPFI")
    assert abs(bpfi["relative_error"]) < 0.015


def test_csv_and_wav_read_the_same_record(tmp_path, capsys):
    """The same samples as .csv (with a header row) and as float32 / int16 .wav (full scale 4 g)
    give the .npy's RMS (to 1e-6 for csv and float wav, 1e-3 for 16-bit PCM)."""
    x = np.load(RECORD)
    csv = tmp_path / "rec.csv"
    csv.write_text("acc_g\n" + "\n".join(f"{v:.9g}" for v in x))
    wav = tmp_path / "rec.wav"
    scipy.io.wavfile.write(wav, 12000, x.astype(np.float32))
    pcm = tmp_path / "pcm.wav"
    scipy.io.wavfile.write(pcm, 12000, np.round(x / 4.0 * 32768).astype(np.int16))
    rms = float(np.std(x.astype(float))) * G
    for path, extra, tol in (
        (csv, ["--sample-rate", 12000], 1e-6),
        (wav, [], 1e-6),
        (pcm, ["--full-scale", 4.0], 1e-3),
    ):
        code, out, err = _run(capsys, path, *extra, "--rpm", 1797, "--units", "g", "--bearing", "6205", "--json")
        assert code == 0, err
        assert json.loads(out)["rms_m_s2"] == pytest.approx(rms, rel=tol)


def test_given_band_and_text_output(capsys):
    code, out, err = _run(
        capsys, RECORD, "--sample-rate", 12000, "--rpm", 1797, "--units", "g", "--bearing", "6205", "--band", 2000, 5000
    )
    assert code == 0, err
    assert "2000-5000 Hz (given)" in out and "BPFI" in out


@pytest.mark.parametrize(
    "args, message",
    [
        (["missing.npy", "--sample-rate", 12000, "--rpm", 1797, "--bearing", "6205"], "FILE: "),
        (["rec.txt", "--sample-rate", 12000, "--rpm", 1797, "--bearing", "6205"], "FILE: rec.txt: unknown format"),
        ([RECORD, "--rpm", 1797, "--bearing", "6205"], "--sample-rate: required"),
        (
            [RECORD, "--sample-rate", -5, "--rpm", 1797, "--bearing", "6205"],
            "--sample-rate: -5 is out of range; allowed (0, 1e+06] Hz",
        ),
        ([RECORD, "--sample-rate", 12000, "--rpm", 0, "--bearing", "6205"], "--rpm: 0; allowed (0, 36000]"),
        ([RECORD, "--sample-rate", 12000, "--bearing", "6205"], "--rpm: required (a .mat record may state it"),
        ([RECORD, "--sample-rate", 12000, "--rpm", 1e6, "--bearing", "6205"], "--rpm: "),
        ([RECORD, "--sample-rate", 12000, "--rpm", 1797, "--bearing", "9999"], "--bearing: "),
        ([RECORD, "--sample-rate", 12000, "--rpm", 1797], "--bearing: required"),
        ([RECORD, "--sample-rate", 12000, "--rpm", 1797, "--bearing", "6205", "--band", 5000, 2000], "--band: "),
        ([RECORD, "--sample-rate", 12000, "--rpm", 1797, "--bearing", "6205", "--column", 1], "--column: 1"),
    ],
)
def test_errors_name_the_option(capsys, args, message):
    code, out, err = _run(capsys, *args)
    assert code == 2 and out == ""
    assert err.startswith("error: ") and message in err
    assert "Traceback" not in err


def test_nan_in_the_record_is_refused(tmp_path, capsys):
    x = np.load(RECORD).astype(float)
    x[100] = np.nan
    bad = tmp_path / "nan.npy"
    np.save(bad, x)
    code, _, err = _run(capsys, bad, "--sample-rate", 12000, "--rpm", 1797, "--bearing", "6205")
    assert code == 2 and "FILE: 1 non-finite samples (first at index 100)" in err


def test_an_empty_csv_is_refused_in_one_line(tmp_path, capsys, recwarn):
    """An empty .csv is refused by its sample count, one line, without numpy's warning on stderr."""
    empty = tmp_path / "empty.csv"
    empty.write_text("")
    code, _, err = _run(capsys, empty, "--sample-rate", 12000, "--rpm", 1797, "--bearing", "6205")
    assert code == 2 and err.strip() == "error: FILE: 0 samples; at least 1024 needed"
    assert not [w for w in recwarn if "no data" in str(w.message)]


def test_a_cwru_mat_file_is_read_as_the_data_center_publishes_it(tmp_path, capsys):
    """The data center's .mat files (MATLAB 5) hold the drive end, the fan end and the base as
    column vectors `X105_DE_time`, `X105_FE_time`, `X105_BA_time` and the speed `X105RPM`: the drive
    end is taken by default and gives the .npy's analysis exactly, at the file's own speed when
    --rpm is left out; --variable picks another channel; a file
    with two drive-end channels (the data center's 99.mat also holds X098_DE_time) needs --variable,
    and the error lists the file's channels."""
    x = np.load(RECORD)
    mat = tmp_path / "105.mat"
    scipy.io.savemat(
        mat, {"X105_DE_time": x[:, None], "X105_FE_time": 0.5 * x[:, None], "X105RPM": np.array([[1797.0]])}
    )
    args = ["--sample-rate", 12000, "--rpm", 1797, "--units", "g", *LINES, "--json"]
    code, out, err = _run(capsys, mat, *args)
    assert code == 0, err
    code_npy, out_npy, _ = _run(capsys, RECORD, *args)
    strip = lambda text: {k: v for k, v in json.loads(text).items() if k != "input"}  # noqa: E731
    assert code_npy == 0 and strip(out) == strip(out_npy)
    no_rpm = [a for a in args if a not in ("--rpm", 1797)]  # the file's X105RPM is the speed
    code, out, err = _run(capsys, mat, *no_rpm)
    assert code == 0, err
    assert json.loads(out)["input"]["rpm"] == 1797.0 and strip(out) == strip(out_npy)
    code, out, err = _run(capsys, mat, *args, "--variable", "X105_FE_time")
    assert code == 0, err
    assert json.loads(out)["rms_m_s2"] == pytest.approx(0.5 * json.loads(out_npy)["rms_m_s2"], rel=1e-6)
    two = tmp_path / "99.mat"
    scipy.io.savemat(two, {"X098_DE_time": x[:, None], "X099_DE_time": x[:, None]})
    code, out, err = _run(capsys, two, *args)
    assert code == 2 and "--variable: 99.mat holds 2 candidate channels; pick one of: X098_DE_time, X099_DE_time" in err
    code, out, err = _run(capsys, mat, *args, "--variable", "X105RPM")
    assert code == 2 and "--variable: 'X105RPM' is not a numeric vector of 105.mat" in err
    bad = tmp_path / "bad.mat"
    bad.write_text("not a mat file")
    code, out, err = _run(capsys, bad, *args)
    assert code == 2 and "FILE: bad.mat is not a readable MATLAB 5 .mat record" in err
    v73 = tmp_path / "v73.mat"  # MATLAB 7.3 (HDF5): the header of one, which scipy refuses
    header = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, HDF5 schema 1.00 ."
    v73.write_bytes(header.ljust(124) + b"\x00\x02IM" + bytes(400))
    code, out, err = _run(capsys, v73, *args)
    assert code == 2 and "FILE: v73.mat is not a readable MATLAB 5 .mat record (MATLAB 7.3, HDF5)" in err
