"""Errors the service answers with, whatever the transport: `FieldError` (where, what, allowed),
`InputError` (a list of them and the status: 422 invalid input, 404 unknown twin, 409 conflict,
401/413/429 refused by the admission gate), and the conversions from pydantic's and the setpoint
vocabulary's errors. Messages never echo the input (it may hold NaN, which JSON cannot carry)."""

from __future__ import annotations

import math
import typing
from collections.abc import Mapping, Sequence
from typing import Any

from pydantic import BaseModel, Field
from pydantic.fields import FieldInfo

from twin.setpoint import FIELD as SETPOINT_FIELDS
from twin.setpoint import SetpointError, SetpointLimits
from twin.setpoint import unit as setpoint_unit


class FieldError(BaseModel):
    """One thing wrong with a request."""

    field: str | None = Field(
        description="Where: the field name or path (e.g. 'radial_load_n', 'steps[2].at_s'); null when the request as a "
        "whole is wrong [text]."
    )
    message: str = Field(description="What is wrong, with the allowed range and unit when there is one [text].")
    allowed: list[Any] | None = Field(
        default=None,
        description="Allowed [low, high] in the field's unit, or the allowed names; null when not applicable [field "
        "unit].",
    )


class InputError(Exception):
    """Bad input: the FieldErrors, the HTTP status to answer with and extra response headers."""

    def __init__(self, errors: list[FieldError], status_code: int = 422, headers: Mapping[str, str] | None = None):
        self.errors, self.status_code = errors, status_code
        self.headers = dict(headers or {})
        super().__init__("; ".join(f"{e.field}: {e.message}" if e.field else e.message for e in errors))

    @classmethod
    def one(
        cls,
        field: str | None,
        message: str,
        allowed: list | None = None,
        status_code: int = 422,
        headers: Mapping[str, str] | None = None,
    ) -> InputError:
        return cls([FieldError(field=field, message=message, allowed=allowed)], status_code, headers)


def setpoint_field_errors(exc: SetpointError, prefix: str = "") -> list[FieldError]:
    """A SetpointError (fields outside the bearing's range) as FieldErrors."""
    return [
        FieldError(field=f"{prefix}{name}", message=message, allowed=allowed)
        for name, message, allowed in exc.messages()
    ]


def loc_text(loc: tuple | list, skip: tuple[str, ...] = ("body",)) -> str | None:
    """pydantic's error location as a path: ('body', 'steps', 2, 'at_s') -> 'steps[2].at_s'."""
    parts = list(loc)
    while parts and parts[0] in skip:
        parts.pop(0)
    out = ""
    for part in parts:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out or None


_UNIT_SUFFIXES = (
    ("_rad_s", "rad/s"),
    ("_m2_s", "m^2/s"),
    ("_pa_s", "Pa s"),
    ("_hz", "Hz"),
    ("_n", "N"),
    ("_m", "m"),
    ("_c", "degC"),
    ("_s", "s"),
    ("_a", "A"),
    ("_v", "V"),
)


def unit_of(field: str) -> str:
    """The unit a field name carries in its suffix ('radial_load_n' -> 'N'), '' if none."""
    for suffix, unit in _UNIT_SUFFIXES:
        if field.endswith(suffix):
            return unit
    return ""


def _fmt(value: Any, open_side: str) -> str:
    """A bound as text; `open_side` ("-inf" or "inf") for a side the range leaves open."""
    return open_side if value is None else (f"{value:g}" if isinstance(value, (int, float)) else str(value))


def _jsonable(value: Any) -> Any:
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, (int, float, str)) or value is None:
        return value
    return str(value)


def declared_bounds(model: type[BaseModel], loc: Sequence[Any]) -> tuple[Any, Any] | None:
    """Both sides of the range `model` declares for the field at `loc` (a pydantic error's path:
    nested models and list items followed), from its ge/gt and le/lt constraints; None when `loc`
    names no such field. pydantic's error names only the side that was crossed."""
    info = None
    current: Any = model
    for part in loc:
        if isinstance(part, int):
            continue  # an item of a list or tuple of models
        fields = getattr(current, "model_fields", None)
        if not fields or str(part) not in fields:
            return None
        info = fields[str(part)]
        current = _model_in(info.annotation)
    return None if info is None else field_bounds(info)


def field_bounds(info: FieldInfo) -> tuple[Any, Any] | None:
    """(low, high) a pydantic field declares (its annotated_types Ge / Gt and Le / Lt; None for a
    side it leaves open), or None when it declares neither."""
    low = high = None
    for constraint in info.metadata:
        low = getattr(constraint, "ge", getattr(constraint, "gt", low)) if low is None else low
        high = getattr(constraint, "le", getattr(constraint, "lt", high)) if high is None else high
    return None if low is None and high is None else (low, high)


def models_bounds(models: Sequence[type[BaseModel]]) -> dict[str, tuple[Any, Any]]:
    """field name -> (low, high) declared on `models` (`field_bounds`; the first model that
    declares a name wins), for `field_errors(bounds=...)`."""
    bounds: dict[str, tuple[Any, Any]] = {}
    for model in models:
        for name, info in model.model_fields.items():
            declared = field_bounds(info)
            if declared is not None:
                bounds.setdefault(name, declared)
    return bounds


def _model_in(annotation: Any) -> type[BaseModel] | None:
    """The pydantic model a field's annotation holds (itself, or inside Optional / list / tuple)."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation
    for arg in typing.get_args(annotation):
        found = _model_in(arg)
        if found is not None:
            return found
    return None


def field_errors(
    errors: Sequence[Mapping[str, Any]],
    limits: SetpointLimits | None = None,
    bounds: Mapping[str, tuple[Any, Any]] | None = None,
    model: type[BaseModel] | None = None,
    prefix: str = "",
) -> list[FieldError]:
    """pydantic error dicts -> FieldErrors naming the field and its allowed range: for setpoint
    fields the bearing's (`limits`) or else the vocabulary's static bounds, for other fields
    both sides of the declared range (`bounds` by field name, or what `model`, the validated
    model, declares at the error's path; pydantic names only the side crossed). `prefix`: put
    before each field's path (the input nested in a request, as `setpoint_field_errors`)."""
    out = []
    for e in errors:
        loc = tuple(e.get("loc", ()))
        field = loc_text(loc)
        leaf = str(loc[-1]) if loc else None
        msg = str(e.get("msg", "invalid")).removeprefix("Value error, ")
        ctx = e.get("ctx") or {}
        allowed: list[Any] | None = None
        if leaf is not None and leaf in SETPOINT_FIELDS:
            if limits is not None:
                low, high = limits[leaf]
                where = f"for bearing {limits.bearing}" if limits.bearing else "for this bearing"
            else:
                low, high = SETPOINT_FIELDS[leaf].low, SETPOINT_FIELDS[leaf].high
                where = "(the bearing's own limits may be narrower)"
            allowed = [low, high]
            msg = f"{msg}; allowed range [{low:g}, {high:g}] {setpoint_unit(leaf)} {where}"
        else:
            low_bound = ctx.get("ge", ctx.get("gt"))
            high_bound = ctx.get("le", ctx.get("lt"))
            if low_bound is not None or high_bound is not None:
                known = (bounds or {}).get(leaf or "")
                if known is None and model is not None:
                    known = declared_bounds(model, loc)
                if known is not None:
                    low_bound = known[0] if low_bound is None else low_bound
                    high_bound = known[1] if high_bound is None else high_bound
                allowed = [_jsonable(low_bound), _jsonable(high_bound)]
                unit = unit_of(leaf or "")
                low_text, high_text = _fmt(low_bound, "-inf"), _fmt(high_bound, "inf")
                msg = f"{msg}; allowed range [{low_text}, {high_text}]{' ' + unit if unit else ''}"
        if e.get("type") == "extra_forbidden" and leaf is not None:
            msg = f"unknown field {leaf!r}"
            if limits is not None and len(loc) <= 2:
                allowed = sorted(limits.ranges)
        if e.get("type") == "json_invalid":
            field = None
            msg = f"body is not valid JSON: {ctx.get('error', msg)}"
        if prefix:
            field = f"{prefix}{field}" if field else prefix.rstrip(".")
        out.append(FieldError(field=field, message=msg, allowed=allowed))
    return out
