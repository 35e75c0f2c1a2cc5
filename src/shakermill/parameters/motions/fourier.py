"""The user's own motion: Fourier terms of the vial's six coordinates, given in the key ``motion``."""

from __future__ import annotations

import math
from typing import Any

from shakermill.parameters.motions import MAX_MOTION_TRANSLATION, MOTION_COORDINATES, KinematicModel, Term

# A steady turn of more than five radians per radian of the drive's phase describes no mill (planetary jars turn
# at most ~3 times their sun wheel's speed), as speed_ratio's bounds say.
MAX_STEADY_RATE = 5.0


def given_terms(motion: tuple[Term, ...]) -> tuple[Term, ...]:
    """The user's own terms (key ``motion``)."""
    return motion


def check_motion(values: Any) -> None:
    """The motion has terms; the summed harmonic amplitudes of each coordinate stay within a metre's half and a half
    turn; only angles turn steadily (a k = 0 sine), and at most MAX_STEADY_RATE."""
    motion = values.motion
    if not motion:
        raise ValueError(
            "motion: kinematics = 'fourier' needs at least one harmonic; allowed (coordinate, k, cos, sin) terms"
        )
    for name, k, _, steady in motion:
        if k == 0 and steady != 0.0 and (name in MOTION_COORDINATES[:3] or abs(steady) > MAX_STEADY_RATE):
            raise ValueError(
                f"motion: a steady rate {steady:g} of {name} (its sin at k = 0); allowed only for roll, pitch and yaw, "
                f"at most {MAX_STEADY_RATE:g} rad per radian of ωt + φ"
            )
    for coordinate in MOTION_COORDINATES:
        amplitude = sum(abs(a) + abs(b) * (k > 0) for name, k, a, b in motion if name == coordinate)
        limit, unit = (math.pi, "rad") if coordinate in ("roll", "pitch", "yaw") else (MAX_MOTION_TRANSLATION, "m")
        if amplitude > limit:
            raise ValueError(
                f"motion: the harmonics of {coordinate} add up to {amplitude:g} {unit}; allowed at most {limit:g} "
                f"{unit}"
            )


MOTION = KinematicModel("fourier", "the user's Fourier terms in `motion`", given_terms, check=check_motion)
