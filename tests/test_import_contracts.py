"""The import rules of the README's "Architecture" section, as import-linter contracts in
pyproject.toml ([tool.importlinter]): `twin` never imports `service` (nor fastapi, zenoh, rerun,
matplotlib); the runtime engine never imports `twin.validation` (the offline science); `service.core` imports no fastapi, zenoh or rerun, nor the wings built on them;
the service's layers go tools > reports > api > wiring > bus | recording > core > settings; no
import cycle among the modules of `service` and `loadtest`, nor among those of `twin`; the runtime
never imports the load tools.
import-linter reads every import statement, those inside functions included."""

from __future__ import annotations

import sys
import tomllib
from pathlib import Path

import pytest

lint = pytest.importorskip("importlinter.cli")

ROOT = Path(__file__).resolve().parents[1]


def test_the_contracts_are_declared():
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]
    contracts = {c["id"]: c for c in config["contracts"]}
    assert set(contracts) == {"engine", "runtime", "core", "layers", "service-acyclic", "twin-acyclic", "loadtest"}
    assert contracts["service-acyclic"]["type"] == "acyclic_siblings"
    assert contracts["twin-acyclic"]["type"] == "acyclic_siblings" and contracts["twin-acyclic"]["ancestors"] == ["twin"]
    assert set(contracts["service-acyclic"]["ancestors"]) == {"service", "loadtest"}
    assert {"loadtest", "httpx"} <= set(contracts["loadtest"]["forbidden_modules"])
    assert {"service", "fastapi", "zenoh", "rerun"} <= set(contracts["engine"]["forbidden_modules"])
    assert contracts["runtime"]["forbidden_modules"] == ["twin.validation"]
    # every runtime module of twin/ (all but the offline packages) is a source of the "runtime" contract
    runtime = {p.stem for p in (ROOT / "twin").glob("*.py") if p.stem != "__init__"}
    runtime |= {p.name for p in (ROOT / "twin").iterdir() if (p / "__init__.py").exists()}
    runtime -= {"validation", "ehl_solver"}
    assert {m.removeprefix("twin.") for m in contracts["runtime"]["source_modules"]} == runtime
    assert {"fastapi", "zenoh", "rerun"} <= set(contracts["core"]["forbidden_modules"])
    layers = contracts["layers"]["layers"]
    assert layers[0] == "service.tools" and layers[-3:] == ["service.core", "service.settings", "service.keys"]


def test_the_code_keeps_the_contracts(monkeypatch):
    monkeypatch.syspath_prepend(str(ROOT))
    assert lint.lint_imports(config_filename=str(ROOT / "pyproject.toml"), no_cache=True, no_logo=True) == 0


def test_a_broken_rule_is_caught(tmp_path, monkeypatch):
    """The tool does fail: a core module importing fastapi inside a function breaks the rule."""
    pkg = tmp_path / "demo"
    (pkg / "core").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "core" / "__init__.py").write_text("")
    (pkg / "core" / "bad.py").write_text("def handler():\n    import fastapi\n    return fastapi\n")
    config = tmp_path / "contracts.toml"
    config.write_text('[tool.importlinter]\nroot_packages = ["demo"]\ninclude_external_packages = true\n\n'
                      '[[tool.importlinter.contracts]]\nname = "core has no web"\ntype = "forbidden"\n'
                      'source_modules = ["demo.core"]\nforbidden_modules = ["fastapi"]\n')
    monkeypatch.syspath_prepend(str(tmp_path))
    sys.modules.pop("demo", None)
    assert lint.lint_imports(config_filename=str(config), no_cache=True, no_logo=True) == 1


def test_a_hidden_cycle_is_caught(tmp_path, monkeypatch):
    """A cycle between two sibling modules, one side hidden in a function, breaks `acyclic_siblings`."""
    pkg = tmp_path / "demo_cycle"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "paths.py").write_text("def taken():\n    from demo_cycle.segments import numbered\n    return numbered\n")
    (pkg / "segments.py").write_text("from demo_cycle.paths import taken\n\nnumbered = taken\n")
    config = tmp_path / "contracts.toml"
    config.write_text('[tool.importlinter]\nroot_packages = ["demo_cycle"]\n\n'
                      '[[tool.importlinter.contracts]]\nname = "acyclic"\ntype = "acyclic_siblings"\n'
                      'ancestors = ["demo_cycle"]\n')
    monkeypatch.syspath_prepend(str(tmp_path))
    sys.modules.pop("demo_cycle", None)
    assert lint.lint_imports(config_filename=str(config), no_cache=True, no_logo=True) == 1
