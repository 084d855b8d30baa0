"""Reading a recording back with `rerun.chunk.RrdReader` (a file, or the segments of one
recording given as a list of paths). Flush and close the recorder first.

An empty file (a segment created but never written, e.g. by a kill -9 in between) reads as an
empty segment. Rows are the snapshots recorded: the chunks of an entity that carry the `seq` timeline. The
line breaks of `service.recording.columns.Batch.breaks` (empty rows on `sim_time` only) are no
snapshots and are counted apart (`"breaks"`).
"""

from __future__ import annotations

import warnings
from collections.abc import Iterable
from pathlib import Path

import numpy as np

from service.recording.layout import SEQ

PathOrPaths = str | Path | Iterable[str | Path]


def _paths(path: PathOrPaths) -> list[Path]:
    if isinstance(path, (str, Path)):
        return [Path(path)]
    return [Path(p) for p in path]


def _empty(path: Path) -> bool:
    """A file created but never written (a kill between creating a segment and writing its
    first bytes): an empty segment, nothing to read."""
    try:
        return path.stat().st_size == 0
    except OSError:
        return False


def open_reader(path: str | Path):
    """`RrdReader` of one file; the "no footer" warning of a footerless file (the default) is
    expected here and silenced."""
    from rerun.chunk import RrdReader

    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=".*no footer.*")
        return RrdReader(str(path))


def describe_recording(path: PathOrPaths) -> dict:
    """What an .rrd (or the segments of one recording) holds:

    {"application_id", "recording_id", "blueprints": number of blueprint stores,
     "segments": number of files read,
     "entities": {entity path (no leading slash): {"rows": snapshot rows, "static_rows": n,
                  "breaks": line-break rows, "chunks": temporal chunks,
                  "components": [...], "timelines": [...]}}}

    Application and recording id are those of the first file; a later file of another recording
    raises ValueError (segments of one recording share them).
    """
    info: dict = {"application_id": None, "recording_id": None, "blueprints": 0, "segments": 0, "entities": {}}
    entities: dict = info["entities"]
    for p in _paths(path):
        info["segments"] += 1
        if _empty(p):
            continue
        reader = open_reader(p)
        recordings = reader.recordings()
        info["blueprints"] += len(reader.blueprints())
        if not recordings:
            continue
        ids = (recordings[0].application_id, recordings[0].recording_id)
        if info["recording_id"] is None:
            info["application_id"], info["recording_id"] = ids
        elif ids != (info["application_id"], info["recording_id"]):
            raise ValueError(f"{p} holds recording {ids}, not {(info['application_id'], info['recording_id'])}")
        for chunk in reader.stream(store=recordings[0]):
            entity = chunk.entity_path.lstrip("/")
            e = entities.setdefault(
                entity, {"rows": 0, "static_rows": 0, "breaks": 0, "chunks": 0, "components": set(), "timelines": set()}
            )
            if chunk.is_static:
                e["static_rows"] += chunk.num_rows
            else:
                names = chunk.timeline_names
                if SEQ in names:
                    e["rows"] += chunk.num_rows
                else:
                    e["breaks"] += chunk.num_rows
                e["chunks"] += 1
                e["timelines"].update(names)
            schema = chunk.to_record_batch().schema
            for f in schema:
                meta = f.metadata or {}
                comp = meta.get(b"rerun:component") or meta.get(b"rerun.component")
                if comp is not None:
                    e["components"].add(comp.decode())
    for e in entities.values():
        e["components"] = sorted(e["components"])
        e["timelines"] = sorted(e["timelines"])
    return info


def read_recording(path: PathOrPaths) -> dict[str, int]:
    """{entity path (no leading slash, e.g. "bearing/a/friction_torque_n_m"): number of snapshot
    rows} of the first recording in an .rrd, or summed over the segments of one recording given
    as a list (`read_recording(recording_segments(path))`); entities with static data only map to
    0; rerun's own `__properties` entity is left out."""
    return {k: v["rows"] for k, v in describe_recording(path)["entities"].items() if not k.startswith("__")}


def read_column(path: PathOrPaths, entity: str, column: str) -> list:
    """The values of one column (a timeline such as "seq", or a component such as
    "Points3D:positions" / "Scalars:scalars") over the snapshot rows of one entity, in the order
    the rows were written (file after file for a list of segments), one item per row (a list for
    components, an int for "seq", integer nanoseconds for "sim_time")."""
    import pyarrow as pa

    want = "/" + entity.lstrip("/")
    values: list = []
    for p in _paths(path):
        if _empty(p):
            continue
        for chunk in open_reader(p).stream():
            if chunk.entity_path == want and not chunk.is_static and SEQ in chunk.timeline_names:
                batch = chunk.to_record_batch()
                i = batch.schema.get_field_index(column)
                if i < 0:
                    continue
                col = batch.column(i)
                if pa.types.is_duration(col.type) or pa.types.is_timestamp(col.type):
                    col = col.cast(pa.int64())
                values.extend(col.to_pylist())
    return values


def read_index(path: PathOrPaths, entity: str, timeline: str = SEQ) -> np.ndarray:
    """Sorted values of one timeline ("seq", or "sim_time" in integer nanoseconds) over the
    snapshot rows of one entity, e.g. the `seq` numbers that made it into the file(s)."""
    return np.sort(np.array(read_column(path, entity, timeline), dtype=np.int64))


def snapshots_per_trend_window(publish_rate_hz: float, trend_window_s: float) -> int:
    """Snapshots a trend row of the service's recordings averages (`RerunRecorder.SERVICE_OPTIONS`
    trend_window_s at the service's publish rate), at least 1."""
    return max(1, int(round(publish_rate_hz * trend_window_s)))


def window_seq_gaps(seqs: np.ndarray, per_window: int) -> int:
    """Lost trend windows in a windowed entity's sorted `seq` index: each row carries the seq of
    the last snapshot of its window, so consecutive rows lie at most one window apart; a step of
    more than 1.5 windows is a window missing from the file."""
    s = np.asarray(seqs, dtype=np.int64)
    if s.size < 2:
        return 0
    return int(((s[1:] - s[:-1]) > 1.5 * per_window).sum())
