"""shakermill: thermomechanical simulation of a high-energy shaker mill (SPEX 8000M type).

``shakermill.simulate(params) -> Result`` runs the full-resolution model of
MODEL.md; ``shakermill.default_parameters()`` gives the ``spex8000m`` preset;
``shakermill.sweep(base, {"omega": [...], "amplitude": [...]}, out_dir) -> pandas.DataFrame``
runs one simulation per point of a grid (in parallel, resumable).
"""

from importlib.metadata import PackageNotFoundError, version

# Before the submodules: they record the version in the files they write.
try:
    __version__ = version("shakermill")
except PackageNotFoundError:  # running from a source tree without installation
    __version__ = "0+unknown"

from ._numba_cache import drop_stale_cache  # noqa: E402

drop_stale_cache()

from .params import Parameters, ParameterError, build_parameters, default_parameters  # noqa: E402
from .simulate import Result, simulate  # noqa: E402

# The function shadows its module as an attribute of the package, so that ``shakermill.sweep(...)``
# runs a sweep; the module's other names are imported with ``from shakermill.sweep import ...``.
from .sweep import sweep  # noqa: E402

__all__ = [
    "Parameters",
    "ParameterError",
    "Result",
    "build_parameters",
    "default_parameters",
    "simulate",
    "sweep",
    "__version__",
]
