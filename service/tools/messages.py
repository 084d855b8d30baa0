"""One line of text for an input error, as the CLI commands print it after "error: "."""

from __future__ import annotations

import importlib
import re
from collections.abc import Mapping
from functools import cache

from pydantic import BaseModel, ValidationError

from service.core.errors import field_errors, models_bounds
from twin.setpoint import SetpointError

#: the modules whose models a command validates its input with (a bearing spec and its parts,
#: the model's options and settings): an error of one of them states both sides of the range
MODEL_MODULES = (
    "twin.spec",
    "twin.setpoint",
    "twin.thermal.settings",
    "twin.life.settings",
    "twin.vibration.housing",
    "twin.vibration.surface",
    "twin.vibration.defects",
)

#: the parts of a bearing spec (twin.spec.BearingSpec's fields but its designation; named here, as
#: twin.spec loads numba): an error in one is in the `--bearing` file
SPEC_PARTS = (
    "kind",
    "geometry",
    "material",
    "surface",
    "lubricant",
    "mounting",
    "electrical",
    "thermal",
    "limiting_speed_rad_s",
    "lubrication",
    "housing",
    "surface_profile",
)

#: the options of the commands that run a bearing at an operating point, by the field they set
#: (an error names both)
OPERATING_FLAGS = {
    "designation": "--bearing",
    **{part: "--bearing" for part in SPEC_PARTS},
    "shaft_speed_rad_s": "--speed",
    "radial_load_n": "--radial-load",
    "axial_load_n": "--axial-load",
    "oil_temperature_c": "--oil-temperature",
    "diametral_clearance_m": "--clearance",
}


@cache
def _models() -> dict[str, type[BaseModel]]:
    found: dict[str, type[BaseModel]] = {}
    for name in MODEL_MODULES:
        for value in vars(importlib.import_module(name)).values():
            if isinstance(value, type) and issubclass(value, BaseModel) and value.__module__ == name:
                found.setdefault(value.__name__, value)
    return found


@cache
def _all_bounds() -> dict:
    """field name -> declared range over every model of `MODEL_MODULES` (for an error raised by a
    validator of a union or a list of them, which names no single model)."""
    return models_bounds(list(_models().values()))


def error_text(exc: Exception, flags: Mapping[str, str] | None = None) -> str:
    """A pydantic `ValidationError` as "field.path: message; ..." with the field's allowed range,
    both sides where the validated model is one of `MODEL_MODULES`' (pydantic names only the side
    crossed; service.core.errors.field_errors, as the HTTP API answers); a model-level check names
    its field at the start of its message, "zenoh_user: ...", and is printed without pydantic's
    "Value error, " prefix. A `SetpointError` as its problems. Any other exception as its text.
    `flags`: the command's option for a field (by the field's name, the last part of its path):
    each problem of such a field starts with the option, "--radial-load: radial_load_n = ..."."""
    parts: list[tuple[str | None, str]]
    if isinstance(exc, ValidationError):
        model = _models().get(exc.title)
        described = field_errors(exc.errors(), model=model, bounds=None if model is not None else _all_bounds())
        parts = [(e.field, f"{e.field}: {e.message}" if e.field else e.message) for e in described]
    elif isinstance(exc, SetpointError):
        parts = [(name, message) for name, message, _ in exc.messages()]
    else:
        text = str(exc)
        named = _LEADING_FIELD.match(text)
        parts = [(named.group(1) if named else None, text)]
    return "; ".join(_with_flag(field, text, flags) for field, text in parts)


_LEADING_FIELD = re.compile(r"^([a-z_][a-z0-9_.]*)(?::| =)")


def _with_flag(field: str | None, text: str, flags: Mapping[str, str] | None) -> str:
    """`text` led by the option of `field`: the one of its name (the last part of its path), else
    the one of its root (a part of the bearing spec file given with `--bearing`)."""
    if not flags or not field:
        return text
    flag = flags.get(field.rsplit(".", 1)[-1]) or flags.get(field.split(".", 1)[0])
    return f"{flag}: {text}" if flag else text
