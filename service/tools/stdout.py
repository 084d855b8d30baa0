"""A command's document on standard output, written whole."""

from __future__ import annotations

import sys


def print_document(text: str) -> None:
    """Write `text` and its newline to standard output in one write and flush it.

    `print` writes the text and the newline apart: a document larger than the stream's buffer
    (8 KiB; a snapshot is about 11 kB) goes out at once and its newline at the final flush, by
    which time a reader that took only the start (`bearing-twin simulate --json | head -c 200`)
    may have gone, and the command ends with a broken pipe (status 141). Written whole, a
    document that fits the pipe's buffer is in the pipe before the reader can go: status 0."""
    sys.stdout.write(text + "\n")
    sys.stdout.flush()
