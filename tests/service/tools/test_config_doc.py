"""docs/configuration.md is generated from the settings models (service.tools.config_doc) and is
current: a default or description changed in service/settings.py without regenerating fails here."""

from __future__ import annotations

from service.settings import ServiceSettings
from service.tools.config_doc import DOC, configuration_markdown, main


def test_configuration_doc_is_current():
    assert DOC.read_text(encoding="utf-8") == configuration_markdown(), \
        "run: python -m service.tools.config_doc"
    assert main(["--check"]) == 0


def test_every_setting_has_a_row_with_its_default(tmp_path):
    text = configuration_markdown()
    for name, field in ServiceSettings.model_fields.items():
        assert f"`BEARING_TWIN_{name.upper()}`" in text, name
        assert field.description, f"{name} has no description"
    assert "| `BEARING_TWIN_PORT` | `8000` |" in text
    stale = tmp_path / "configuration.md"
    stale.write_text(text.replace("`8000`", "`8001`"))
    assert main(["--check", "--out", str(stale)]) == 1
