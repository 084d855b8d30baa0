"""The import rules of the README's "Architecture" section, as import-linter contracts in
pyproject.toml ([tool.importlinter]): `twin` never imports `service` (nor fastapi, zenoh, rerun,
matplotlib); the runtime engine never imports `twin.validation` (the offline science); `service.core` imports no
fastapi, zenoh or rerun, nor the wings built on them;
the service's layers go tools > reports > api > wiring > bus | recording > core > settings; twin's
layers go validation > engine > its couplings > state > model > spec > kernels > laws > jit, with
every module of twin placed in a layer (exhaustive); no import cycle among the modules of `service`
and `loadtest`, nor among those of `twin`; the runtime never imports the load tools.
import-linter reads every import statement, those inside functions included."""

from __future__ import annotations

import ast
import sys
import tomllib
from pathlib import Path

import pytest

lint = pytest.importorskip("importlinter.cli")

ROOT = Path(__file__).resolve().parents[1]


def test_the_contracts_are_declared():
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]
    contracts = {c["id"]: c for c in config["contracts"]}
    assert set(contracts) == {
        "engine",
        "runtime",
        "core",
        "layers",
        "service-acyclic",
        "twin-acyclic",
        "twin-layers",
        "loadtest",
    }
    assert contracts["service-acyclic"]["type"] == "acyclic_siblings"
    assert contracts["twin-acyclic"]["type"] == "acyclic_siblings" and contracts["twin-acyclic"]["ancestors"] == [
        "twin"
    ]
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
    twin_layers = contracts["twin-layers"]
    assert twin_layers["type"] == "layers" and twin_layers["containers"] == ["twin"] and twin_layers["exhaustive"]
    assert twin_layers["layers"][0] == "validation" and twin_layers["layers"][-1] == "jit"
    assert twin_layers["layers"][1].split(" | ")[0] == "engine"


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
    config.write_text(
        '[tool.importlinter]\nroot_packages = ["demo"]\ninclude_external_packages = true\n\n'
        '[[tool.importlinter.contracts]]\nname = "core has no web"\ntype = "forbidden"\n'
        'source_modules = ["demo.core"]\nforbidden_modules = ["fastapi"]\n'
    )
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
    config.write_text(
        '[tool.importlinter]\nroot_packages = ["demo_cycle"]\n\n'
        '[[tool.importlinter.contracts]]\nname = "acyclic"\ntype = "acyclic_siblings"\n'
        'ancestors = ["demo_cycle"]\n'
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    sys.modules.pop("demo_cycle", None)
    assert lint.lint_imports(config_filename=str(config), no_cache=True, no_logo=True) == 1


def test_an_unplaced_module_and_an_upward_import_are_caught(tmp_path, monkeypatch):
    """An exhaustive `layers` contract such as twin's fails on a module placed in no layer and on
    a lower layer importing a higher one."""
    pkg = tmp_path / "demo_layers"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "facade.py").write_text("from demo_layers.laws import law\n")
    (pkg / "laws.py").write_text("def law():\n    return 1.0\n")
    config = tmp_path / "contracts.toml"
    config.write_text(
        '[tool.importlinter]\nroot_packages = ["demo_layers"]\n\n'
        '[[tool.importlinter.contracts]]\nname = "layers"\ntype = "layers"\n'
        'containers = ["demo_layers"]\nexhaustive = true\nlayers = ["facade", "laws"]\n'
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    for name in ("demo_layers", "demo_layers.facade", "demo_layers.laws"):
        sys.modules.pop(name, None)
    assert lint.lint_imports(config_filename=str(config), no_cache=True, no_logo=True) == 0
    (pkg / "extra.py").write_text("")
    assert lint.lint_imports(config_filename=str(config), no_cache=True, no_logo=True) == 1
    (pkg / "extra.py").unlink()
    (pkg / "laws.py").write_text("def law():\n    from demo_layers import facade\n    return facade\n")
    assert lint.lint_imports(config_filename=str(config), no_cache=True, no_logo=True) == 1


def test_twin_imports_at_module_top():
    """Every import of twin/ sits at the top of its module (or under `if TYPE_CHECKING`), where
    import-linter and a reader see it: no function-local import hides a dependency or a cycle."""
    local = []
    for path in sorted((ROOT / "twin").rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for fn in ast.walk(tree):
            if isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)):
                local += [
                    f"{path.relative_to(ROOT)}:{st.lineno}"
                    for st in ast.walk(fn)
                    if isinstance(st, (ast.Import, ast.ImportFrom))
                ]
    assert local == []
