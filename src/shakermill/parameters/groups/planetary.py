"""The keys of a planetary mill's jar on its sun wheel (``parameters/motions/planetary.py``)."""

from __future__ import annotations

import math

from shakermill.parameters.fields import quantity
from shakermill.parameters.key_group import BY_MOTION, VIAL_MOTION, KeyGroup


class Planetary(KeyGroup):
    """The radius of the jar's circle, the jar's speed relative to the sun wheel and its tilt (``kinematics =
    'planetary'``)."""

    title = "the planetary jar"
    rule = BY_MOTION
    role = VIAL_MOTION

    # A planetary jar's sun wheel: from a laboratory mill's ~5 cm to a metre, beyond any production mill's.
    revolution_radius: float = quantity(
        "m",
        "kinematics = 'planetary': radius R_p of the jar centre's circle about the sun axis",
        default=0.07,
        source="Fritsch Pulverisette 7 premium line: effective sun-disc diameter 140 mm (used only by kinematics = "
        "'planetary')",
        ge=1e-2,
        le=1.0,
    )
    # The jar's speed relative to the sun wheel: mills are built from −3 to −1 (Retsch, Fritsch); ±5 covers any gear.
    speed_ratio: float = quantity(
        "",
        "kinematics = 'planetary': the jar's spin relative to the sun wheel, k of 1 : k",
        default=-2.0,
        source="Retsch PM 100 and Fritsch Pulverisette 7: jar to sun wheel 1 : −2 (kinematics = 'planetary')",
        ge=-5.0,
        le=5.0,
    )
    # Jars stand upright in most mills; tilted ones lean by tens of degrees. Past 60° a jar would lie nearly flat.
    jar_tilt: float = quantity(
        "rad",
        "kinematics = 'planetary': lean of the jar's top away from the sun axis",
        default=0.0,
        source="upright jars, as in the Pulverisette 7 and PM 100 (kinematics = 'planetary')",
        ge=0.0,
        le=math.pi / 3,
    )
