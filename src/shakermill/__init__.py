"""shakermill: thermomechanical simulation of a high-energy shaker mill (SPEX 8000M type).

``shakermill.simulate(params) -> Result`` runs the full-resolution model of
MODEL.md; ``shakermill.default_parameters()`` gives the ``spex8000m`` preset.
"""

from importlib.metadata import PackageNotFoundError, version

from ._numba_cache import drop_stale_cache

drop_stale_cache()

from .params import Parameters, ParameterError, build_parameters, default_parameters  # noqa: E402
from .simulate import Result, simulate  # noqa: E402

try:
    __version__ = version("shakermill")
except PackageNotFoundError:  # running from a source tree without installation
    __version__ = "0+unknown"

__all__ = ["Parameters", "ParameterError", "Result", "build_parameters", "default_parameters", "simulate", "__version__"]
