"""Compatibility: the recorder now lives in the package `service.recording` (see its
docstring); this module re-exports the names the service and its tools imported from here."""

from service.recording import (  # noqa: F401
    RerunRecorder,
    RerunStreams,
    describe_recording,
    read_column,
    read_index,
    read_recording,
    recording_segments,
    segment_path,
)
from service.recording.layout import SEQ, SIM_TIME  # noqa: F401
from service.recording.reader import open_reader as _reader  # noqa: F401
