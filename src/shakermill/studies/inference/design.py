"""Where a study's runs go: a scrambled Sobol' design over a prior's unit cube (``scipy.stats.qmc``), balanced at
powers of two, its seed a hash of the configuration and the prior, so that the same study asked for twice runs the same
points (and resumes)."""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Sequence

import numpy as np

from shakermill.parameters.assumed import AssumedInput
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.keys import Parameters


def check_power_of_two(name: str, count: int) -> None:
    if count < 1 or count & (count - 1):
        raise ParameterError(f"{name}: {count} is not allowed; a power of two (a Sobol' design is balanced there)")


def sobol(dimensions: int, count: int, seed: int) -> np.ndarray:
    """``count`` points (a power of two) of a scrambled Sobol' design over the unit cube of ``dimensions``."""
    from scipy.stats import qmc

    return qmc.Sobol(dimensions, scramble=True, seed=seed).random_base2(int(math.log2(count)))


def design_seed(base: Parameters, inputs: Sequence[AssumedInput]) -> int:
    """A design's seed: a hash of the configuration and the inputs' ranges, so that the same design asked for twice
    has the same points."""
    # An input that moves no derived key hashes as before that field existed: recorded ensembles keep their members.
    described = [{key: value for key, value in vars(item).items() if key != "moves" or value} for item in inputs]
    text = json.dumps([base.model_dump(mode="json"), described], sort_keys=True, default=str)
    return int.from_bytes(hashlib.sha256(text.encode()).digest()[:4], "big")
