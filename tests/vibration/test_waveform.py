"""Binary waveform chunks (twin.vibration.waveform): round trip and refusals."""

import struct

import numpy as np
import pytest

from twin.vibration.waveform import MAGIC, decode_chunk, encode_chunk


def test_round_trip_keeps_every_field_and_float32_sample():
    x = np.random.default_rng(0).normal(0.0, 30.0, 51200)
    blob = encode_chunk("bearing-ü-7", 2**40 + 3, 12.345678901234, 51200.0, x)
    c = decode_chunk(blob)
    assert (c.twin_id, c.seq, c.t0_s, c.sample_rate_hz, c.units) == (
        "bearing-ü-7",
        2**40 + 3,
        12.345678901234,
        51200.0,
        "m/s^2",
    )
    assert np.array_equal(c.samples, x.astype(np.float32))
    assert c.times_s[1] - c.times_s[0] == pytest.approx(1 / 51200.0)
    header = struct.unpack_from("<H", blob, 6)[0]
    assert header % 4 == 0 and len(blob) == header + 4 * x.size
    assert len(blob) - 4 * x.size < 64  # compact: the header is tens of bytes
    assert blob[:4] == MAGIC


def test_units_and_empty_chunk():
    c = decode_chunk(encode_chunk("t", 0, 0.0, 1000.0, np.zeros(0), units="N"))
    assert c.units == "N" and c.samples.size == 0


@pytest.mark.parametrize(
    "mutate, message",
    [
        (lambda b: b"XXXX" + b[4:], "magic"),
        (lambda b: b[:4] + struct.pack("<H", 9) + b[6:], "version"),
        (lambda b: b[:-4], "truncated"),
        (lambda b: b[:10], "shorter"),
        (lambda b: b[:10] + struct.pack("<H", 7) + b[12:], "dtype"),
        (lambda b: b[:8] + struct.pack("<H", 99) + b[10:], "units"),
    ],
)
def test_corrupt_chunks_are_refused_with_a_reason(mutate, message):
    blob = encode_chunk("twin-1", 5, 1.0, 51200.0, np.ones(16))
    with pytest.raises(ValueError, match=message):
        decode_chunk(mutate(blob))


def test_bad_arguments_are_refused():
    with pytest.raises(ValueError, match="twin_id"):
        encode_chunk("x" * 300, 0, 0.0, 1.0, np.ones(2))
    with pytest.raises(ValueError, match="units"):
        encode_chunk("t", 0, 0.0, 1.0, np.ones(2), units="g")
    with pytest.raises(ValueError, match="sample_rate_hz"):
        encode_chunk("t", 0, 0.0, 0.0, np.ones(2))
