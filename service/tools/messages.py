"""One line of text for an input error, as the CLI commands print it after "error: "."""

from __future__ import annotations

from pydantic import ValidationError


def error_text(exc: Exception) -> str:
    """A pydantic `ValidationError` as "field.path: message; ..." (a model-level check names its
    field at the start of its message, "zenoh_user: ...", and is printed without pydantic's
    "Value error, " prefix); any other exception as its text."""
    if isinstance(exc, ValidationError):
        return "; ".join(
            f"{'.'.join(str(p) for p in e['loc'])}: {e['msg']}"
            if e["loc"]
            else str(e["msg"]).removeprefix("Value error, ")
            for e in exc.errors()
        )
    return str(exc)
