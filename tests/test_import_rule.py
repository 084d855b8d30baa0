"""DESIGN.md: `twin` never imports `service`, fastapi, zenoh or rerun (poliastro-style core rule)."""

import ast
import pathlib

FORBIDDEN = {"service", "fastapi", "zenoh", "rerun", "uvicorn", "starlette", "matplotlib"}


def test_twin_imports_nothing_of_the_outside_world():
    offenders = []
    for path in pathlib.Path(__file__).resolve().parents[1].joinpath("twin").rglob("*.py"):
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            names = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                names = [node.module]
            offenders += [f"{path.name}: {n}" for n in names if n.split(".")[0] in FORBIDDEN]
    assert offenders == []
