"""YAML as people write numbers in it: the loader of spec files and scenarios.

YAML 1.1, PyYAML's default, reads `5e-4` and `1e-5` (an exponent without a decimal point) as
strings; YAML 1.2 and JSON read them as numbers. The spec and scenario models are strict (a
string is never taken for a number), so both files are read with YAML 1.2's float rule."""

from __future__ import annotations

import re
from typing import Any

import yaml


class Yaml12NumbersLoader(yaml.SafeLoader):
    """PyYAML's safe loader with YAML 1.2's floats: `5e-4` is a float, as `5.0e-4` is."""


Yaml12NumbersLoader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(
        r"""^(?:[-+]?(?:[0-9][0-9_]*)\.[0-9_]*(?:[eE][-+]?[0-9]+)?
                |[-+]?(?:[0-9][0-9_]*)(?:[eE][-+]?[0-9]+)
                |\.[0-9_]+(?:[eE][-+]?[0-9]+)?
                |[-+]?\.(?:inf|Inf|INF)
                |\.(?:nan|NaN|NAN))$""",
        re.X,
    ),
    list("-+0123456789."),
)


def load_yaml(text: str) -> Any:
    """The document of `text` (yaml.YAMLError when it is not YAML)."""
    return yaml.load(text, Loader=Yaml12NumbersLoader)
