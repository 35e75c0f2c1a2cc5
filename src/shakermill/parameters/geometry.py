"""The geometry of balls and vials (MODEL.md sections 1 and 6): volumes, areas, and how many balls fill a vial."""

from __future__ import annotations

import math

# No packing of equal spheres fills more of space than π/√18 (Kepler's conjecture, proved by Hales), let
# alone a vial, whose walls leave gaps: the bound of ``fill``.
DENSEST_PACKING = math.pi / math.sqrt(18.0)


def ball_volume(radius: float) -> float:
    """4/3·π R³ (m³) of a ball of radius ``radius`` (m)."""
    return 4.0 / 3.0 * math.pi * radius**3


def vial_volume(vial_length: float, vial_diameter: float) -> float:
    """π d_v²/4·l_v (m³): the inner volume of a cylindrical vial (m, m)."""
    return math.pi * vial_diameter**2 / 4.0 * vial_length


def balls_for_fill(fill: float, ball_radius: float, vial_length: float, vial_diameter: float) -> int:
    """How many equal balls of ``ball_radius`` (m) take ``fill`` of a vial's inner volume (m, m; fill
    dimensionless): n = max(1, round(fill·V_vial/V_ball)), V_vial = π d_v²/4·l_v, halves rounded up."""
    balls = fill * vial_volume(vial_length, vial_diameter) / ball_volume(ball_radius)
    return max(1, math.floor(balls + 0.5))


def end_faces_area(vial_diameter: float) -> float:
    """Area of the two circular end faces of a vial of inner diameter ``vial_diameter`` (m²)."""
    return 2.0 * math.pi * vial_diameter**2 / 4.0


def bore_area(vial_diameter: float, vial_length: float) -> float:
    """Inner area of a flat-ended cylindrical bore: its side and both ends (m²)."""
    return math.pi * vial_diameter * vial_length + end_faces_area(vial_diameter)


def wall_volume(outer_diameter: float, outer_length: float, vial_diameter: float, vial_length: float) -> float:
    """Volume of the material between a cylinder's outside and its bore (m³)."""
    return math.pi / 4.0 * (outer_diameter**2 * outer_length - vial_diameter**2 * vial_length)
