"""The keys of the SPEX 8000M clamp's figure of eight (``parameters/motions/spex8000m.py``): its lateral motion and
its yaw, each a stated assumption (no published value found)."""

from __future__ import annotations

import math

from shakermill.parameters.fields import quantity
from shakermill.parameters.key_group import BY_MOTION, VIAL_MOTION, KeyGroup
from shakermill.parameters.motions import MAX_MOTION_TRANSLATION, NO_SOURCE


class SpexClamp(KeyGroup):
    """The SPEX clamp's lateral motion and yaw (``kinematics = 'spex8000m'``); 0 leaves either out."""

    title = "the SPEX 8000M clamp"
    rule = BY_MOTION
    role = VIAL_MOTION

    # Half a metre, as any translation of a vial. A figure of eight visibly narrower than long: 2Y = 10 mm across a
    # 2X_v = 50 mm stroke (1:5).
    lateral_amplitude: float = quantity(
        "m",
        "kinematics = 'spex8000m': lateral amplitude Y of the vial's centre, y = Y sin 2θ",
        default=5e-3,
        source="assumption: ±5 mm at twice the drive frequency, a figure of eight 10 mm wide across the 50 mm stroke; "
        f"{NO_SOURCE}",
        ge=0,
        le=MAX_MOTION_TRANSLATION,
    )
    # A quarter turn, far beyond the few degrees a clamp turns. A clamp carried on a curved path of radius ρ turns by
    # X_v/ρ: ρ ≈ 0.3 m, the size of the mill's housing, gives 25 mm/0.3 m = 0.083 rad.
    yaw_amplitude: float = quantity(
        "rad",
        "kinematics = 'spex8000m': yaw amplitude Ψ about the vertical, yaw = Ψ sin θ",
        default=math.radians(5.0),
        source="assumption: ±5° (0.0873 rad) in phase with the stroke, X_v/ρ for a curved path of radius ρ ≈ 0.3 m; "
        f"{NO_SOURCE}",
        ge=0,
        le=0.5 * math.pi,
    )
