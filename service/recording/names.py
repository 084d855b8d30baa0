"""Names of a recording's files: segment 0 of `name.rrd` is `name.rrd` itself, then `name-0001.rrd`,
`name-0002.rrd`, ... in the same folder. Pure path arithmetic and a directory listing; the files are
created by `service.recording.paths` and written by `service.recording.segments`."""

from __future__ import annotations

import re
from pathlib import Path


def segment_path(path: str | Path, index: int) -> Path:
    """Path of segment `index` of the recording `path`: the path itself for 0, else
    `<stem>-<index:04d><suffix>` in the same folder (run.rrd, run-0001.rrd, run-0002.rrd, ...)."""
    path = Path(path)
    if index < 0:
        raise ValueError(f"segment index {index}: must be >= 0")
    return path if index == 0 else path.with_name(f"{path.stem}-{index:04d}{path.suffix}")


def numbered_segments(path: str | Path) -> dict[int, Path]:
    """{index: path} of the files `<stem>-NNNN<suffix>` (index >= 1) beside `path`."""
    path = Path(path)
    pattern = re.compile(re.escape(path.stem) + r"-(\d{4,})" + re.escape(path.suffix) + "$")
    found: dict[int, Path] = {}
    try:
        siblings = list(path.parent.iterdir())
    except OSError:
        return found
    for p in siblings:
        m = pattern.match(p.name)
        if m and int(m.group(1)) > 0:
            found[int(m.group(1))] = p
    return found


def is_segment_of(main: str | Path, candidate: str | Path) -> bool:
    """Whether `candidate` is (or would be) a segment of the recording `main`."""
    main, candidate = Path(main).absolute(), Path(candidate).absolute()
    if candidate == main:
        return True
    return (
        candidate.parent == main.parent
        and re.fullmatch(re.escape(main.stem) + r"-\d{4,}" + re.escape(main.suffix), candidate.name) is not None
    )


def recording_segments(path: str | Path) -> list[Path]:
    """The segments of the recording `path` in order: `path` itself, then `<stem>-0001<suffix>`,
    `<stem>-0002<suffix>`, ... as long as they follow each other. Empty when `path` does not
    exist."""
    path = Path(path)
    if not path.is_file():
        return []
    numbered = {i: p for i, p in numbered_segments(path).items() if p.is_file()}
    out = [path]
    i = 1
    while i in numbered:
        out.append(numbered[i])
        i += 1
    return out
