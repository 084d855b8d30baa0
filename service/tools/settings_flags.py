"""The `serve` and `router` flags, generated from the settings model (service.settings): one flag per field of
a group, named after the field's flat name (`--port`, `--zenoh-listen`, `--no-zenoh`), its help
the field's description. Flags default to nothing (argparse.SUPPRESS), so only the flags given
override the environment. Secrets (SecretStr: the token, the zenoh password) have no flag: a
command line is visible to the other users of the machine."""

from __future__ import annotations

import argparse
import types
import typing
from pathlib import Path
from typing import Any

from pydantic import BaseModel, SecretStr, ValidationError

from service.settings import FlatSetting, flat_settings

_METAVARS = {int: "N", float: "VALUE", Path: "PATH"}


def _plain_types(annotation: Any) -> list[Any]:
    """The members of an optional or union annotation, None left out."""
    if typing.get_origin(annotation) in (typing.Union, types.UnionType):
        return [a for a in typing.get_args(annotation) if a is not type(None)]
    return [annotation]


def _help_text(setting: FlatSetting, kind: Any) -> str:
    """A flag's help: the field's one-line description, its default (left out where the
    description says what unset means) and its environment variable. A switch's help says what
    the flag does instead of the default and the [bool] unit."""
    text = " ".join((setting.info.description or "").split()).rstrip(".").replace("%", "%%")
    if kind is bool:
        text = text.removesuffix(" [bool]")
        if setting.info.default is True:
            return f"{text}: on unless this flag is given [{setting.env}]"
        return f"{text} [{setting.env}]"
    if setting.default_text == "unset" and "unset =" in text:
        return f"{text} [{setting.env}]"
    return f"{text} (default {setting.default_text}) [{setting.env}]"


def _flag_options(setting: FlatSetting) -> dict[str, Any] | None:
    """argparse options of one setting's flag, or None when it has none (a secret)."""
    members = _plain_types(setting.info.annotation)
    kind = members[0] if len(members) == 1 else str
    origin = typing.get_origin(kind)
    options: dict[str, Any] = {"dest": setting.path, "default": argparse.SUPPRESS, "help": _help_text(setting, kind)}
    if kind is SecretStr:
        return None
    if kind is bool:
        options.update(action="store_const", const=setting.info.default is not True)
        return options
    if origin is list:
        options.update(action="append")
    elif origin is typing.Literal:
        options.update(choices=[str(c) for c in typing.get_args(kind)])
    elif kind in (int, float):
        options.update(type=kind)
    if setting.metavar is not None:
        options["metavar"] = setting.metavar
    elif origin is not typing.Literal:
        options["metavar"] = _METAVARS.get(kind, "TEXT")
    return options


def add_settings_flags(
    parser: argparse.ArgumentParser, root: type[BaseModel], aliases: dict[str, tuple[str, ...]] | None = None
) -> None:
    """A flag for every field of `root`'s groups that has a flat name and is no secret, in one
    help section per group; `aliases`: further option strings of a setting of this command
    (`{"zenoh.prefix": ("--prefix",)}`), shown first."""
    sections: dict[str, Any] = {}
    for setting in flat_settings(root):
        options = _flag_options(setting)
        if options is None:
            continue
        if setting.group not in sections:
            sections[setting.group] = parser.add_argument_group(
                f"{setting.group} settings", root.model_fields[setting.group].description
            )
        flags = (*(aliases or {}).get(setting.path, ()), *setting.flags)
        sections[setting.group].add_argument(*flags, **options)


def flag_overrides(args: argparse.Namespace) -> dict[str, Any]:
    """The flags given, as nested settings keywords: `{"http": {"port": 8001}}`."""
    nested: dict[str, Any] = {}
    for dest, value in vars(args).items():
        group, dot, field = dest.partition(".")
        if dot:
            nested.setdefault(group, {})[field] = value
    return nested


def flag_of(root: type[BaseModel], path: str) -> str | None:
    """The first flag of the setting at `path` (e.g. `recording.path` -> `--record`), None for a secret."""
    for setting in flat_settings(root):
        if setting.path == path:
            return setting.flags[0] if _flag_options(setting) is not None else None
    raise KeyError(path)


def settings_error_text(exc: ValidationError, root: type[BaseModel]) -> str:
    """A settings ValidationError on one line, each field named as the user may have set it:
    `http.port (BEARING_TWIN_PORT, --port): Input should be ...`."""
    names = {(s.group, s.field): s for s in flat_settings(root)}
    parts = []
    for error in exc.errors():
        loc = tuple(str(p) for p in error["loc"])
        message = str(error["msg"]).removeprefix("Value error, ")
        setting = names.get((loc[0], loc[1])) if len(loc) >= 2 else None
        if setting is None:
            whole_model = not loc or (len(loc) == 1 and loc[0] in root.model_fields)
            parts.append(message if whole_model else f"{'.'.join(loc)}: {message}")  # a check names its field
            continue
        flag = flag_of(root, setting.path)
        where = setting.env + (f", {flag}" if flag is not None else "")
        parts.append(f"{'.'.join(loc)} ({where}): {message}")
    return "; ".join(parts)
