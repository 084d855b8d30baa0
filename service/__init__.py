"""bearing-twin service: HTTP (api), zenoh (bus), rerun (recorder), the core it wraps, tools and reports."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("bearing-twin")  # written once, in pyproject.toml
except PackageNotFoundError:  # a source tree that is not installed
    __version__ = "0+unknown"
