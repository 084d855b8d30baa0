"""Compact binary layout of waveform chunks (zenoh `.../vibration/waveform`), not JSON numbers.

A chunk is a header followed by the samples. All fields little-endian, no padding:

    offset size type     field
    0      4    bytes    magic b"BTWF" (bearing-twin waveform)
    4      2    uint16   version (1)
    6      2    uint16   header_bytes: offset of the first sample (42 + id length, rounded up to
                         a multiple of 4); readers skip to it, so later versions can append
                         header fields
    8      2    uint16   units code (UNITS: 1 acceleration m/s^2, 2 velocity m/s, 3 displacement m,
                         4 force N)
    10     2    uint16   dtype code (1 = float32 little-endian; the only one in version 1)
    12     8    uint64   seq: chunk sequence number (gaps reveal lost chunks)
    20     8    float64  t0 [s]: twin time of the first sample
    28     8    float64  sample rate [Hz]
    36     4    uint32   count: number of samples
    40     2    uint16   id_len: length of the twin id in bytes
    42     n    bytes    twin id, UTF-8 (n = id_len <= 255)
    ..     pad  zeros    to header_bytes
    header_bytes  4 count  float32 samples

Sample k is at t0 + k / rate. A 1 s chunk at 51.2 kHz is 204.8 kB + ~60 B of header (JSON
numbers would take ~4x that).
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

import numpy as np

MAGIC = b"BTWF"
VERSION = 1
UNITS = {1: "m/s^2", 2: "m/s", 3: "m", 4: "N"}
_UNIT_CODES = {v: k for k, v in UNITS.items()}
DTYPE_FLOAT32_LE = 1
_FIXED = struct.Struct("<4sHHHHQddIH")  # through id_len: 42 bytes
MAX_ID_BYTES = 255


@dataclass(frozen=True)
class WaveformChunk:
    """A decoded chunk: samples (float32), their start time [s], rate [Hz], units, seq, twin id."""

    twin_id: str
    seq: int
    t0_s: float
    sample_rate_hz: float
    units: str
    samples: np.ndarray

    @property
    def times_s(self) -> np.ndarray:
        """Sample times [s]."""
        return self.t0_s + np.arange(self.samples.size) / self.sample_rate_hz


def _header_bytes(id_len: int) -> int:
    return (_FIXED.size + id_len + 3) // 4 * 4


def encode_chunk(twin_id: str, seq: int, t0_s: float, sample_rate_hz: float, samples, units: str = "m/s^2") -> bytes:
    """Bytes of one chunk (layout in the module docstring). Samples are stored as float32."""
    ident = twin_id.encode("utf-8")
    if len(ident) > MAX_ID_BYTES:
        raise ValueError(f"twin_id is {len(ident)} bytes in UTF-8: at most {MAX_ID_BYTES}")
    if units not in _UNIT_CODES:
        raise ValueError(f"units = {units!r}: one of {sorted(_UNIT_CODES)}")
    if not (0 <= seq < 2**64):
        raise ValueError(f"seq = {seq}: must be in [0, 2^64)")
    if not (sample_rate_hz > 0.0 and np.isfinite(sample_rate_hz) and np.isfinite(t0_s)):
        raise ValueError("sample_rate_hz must be positive and finite, t0_s finite")
    data = np.ascontiguousarray(samples, dtype="<f4").ravel()
    hb = _header_bytes(len(ident))
    head = (
        _FIXED.pack(
            MAGIC,
            VERSION,
            hb,
            _UNIT_CODES[units],
            DTYPE_FLOAT32_LE,
            seq,
            float(t0_s),
            float(sample_rate_hz),
            data.size,
            len(ident),
        )
        + ident
    )
    return head + bytes(hb - len(head)) + data.tobytes()


def decode_chunk(payload: bytes) -> WaveformChunk:
    """Inverse of `encode_chunk`. Raises ValueError naming what is wrong (magic, version, dtype,
    units, truncated payload)."""
    buf = memoryview(payload)
    if len(buf) < _FIXED.size:
        raise ValueError(f"waveform chunk of {len(buf)} bytes: shorter than the {_FIXED.size}-byte header")
    magic, version, hb, unit, dtype, seq, t0, rate, count, id_len = _FIXED.unpack_from(buf, 0)
    if magic != MAGIC:
        raise ValueError(f"not a waveform chunk: magic {bytes(magic)!r}, expected {MAGIC!r}")
    if version != VERSION:
        raise ValueError(f"waveform chunk version {version}: this reader knows version {VERSION}")
    if dtype != DTYPE_FLOAT32_LE:
        raise ValueError(f"waveform dtype code {dtype}: version 1 knows only {DTYPE_FLOAT32_LE} (float32 LE)")
    if unit not in UNITS:
        raise ValueError(f"waveform units code {unit}: one of {sorted(UNITS)}")
    if hb < _FIXED.size + id_len or len(buf) < hb + 4 * count:
        raise ValueError(f"waveform chunk truncated: {len(buf)} bytes, header says {hb} + 4 x {count}")
    twin_id = bytes(buf[_FIXED.size : _FIXED.size + id_len]).decode("utf-8")
    samples = np.frombuffer(buf, dtype="<f4", count=count, offset=hb).copy()
    return WaveformChunk(
        twin_id=twin_id, seq=int(seq), t0_s=float(t0), sample_rate_hz=float(rate), units=UNITS[unit], samples=samples
    )
