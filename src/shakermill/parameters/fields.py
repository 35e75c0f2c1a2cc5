"""The building blocks of :class:`~shakermill.parameters.keys.Parameters`' fields: a field of each kind (a
quantity with its unit, a count, a material's name, a choice, a per-ball list) with its description, and the
shapes of the tuple keys (a harmonic of the vial's motion, a recording window)."""

from __future__ import annotations

from typing import Annotated, Any, Literal

import annotated_types
from pydantic import Field

from shakermill.parameters.engine_keys import MAX_BALLS
from shakermill.parameters.kinematic_models import MAX_MOTION_HARMONIC
from shakermill.support.limits import MAX_RECORDED_SECONDS


def quantity(unit: str, description: str, **bounds: float) -> Any:
    return Field(json_schema_extra={"unit": unit, "description": description}, **bounds)


def count(description: str, **bounds: int) -> Any:
    return Field(json_schema_extra={"unit": "", "description": description}, strict=True, **bounds)


def material_name(of: str, keys: str) -> Any:
    return Field(
        json_schema_extra={
            "unit": "",
            "description": f"material of {of} from `shakermill materials`: fills {keys} unless they are set with it or "
            "later; '': none",
        }
    )


def choice(description: str) -> Any:
    """A key that names one of a few alternatives (a ``Literal``), and what each means."""
    return Field(json_schema_extra={"description": description})


def per_ball(scalar_key: str) -> Any:
    return Field(
        max_length=MAX_BALLS,
        json_schema_extra={
            "unit": "",
            "per_ball": scalar_key,
            "description": f"per-ball {scalar_key} (engine = 'dem')",
        },
    )


# The most harmonics of a user-given vial motion.
MAX_HARMONICS = 60
Harmonic = tuple[
    Literal["x", "y", "z", "roll", "pitch", "yaw"],
    Annotated[int, annotated_types.Ge(0), annotated_types.Le(MAX_MOTION_HARMONIC)],
    float,
    float,
]


# The longest run (s): longer than any milling run (~100 h).
LONGEST_RUN_S = 1e6
Window = tuple[
    # A window may start anywhere in the longest run; its length is capped with the others' (MAX_RECORDED_SECONDS).
    Annotated[float, annotated_types.Ge(0), annotated_types.Le(LONGEST_RUN_S)],
    Annotated[float, annotated_types.Gt(0), annotated_types.Le(MAX_RECORDED_SECONDS)],
]


# Stress energies (J) a run reports the power of the impacts above: a ball of a gram at a centimetre a second stores
# ~0.05 µJ, a 40 mm steel ball at 10 m/s ~13 J; 1 nJ to 1 kJ spans every mill, and eight thresholds any spectrum.
MAX_STRESS_THRESHOLDS = 8
StressThreshold = Annotated[float, annotated_types.Ge(1e-9), annotated_types.Le(1e3)]
