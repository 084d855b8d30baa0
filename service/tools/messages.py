"""One line of text for an input error, as the CLI commands print it after "error: "."""

from __future__ import annotations

import importlib
from functools import cache

from pydantic import BaseModel, ValidationError

from service.core.errors import field_errors

#: the modules whose models a command validates its input with (a bearing spec and its parts,
#: the model's options and settings): an error of one of them states both sides of the range
MODEL_MODULES = (
    "twin.spec",
    "twin.setpoint",
    "twin.thermal.settings",
    "twin.life.settings",
    "twin.vibration.housing",
    "twin.vibration.surface",
)


@cache
def _models() -> dict[str, type[BaseModel]]:
    found: dict[str, type[BaseModel]] = {}
    for name in MODEL_MODULES:
        for value in vars(importlib.import_module(name)).values():
            if isinstance(value, type) and issubclass(value, BaseModel) and value.__module__ == name:
                found.setdefault(value.__name__, value)
    return found


def error_text(exc: Exception) -> str:
    """A pydantic `ValidationError` as "field.path: message; ..." with the field's allowed range,
    both sides where the validated model is one of `MODEL_MODULES`' (pydantic names only the side
    crossed; service.core.errors.field_errors, as the HTTP API answers); a model-level check names
    its field at the start of its message, "zenoh_user: ...", and is printed without pydantic's
    "Value error, " prefix. Any other exception as its text."""
    if isinstance(exc, ValidationError):
        model = _models().get(exc.title)
        return "; ".join(
            f"{e.field}: {e.message}" if e.field else e.message for e in field_errors(exc.errors(), model=model)
        )
    return str(exc)
