"""The installed package's version, recorded in every file shakermill writes."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("shakermill")
except PackageNotFoundError:  # running from a source tree without installation
    __version__ = "0+unknown"
