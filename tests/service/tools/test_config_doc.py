"""docs/configuration.md is generated from the settings models (service.tools.config_doc) and is
current: a default, description, environment name or flag changed in service/settings/ without
regenerating fails here."""

from __future__ import annotations

from service.settings import ServiceSettings, flat_settings
from service.tools.config_doc import DOC, configuration_markdown, main


def test_configuration_doc_is_current():
    assert DOC.read_text(encoding="utf-8") == configuration_markdown(), "run: python -m service.tools.config_doc"
    assert main(["--check"]) == 0


def test_every_setting_has_a_row_with_its_default(tmp_path):
    text = configuration_markdown()
    for setting in flat_settings(ServiceSettings):
        assert f"| `{setting.env}` |" in text, setting.flat
        assert f"`{setting.nested_env}`" in text, setting.path
        assert setting.info.description, f"{setting.path} has no description"
    assert "| `BEARING_TWIN_PORT` | `8000` | `BEARING_TWIN_HTTP__PORT` | `--port` |" in text
    assert "| `BEARING_TWIN_TOKEN` | unset | `BEARING_TWIN_SECURITY__TOKEN` | (environment only) |" in text
    stale = tmp_path / "configuration.md"
    stale.write_text(text.replace("`8000`", "`8001`"))
    assert main(["--check", "--out", str(stale)]) == 1
