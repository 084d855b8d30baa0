"""argparse value types shared by the command-line tools: a bad value is refused by argparse
itself, which names the option (`argument --duration: must be a finite number >= 0, got -1`) and
exits with status 2."""

from __future__ import annotations

import argparse
import math
from pathlib import Path


def positive_float(text: str) -> float:
    """A finite number > 0."""
    value = float(text)
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"must be a finite number > 0, got {text}")
    return value


def positive_int(text: str) -> int:
    """A whole number >= 1."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a whole number, got {text}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be >= 1, got {text}")
    return value


def int_in(low: int, high: int):
    """A whole number in [low, high]; the refusal states the range."""

    def int_in_range(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be a whole number in [{low}, {high}], got {text}") from None
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"must be in [{low}, {high}], got {text}")
        return value

    return int_in_range


def non_negative_float(text: str) -> float:
    """A finite number >= 0."""
    value = float(text)
    if not (math.isfinite(value) and value >= 0):
        raise argparse.ArgumentTypeError(f"must be a finite number >= 0, got {text}")
    return value


def float_in(low: float, high: float, unit: str, *, low_open: bool = False):
    """A finite number in [low, high] (`low_open`: (low, high]) in `unit`; the refusal states the
    range and unit."""
    left = "(" if low_open else "["

    def value_in_range(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        above_low = value > low if low_open else value >= low
        if not (math.isfinite(value) and above_low and value <= high):
            raise argparse.ArgumentTypeError(f"must be in {left}{low:g}, {high:g}] {unit}, got {text}")
        return value

    return value_in_range


def output_file(*suffixes: str):
    """A file the command will write, checked before it runs: its name ends in one of `suffixes`
    and the file can be created (its folder is made when missing); a command that would fail to
    save only after minutes of simulation is refused at once, naming the option."""

    def writable(text: str) -> str:
        path = Path(text)
        if path.suffix.lower() not in suffixes:
            raise argparse.ArgumentTypeError(f"must end in {' or '.join(suffixes)}, got {text}")
        existed = path.exists()
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            with open(path, "ab"):
                pass
        except OSError as exc:
            raise argparse.ArgumentTypeError(f"cannot write {text}: {exc.strerror or exc}") from None
        if not existed:
            path.unlink(missing_ok=True)
        return text

    return writable
