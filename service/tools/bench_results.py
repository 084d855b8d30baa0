"""Benchmark results as data: a result dict with the machine, the versions and the git commit it
was measured with, written as dated JSON (`bearing-twin bench --save`).

File name: `<UTC date>-<cpu slug>-<kind>.json` (e.g. `YYYY-MM-DD-amd-epyc-bench.json`) under
`benchmarks/results/` of the current directory by default; a second run on the same day and CPU
gets a `-2`, `-3`, ... suffix rather than overwriting the first. docs/performance.md quotes the
newest file.
"""

from __future__ import annotations

import datetime as _dt
import json
import os
import platform
import re
import subprocess
from importlib import metadata
from pathlib import Path

DEFAULT_DIRECTORY = Path("benchmarks") / "results"
_PACKAGES = ("bearing-twin", "numpy", "numba", "pydantic", "fastapi", "eclipse-zenoh", "rerun-sdk")


def cpu_model() -> str:
    """The CPU's model name (Linux /proc/cpuinfo "model name"; elsewhere platform.processor())."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine() or "unknown"


def slug(text: str) -> str:
    """Lower-case words joined by '-', only [a-z0-9-] (for a file name)."""
    return re.sub(r"[^a-z0-9]+", "-", text.lower()).strip("-") or "unknown"


def git_commit(cwd: Path | None = None) -> str | None:
    """HEAD's commit of the repository holding this package, with "-dirty" if the tree has
    changes; None outside a git checkout or without git."""
    here = cwd or Path(__file__).resolve().parent
    try:
        head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=here, capture_output=True, text=True, timeout=10)
        if head.returncode != 0:
            return None
        dirty = subprocess.run(
            ["git", "status", "--porcelain", "--untracked-files=no"],
            cwd=here,
            capture_output=True,
            text=True,
            timeout=10,
        ).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None
    return head.stdout.strip() + ("-dirty" if dirty else "")


def versions() -> dict[str, str | None]:
    """Python and the installed versions of the packages the figures depend on (None: absent)."""
    out: dict[str, str | None] = {"python": platform.python_version()}
    for name in _PACKAGES:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = None
    return out


def environment(command: str) -> dict:
    """Where and with what a result was measured: UTC time, command, CPU, cores, OS, versions, commit."""
    return {
        "measured_utc": _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"),
        "command": command,
        "cpu_model": cpu_model(),
        "cpu_count": os.cpu_count(),
        "platform": platform.platform(),
        "versions": versions(),
        "git_commit": git_commit(),
    }


def save(result: dict, kind: str, command: str, directory: Path = DEFAULT_DIRECTORY) -> Path:
    """Write {"environment": environment(command), "result": result} as
    `<directory>/<UTC date>-<cpu slug>-<kind>[-n].json`; returns the path."""
    env = environment(command)
    directory.mkdir(parents=True, exist_ok=True)
    stem = f"{env['measured_utc'][:10]}-{slug(env['cpu_model'])}-{slug(kind)}"
    path, n = directory / f"{stem}.json", 1
    while path.exists():
        n += 1
        path = directory / f"{stem}-{n}.json"
    path.write_text(json.dumps({"environment": env, "result": result}, indent=1) + "\n")
    return path


def newest(directory: Path = DEFAULT_DIRECTORY, kind: str = "bench") -> Path | None:
    """The newest `*-<kind>*.json` of `directory` by its measured time (None: there is none)."""
    files = list(directory.glob(f"*-{slug(kind)}*.json"))
    if not files:
        return None
    return max(files, key=lambda f: (json.loads(f.read_text())["environment"]["measured_utc"], f.name))


def bench_table(saved: dict) -> str:
    """The Markdown table of a saved `bearing-twin bench` result (docs/performance.md): per case the
    auto step, the real-time factor best / median at it and at 1 us, and ns per step (best)."""
    r = saved["result"]
    rows = [
        (
            "serve-default",
            r["designation"],
            r["time_step_s"],
            r["real_time_factor"],
            r["real_time_factor_median"],
            r["ns_per_step"],
            r["real_time_factor_1us"],
            r["real_time_factor_1us_median"],
            r["ns_per_step_1us"],
        )
    ]
    for c in r.get("cases", []):
        a, one = c["default_step"], c["step_1us"]
        rows.append(
            (
                c["id"],
                c["designation"],
                a["time_step_s"],
                a["real_time_factor"],
                a["real_time_factor_median"],
                a["ns_per_step"],
                one["real_time_factor"],
                one["real_time_factor_median"],
                one["ns_per_step"],
            )
        )
    lines = [
        "| case | bearing | auto step [us] | real-time factor at auto, best / median | ns per step at auto "
        "| real-time factor at 1 us, best / median | ns per step at 1 us |",
        "|---|---|---|---|---|---|---|",
    ]
    for case, des, dt, rtf, rtf_med, ns, rtf1, rtf1_med, ns1 in rows:
        lines.append(
            f"| {case} | {des} | {dt * 1e6:.3f} | {rtf:.2f} / {rtf_med:.2f} | {ns:.0f} "
            f"| {rtf1:.2f} / {rtf1_med:.2f} | {ns1:.0f} |"
        )
    return "\n".join(lines)
