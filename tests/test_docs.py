"""The documentation: README.md stays a page for users, the docs site builds with `--strict`
(every internal link and anchor resolves), docs/performance.md shows the newest saved benchmark,
and the code speaks in the present tense (no issue numbers or dates in the .py files of twin/,
service/, tests/, loadtest/ and benchmarks/).
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
# History in code: a date, or a number of this project's issue tracker ("issue N", "issues N",
# "issue #N"). Another project's issue is a citation and stays, written "<project> issue #N" (e.g.
# "rerun issue #2116"): a "#" and a name before it that is no English word of the NOT_A_PROJECT list.
CODE_PACKAGES = ("twin", "service", "tests", "loadtest", "benchmarks")
DATE = re.compile(r"20[0-9]{2}-[0-9]{2}-[0-9]{2}")
ISSUE = re.compile(r"(?:([\w.-]+) )?\bissues? (#?)[0-9]+", re.IGNORECASE)
NOT_A_PROJECT = set("a an and by for from in its of or our per see the this to".split())


def speaks_of_history(line: str) -> bool:
    """True for a date or an issue of this project in `line`; "<project> issue #N" is a citation."""
    for match in ISSUE.finditer(line):
        project, hash_sign = match.group(1), match.group(2)
        if not (hash_sign and project and project.lower() not in NOT_A_PROJECT):
            return True
    return DATE.search(line) is not None


def test_readme_is_short():
    assert len((ROOT / "README.md").read_text().splitlines()) <= README_MAX_LINES


def test_performance_page_shows_the_newest_bench_result():
    path = newest(ROOT / "benchmarks" / "results")
    assert path is not None, "no benchmarks/results/*-bench.json"
    saved = json.loads(path.read_text())
    page = (ROOT / "docs" / "performance.md").read_text()
    assert bench_table(saved) in page, f"docs/performance.md does not show the table of {path.name}"
    assert path.name in page and saved["environment"]["cpu_model"] in page


def test_history_pattern_tells_our_issues_from_citations():
    ours = ("(issue {n})", "Issue {n} criteria", "issues {n} and 14", "see issue #{n}", "the issue #{n}", "20{n}-11-23")
    for history in (text.format(n=13) for text in ours):  # spelled as templates: this file is checked too
        assert speaks_of_history(history), history
    for citation in ("(rerun issue #2116)", "zenoh issue #1234", "the issue's targets", "reissued 3 times"):
        assert not speaks_of_history(citation), citation


def test_code_speaks_in_the_present_tense():
    hits = [
        f"{path.relative_to(ROOT)}:{n}: {line.strip()[:100]}"
        for package in CODE_PACKAGES
        for path in sorted((ROOT / package).rglob("*.py"))
        for n, line in enumerate(path.read_text().splitlines(), 1)
        if speaks_of_history(line)
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
