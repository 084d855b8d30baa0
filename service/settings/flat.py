"""Flat environment names of the nested settings, read beside pydantic-settings' nested ones.

A settings root (`ServiceSettings`, `RouterSettings`, `ZenohAccessSettings`) holds groups
(`http`, `zenoh`, ...). pydantic-settings reads a group's field from `BEARING_TWIN_<GROUP>__<FIELD>`
(`BEARING_TWIN_HTTP__PORT`). Every field also has a flat name, stored once in its
`json_schema_extra` by `flat()`: the short environment name (`BEARING_TWIN_PORT`), the keyword
a root accepts (`ServiceSettings(port=8001)`) and the default name of its `serve` flag
(`--port`). The nested environment name wins over the flat one.

A field's `description` is one line (what it is, its unit in brackets, what 0 or unset means): the
`--help` of its flag and the Meaning column of docs/configuration.md. The reason, trade-offs,
interactions and references go to its `details` (`flat(..., details=...)`, or `details(...)` for a
field without a flat name), listed under its group's table on that page.

A flat name may equal a group's name: `BEARING_TWIN_OPCUA=opc.tcp://...` is `opcua.endpoint`,
while a JSON object in it (`BEARING_TWIN_OPCUA='{"security": "sign"}'`) is the whole group.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any, cast

from pydantic import BaseModel
from pydantic.fields import FieldInfo
from pydantic_settings import (
    BaseSettings,
    EnvSettingsSource,
    InitSettingsSource,
    PydanticBaseSettingsSource,
    SettingsConfigDict,
)

ENV_PREFIX = "BEARING_TWIN_"
NESTED_DELIMITER = "__"
DESCRIPTION_MAX_CHARS = 110  # a description is one line of at most this many characters


def details(text: str) -> dict[str, Any]:
    """The `json_schema_extra` of a settings field without a flat name that has details: the
    sentences beyond its one-line description, shown under its group's table in the docs."""
    return {"details": text}


def flat(name: str, *flags: str, metavar: str | None = None, details: str | None = None) -> dict[str, Any]:
    """The `json_schema_extra` of a settings field: its flat name (lower case, without the
    prefix) and, when they differ from `--<flat-name>` (`--no-<flat-name>` for a setting on by
    default), its `serve` flags (the first is shown); `details`: the sentences beyond its
    one-line description (the docs show them, `--help` does not)."""
    extra: dict[str, Any] = {"flat": name}
    if flags:
        extra["flags"] = list(flags)
    if metavar is not None:
        extra["metavar"] = metavar
    if details is not None:
        extra["details"] = details
    return extra


def field_details(info: FieldInfo) -> str | None:
    """The details of a settings field (`flat(..., details=...)` or `details(...)`), or None."""
    extra = info.json_schema_extra
    if isinstance(extra, dict) and extra.get("details") is not None:
        return str(extra["details"])
    return None


@dataclass(frozen=True)
class FlatSetting:
    """One field of a settings group and its flat name."""

    flat: str  # e.g. "port"
    group: str  # e.g. "http"
    field: str  # e.g. "port"
    info: FieldInfo
    flags: tuple[str, ...]  # e.g. ("--port",)
    metavar: str | None

    @property
    def env(self) -> str:
        """The flat environment variable, e.g. BEARING_TWIN_PORT."""
        return f"{ENV_PREFIX}{self.flat.upper()}"

    @property
    def nested_env(self) -> str:
        """The nested environment variable, e.g. BEARING_TWIN_HTTP__PORT."""
        return f"{ENV_PREFIX}{self.group.upper()}{NESTED_DELIMITER}{self.field.upper()}"

    @property
    def default_text(self) -> str:
        """The default as the docs and `--help` show it: `unset`, a value, or the rule of a computed one."""
        return default_text(self.info)

    @property
    def details(self) -> str | None:
        """The sentences beyond the one-line description, or None."""
        return field_details(self.info)

    @property
    def path(self) -> str:
        """The attribute path from the root, e.g. http.port."""
        return f"{self.group}.{self.field}"


def default_text(info: FieldInfo) -> str:
    """A field's default as text: `unset` for None, the value (a list comma-separated, `none` when
    empty), or the first line of the factory's docstring for a computed default (a recording name
    with the start time)."""
    if info.default_factory is not None:
        factory = info.default_factory
        doc = (getattr(factory, "__doc__", None) or "").strip()
        if getattr(factory, "__name__", "") != "<lambda>" and doc and not isinstance(factory, type):
            return doc.split("\n")[0].strip("`").split("`")[0]
        value = cast(Any, factory)()
        if isinstance(value, BaseModel):
            return "(a group)"
    else:
        value = info.default
    if value is None:
        return "unset"
    if isinstance(value, list):
        return ",".join(str(v) for v in value) or "none"  # as the environment takes it
    return str(value)


def group_model(info: FieldInfo) -> type[BaseModel] | None:
    """The model class of a settings group field, or None for a plain field."""
    annotation = info.annotation
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation
    return None


@functools.cache
def flat_settings(root: type[BaseModel]) -> tuple[FlatSetting, ...]:
    """Every field of `root`'s groups that has a flat name, in declaration order."""
    found = []
    for group, group_info in root.model_fields.items():
        model = group_model(group_info)
        if model is None:
            continue
        for name, info in model.model_fields.items():
            extra = info.json_schema_extra
            if not isinstance(extra, dict) or "flat" not in extra:
                continue
            flat_name = str(extra["flat"])
            negated = info.default is True  # a switch that turns a default-on setting off
            option = f"--{'no-' if negated else ''}{flat_name.replace('_', '-')}"
            flags = tuple(str(f) for f in cast(list, extra.get("flags", [option])))
            metavar = extra.get("metavar")
            found.append(FlatSetting(flat_name, group, name, info, flags, None if metavar is None else str(metavar)))
    names = [s.flat for s in found]
    if len(set(names)) != len(names):
        raise TypeError(f"{root.__name__}: a flat settings name is used twice")
    return tuple(found)


def nest_flat(root: type[BaseModel], data: dict[str, Any]) -> dict[str, Any]:
    """`data` with its flat keys moved into their groups: `{"port": 1}` -> `{"http": {"port": 1}}`.
    A key that is a group's name and holds a mapping or a model is the group itself."""
    by_flat = {s.flat: s for s in flat_settings(root)}
    nested: dict[str, Any] = {}
    moved: list[tuple[FlatSetting, Any]] = []
    for key, value in data.items():
        setting = by_flat.get(key)
        is_group = key in root.model_fields and isinstance(value, (dict, BaseModel))
        if setting is None or is_group:
            nested[key] = value
        else:
            moved.append((setting, value))
    for setting, value in moved:
        group = nested.get(setting.group)
        if isinstance(group, BaseModel):
            group = group.model_dump(exclude_unset=True)
        group = dict(group) if isinstance(group, dict) else {}
        group[setting.field] = value
        nested[setting.group] = group
    return nested


class FlatEnvSettingsSource(EnvSettingsSource):
    """pydantic-settings' environment source that also reads the flat names
    (`BEARING_TWIN_PORT` for `http.port`); a nested name given too wins."""

    def __init__(self, settings_cls: type[BaseSettings]) -> None:
        super().__init__(settings_cls)
        env = dict(self.env_vars)
        self.flat_values: list[tuple[FlatSetting, str | None]] = []
        for setting in flat_settings(settings_cls):
            key = self.env_prefix + setting.flat
            key = key if self.case_sensitive else key.lower()
            if key not in env:
                continue
            value = env[key]
            if setting.flat in settings_cls.model_fields and (value or "").lstrip().startswith("{"):
                continue  # the group itself, as JSON
            self.flat_values.append((setting, env.pop(key)))
        self.env_vars = env

    def __call__(self) -> dict[str, Any]:
        data = super().__call__()
        for setting, value in self.flat_values:
            group = data.setdefault(setting.group, {})
            if isinstance(group, dict):
                group.setdefault(setting.field, value)
        return data


class NestedSettings(BaseSettings):
    """A settings root: groups read from `BEARING_TWIN_<GROUP>__<FIELD>` or the flat names,
    keyword arguments nested or flat; an unknown keyword is an error."""

    model_config = SettingsConfigDict(
        env_prefix=ENV_PREFIX,
        env_nested_delimiter=NESTED_DELIMITER,
        extra="forbid",
        validate_default=True,
        hide_input_in_errors=True,
    )

    @classmethod
    def settings_customise_sources(
        cls,
        settings_cls: type[BaseSettings],
        init_settings: PydanticBaseSettingsSource,
        env_settings: PydanticBaseSettingsSource,
        dotenv_settings: PydanticBaseSettingsSource,
        file_secret_settings: PydanticBaseSettingsSource,
    ) -> tuple[PydanticBaseSettingsSource, ...]:
        given = cast(InitSettingsSource, init_settings).init_kwargs
        return (
            InitSettingsSource(settings_cls, init_kwargs=nest_flat(settings_cls, given)),
            FlatEnvSettingsSource(settings_cls),
            dotenv_settings,
            file_secret_settings,
        )
