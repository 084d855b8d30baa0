"""Scenarios read and validated: from a parsed mapping (`scenario_from_dict`), from a YAML file with
YAML 1.2 numbers and bearing spec files beside it (`load_scenario`), by name from a folder
(`find_scenario`). Every error is a ScenarioError naming the field. The format: service.core.scenarios.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import yaml
from pydantic import ValidationError

from service.core.errors import loc_text
from service.core.scenarios import DESIGNATION_TAG, SPEC_TAG, Scenario, ScenarioError
from twin import catalog
from twin.yaml_numbers import load_yaml


# ---- loading ----------------------------------------------------------------------------------
def scenario_from_dict(data: Any, *, source: str = "scenario") -> Scenario:
    """Validate a parsed scenario. Raises ScenarioError naming the field (first error) and
    keeps pydantic's full error list in `__cause__`."""
    if not isinstance(data, dict):
        raise ScenarioError(
            source, f"a scenario is a mapping (name, duration_s, steps, ...), got {type(data).__name__}"
        )
    try:
        return Scenario.model_validate(data)
    except ValidationError as exc:
        located = [locate_error(e) for e in exc.errors()]
        where = located[0][0]
        message = "; ".join(f"{w or source}: {m}" for w, m in located)
        raise ScenarioError(where or source, message) from exc


_PATH_PREFIX = re.compile(r"^([A-Za-z_][\w.\[\]]*): (.*)$", re.DOTALL)


def locate_error(error: Mapping[str, Any]) -> tuple[str, str]:
    """(field path, message) of a pydantic error; model-level errors carry the path in front of
    their message ('steps[2].at_s: ...')."""
    where = loc_text([p for p in error.get("loc", ()) if p not in (DESIGNATION_TAG, SPEC_TAG)], skip=()) or ""
    msg = str(error.get("msg", "")).removeprefix("Value error, ")
    match = _PATH_PREFIX.match(msg)
    if match:
        path, rest = match.groups()
        return (f"{where}.{path}" if where else path), rest
    return where, msg


def load_scenario(path: str | Path) -> Scenario:
    """Read and validate a scenario YAML file."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ScenarioError(str(path), f"cannot read: {exc.strerror or exc}") from exc
    except UnicodeDecodeError as exc:
        raise ScenarioError(str(path), f"not UTF-8 text (byte {exc.start}): a scenario is a YAML file") from None
    try:
        data = load_yaml(text)  # YAML 1.2's numbers (twin.yaml_numbers): `5e-4` is a float
    except yaml.YAMLError as exc:
        raise ScenarioError(str(path), f"not valid YAML: {' '.join(str(exc).split())}") from exc
    if isinstance(data, dict):
        data = _read_spec_files(data, path.parent)
    return scenario_from_dict(data, source=str(path))


def _read_spec_files(data: dict, folder: Path) -> dict:
    """The scenario with every `bearing:` that names a spec file (top level and per run) replaced
    by the BearingSpec read from it, the path relative to `folder` (the scenario file's).
    ScenarioError naming `bearing` / `runs[j].bearing` (and the spec's field) when one cannot be read."""

    def read(value: Any, where: str) -> Any:
        if not (isinstance(value, str) and value.strip().lower().endswith(catalog.SPEC_FILE_SUFFIXES)):
            return value
        file = folder / value.strip()
        try:
            return catalog.load_spec_file(str(file))
        except ValidationError as exc:
            located = [locate_error(e) for e in exc.errors()]
            message = "; ".join(f"{w}: {m}" if w else m for w, m in located)
            raise ScenarioError(
                f"{where}.{located[0][0]}" if located[0][0] else where, f"spec file {str(file)!r}: {message}"
            ) from exc
        except ValueError as exc:
            raise ScenarioError(where, str(exc).removeprefix("bearing: ")) from None

    out = {**data, "bearing": read(data["bearing"], "bearing")} if "bearing" in data else dict(data)
    runs = data.get("runs")
    if isinstance(runs, list):
        out["runs"] = [
            {**run, "bearing": read(run["bearing"], f"runs[{j}].bearing")}
            if isinstance(run, dict) and "bearing" in run
            else run
            for j, run in enumerate(runs)
        ]
    return out


def list_scenarios(directory: str | Path) -> dict[str, Path]:
    """name -> file of every *.yaml / *.yml scenario in a directory (file stem = default name)."""
    directory = Path(directory)
    if not directory.is_dir():
        return {}
    out: dict[str, Path] = {}
    for p in sorted([*directory.glob("*.yaml"), *directory.glob("*.yml")]):
        out[p.stem] = p
    return out


def find_scenario(name: str, directory: str | Path) -> Scenario:
    """Load the named scenario from a directory (by file stem). Raises ScenarioError('name', ...)."""
    known = list_scenarios(directory)
    if name not in known:
        raise ScenarioError("name", f"unknown scenario {name!r}; known: {', '.join(known) or 'none'}", sorted(known))
    return load_scenario(known[name])
