"""Retention: the only thing that deletes recordings.

`Retention(folder, family, keep_bytes=..., keep_age_s=...)` keeps the newest segments of the
service-wide recordings in `folder` up to a total size and/or age and deletes the older ones.
It looks only at files of the recording family (`family_of`): for the default name
`bearing-twin-<UTC>.rrd` every `bearing-twin-*.rrd` (all runs of the service, their segments and
later-run names), for an operator's name `run.rrd` the files `run.rrd`, `run-NNNN.rrd`,
`run.runN.rrd`, `run.runN-NNNN.rrd`. Per-twin recordings (`POST .../recording`, named by the
client) and anything else in the folder are never touched. Only regular files are deleted (no
links, no folders), never one that a recorder of this process has open (`protect`), newest kept
first (by modification time). Both limits 0 = keep everything.
"""

from __future__ import annotations

import logging
import os
import re
import stat
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

log = logging.getLogger("service.recording")

_DEFAULT_FAMILY = re.compile(r"^(bearing-twin-)\d{8}T\d{6}Z")


def family_of(path: str | Path) -> re.Pattern:
    """The file names that belong to the recording family of `path` (module doc)."""
    name = Path(path).name
    m = _DEFAULT_FAMILY.match(name)
    if m:
        return re.compile(re.escape(m.group(1)) + r".*\.rrd$")
    stem = re.escape(Path(path).stem)
    return re.compile(rf"^{stem}(\.run\d+)?(-\d{{4,}})?\.rrd$")


@dataclass
class Retention:
    """Keeps the newest files of one recording family within a size and/or age (module doc)."""

    folder: Path
    family: re.Pattern
    keep_bytes: int = 0  # total size kept [bytes]; 0 = no size limit
    keep_age_s: float = 0.0  # files older than this are deleted [s]; 0 = no age limit
    deleted: int = 0  # files deleted so far
    deleted_bytes: int = 0
    _protected: set = field(default_factory=set)
    _lock: threading.Lock = field(default_factory=threading.Lock)

    @classmethod
    def for_recording(cls, path: str | Path, *, keep_bytes: int = 0, keep_age_s: float = 0.0) -> Retention:
        path = Path(path)
        return cls(folder=path.parent, family=family_of(path), keep_bytes=int(keep_bytes), keep_age_s=float(keep_age_s))

    @property
    def enabled(self) -> bool:
        return self.keep_bytes > 0 or self.keep_age_s > 0

    def protect(self, path: str | Path) -> None:
        with self._lock:
            self._protected.add(os.path.abspath(path))

    def release(self, path: str | Path) -> None:
        with self._lock:
            self._protected.discard(os.path.abspath(path))

    def candidates(self) -> list[tuple[float, int, Path]]:
        """(mtime, size, path) of the family's regular files, newest first."""
        out = []
        try:
            with os.scandir(self.folder) as it:
                for entry in it:
                    if not self.family.match(entry.name):
                        continue
                    try:
                        st = entry.stat(follow_symlinks=False)
                    except OSError:
                        continue
                    if stat.S_ISREG(st.st_mode):
                        out.append((st.st_mtime, st.st_size, Path(entry.path)))
        except OSError:
            return []
        out.sort(key=lambda x: (x[0], x[2].name), reverse=True)
        return out

    def apply(self, now: float | None = None) -> list[Path]:
        """Delete what is beyond the limits; returns the paths deleted."""
        if not self.enabled:
            return []
        now = time.time() if now is None else now
        with self._lock:
            protected = set(self._protected)
        candidates = self.candidates()
        kept = sum(size for _, size, path in candidates if os.path.abspath(path) in protected)  # open: always kept
        deleted: list[Path] = []
        for mtime, size, path in candidates:
            if os.path.abspath(path) in protected:
                continue
            too_old = self.keep_age_s > 0 and now - mtime > self.keep_age_s
            too_much = self.keep_bytes > 0 and kept + size > self.keep_bytes
            if too_old or too_much:
                try:
                    st = os.lstat(path)
                    if not stat.S_ISREG(st.st_mode):
                        continue
                    os.unlink(path)
                except OSError as exc:
                    log.warning("retention: could not delete %s: %s", path, exc)
                    continue
                deleted.append(path)
                self.deleted += 1
                self.deleted_bytes += size
                log.info(
                    "retention: deleted %s (%.1f MB, %s)",
                    path,
                    size / 1e6,
                    "older than the age limit" if too_old else "beyond the size limit",
                )
            else:
                kept += size
        return deleted
