"""The package version, single-sourced: pyproject.toml reads it from here (``[tool.setuptools.dynamic]``)."""

__version__ = "0.3.0.dev0"
