"""The vial's inner size and its drive: the frequency and phase every motion turns by, and the stroke of the motions
that take one."""

from __future__ import annotations

import math

from shakermill.parameters.fields import quantity
from shakermill.parameters.key_group import BY_MOTION, KeyGroup
from shakermill.parameters.sources import PAPER


class Vial(KeyGroup):
    """The vial's inner length and diameter (MODEL.md §1)."""

    title = "the vial's size"

    # 1 mm to 1 m: from micro-vials to twice the largest vibratory mill's vessel.
    vial_length: float = quantity(
        "m", "inner length of the vial l_v", default=58e-3, source=f"{PAPER}, Table 1", ge=1e-3, le=1.0
    )
    vial_diameter: float = quantity(
        "m",
        "inner diameter of the vial d_v",
        default=19e-3,
        source=f"{PAPER}, Table 1 (A_i = A_o = 567.06 mm² = 2·π·d_v²/4)",
        ge=1e-3,
        le=1.0,
    )


class Drive(KeyGroup):
    """The drive's frequency and its phase at t = 0: θ = ωt + φ of every vial motion (MODEL.md §§1, 12.2)."""

    title = "the drive"

    # 1 rad/s (0.16 Hz): thirty times slower than any mill. 1e4 rad/s (1.6 kHz): beyond acoustic mixers
    # (60 Hz), high enough that 1060 typed for rpm is warned about, not refused; the step count grows with ω.
    omega: float = quantity(
        "rad/s",
        "vial angular frequency ω (kinematics = 'planetary': the sun wheel's speed)",
        default=111.0,
        source="assumption: not stated (range 90-130 rad/s); ~1060 cycles/min, the SPEX 8000M on 60 Hz mains",
        ge=1.0,
        le=1e4,
    )
    # One turn either way: every phase has an equal one inside, and larger ones only cost precision in sin(ωt + φ).
    phase: float = quantity(
        "rad", "vial phase φ at t = 0", default=0.0, source="assumption", ge=-2 * math.pi, le=2 * math.pi
    )


class Stroke(KeyGroup):
    """The stroke of the motions that take one (``axial``, ``spex8000m``, ``mixer-mill-arc``): read where the run's
    motion takes it."""

    title = "the stroke"
    rule = BY_MOTION

    # Open at 0: a vanishing stroke is a resting wall, the analytic test of a single impact. 0.5 m: five
    # times the longest stroke of a shaker mill.
    amplitude: float = quantity(
        "m",
        "vial oscillation amplitude X_v (kinematics = 'mixer-mill-arc': along the arc, at the jar's centre)",
        default=25e-3,
        source=f"{PAPER}, Table 1 (X_v)",
        gt=0,
        le=0.5,
    )
