"""shakermill: thermomechanical simulation of a high-energy shaker mill (SPEX 8000M type).

``shakermill.simulate(params) -> Result`` runs the full-resolution model of
MODEL.md; ``shakermill.default_parameters()`` gives the ``spex8000m`` preset;
``shakermill.sweep(base, {"omega": [...], "amplitude": [...]}, out_dir) -> pandas.DataFrame``
runs one simulation per point of a grid (in parallel, resumable).

The names are imported when first used, so that ``import shakermill`` (and ``shakermill --help``)
does not load NumPy, Numba, pandas, xarray and SciPy before anything needs them.
"""

import sys
import types
from importlib import import_module
from importlib.metadata import PackageNotFoundError, version

# Before the submodules: they record the version in the files they write.
try:
    __version__ = version("shakermill")
except PackageNotFoundError:  # running from a source tree without installation
    __version__ = "0+unknown"

from ._numba_cache import drop_stale_cache  # noqa: E402

drop_stale_cache()

_LAZY = {
    "Parameters": "params",
    "ParameterError": "params",
    "build_parameters": "params",
    "default_parameters": "params",
    "Result": "simulate",
}

__all__ = [*_LAZY, "simulate", "sweep", "__version__"]


def __getattr__(name: str) -> object:
    if name not in _LAZY:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(import_module(f".{_LAZY[name]}", __name__), name)
    globals()[name] = value
    return value


class _FunctionOfItsModule:
    """A package attribute that is the function of the same name in the submodule of that name.

    Importing a submodule binds its name on the package; the ignored assignment keeps the function
    there, as ``from .sweep import sweep`` at the end of an eager ``__init__`` did. The modules'
    other names are imported with ``from shakermill.sweep import ...``.
    """

    def __set_name__(self, _owner: type, name: str) -> None:
        self.name = name

    def __get__(self, _package: object, _owner: type | None = None) -> object:
        return getattr(import_module(f".{self.name}", __name__), self.name)

    def __set__(self, _package: object, _module: object) -> None:
        pass


class _Package(types.ModuleType):
    simulate = _FunctionOfItsModule()
    sweep = _FunctionOfItsModule()


sys.modules[__name__].__class__ = _Package
