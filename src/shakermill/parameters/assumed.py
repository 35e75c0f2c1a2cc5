"""Assumed inputs: values no source fixes, each with a range, a distribution and its reason (MODEL.md §14.1).

A preset states them in ``[assumed.KEY]`` tables of its file (``low``, ``high`` in the key's SI unit,
``distribution``, ``reason``); a preset inherits those of the preset it builds on, but not a key it fitted (its
posterior says what it is) nor a key its own run does not read (a planetary jar has no SPEX clamp's yaw).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

from shakermill.parameters.engine_keys import Reader
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.file_models import DERIVED_KEYS, AssumedTable, read_table
from shakermill.parameters.geometry import bore_area, wall_volume
from shakermill.parameters.keys import Parameters, bounds, field_unit

TABLE_FIELDS = ("low", "high", "distribution", "reason")
# A table may also say which keys derived from the vial's dimensions follow the input (``moves``): a bowl whose bore
# is uncertain has an inner area and a mass that go with it, and a member that moved one alone would be no bowl.
MOVES_FIELD = "moves"
BOWL_KEYS = ("vial_diameter", "vial_length", "outer_diameter", "outer_length")


@dataclass(frozen=True)
class AssumedInput:
    """One assumed input: its key, range (SI), distribution and reason."""

    key: str
    low: float
    high: float
    distribution: str
    reason: str
    moves: tuple[str, ...] = ()

    def shown_range(self) -> str:
        unit = field_unit(self.key)
        return f"[{self.low:g}, {self.high:g}]" + (f" {unit}" if unit else "")

    def contains(self, value: float) -> bool:
        return self.low <= value <= self.high

    def table(self) -> dict[str, Any]:
        """Its ``[assumed.KEY]`` table: range, distribution and reason."""
        return {field: getattr(self, field) for field in TABLE_FIELDS}


def assumed_input(key: str, table: Any, where: str) -> AssumedInput:
    """The ``[assumed.KEY]`` ``table`` of ``where`` (a preset file, a command's option), checked: a numeric key,
    every field and no other, low < high within the key's bounds, and a known distribution."""
    name = f"{where}: [assumed.{key}]"
    field = Parameters.model_fields.get(key)
    if field is None or field.annotation is not float:
        raise ParameterError(f"{name}: {key!r} is not a numeric key of a single value; only those can be assumed")
    read = read_table(AssumedTable, table, name)
    low, high, distribution, moves = read.low, read.high, read.distribution, read.moves
    if key not in BOWL_KEYS and moves:
        raise ParameterError(
            f"{name}: {MOVES_FIELD} lists keys derived from the vial's dimensions "
            f"({', '.join(DERIVED_KEYS)}), only for {', '.join(BOWL_KEYS)}"
        )
    if not low < high:
        raise ParameterError(f"{name}: low and high must be finite numbers with low < high, not {low!r}, {high!r}")
    allowed = bounds(key)
    if not (allowed.contains(low) and allowed.contains(high)):
        raise ParameterError(f"{name}: [{low:g}, {high:g}] leaves {key}'s allowed range {allowed}")
    if distribution == "log-uniform" and low <= 0:
        raise ParameterError(f"{name}: distribution log-uniform needs low > 0")
    return AssumedInput(key, low, high, distribution, read.reason, moves)


def check_holds(assumed: AssumedInput, value: float, where: str) -> None:
    """A preset's own value of an assumed input lies in the range it states."""
    if not assumed.contains(float(value)):
        raise ParameterError(
            f"{where}: [assumed.{assumed.key}]: the preset's {assumed.key} = {value:g} lies outside "
            f"its range {assumed.shown_range()}; state its own [assumed.{assumed.key}]"
        )


def check_derived(assumed: AssumedInput, values: Mapping[str, Any], where: str) -> None:
    """A key an input ``moves`` must be what the preset's own dimensions give (to 1e-6), or moving it with them would
    change the bowl in two ways at once (the bore's area; the wall's mass sets the density it moves with)."""
    for key, expected in derived_values(assumed.moves, values, values).items():
        if abs(float(values[key]) - expected) > 1e-6 * abs(expected):
            raise ParameterError(
                f"{where}: [assumed.{assumed.key}]: moves {key}, but the preset's {key} = "
                f"{float(values[key]):g} is not the {expected:g} its vial's dimensions give"
            )


def derived_values(keys: Sequence[str], values: Mapping[str, Any], base: Mapping[str, Any]) -> dict[str, float]:
    """``keys`` (of DERIVED_KEYS) for the vial dimensions of ``values``: the bore's area, and the mass of the wall
    at the density ``base``'s mass and dimensions imply (a preset states no density of its vial)."""

    def wall(of: Mapping[str, Any]) -> float:
        return wall_volume(
            *(float(of[key]) for key in ("outer_diameter", "outer_length", "vial_diameter", "vial_length"))
        )

    found = {}
    if "inner_area" in keys:
        found["inner_area"] = bore_area(float(values["vial_diameter"]), float(values["vial_length"]))
    if "vial_mass" in keys:
        found["vial_mass"] = float(base["vial_mass"]) * wall(values) / wall(base)
    return found


def with_derived(params: Parameters, inputs: Sequence[AssumedInput], point: Mapping[str, float]) -> dict[str, float]:
    """A member's values (``point``) of ``params`` with the keys its varied inputs move, derived again."""
    moved = tuple(dict.fromkeys(key for item in inputs if item.key in point for key in item.moves))
    if not moved:
        return dict(point)
    base = params.model_dump()
    return {**point, **derived_values(moved, {**base, **point}, base)}


def keeping_moves(user: AssumedInput, stated: Mapping[str, AssumedInput]) -> AssumedInput:
    """A user's range of an input with the derived keys the preset's range of it moves."""
    return replace(user, moves=stated[user.key].moves) if user.key in stated else user


def inherited_assumed(
    base: Mapping[str, AssumedInput],
    tables: Mapping[str, Any],
    values: Mapping[str, Any],
    fitted: tuple[str, ...],
    reader: Reader,
    where: str,
) -> dict[str, AssumedInput]:
    """A preset's assumed inputs: those of its ``base`` and its own ``tables`` (which replace the base's), less the
    keys it ``fitted`` and those its run (``reader``) does not read; each checked against the preset's ``values``."""
    own = {key: assumed_input(key, table, where) for key, table in tables.items()}
    kept = {
        key: assumed for key, assumed in {**base, **own}.items() if key not in fitted and reader.not_read(key) is None
    }
    for key, assumed in kept.items():
        check_holds(assumed, values[key], where)
        check_derived(assumed, values, where)
    return kept


def parse_assumption(text: str, reader: Reader) -> AssumedInput:
    """``KEY=LOW:HIGH`` or ``KEY=LOW:HIGH:DISTRIBUTION`` (SI units) from the command line: a user's own range of an
    input, read by the run (``reader``), replacing a preset's."""
    key, _, spec = text.partition("=")
    parts = spec.split(":")
    if not key or len(parts) not in (2, 3):
        raise ParameterError(f"--assume {text!r}: write KEY=LOW:HIGH or KEY=LOW:HIGH:DISTRIBUTION (SI units)")
    try:
        low, high = (float(part) for part in parts[:2])
    except ValueError:
        raise ParameterError(f"--assume {text!r}: LOW and HIGH must be numbers in the key's SI unit") from None
    why = reader.not_read(key) if key in Parameters.model_fields else None
    if why is not None:
        raise ParameterError(f"--assume {key}: the run does not read it: {why}")
    table = {
        "low": low,
        "high": high,
        "distribution": parts[2] if len(parts) == 3 else "uniform",
        "reason": "the user's range (--assume)",
    }
    return assumed_input(key, table, "--assume")
