"""The building blocks of a key group's fields (:mod:`key_group`): a field of each kind (a quantity with its unit, a
count, a switch, a material's name, a choice, a per-ball list, a list of terms) with its description, its default
and the source of that default; and the shapes of the tuple keys (a harmonic of the vial's motion, a recording
window, a stress-energy threshold).

A field's ``json_schema_extra`` carries what the package reads of it besides its type and bounds: ``unit``,
``description``, ``source`` (of its default), ``per_ball`` (the scalar key a per-ball list refines), ``material``
(a key that names materials) and ``thermal_only`` (a key that enters the thermal network alone, never a force, a
contact's heat or what the stepping measures: runs that differ in such keys alone share one measured mechanics,
``EngineKeys.thermal_only_keys``)."""

from __future__ import annotations

from collections.abc import Iterable
from typing import Annotated, Any, Literal

import annotated_types
from pydantic import Field, JsonValue
from pydantic_core import PydanticCustomError

from shakermill.parameters.motions import MAX_MOTION_HARMONIC
from shakermill.support.limits import MAX_BALLS, MAX_RECORDED_SECONDS


def _extra(unit: str, description: str, source: str, thermal_only: bool, **more: JsonValue) -> dict[str, JsonValue]:
    return {
        "unit": unit,
        "description": description,
        "source": source,
        **({"thermal_only": True} if thermal_only else {}),
        **more,
    }


def quantity(
    unit: str,
    description: str,
    *,
    default: float,
    source: str,
    thermal_only: bool = False,
    gt: float | None = None,
    ge: float | None = None,
    lt: float | None = None,
    le: float | None = None,
) -> Any:
    extra = _extra(unit, description, source, thermal_only)
    return Field(default, json_schema_extra=extra, gt=gt, ge=ge, lt=lt, le=le)


def count(
    description: str,
    *,
    default: int,
    source: str,
    strict: bool = True,
    gt: int | None = None,
    ge: int | None = None,
    le: int | None = None,
) -> Any:
    extra = _extra("", description, source, False)
    return Field(default, json_schema_extra=extra, strict=strict, gt=gt, ge=ge, le=le)


def switch(description: str, *, default: bool, source: str) -> Any:
    """A key that is true or false."""
    return Field(default, strict=True, json_schema_extra=_extra("", description, source, False))


def material_name(of: str, keys: str, *, default: str, source: str) -> Any:
    description = (
        f"material of {of} from `shakermill materials`: fills {keys} unless they are set with it or later; '': none"
    )
    return Field(default, json_schema_extra=_extra("", description, source, False, material=True))


def choice(description: str, *, default: str, source: str, thermal_only: bool = False) -> Any:
    """A key that names one of a few alternatives (a ``Literal``), and what each means."""
    return Field(default, json_schema_extra=_extra("", description, source, thermal_only))


def one_of(value: Any, names: Iterable[str]) -> Any:
    """``value`` where it is one of ``names`` (a key whose choices are found at import: the engines, the motions),
    refused as pydantic words a value outside a ``Literal``'s choices, as the other options are."""
    if value not in names:
        raise PydanticCustomError(
            "literal_error", "Input should be {expected}", {"expected": " or ".join(map(repr, names))}
        )
    return value


def per_ball(scalar_key: str, *, source: str = "every ball takes the scalar key's value") -> Any:
    return Field(
        (),
        max_length=MAX_BALLS,
        json_schema_extra=_extra("", f"per-ball {scalar_key} (engine = 'dem')", source, False, per_ball=scalar_key),
    )


def listed(
    unit: str, description: str, *, default: tuple[Any, ...], source: str, most: int, material: bool = False
) -> Any:
    """A key that holds a list of values or terms (at most ``most``); ``material``: of materials' names."""
    marks = {"material": True} if material else {}
    return Field(default, max_length=most, json_schema_extra=_extra(unit, description, source, False, **marks))


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
