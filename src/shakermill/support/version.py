"""The package's version, recorded in every file shakermill writes; ``pyproject.toml`` reads it from here."""

__version__ = "0.1.0"
