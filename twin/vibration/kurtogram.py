"""Antoni's fast kurtogram: the band of a signal where it is most impulsive.

J. Antoni, "Fast computation of the kurtogram for the detection of transient faults", Mechanical
Systems and Signal Processing 21 (2007) 108-124, sec. 3-4 and fig. 4: the spectral kurtosis of a
signal is estimated on the nodes of a 1/3-binary tree of analytic, quasi-ideal band-pass filters.

- Binary split (sec. 3.2, eq. 15): a node c(n) at rate r, an analytic signal of the band
  [f0, f0 + r / 2], goes through the low-pass h(n) = h0(n) e^(j pi n / 4) (band [0, r / 4]) and the
  high-pass g(n) = h(1 - n) (-1)^(1 - n) (band [r / 4, r / 2]), each decimated by 2; the high-pass
  child is multiplied by (-1)^n so both children lie in their own [0, r' / 2] in natural frequency
  order. h0 is the 16th-order FIR low-pass of cut-off 0.4 (of Nyquist, Hamming window): Antoni's
  "a short filter is just good enough" (sec. 3.3).
- Ternary split (sec. 3.4): three filters h1, h2, h3 of order 24, h1 the low-pass of cut-off
  2 / 3 x 0.4 shifted to r / 12 and h2, h3 the same shifted by r / 6 and r / 3, each decimated
  by 3, fill the levels k + log2(3) - 1 between the binary ones.
- The kurtosis of a node is that of its complex envelope, K = <|c|^4> / <|c|^2>^2 - 2 (eq. 8; -3
  for the real signal at level 0), the first len(h) samples (the filters' transient) left out;
  negative values are set to 0.

Level k (k = 0, 1, log2(3), 2, 1 + log2(3), ..., nlevel) has bands of width fs / 2^(k + 1); the
band of largest kurtosis wins (ties: the lowest frequency, then the coarsest level, as in Antoni's
reference implementation Fast_Kurtogram.m). The filters and the tree follow that implementation
(J. Antoni, 2005, rev. 2014, distributed with the paper); the tree is computed level by level on
all nodes at once (one matrix product per split and level).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.signal

_BINARY_ORDER = 16
_BINARY_CUTOFF = 0.4  # of Nyquist (Antoni 2007 sec. 3.3)


def _filters() -> tuple[np.ndarray, ...]:
    """(h, g, h1, h2, h3): the analytic generating filters of the tree (module docstring)."""
    n = np.arange(_BINARY_ORDER + 1)
    h = scipy.signal.firwin(_BINARY_ORDER + 1, _BINARY_CUTOFF) * np.exp(2j * np.pi * n * 0.125)
    m = np.arange(2, _BINARY_ORDER + 2)
    g = h[np.mod(1 - m, _BINARY_ORDER)] * (-1.0) ** (1 - m)
    order3 = (3 * _BINARY_ORDER) // 2
    n3 = np.arange(order3 + 1)
    h1 = scipy.signal.firwin(order3 + 1, 2.0 / 3.0 * _BINARY_CUTOFF) * np.exp(2j * np.pi * n3 * 0.25 / 3.0)
    h2 = h1 * np.exp(2j * np.pi * n3 / 6.0)
    h3 = h1 * np.exp(2j * np.pi * n3 / 3.0)
    return h, g, h1, h2, h3


_H, _G, _H1, _H2, _H3 = _filters()


def complex_envelope_kurtosis(nodes: np.ndarray) -> np.ndarray:
    """Kurtosis [-] of each row of `nodes` (Antoni 2007 eq. 8): <|c - <c>|^4> / <|c - <c>|^2>^2
    minus 2 for complex rows (the complex envelope of Gaussian noise), minus 3 for real ones;
    0 for a row of zero energy."""
    c = np.atleast_2d(nodes)
    c = c - c.mean(axis=1, keepdims=True)
    power = c.real**2 + c.imag**2 if np.iscomplexobj(c) else c * c
    p2 = np.mean(power, axis=1)
    p4 = np.mean(power * power, axis=1)
    offset = 2.0 if np.iscomplexobj(c) else 3.0
    with np.errstate(divide="ignore", invalid="ignore"):
        k = np.where(p2 > np.finfo(float).eps, p4 / np.maximum(p2, 1e-300) ** 2 - offset, 0.0)
    return k


def _filter_bank(nodes: np.ndarray, taps: np.ndarray, factor: int) -> np.ndarray:
    """Every row of `nodes` filtered causally by each column of `taps` (lfilter(taps[:, m], 1,
    row)) and kept at the samples factor - 1, 2 factor - 1, ... (the reference implementation's
    a(factor:factor:N)): (rows, n // factor, filters), a polyphase sum over the taps, in place
    (no BLAS product: its threads stall on a shared machine)."""
    rows, n = nodes.shape
    length, count = taps.shape[0], n // factor
    padded = np.concatenate((np.zeros((rows, length - 1), dtype=nodes.dtype), nodes), axis=1)
    out = np.zeros((rows, count, taps.shape[1]), dtype=complex)
    for m in range(taps.shape[1]):
        acc = out[:, :, m]
        for k in range(length):
            start = factor - 1 + length - 1 - k
            acc += padded[:, start : start + factor * count : factor] * taps[k, m]
    return out


_BINARY_TAPS = np.stack((_H, np.concatenate((_G, np.zeros(_H.size - _G.size)))), axis=1)
_TERNARY_TAPS = np.stack((_H1, _H2, _H3), axis=1)


def _binary_split(nodes: np.ndarray) -> np.ndarray:
    """Children of every node (rows), in natural frequency order: (2 x rows, cols // 2)."""
    out = _filter_bank(nodes, _BINARY_TAPS, 2)
    out[:, :, 1] *= (-1.0) ** np.arange(1, out.shape[1] + 1)
    return np.moveaxis(out, 2, 1).reshape(-1, out.shape[1])


def _ternary_split(nodes: np.ndarray) -> np.ndarray:
    """The three children of every node (rows), in natural frequency order: (3 x rows, cols // 3)."""
    out = _filter_bank(nodes, _TERNARY_TAPS, 3)
    return np.moveaxis(out, 2, 1).reshape(-1, out.shape[1])


@dataclass(frozen=True)
class Kurtogram:
    """The fast kurtogram of a signal and its best band.

    levels [-]: the 2 nlevel levels k (0, 1, log2 3, 2, ..., nlevel); bandwidth_hz [Hz] per level,
    fs / 2^(k + 1); kurtosis [-]: (2 nlevel, 3 x 2^nlevel), each row the kurtosis of that level's
    bands spread over the columns (column j spans fs / 2 x [j, j + 1] / (3 x 2^nlevel) Hz);
    band_hz (low, high) [Hz], level and band_kurtosis [-]: the winning band."""

    sample_rate_hz: float
    levels: np.ndarray
    bandwidth_hz: np.ndarray
    kurtosis: np.ndarray
    band_hz: tuple[float, float]
    level: float
    band_kurtosis: float


def max_level(n_samples: int) -> int:
    """Deepest level Antoni recommends for n samples: log2(n) - 7 (rounded down), so that the
    finest band keeps ~128 samples per node."""
    return math.floor(math.log2(max(n_samples, 1))) - 7


def fast_kurtogram(
    signal: np.ndarray,
    sample_rate_hz: float,
    nlevel: int | None = None,
    min_bandwidth_hz: float = 0.0,
    low_edge_range_hz: tuple[float, float] | None = None,
    max_high_edge_hz: float | None = None,
) -> Kurtogram:
    """The fast kurtogram of a real signal (module docstring) up to level `nlevel` (default and
    upper bound `max_level`), and its best band among those at least min_bandwidth_hz [Hz] wide
    whose lower edge lies in low_edge_range_hz = [min, max) [Hz] and upper edge at most
    max_high_edge_hz [Hz] (default: every band, as in the reference implementation). Raises
    ValueError naming the argument when the signal is too short
    (fewer than 256 samples) or no band is eligible."""
    x = np.asarray(signal, dtype=float).ravel()
    fs = float(sample_rate_hz)
    deepest = max_level(x.size)
    if deepest < 1:
        raise ValueError(f"signal: {x.size} samples, the fast kurtogram needs at least 256")
    nlevel = deepest if nlevel is None else int(nlevel)
    if not 1 <= nlevel <= deepest:
        raise ValueError(f"nlevel = {nlevel}: must be in [1, {deepest}] for {x.size} samples")
    x = x - x.mean()
    lh = _H.size
    columns = 3 * 2**nlevel
    binary_rows = [np.full(columns, complex_envelope_kurtosis(x[None, :])[0])]
    ternary_rows = []
    nodes = x[None, :].astype(complex)
    for k in range(nlevel):
        if k <= nlevel - 2:
            # the ternary split of level k, level k + log2(3): bands of width fs / (3 x 2^(k + 1))
            kq = complex_envelope_kurtosis(_ternary_split(nodes)[:, lh - 1 :])
            ternary_rows.append(np.repeat(kq, columns // kq.size))
        nodes = _binary_split(nodes)
        kb = complex_envelope_kurtosis(nodes[:, lh - 1 :])
        binary_rows.append(np.repeat(kb, columns // kb.size))
    levels, rows = [0.0], [binary_rows[0]]
    for k in range(1, nlevel + 1):
        levels.append(float(k))
        rows.append(binary_rows[k])
        if k - 1 < len(ternary_rows):
            levels.append(k + math.log2(3.0) - 1.0)
            rows.append(ternary_rows[k - 1])
    kurt = np.maximum(np.vstack(rows), 0.0)
    levels_arr = np.array(levels)
    bandwidth = fs * 2.0 ** -(levels_arr + 1.0)
    column_hz = (np.arange(columns) + 0.5) * 0.5 * fs / columns
    low_edge = np.floor(column_hz[None, :] / bandwidth[:, None]) * bandwidth[:, None]
    usable = np.broadcast_to(bandwidth[:, None] >= min_bandwidth_hz * (1.0 - 1e-12), kurt.shape)
    if low_edge_range_hz is not None:
        usable = usable & (low_edge >= low_edge_range_hz[0]) & (low_edge < low_edge_range_hz[1])
    if max_high_edge_hz is not None:
        usable = usable & (low_edge + bandwidth[:, None] <= max_high_edge_hz * (1.0 + 1e-12))
    if not np.any(usable):
        raise ValueError(
            f"min_bandwidth_hz = {min_bandwidth_hz:g}, low_edge_range_hz = {low_edge_range_hz}, "
            f"max_high_edge_hz = {max_high_edge_hz}: "
            f"no band of the kurtogram (0 - {0.5 * fs:g} Hz) is eligible"
        )
    masked = np.where(usable, kurt, -1.0)
    flat = int(np.argmax(masked.T.ravel()))  # column-major: lowest column, then coarsest level
    j, i = divmod(flat, masked.shape[0])
    bw = float(bandwidth[i])
    lo = float(low_edge[i, j])
    return Kurtogram(
        sample_rate_hz=fs,
        levels=levels_arr,
        bandwidth_hz=bandwidth,
        kurtosis=kurt,
        band_hz=(lo, lo + bw),
        level=float(levels_arr[i]),
        band_kurtosis=float(kurt[i, j]),
    )
