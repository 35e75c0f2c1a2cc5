"""Named motions of the vial for the 'dem' engine (MODEL.md section 12.2), one module each, as data.

A motion is the Fourier terms ``(coordinate, k, cos, sin)`` of the vial's six rigid-body coordinates in the harmonics
k of θ = ωt + φ (translations x, y, z of its centre in m; roll, pitch, yaw about the lab's x, y, z axes in rad), made
by its ``terms`` function from the keys that function takes. ``engines.dem.model.harmonics_of`` turns them into the
array the compiled stepping evaluates (``physics.kinematics.fourier_coordinates``), so a new mill is a module here,
a :class:`KinematicModel` named ``MOTION``, and its keys a group in ``parameters/groups/``; nothing else names it
(``kinematic_models.KINEMATIC_MODELS`` finds it). Angles may also turn steadily (a k = 0 term's sine is its rate per
radian of θ), as a planetary mill's do. The lab frame has z up; every motion but the planetary keeps the vial's axis
horizontal, so gravity stays along −z of the vial at rest; a planetary jar stands on its end.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

Term = tuple[str, int, float, float]

# The vial's six rigid-body coordinates: translations of its centre (m) and angles about the lab's axes (rad).
MOTION_COORDINATES = ("x", "y", "z", "roll", "pitch", "yaw")
# Harmonics beyond the 20th describe no mill (a user's `motion` is held to it too).
MAX_MOTION_HARMONIC = 20
# Translations of a vial beyond half a metre describe no mill.
MAX_MOTION_TRANSLATION = 0.5
# Where no source reachable here gives a motion's amplitude or phase (its keys' sources cite this).
NO_SOURCE = "no published value found (docs/notes/dem-references.md §§2.3-2.4)"


def _no_check(values: Any) -> None:
    """A motion whose terms are well formed for every value its keys' bounds allow."""


@dataclass(frozen=True)
class KinematicModel:
    """A vial motion: its name (the value of ``kinematics``), what it is, the function from its keys' values to its
    terms (its arguments are the keys it reads, in order), which of those keys no source gives, and the check across
    its keys that their bounds cannot say (raising ``ValueError`` with one line naming the key)."""

    name: str
    description: str
    terms: Callable[..., tuple[Term, ...]]
    assumed: tuple[str, ...] = ()
    # The vial's axis stands up (its frame's x along the lab's z) and the vial is carried across it, as a planetary
    # jar round its sun wheel: the air meets its outside across the axis, not along it as a shaken vial's
    # (engines/thermal/network.py), and the figures name its views as seen with the axis up (views/trajectories.py).
    axis_upright: bool = False
    check: Callable[[Any], None] = _no_check

    @property
    def keys(self) -> tuple[str, ...]:
        """The keys the motion reads: its terms' arguments."""
        return tuple(inspect.signature(self.terms).parameters)
