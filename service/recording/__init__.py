"""Rerun recordings of the twins, for people: streams and segments, entity layout and blueprint,
columns, retention, read-back, path safety.

    paths       where recordings may be written; exclusive, no-follow creation (no rerun import)
    segments    segment names, the files a segment is written to, RRD framing
    streams     making and freeing rerun streams, one blueprint stream per recorder
    layout      entity paths, static data, legends and the default blueprint
    columns     snapshots -> rows -> rerun columns, event rows
    recorder    RerunRecorder, the SnapshotSink
    retention   keeps the newest segments up to a size / age (the only thing that deletes)
    reader      describe_recording, read_recording, read_column, read_index

The public names below are imported lazily (PEP 562): `from service.recording import
check_relative_path` does not import rerun; `RerunRecorder` does.
"""

from __future__ import annotations

import importlib

_NAMES = {
    # recorder
    "RerunRecorder": "recorder",
    # streams
    "RerunStreams": "streams",
    "BlueprintSender": "streams",
    # layout
    "SIM_TIME": "layout",
    "SEQ": "layout",
    # segments
    "segment_path": "segments",
    "recording_segments": "segments",
    "numbered_segments": "segments",
    "is_segment_of": "segments",
    "RecordingWriteError": "segments",
    # paths
    "RecordingPathError": "paths",
    "check_relative_path": "paths",
    "create_exclusive": "paths",
    "create_recording": "paths",
    "free_recording_name": "paths",
    "CreatedFile": "paths",
    # retention
    "Retention": "retention",
    "family_of": "retention",
    # reader
    "describe_recording": "reader",
    "read_recording": "reader",
    "read_column": "reader",
    "read_index": "reader",
    "open_reader": "reader",
}

__all__ = sorted(_NAMES)


def __getattr__(name: str):
    module = _NAMES.get(name)
    if module is None:
        raise AttributeError(f"module 'service.recording' has no attribute {name!r}")
    return getattr(importlib.import_module(f"service.recording.{module}"), name)


def __dir__() -> list[str]:
    return __all__
