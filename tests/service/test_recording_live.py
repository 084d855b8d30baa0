"""`serve --rerun-web PORT`: rerun's web viewer shows the running twin, live, in headless Chromium.

The viewer draws into a WebGL canvas (no DOM text to read), so the page is checked on its pixels:
the balls of the 3D view are drawn in the regime colours of `service.recording.layout.REGIME_RGB`,
which the viewer's own chrome (welcome screen, panels) never uses. The test also checks that both
of rerun's ports are bound to loopback only, and that a non-loopback bind is refused while an HTTP
token is set (rerun's server checks no token).

Needs Chromium and websocket-client (`.ci/run` installs both); skips with the reason otherwise.
"""

from __future__ import annotations

import importlib.util
import io
import os
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("rerun")
pytest.importorskip("zenoh")
pytest.importorskip("httpx")

from service.recording.layout import REGIME_RGB
from service.recording.live import LiveViewerError, check_bind, is_loopback


def _sibling(name: str):
    # --import-mode=importlib: the helpers beside this file are loaded by path
    spec = importlib.util.spec_from_file_location(f"bearing_twin_{name}", Path(__file__).with_name(f"{name}.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


_chromium = _sibling("headless_chromium")
_e2e = _sibling("test_end_to_end")
HeadlessChromium, chromium_path = _chromium.HeadlessChromium, _chromium.chromium_path
REPO, Service, free_port = _e2e.REPO, _e2e.Service, _e2e.free_port

WAIT_S = 90.0


def test_non_loopback_bind_is_refused_with_a_token():
    check_bind("127.0.0.1", token_set=True)
    check_bind("0.0.0.0", token_set=False)
    with pytest.raises(LiveViewerError, match="rerun_web_bind"):
        check_bind("0.0.0.0", token_set=True)
    assert is_loopback("::1") and is_loopback("localhost") and not is_loopback("10.0.0.1")


def test_serve_refuses_a_public_rerun_web_with_a_token(tmp_path):
    env = {k: v for k, v in os.environ.items() if not k.startswith("BEARING_TWIN_")}
    env["BEARING_TWIN_TOKEN"] = "s3cret-token-for-the-test"
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "service.cli",
            "serve",
            "--port",
            "0",
            "--no-zenoh",
            "--no-record",
            "--rerun-web",
            str(free_port()),
            "--rerun-web-bind",
            "0.0.0.0",
        ],
        cwd=REPO,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode != 0
    assert "rerun_web_bind" in r.stderr + r.stdout and "Traceback" not in r.stderr


def _regime_pixels(png: bytes) -> int:
    """Pixels within 12 of a regime colour of the balls (full film, mixed, boundary)."""
    from PIL import Image

    img = np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(np.int16)
    hits = np.zeros(img.shape[:2], dtype=bool)
    for rgb in REGIME_RGB[1:]:
        hits |= np.abs(img - rgb.astype(np.int16)).max(axis=2) <= 12
    return int(hits.sum())


def _listeners(port: int) -> list[str]:
    out = subprocess.run(["ss", "-ltnH", f"sport = :{port}"], capture_output=True, text=True).stdout
    return re.findall(rf"\s(\S+):{port}\s", out)


@pytest.mark.skipif(chromium_path() is None, reason="needs Chromium (apt-get install chromium; .ci/run installs it)")
def test_live_web_viewer_shows_the_running_twin(tmp_path):
    pytest.importorskip("websocket", reason="needs websocket-client (pip install websocket-client)")
    pytest.importorskip("PIL", reason="needs Pillow")
    web = free_port()
    while web + 1 > 65534 or _listeners(web + 1):
        web = free_port()
    svc = Service(tmp_path, "--rerun-web", str(web), record=False)
    browser = None
    try:
        assert any(f"rerun web viewer: open http://127.0.0.1:{web}/" in line for line in svc.log), "".join(svc.log)
        if Path("/usr/bin/ss").exists() or Path("/bin/ss").exists():
            for port in (web, web + 1):
                hosts = _listeners(port)
                assert hosts and all(h in ("127.0.0.1", "[::1]") for h in hosts), (port, hosts)
        browser = HeadlessChromium(1600, 1000)
        browser.navigate(f"http://127.0.0.1:{web}/?url=rerun%2Bhttp%3A%2F%2F127.0.0.1%3A{web + 1}%2Fproxy")
        deadline = time.monotonic() + WAIT_S
        pixels = 0
        while time.monotonic() < deadline:
            time.sleep(3.0)
            png = browser.screenshot()
            pixels = _regime_pixels(png)
            if pixels > 2000:  # the balls (each ~60 px across at 1600 x 1000) are drawn
                break
        else:
            (tmp_path / "live.png").write_bytes(png)
        assert pixels > 2000, f"no twin drawn after {WAIT_S:.0f} s ({pixels} regime-coloured pixels)"
        assert browser.evaluate("document.title") == "Rerun Viewer"
    finally:
        if browser is not None:
            browser.close()
        svc.terminate(30.0)
