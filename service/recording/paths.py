"""Where recordings may be written, and creating them without following links or overwriting.

Recordings are append-only history: the service never truncates or replaces a file it did not
create in this run. Every recording file is made here with one exclusive create
(`O_CREAT | O_EXCL | O_NOFOLLOW`), inside a folder reached component by component from the
recordings folder with `O_DIRECTORY | O_NOFOLLOW` (`openat`-style, through folder descriptors),
so a symbolic link anywhere below the recordings folder - as the file itself or as a folder on
the way - is refused instead of followed, and an existing file is never opened for writing.

Two kinds of names:

* the service-wide recording (`--record PATH.rrd`, chosen by the operator): an existing file
  (from an earlier run, e.g. one that was killed) is left as it is and this run records beside
  it under the next free name `<stem>.run2.rrd`, `<stem>.run3.rrd`, ... (`free_recording_name`);
* per-twin recordings (`POST /v1/bearings/{id}/recording`): a path relative to the recordings
  folder, checked by `check_relative_path` (plain names, at most `MAX_DEPTH` components and
  `MAX_PATH_CHARS` characters); an existing file, a link, `..` or an absolute path is refused
  (`RecordingPathError`, which the HTTP layer answers with 422 naming `path`).

Nothing here imports rerun.
"""

from __future__ import annotations

import errno
import os
import re
import stat
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath

from service.recording.names import numbered_segments

MAX_DEPTH = 8  # components of a per-twin path (7 folders and the file)
MAX_PATH_CHARS = 255  # characters of a per-twin path
MAX_NAME_CHARS = 100  # characters of one component
SUFFIX = ".rrd"

_COMPONENT_RE = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9_.-]*$")
_O_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
_O_DIRECTORY = getattr(os, "O_DIRECTORY", 0)
_O_CLOEXEC = getattr(os, "O_CLOEXEC", 0)
_DIR_FLAGS = os.O_RDONLY | _O_DIRECTORY | _O_NOFOLLOW | _O_CLOEXEC
_FILE_FLAGS = os.O_WRONLY | os.O_CREAT | os.O_EXCL | _O_NOFOLLOW | _O_CLOEXEC
_HAVE_DIR_FD = os.open in os.supports_dir_fd and os.mkdir in os.supports_dir_fd


class RecordingPathError(ValueError):
    """A recording path that is not allowed (the message says why; the field is `path`)."""


def check_relative_path(path: str) -> PurePosixPath:
    """A per-twin recording path, checked lexically: relative, components of letters, digits and
    '_', '.', '-' (none starting with '.'), at most `MAX_DEPTH` components of at most
    `MAX_NAME_CHARS` characters, `MAX_PATH_CHARS` in all, ending in .rrd. Raises
    RecordingPathError saying which rule it breaks."""
    if not isinstance(path, str) or not path:
        raise RecordingPathError("give a file name ending in .rrd, relative to the recordings folder")
    if len(path) > MAX_PATH_CHARS:
        raise RecordingPathError(f"{len(path)} characters: at most {MAX_PATH_CHARS}")
    if path.startswith(("/", "\\")) or (len(path) > 1 and path[1] == ":"):
        raise RecordingPathError(f"{path!r} is absolute: give a path relative to the recordings folder")
    parts = path.split("/")
    if any(p == ".." for p in parts):
        raise RecordingPathError(f"{path!r}: '..' is not allowed (the recording stays inside the recordings folder)")
    if len(parts) > MAX_DEPTH:
        raise RecordingPathError(
            f"{path!r} has {len(parts)} levels: at most {MAX_DEPTH} ({MAX_DEPTH - 1} folders and the file)"
        )
    for p in parts:
        if not p:
            raise RecordingPathError(f"{path!r}: empty folder name ('//' or a trailing '/')")
        if len(p) > MAX_NAME_CHARS:
            raise RecordingPathError(f"{p[:20]!r}...: a name has at most {MAX_NAME_CHARS} characters")
        if not _COMPONENT_RE.match(p):
            raise RecordingPathError(f"{p!r}: names are letters, digits and '_', '.', '-' and do not start with '.'")
    if not parts[-1].endswith(SUFFIX) or parts[-1] == SUFFIX:
        raise RecordingPathError(f"{path!r}: a rerun recording ends in {SUFFIX}")
    return PurePosixPath(path)


@dataclass
class CreatedFile:
    """A recording file this process created (exclusively) and holds open for writing."""

    path: Path
    fd: int
    created_dirs: list[Path] = field(default_factory=list)  # folders made for it, outermost first
    ident: tuple[int, int] | None = None  # (st_dev, st_ino) of the file made

    def __post_init__(self) -> None:
        if self.ident is None and self.fd >= 0:
            st = os.fstat(self.fd)
            self.ident = (st.st_dev, st.st_ino)

    def close(self) -> None:
        fd, self.fd = self.fd, -1
        if fd >= 0:
            os.close(fd)

    def discard(self) -> None:
        """Remove the file (and the folders made for it, if empty) - only if the name still
        points at the file this process created - and close it. For a start that failed: leaves
        the file system as it was."""
        try:
            st = os.lstat(self.path)
            if self.ident is not None and (st.st_dev, st.st_ino) == self.ident and stat.S_ISREG(st.st_mode):
                os.unlink(self.path)
        except OSError:
            pass
        self.close()
        for d in reversed(self.created_dirs):
            try:
                os.rmdir(d)
            except OSError:
                break


def _open_dir(name: str, dir_fd: int | None) -> int:
    return os.open(name, _DIR_FLAGS, dir_fd=dir_fd) if dir_fd is not None else os.open(name, _DIR_FLAGS)


def _why_not(name: str, dir_fd: int | None, display: str, exc: OSError) -> RecordingPathError:
    try:
        st = os.lstat(name, dir_fd=dir_fd) if dir_fd is not None else os.lstat(name)
        if stat.S_ISLNK(st.st_mode):
            return RecordingPathError(f"{display!r} is a symbolic link: links are not followed")
        if exc.errno == errno.EEXIST:
            return RecordingPathError(f"{display!r} exists: recordings are never overwritten, choose a new name")
        if exc.errno == errno.ENOTDIR or not stat.S_ISDIR(st.st_mode):
            return RecordingPathError(f"{display!r} exists and is not a folder")
    except OSError:
        pass
    return RecordingPathError(f"cannot create {display!r}: {exc.strerror or exc}")


def create_exclusive(
    folder: str | Path, relative: str | PurePosixPath, *, make_dirs: bool = True, mode: int = 0o644
) -> CreatedFile:
    """Create `folder / relative` exclusively and open it for writing. `folder` (the recordings
    folder, chosen by the operator) is made if missing; below it, every folder component is
    opened without following links (missing ones are made when `make_dirs`), and the file is
    created with O_EXCL | O_NOFOLLOW: a link or an existing file raises RecordingPathError (as
    does any other OS error, e.g. permission denied, with its reason). On an error nothing is
    left behind: folders made for this call are removed again."""
    folder = Path(folder)
    rel = PurePosixPath(relative)
    if rel.is_absolute() or ".." in rel.parts or not rel.parts:
        raise RecordingPathError(f"{str(relative)!r}: give a path inside the recordings folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise RecordingPathError(
            f"cannot create the recordings folder {str(folder)!r}: {exc.strerror or exc}"
        ) from None
    created: list[Path] = []
    fds: list[int] = []
    try:
        try:
            cur = os.open(str(folder), os.O_RDONLY | _O_DIRECTORY | _O_CLOEXEC)
        except OSError as exc:
            raise RecordingPathError(
                f"cannot open the recordings folder {str(folder)!r}: {exc.strerror or exc}"
            ) from None
        fds.append(cur)
        where = folder
        shown = PurePosixPath()
        for part in rel.parts[:-1]:
            shown /= part
            where = where / part
            at = cur if _HAVE_DIR_FD else None
            try:
                nxt = _open_dir(part if at is not None else str(where), at)
            except FileNotFoundError:
                if not make_dirs:
                    raise RecordingPathError(f"folder {str(shown)!r} does not exist") from None
                try:
                    os.mkdir(part, 0o755, dir_fd=at) if at is not None else os.mkdir(where, 0o755)
                except OSError as exc:
                    raise RecordingPathError(
                        f"cannot create the folder {str(shown)!r}: {exc.strerror or exc}"
                    ) from None
                created.append(where)
                try:
                    nxt = _open_dir(part if at is not None else str(where), at)
                except OSError as exc:
                    raise _why_not(part if at is not None else str(where), at, str(shown), exc) from None
            except OSError as exc:
                raise _why_not(part if at is not None else str(where), at, str(shown), exc) from None
            fds.append(nxt)
            cur = nxt
        name = rel.parts[-1]
        shown /= name
        at = cur if _HAVE_DIR_FD else None
        try:
            fd = os.open(name if at is not None else str(where / name), _FILE_FLAGS, mode, dir_fd=at)
        except OSError as exc:
            raise _why_not(name if at is not None else str(where / name), at, str(shown), exc) from None
        return CreatedFile(path=folder.joinpath(*rel.parts), fd=fd, created_dirs=created)
    except BaseException:
        for d in reversed(created):
            try:
                os.rmdir(d)
            except OSError:
                break
        raise
    finally:
        for fd in fds:
            os.close(fd)


def run_name(path: Path, run: int) -> Path:
    """`<stem>.run<run>.rrd` beside `path` (run >= 2), the name of a later run's recording."""
    return path.with_name(f"{path.stem}.run{run}{path.suffix}")


def _taken(path: Path) -> bool:
    return os.path.lexists(path) or bool(numbered_segments(path))


def free_recording_name(path: str | Path, *, max_runs: int = 100_000) -> Path:
    """`path` if neither it nor any of its segments exists, else the first free
    `<stem>.runN.rrd` (N = 2, 3, ...), so a new run never touches an earlier run's files."""
    path = Path(path)
    if not _taken(path):
        return path
    for run in range(2, max_runs):
        candidate = run_name(path, run)
        if not _taken(candidate):
            return candidate
    raise RecordingPathError(f"{str(path)!r}: no free name left for a new run")


def create_recording(path: str | Path, *, rename: bool = True) -> CreatedFile:
    """Create the recording file `path` (a path chosen by the operator or the service): with
    `rename`, a taken name moves this run to `free_recording_name(path)`; without, it is an
    error. The folder of `path` is made if missing; the file is made exclusively, never through
    a link."""
    path = Path(path)
    if path.suffix != SUFFIX:
        raise RecordingPathError(f"{str(path)!r}: a rerun recording ends in {SUFFIX}")
    for _ in range(100):
        target = free_recording_name(path) if rename else path
        try:
            return create_exclusive(target.parent, target.name)
        except RecordingPathError:
            if rename and os.path.lexists(target):  # taken meanwhile: try the next name
                continue
            raise
    raise RecordingPathError(f"{str(path)!r}: could not find a free name")
