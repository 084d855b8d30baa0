"""Compaction of a closed segment: fewer, larger chunks and rerun's footer, in place.

While a segment is open the recorder sends a chunk per entity and send (a live viewer and a
crash lose at most a send); a viewer opening the file later pays for every chunk (each costs
about 1.5 kB and its own decoding). Once a segment is closed, `compact(path)` rewrites it with
`rerun rrd optimize` (rerun's own chunk compaction, in a process of its own, at low priority):
about a tenth of the chunks, half to a third of the bytes (a file of a few seconds can grow by
the footer), and rerun's current format with its footer (chunk manifest), so that readers
neither scan the whole file nor warn about a legacy format. The result goes to a file created
exclusively beside the segment and replaces it by `os.replace` (the same rows, never a partial
file under the segment's name); on any failure the segment stays as it was and the temporary
file is removed.
"""

from __future__ import annotations

import logging
import os
import shutil
import subprocess
from pathlib import Path

from service.recording.live import LiveViewerError, rerun_command
from service.recording.paths import RecordingPathError, create_exclusive

log = logging.getLogger("service.recording")

COMPACT_TIMEOUT_S = 300.0


def compact(path: str | Path, timeout_s: float = COMPACT_TIMEOUT_S) -> bool:
    """Rewrite the closed segment `path` compacted (see module doc); True when it was replaced."""
    path = Path(path)
    try:
        if path.stat().st_size == 0:
            return False
        tmp = create_exclusive(path.parent, f".{path.name}.compacting-{os.getpid()}", make_dirs=False)
    except (OSError, RecordingPathError) as exc:
        log.warning("rerun: %s not compacted: %s", path, exc)
        return False
    tmp.close()
    try:
        nice = shutil.which("nice")
        cmd = [
            *([nice, "-n", "10"] if nice else []),
            rerun_command(),
            "rrd",
            "optimize",
            str(path),
            "-o",
            str(tmp.path),
        ]
        r = subprocess.run(
            cmd,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            timeout=timeout_s,
            env={**os.environ, "RERUN_ANALYTICS": "0"},
        )
        if r.returncode != 0 or tmp.path.stat().st_size == 0:
            err = r.stderr.decode(errors="replace").strip().splitlines()
            raise RuntimeError(err[-1] if err else f"exit code {r.returncode}")
        before = path.stat().st_size
        os.replace(tmp.path, path)
        log.info("rerun: %s compacted: %.2f -> %.2f MB", path, before / 1e6, path.stat().st_size / 1e6)
        return True
    except (OSError, RuntimeError, LiveViewerError, subprocess.TimeoutExpired) as exc:
        log.warning("rerun: %s not compacted (kept as written): %s", path, exc)
        try:
            tmp.path.unlink()
        except OSError:
            pass
        return False
