"""The key of a horizontal mixer mill's arc (``parameters/motions/mixer_mill_arc.py``): the radius of the jar's
swing, a stated assumption (no published value found)."""

from __future__ import annotations

from shakermill.parameters.fields import quantity
from shakermill.parameters.key_group import BY_MOTION, VIAL_MOTION, KeyGroup
from shakermill.parameters.motions import NO_SOURCE


class MixerArc(KeyGroup):
    """The swing radius of a jar on a horizontal arc (``kinematics = 'mixer-mill-arc'``)."""

    title = "the mixer mill's arc"
    rule = BY_MOTION
    role = VIAL_MOTION

    # 1 mm to 1 m: from a jar turning about a pivot next to it to an arm longer than any mill. Mixer mills carry their
    # jars on arms of the order of a decimetre (the mill is ~0.4 m wide).
    swing_radius: float = quantity(
        "m",
        "kinematics = 'mixer-mill-arc': radius R of the jar centre's arc about the vertical pivot",
        default=0.1,
        source="assumption: 100 mm from the vertical pivot to the jar's centre, an arm of the size of a mixer mill's "
        f"housing; {NO_SOURCE}",
        ge=1e-3,
        le=1.0,
    )
