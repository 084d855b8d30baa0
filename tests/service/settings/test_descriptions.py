"""The settings' texts follow one rule: a field's description is a single line of at most
DESCRIPTION_MAX_CHARS characters saying what the setting is, its unit in brackets and what 0 or
unset means; the reason, the trade-off, the interactions and the references are its details.
`--help` shows the description, docs/configuration.md the description in its table and the
details in a list under it."""

from __future__ import annotations

import argparse

import pytest
from pydantic import BaseModel
from pydantic.fields import FieldInfo

from service.settings import (
    AlarmSettings,
    RouterSettings,
    ScenarioSettings,
    ServiceSettings,
    ZenohAccessSettings,
    flat_settings,
)
from service.settings.flat import DESCRIPTION_MAX_CHARS, field_details
from service.tools.cli import build_parser
from service.tools.config_doc import configuration_markdown

ROOTS = (ServiceSettings, RouterSettings, ZenohAccessSettings, ScenarioSettings)


def _fields(model: type[BaseModel], path: str = "") -> list[tuple[str, FieldInfo]]:
    """Every field of `model` and of its nested groups, with its dotted path."""
    found = []
    for name, info in model.model_fields.items():
        found.append((f"{path}{name}", info))
        if isinstance(info.annotation, type) and issubclass(info.annotation, BaseModel):
            found += _fields(info.annotation, f"{path}{name}.")
    return found


def _help(command: str) -> str:
    parser = build_parser()
    subparsers = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return " ".join(subparsers.choices[command].format_help().split())


def _broken_descriptions(root: type[BaseModel]) -> list[str]:
    """The fields of `root` (groups included) whose description is missing, not one line, or longer
    than DESCRIPTION_MAX_CHARS characters."""
    broken = []
    for path, info in _fields(root):
        text = info.description or ""
        if not text:
            broken.append(f"{path}: no description")
        elif text != " ".join(text.split()):
            broken.append(f"{path}: not one line: {text!r}")
        elif len(text) > DESCRIPTION_MAX_CHARS:
            broken.append(f"{path}: {len(text)} characters: {text!r}")
    return broken


@pytest.mark.parametrize("root", ROOTS, ids=lambda r: r.__name__)
def test_every_description_is_one_short_line(root):
    assert len(_fields(root)) > 5
    broken = _broken_descriptions(root)
    assert not broken, (
        f"descriptions over {DESCRIPTION_MAX_CHARS} characters or lines: move the reason, trade-off or "
        "reference to the field's details:\n" + "\n".join(broken)
    )


def test_the_check_finds_a_long_or_multi_line_description():
    from pydantic import Field

    class Group(BaseModel):
        long: float = Field(default=0.0, description="x" * (DESCRIPTION_MAX_CHARS + 1))
        two_lines: float = Field(default=0.0, description="First line.\nSecond line.")
        fits: float = Field(default=0.0, description="x" * DESCRIPTION_MAX_CHARS)

    class Root(BaseModel):
        group: Group = Field(default_factory=Group, description="A group.")

    assert _broken_descriptions(Root) == [
        f"group.long: {DESCRIPTION_MAX_CHARS + 1} characters: {'x' * (DESCRIPTION_MAX_CHARS + 1)!r}",
        "group.two_lines: not one line: 'First line.\\nSecond line.'",
    ]


def test_details_are_on_the_configuration_page_not_in_the_help():
    page = " ".join(configuration_markdown().split())
    serve_help = _help("serve")
    with_details = [s for s in flat_settings(ServiceSettings) if s.details]
    assert len(with_details) >= 35
    for setting in with_details:
        first = setting.details.split(". ")[0].split(" (docs/")[0]
        assert f"- `{setting.env}`: {first}" in page, setting.path
        assert first not in serve_help, f"{setting.path}: the details reach --help"
    for name, info in AlarmSettings.model_fields.items():
        text = field_details(info)
        if text:
            assert f"- `{name}`: {text.split('. ')[0]}" in page, name


def test_a_docs_reference_in_the_details_is_a_link_to_its_section():
    page = configuration_markdown()
    assert '([service.md "Runner pool"](service.md#runner-pool-many-twins-per-host))' in page
    assert '([operations.md "Access"](operations.md#access))' in page
    assert "(docs/" not in page


def test_a_switch_says_what_its_flag_does():
    serve_help = _help("serve")
    assert "Start the zenoh bus: on unless this flag is given [BEARING_TWIN_ENABLE_ZENOH]" in serve_help
    assert "Run the twins as fast as possible instead of paced to the wall clock [BEARING_TWIN_FAST]" in serve_help
    assert "[bool]" not in serve_help
    router_help = _help("router")
    assert "(default tcp/127.0.0.1:7447) [BEARING_TWIN_ZENOH_LISTEN]" in router_help
