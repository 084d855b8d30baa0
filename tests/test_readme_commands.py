"""Every shell and Python block of README.md and docs/*.md works: each command a user would type
is run in a subprocess (the CLI as `python -m service.cli`, like the other CLI tests; short
variants where the documented one would run for minutes) and must exit 0, and each ```python
block runs as printed. The blocks are read from the files themselves, so a block added there
without a way to run it here fails `test_every_shell_line_is_covered` or
`test_every_python_block_is_covered`. A command that appears on several pages runs once.

Not run, with the reason in SKIPPED: the venv/pip install lines (this test runs inside an
installed environment), docker, and the multi-host lines (tests/service/test_end_to_end.py runs
that setup on loopback). Blocks that need a running service get one started here on free
loopback ports: `bearing-twin serve`, then the curl lines, the zenoh client, `monitor`, the
OPC UA client snippets; `serve` stops with SIGINT (Ctrl-C)."""

from __future__ import annotations

import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from loadtest.ports import free_port

ROOT = Path(__file__).resolve().parents[1]
DOC_FILES = (ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")))
TIMEOUT_S = 600


def _blocks(lang: str) -> list[str]:
    """The fenced ```lang blocks of README.md and docs/*.md, in file order."""
    return [
        block for path in DOC_FILES for block in re.findall(rf"```{lang}\n(.*?)```", path.read_text(), flags=re.DOTALL)
    ]


def readme_shell_lines() -> list[str]:
    """Logical lines of the ```sh blocks of README.md and docs/*.md (continuations joined, comments
    cut, blanks dropped), each once."""
    out: list[str] = []
    for block in _blocks("sh"):
        text = block.replace("\\\n", " ")
        for line in text.splitlines():
            line = re.sub(r"\s+#\s.*$", "", line).strip()  # trailing comment
            line = " ".join(line.split())
            if line and not line.startswith("#") and line not in out:
                out.append(line)
    return out


# README line (regex, matched at the start) -> how it is run here, or why it is not
SKIPPED = {
    r"python3 -m venv": "installation: the test runs in an installed environment",
    r"\. \.venv/bin/activate": "installation",
    r"pip install": "installation",
    r"docker ": "no docker in the test environment",
    r"host[AB]\$|anywhere\$|router\$": "several hosts: tests/service/test_end_to_end.py, test_fleet.py and "
    "tests/hostile/test_zenoh_access.py run them on loopback",
    r"bearing-twin router": "runs until stopped: tests/service/test_fleet.py runs it",
    r"bearing-twin-loadtest soak --minutes 60 --url": "needs a service of its own: the --start variant is run",
    r"bearing-twin-loadtest attack --seconds 60 --url": "needs a service of its own: the --start variant is run",
    r"export BEARING_TWIN_TOKEN": "run by test_token_and_opcua_commands",
}
SERVED = (r"bearing-twin serve", r"curl ", r"bearing-twin monitor")  # run by test_serve_and_its_clients


def _cli(
    *args: str, cwd: Path, env: dict | None = None, timeout: float = TIMEOUT_S, module: str = "service.cli"
) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", module, *args],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=timeout,
        env={**os.environ, "PYTHONPATH": str(ROOT), **(env or {})},
    )


def _scenario_files() -> list[str]:
    return sorted(str(p.relative_to(ROOT)) for p in (ROOT / "scenarios").glob("*.yaml"))


# bearing-twin subcommands run as one-shot commands: README prefix -> argv (short variants)
ONE_SHOT = {
    "bearing-twin scenario check": lambda out: ["scenario", "check", *_scenario_files()],
    "bearing-twin scenario run scenarios/seed000_startup_steady_slowdown.yaml": lambda out: [
        "scenario",
        "run",
        "scenarios/seed000_startup_steady_slowdown.yaml",
        "--record",
        str(out / "out.rrd"),
        "--table",
        str(out / "out.parquet"),
        "--no-progress",
    ],
    "bearing-twin scenario run scenarios/seed000_speed_sweep.yaml": lambda out: [
        "scenario",
        "run",
        "scenarios/seed000_speed_sweep.yaml",
        "--table",
        str(out / "speed.parquet"),
        "--record",
        str(out / "speed.rrd"),
        "--no-progress",
    ],
    "bearing-twin report": lambda out: ["report", "--out", str(out / "reports"), "--quick"],
    "bearing-twin simulate --bearing 6208": lambda out: [
        "simulate",
        "--bearing",
        "6208",
        "--radial-load",
        "3000",
        "--speed",
        "500",
        "--duration",
        "0.05",
        "--json",
    ],
    "bearing-twin simulate --bearing 7208": lambda out: [
        "simulate",
        "--bearing",
        "7208",
        "--radial-load",
        "3000",
        "--axial-load",
        "3000",
        "--clearance",
        "-1e-5",
        "--dt",
        "1e-6",
    ],
    "bearing-twin bench": lambda out: [
        "bench",
        "--json",
        "--seconds",
        "0.01",
        "--repeats",
        "5",  # >= 5 repeats
        "--save",
        str(out / "results"),
    ],
    "bearing-twin timestep-study": lambda out: ["timestep-study", "--quick", "--json"],
    "bearing-twin life": lambda out: ["life", "--bearing", "6208", "--radial-load", "3000", "--speed", "500", "--json"],
    "bearing-twin ehl solve": lambda out: ["ehl", "solve", "--current", "20", "--grid", "65", "--json"],
    "bearing-twin-loadtest bench-service": lambda out: ["bench-service", "--seconds", "3", "--json"],
    "bearing-twin-loadtest soak --minutes 10 --start": lambda out: ["soak", "--minutes", "0.3", "--start", "--json"],
    "bearing-twin-loadtest attack --seconds 60 --start": lambda out: [
        "attack",
        "--seconds",
        "3",
        "--start",
        "--baseline",
        "1",
        "--json",
    ],
    "bearing-twin vibration": lambda out: [
        "vibration",
        "--bearing",
        "6208",
        "--speed",
        "523",
        "--radial-load",
        "3000",
        "--defect",
        "outer",
        "--duration",
        "0.1",
        "--json",
        "--plot",
        str(out / "vib.png"),
    ],
}
PYTHON_MODULES = {"python -m twin.validation.thermal_law_fit": ["-m", "twin.validation.thermal_law_fit"]}


def _handler(line: str) -> str:
    for pattern, why in SKIPPED.items():
        if re.match(pattern, line):
            return f"skipped: {why}"
    if any(re.match(p, line) for p in SERVED):
        return "served"
    for prefix in sorted(ONE_SHOT, key=len, reverse=True):
        if line.startswith(prefix):
            return prefix
    for prefix in PYTHON_MODULES:
        if line.startswith(prefix):
            return prefix
    return "NOT COVERED"


def test_every_shell_line_is_covered():
    lines = readme_shell_lines()
    assert len(lines) > 20
    uncovered = [line for line in lines if _handler(line) == "NOT COVERED"]
    assert not uncovered, f"README / docs commands this test does not run: {uncovered}"
    # and every variant here still matches a documented line (none left over after an edit)
    used = {_handler(line) for line in lines}
    assert set(ONE_SHOT) | set(PYTHON_MODULES) <= used, (set(ONE_SHOT) | set(PYTHON_MODULES)) - used


@pytest.mark.parametrize("prefix", sorted(ONE_SHOT))
def test_one_shot_command(prefix, tmp_path):
    module = "loadtest" if prefix.startswith("bearing-twin-loadtest ") else "service.cli"
    res = _cli(*ONE_SHOT[prefix](tmp_path), cwd=ROOT, module=module)
    assert res.returncode == 0, f"{prefix}: exit {res.returncode}\n{res.stdout[-2000:]}\n{res.stderr[-3000:]}"
    assert "Traceback" not in res.stderr
    if "--json" in ONE_SHOT[prefix](tmp_path):
        json.loads(res.stdout.splitlines()[-1] if prefix.startswith("bearing-twin bench ") else res.stdout)
    if "--save" in ONE_SHOT[prefix](tmp_path):  # the dated result file: machine and versions beside the figures
        (saved,) = (tmp_path / "results").glob("*-bench.json")
        data = json.loads(saved.read_text())
        assert data["environment"]["cpu_model"] and data["environment"]["versions"]["numba"]
        assert data["result"]["real_time_factor"] > 0


@pytest.mark.parametrize("prefix", sorted(PYTHON_MODULES))
def test_python_module_command(prefix, tmp_path):
    res = subprocess.run(
        [sys.executable, *PYTHON_MODULES[prefix]],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )
    assert res.returncode == 0, res.stderr


# ```python blocks that need a running service (first line -> the test that runs them); every other
# block runs on its own, as printed
SERVED_PYTHON = {"import zenoh": "test_serve_and_its_clients", "import asyncio": "test_token_and_opcua_commands"}
# what a standalone block must print (first line -> text in its output), beside exiting 0
PYTHON_PRINTS = {"from twin import Twin                     # the public face": "2073.6"}  # the 6208's limit


def standalone_python_blocks() -> list[str]:
    return [b for b in _blocks("python") if not any(b.startswith(p) for p in SERVED_PYTHON)]


def test_every_python_block_is_covered():
    blocks = _blocks("python")
    assert len(blocks) >= 5
    assert len(standalone_python_blocks()) >= 4
    for prefix in SERVED_PYTHON:
        assert any(b.startswith(prefix) for b in blocks), f"no ```python block starts with {prefix!r} any more"
    for prefix in PYTHON_PRINTS:
        assert any(b.startswith(prefix) for b in standalone_python_blocks()), prefix


@pytest.mark.parametrize("block", standalone_python_blocks(), ids=lambda b: b.splitlines()[0][:40].strip())
def test_python_block(block, tmp_path):
    res = subprocess.run(
        [sys.executable, "-c", block],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )
    assert res.returncode == 0, res.stderr
    for prefix, text in PYTHON_PRINTS.items():
        if block.startswith(prefix):
            assert text in res.stdout, res.stdout


class _Serve:
    """`bearing-twin serve` as the README starts it, on free loopback ports, in `cwd`."""

    def __init__(self, cwd: Path, env: dict | None = None, extra: tuple[str, ...] = ()):
        self.port, self.zenoh = free_port(), f"tcp/127.0.0.1:{free_port()}"
        self.proc = subprocess.Popen(
            [
                sys.executable,
                "-m",
                "service.cli",
                "serve",
                "--port",
                str(self.port),
                "--zenoh-listen",
                self.zenoh,
                *extra,
            ],
            cwd=cwd,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            env={**os.environ, "PYTHONPATH": str(ROOT), **(env or {})},
        )

    def wait_healthy(self, timeout_s: float = 180.0) -> None:
        import httpx

        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            assert self.proc.poll() is None, self.proc.stdout.read()
            try:
                if httpx.get(f"http://127.0.0.1:{self.port}/health", timeout=2.0).status_code == 200:
                    return
            except httpx.HTTPError:
                pass
            time.sleep(0.2)
        raise AssertionError("serve did not answer /health")

    def stop(self) -> str:
        self.proc.send_signal(signal.SIGINT)  # Ctrl-C, as the README says
        out, _ = self.proc.communicate(timeout=60)
        assert self.proc.returncode == 130, out  # 128 + SIGINT, after a clean shutdown
        return out


def _shell(line: str, port: int, cwd: Path, env: dict | None = None) -> subprocess.CompletedProcess:
    line = line.replace("localhost:8000", f"127.0.0.1:{port}")
    return subprocess.run(
        ["bash", "-c", line],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "PYTHONPATH": str(ROOT), **(env or {})},
    )


@pytest.mark.skipif(shutil.which("curl") is None, reason="curl not installed")
def test_serve_and_its_clients(tmp_path):
    """Quick start: serve, then in a second shell the curl lines, the README's zenoh client and
    monitor; then Ctrl-C and the recording is there."""
    shutil.copytree(ROOT / "scenarios", tmp_path / "scenarios")
    serve = _Serve(tmp_path)
    try:
        serve.wait_healthy()
        curls = [line for line in readme_shell_lines() if line.startswith("curl ") and "Authorization" not in line]
        assert len(curls) >= 4
        for line in curls:
            res = _shell(line, serve.port, tmp_path)
            assert res.returncode == 0 and res.stdout.strip(), (line, res.stderr)
            assert '"detail"' not in res.stdout, (line, res.stdout[:500])  # no error answer
        # the README's zenoh client snippet, on this service's endpoint
        (snippet,) = [b for b in _blocks("python") if b.startswith("import zenoh")]
        snippet = snippet.replace("tcp/127.0.0.1:7447", serve.zenoh)
        res = subprocess.run([sys.executable, "-c", snippet], capture_output=True, text=True, timeout=60)
        assert res.returncode == 0, res.stderr
        monitor = _cli("monitor", "--connect", serve.zenoh, "--once", "--duration", "60", cwd=tmp_path, timeout=120)
        assert monitor.returncode == 0 and "default" in monitor.stdout, monitor.stdout + monitor.stderr
    finally:
        if serve.proc.poll() is None:
            out = serve.stop()
    assert "Traceback" not in out
    assert list((tmp_path / "recordings").glob("bearing-twin-*.rrd"))


def _documented_token() -> str:
    """The token made by the documented `export BEARING_TWIN_TOKEN=...` line."""
    (block,) = [b for b in _blocks("sh") if b.startswith("export BEARING_TWIN_TOKEN")]
    export = block.splitlines()[0]
    token = subprocess.run(
        ["bash", "-c", f'{export} && printf %s "$BEARING_TWIN_TOKEN"'], capture_output=True, text=True, timeout=60
    ).stdout
    assert len(token) >= 32
    return token


@pytest.mark.skipif(shutil.which("curl") is None, reason="curl not installed")
def test_token_and_opcua_commands(tmp_path):
    """Operations, Access, and Service, OPC UA, against one `serve --opcua` with the token from the
    documented command (security `both`) on free loopback ports: the two asyncua snippets as
    printed (the client's certificate, then a SignAndEncrypt session pinning the server's
    certificate that writes radial_load_n = 5000 with the token), then the curl with the token
    and with a wrong one."""
    pytest.importorskip("asyncua")
    blocks = [b for b in _blocks("python") if b.startswith("import asyncio")]
    assert len(blocks) == 2 and "setup_self_signed_certificate" in blocks[0] and "Client(" in blocks[1]
    env = {"BEARING_TWIN_TOKEN": _documented_token()}
    opcua = f"opc.tcp://127.0.0.1:{free_port()}"
    serve = _Serve(tmp_path, env, extra=("--opcua", opcua, "--no-record"))
    try:
        serve.wait_healthy()
        assert (tmp_path / "opcua-pki" / "server-cert.der").exists()
        for block in blocks:
            res = subprocess.run(
                [sys.executable, "-c", block.replace("opc.tcp://127.0.0.1:4840", opcua)],
                cwd=tmp_path,
                capture_output=True,
                text=True,
                timeout=120,
                env={**os.environ, "PYTHONPATH": str(ROOT), **env},
            )
            assert res.returncode == 0, res.stdout + res.stderr
        assert (tmp_path / "client.der").exists()
        float(res.stdout.split()[0])  # min_lambda read over OPC UA
        import httpx

        state = httpx.get(f"http://127.0.0.1:{serve.port}/v1/bearings/default", timeout=10.0).json()
        assert state["setpoint"]["radial_load_n"] == 5000.0  # the OPC UA write landed
        (line,) = [line for line in readme_shell_lines() if line.startswith("curl ") and "Authorization" in line]
        res = _shell(line, serve.port, tmp_path, env)
        assert res.returncode == 0 and '"radial_load_n":5000.0' in res.stdout, res.stdout + res.stderr
        res = _shell(line.replace("$BEARING_TWIN_TOKEN", "wrong"), serve.port, tmp_path, env)
        assert '"status"' not in res.stdout and "invalid token" in res.stdout
    finally:
        if serve.proc.poll() is None:
            serve.stop()
