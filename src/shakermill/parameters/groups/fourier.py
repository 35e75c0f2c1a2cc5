"""The key of a motion given as Fourier terms (``parameters/motions/fourier.py``)."""

from __future__ import annotations

from shakermill.parameters.fields import MAX_HARMONICS, Harmonic, listed
from shakermill.parameters.key_group import BY_MOTION, VIAL_MOTION, KeyGroup


class FourierMotion(KeyGroup):
    """The terms of the user's own vial motion (``kinematics = 'fourier'``)."""

    title = "a motion of Fourier terms"
    rule = BY_MOTION
    role = VIAL_MOTION

    motion: tuple[Harmonic, ...] = listed(
        "m or rad",
        "kinematics = 'fourier': (coordinate, k, cos, sin) terms of the vial's translations x, y, z (m) and angles "
        "roll, pitch, yaw (rad) in the harmonics k of θ = ωt + φ; an angle's sin at k = 0 turns it steadily by that "
        "many radians per radian of θ",
        default=(),
        source="used only with kinematics = 'fourier'",
        most=MAX_HARMONICS,
    )
