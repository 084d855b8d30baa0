"""A plain `pip install .` runs the product (serve, monitor, router) without the load tools'
dependencies: httpx is no runtime dependency (only of the `loadtest` extra), and the runtime
imports with httpx made unimportable. `bearing-twin-loadtest` then names the extra to install."""

from __future__ import annotations

import os
import subprocess
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]

BLOCK_HTTPX = """
import sys
class _NoHttpx:
    def find_spec(self, name, path=None, target=None):
        if name == "httpx" or name.startswith("httpx."):
            raise ImportError("httpx is not installed (plain install)")
        return None
sys.meta_path.insert(0, _NoHttpx())
"""


def _run(code: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-c", BLOCK_HTTPX + code],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )


def _names(requirements: list[str]) -> set[str]:
    return {
        r.split(";")[0].split("[")[0].split("<")[0].split(">")[0].split("=")[0].split("~")[0].strip().lower()
        for r in requirements
    }


def test_httpx_is_an_extra_not_a_runtime_dependency():
    assert "httpx" not in _names(PROJECT["dependencies"])
    assert "httpx" in _names(PROJECT["optional-dependencies"]["loadtest"])
    assert PROJECT["scripts"]["bearing-twin-loadtest"] == "loadtest.cli:main"


def test_serve_monitor_and_router_run_without_httpx():
    res = _run("""
import contextlib, io
from service.cli import main
import service.api.app, service.wiring, service.bus.zenoh_bus, service.tools.monitor, service.tools.router
from service.api.app import create_app
from service.settings import ServiceSettings
create_app(ServiceSettings(enable_zenoh=False, enable_recording=False))
for command in ("serve", "monitor", "router"):
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        try:
            main([command, "--help"])
        except SystemExit as exc:
            assert exc.code == 0, (command, exc.code)
    assert "usage:" in out.getvalue(), command
assert "httpx" not in sys.modules
print("ok")
""")
    assert res.returncode == 0 and res.stdout.strip().endswith("ok"), res.stdout + res.stderr


def test_the_load_tools_name_their_extra_without_httpx():
    res = _run("from loadtest.cli import main\nsys.exit(main(['soak', '--minutes', '1']))")
    assert res.returncode == 2, res.stdout + res.stderr
    assert "pip install" in res.stderr and "[loadtest]" in res.stderr
    res = _run("from service.cli import main\nsys.exit(main(['soak', '--minutes', '1']))")
    assert res.returncode == 2 and "bearing-twin-loadtest soak" in res.stderr, res.stderr
