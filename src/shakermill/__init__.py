"""shakermill: thermomechanical simulation of a high-energy shaker mill (SPEX 8000M type).

``shakermill.simulate(params) -> Result`` runs the model of docs/MODEL.md;
``shakermill.default_parameters()`` gives the ``spex8000m`` preset;
``shakermill.sweep(base, {"omega": [...], "amplitude": [...]}, out_dir) -> pandas.DataFrame``
runs one simulation per point of a grid (in parallel, resumable); ``shakermill.calibrate`` fits
free keys to a measured curve. The layers of the package are described in docs/ARCHITECTURE.md.

The names are imported when first used, so that ``import shakermill`` (and ``shakermill --help``)
does not load NumPy, Numba, pandas, xarray and SciPy before anything needs them.
"""

from importlib import import_module

from shakermill.support.numba_cache import drop_stale_cache
from shakermill.support.version import __version__
from shakermill.views.notebook import register_presenters

drop_stale_cache()
register_presenters()

# The public names, and the modules that define them.
_LAZY = {
    "Parameters": "shakermill.parameters.keys",
    "ParameterError": "shakermill.parameters.errors",
    "build_parameters": "shakermill.parameters.keys",
    "default_parameters": "shakermill.parameters.presets",
    "Result": "shakermill.solvers.result",
    "simulate": "shakermill.solvers.simulate",
    "sweep": "shakermill.studies.sweeps.sweep",
    "calibrate": "shakermill.studies.calibration.calibrate",
}

__all__ = [*_LAZY, "__version__"]


def __getattr__(name: str) -> object:
    if name not in _LAZY:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(import_module(_LAZY[name]), name)
    globals()[name] = value
    return value
