"""The documentation: README.md stays a page for users, the docs site builds with `--strict`
(every internal link and anchor resolves), docs/performance.md shows the newest saved benchmark,
and the code speaks in the present tense (no issue numbers or dates in twin/ and service/).
The blocks of README.md and docs/ are run by tests/test_readme_commands.py."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from service.tools.bench_results import bench_table, newest

ROOT = Path(__file__).resolve().parents[1]
README_MAX_LINES = 300
HISTORY = re.compile(r"issue [0-9]+|20[0-9]{2}-[0-9]{2}-[0-9]{2}", re.IGNORECASE)


def test_readme_is_short():
    assert len((ROOT / "README.md").read_text().splitlines()) <= README_MAX_LINES


def test_performance_page_shows_the_newest_bench_result():
    path = newest(ROOT / "benchmarks" / "results")
    assert path is not None, "no benchmarks/results/*-bench.json"
    saved = json.loads(path.read_text())
    page = (ROOT / "docs" / "performance.md").read_text()
    assert bench_table(saved) in page, f"docs/performance.md does not show the table of {path.name}"
    assert path.name in page and saved["environment"]["cpu_model"] in page


def test_code_speaks_in_the_present_tense():
    hits = [
        f"{path.relative_to(ROOT)}:{n}: {line.strip()[:100]}"
        for package in ("twin", "service")
        for path in sorted((ROOT / package).rglob("*.py"))
        for n, line in enumerate(path.read_text().splitlines(), 1)
        if HISTORY.search(line)
    ]
    assert not hits, "issue numbers or dates in code (history goes to CHANGELOG.md):\n" + "\n".join(hits)


def test_docs_site_builds_strict(tmp_path):
    pytest.importorskip("mkdocs")
    pytest.importorskip("material")
    res = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(tmp_path / "site")],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert res.returncode == 0, res.stdout[-3000:] + res.stderr[-3000:]
    assert (tmp_path / "site" / "index.html").exists()
    shutil.rmtree(tmp_path / "site")
