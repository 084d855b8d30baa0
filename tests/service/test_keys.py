"""One vocabulary (service.keys): the twin-id rule, the key-prefix rule, the default prefix and the
zenoh keys are defined once and used by the settings, the registry, the scenarios, the bus, the
access rules, the monitor and the load tools."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from service import keys
from service.core import registry, scenarios
from service.settings import ServiceSettings, ZenohAccessConfig, ZenohAccessSettings

ROOT = Path(__file__).resolve().parents[2]


def test_key_builders():
    assert keys.twin_key("plant1/line2", "m7") == "plant1/line2/m7"
    assert keys.twin_key("bearing", "a", keys.SETPOINT_RESULT) == "bearing/a/setpoint/result"
    assert keys.ball_key("bearing", "a", 3) == "bearing/a/ball/3"
    assert keys.all_twins("plant1/**", keys.STATE) == "plant1/**/*/state"


@pytest.mark.parametrize("good", ["default", "6208-1", "a.b_c-d", "x" * 64])
def test_twin_ids_accepted_everywhere(good):
    assert keys.check_twin_id(good) == good
    assert ServiceSettings(twin_id=good).twin.id == good
    assert re.match(registry.ID_PATTERN, good)


@pytest.mark.parametrize("bad", ["", "-a", "a/b", "a*", "a b", "a:b", "a@b", "x" * 65, "é"])
def test_twin_ids_refused_everywhere(bad):
    with pytest.raises(ValueError):
        keys.check_twin_id(bad)
    with pytest.raises(ValueError):
        ServiceSettings(twin_id=bad)


@pytest.mark.parametrize("bad", ["", "/a", "a/", "a//b", "a/*", "a/**", "a/$x", "a b", "a:b", "/".join("x" * 9)])
def test_prefixes_refused_by_the_settings_and_the_bus(bad):
    with pytest.raises(ValueError):
        keys.check_prefix(bad)
    if bad.strip("/") != bad.strip("/").strip() or bad in ("/a", "a/"):
        return  # the settings strip the outer '/' of a prefix read from the environment
    with pytest.raises(ValueError):
        ServiceSettings(zenoh_prefix=bad)  # a service publishes under a concrete prefix
    if "*" not in bad:
        with pytest.raises(ValueError):
            ZenohAccessSettings(zenoh_prefix=bad)


def test_one_definition():
    """The rules live in service.keys only: no other module of service/ or loadtest/ writes the id
    regex, a prefix regex or the default prefix as a literal."""
    assert ZenohAccessConfig.model_fields["prefix"].default == keys.DEFAULT_PREFIX
    assert registry.ID_PATTERN is keys.TWIN_ID_PATTERN and scenarios._NAME_RE is keys.TWIN_ID_PATTERN
    literals = re.compile(
        r"\[A-Za-z0-9\]\[A-Za-z0-9_\.-\]|\[A-Za-z0-9_\.:\+=|prefix[^=\n]*=\s*\"bearing\"|"
        r"default=\"bearing\""
    )
    offenders = [
        f"{p.relative_to(ROOT)}:{i}"
        for base in ("service", "loadtest")
        for p in (ROOT / base).rglob("*.py")
        if p.name != "keys.py"
        for i, line in enumerate(p.read_text().splitlines(), 1)
        if literals.search(line)
    ]
    assert not offenders, offenders


def test_version_from_package_metadata():
    """The version is written once (pyproject.toml) and read from the installed package's metadata."""
    import importlib.metadata
    import tomllib

    import service

    declared = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    assert service.__version__ == importlib.metadata.version("bearing-twin") == declared
    offenders = [
        str(p.relative_to(ROOT))
        for base in ("service", "twin", "loadtest")
        for p in (ROOT / base).rglob("*.py")
        if f'version="{declared}"' in p.read_text() or f'__version__ = "{declared}"' in p.read_text()
    ]
    assert not offenders, offenders
