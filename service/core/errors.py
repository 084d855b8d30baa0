"""Errors the service answers with, whatever the transport: `FieldError` (where, what, allowed),
`InputError` (a list of them and the status: 422 invalid input, 404 unknown twin, 409 conflict,
401/413/429 refused by the admission gate), and the conversions from pydantic's and the setpoint
vocabulary's errors. Messages never echo the input (it may hold NaN, which JSON cannot carry)."""

from __future__ import annotations

import math
import re
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


_NUMBER = r"([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)"
# "x = 0.03 m: must be in (0, 0.0255516] m ...": the range a model-level check states (both ends numbers)
_STATED_RANGE = re.compile(r"must be in [\[(]" + _NUMBER + ", " + _NUMBER + r"[\])]")

_UNIT_SUFFIXES = (
    ("_m_s2_rthz", "m/s^2/sqrt(Hz)"),
    ("_m_s2", "m/s^2"),
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


def declared_bounds(model: type[BaseModel], loc: Sequence[Any]) -> Bounds | None:
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


class Bounds(tuple[Any, Any]):
    """(low, high) a field declares (None for a side without a bound); `low_open` / `high_open`:
    that side excludes its bound (gt / lt)."""

    low_open: bool
    high_open: bool

    def __new__(cls, low: Any, high: Any, low_open: bool = False, high_open: bool = False) -> Bounds:
        self = super().__new__(cls, (low, high))
        self.low_open, self.high_open = low_open, high_open
        return self


def field_bounds(info: FieldInfo) -> Bounds | None:
    """The range a pydantic field declares (its annotated_types Ge / Gt and Le / Lt), or None
    when it declares neither side."""
    low = high = None
    low_open = high_open = False
    for constraint in info.metadata:
        if low is None and getattr(constraint, "ge", None) is not None:
            low = constraint.ge
        elif low is None and getattr(constraint, "gt", None) is not None:
            low, low_open = constraint.gt, True
        if high is None and getattr(constraint, "le", None) is not None:
            high = constraint.le
        elif high is None and getattr(constraint, "lt", None) is not None:
            high, high_open = constraint.lt, True
    return None if low is None and high is None else Bounds(low, high, low_open, high_open)


def range_text(low: Any, high: Any, low_open: bool = False, high_open: bool = False) -> str:
    """'[0, 0.05]', '(0, 0.05]', '[1000, inf)': a side without a bound is open, at infinity."""
    left = "(" if low_open or low is None else "["
    right = ")" if high_open or high is None else "]"
    return f"{left}{_fmt(low, '-inf')}, {_fmt(high, 'inf')}{right}"


def models_bounds(models: Sequence[type[BaseModel]]) -> dict[str, Bounds]:
    """field name -> (low, high) declared on `models` (`field_bounds`; the first model that
    declares a name wins), for `field_errors(bounds=...)`."""
    bounds: dict[str, Bounds] = {}
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
    setpoint_body: bool = True,
) -> list[FieldError]:
    """pydantic error dicts -> FieldErrors naming the field and its allowed range: for setpoint
    fields the bearing's (`limits`) or else the vocabulary's static bounds, for other fields
    both sides of the declared range (`bounds` by field name, or what `model`, the validated
    model, declares at the error's path; pydantic names only the side crossed). `prefix`: put
    before each field's path (the input nested in a request, as `setpoint_field_errors`).
    `setpoint_body`: the validated body is a setpoint, so an unknown top-level field is answered
    with the setpoint's fields as the allowed names (False for other bodies of a twin's routes)."""
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
            low_open, high_open = "gt" in ctx, "lt" in ctx
            if low_bound is not None or high_bound is not None:
                known = (bounds or {}).get(leaf or "")
                if known is None and model is not None:
                    known = declared_bounds(model, loc)
                if known is not None:
                    if low_bound is None:
                        low_bound, low_open = known[0], getattr(known, "low_open", False)
                    if high_bound is None:
                        high_bound, high_open = known[1], getattr(known, "high_open", False)
                allowed = [_jsonable(low_bound), _jsonable(high_bound)]
                unit = unit_of(leaf or "")
                text = range_text(low_bound, high_bound, low_open, high_open)
                msg = f"{msg}; allowed range {text}{' ' + unit if unit else ''}"
        if allowed is None:  # a model-level check that states the range in its message
            stated = _STATED_RANGE.search(msg)
            if stated:
                allowed = [float(stated.group(1)), float(stated.group(2))]
        if e.get("type") == "extra_forbidden" and leaf is not None:
            msg = f"unknown field {leaf!r}"
            if limits is not None and setpoint_body and len(loc) <= 2:
                allowed = sorted(limits.ranges)
        if e.get("type") == "json_invalid":
            field = None
            msg = f"body is not valid JSON: {ctx.get('error', msg)}"
        if prefix:
            field = f"{prefix}{field}" if field else prefix.rstrip(".")
        out.append(FieldError(field=field, message=msg, allowed=allowed))
    return out
