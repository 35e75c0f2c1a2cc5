"""Assumed inputs: values no source fixes, each with a range, a distribution and its reason (MODEL.md §14.1).

A preset states them in ``[assumed.KEY]`` tables of its file (``low``, ``high`` in the key's SI unit,
``distribution``, ``reason``); a preset inherits those of the preset it builds on, but not a key it fitted (its
posterior says what it is) nor a key its own run does not read (a planetary jar has no SPEX clamp's yaw).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping

from shakermill.parameters.engine_keys import Reader
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.keys import Parameters, bounds, field_unit

# Uniform on [low, high], or uniform in the logarithm where the range spans orders of magnitude.
DISTRIBUTIONS = ("uniform", "log-uniform")
TABLE_FIELDS = ("low", "high", "distribution", "reason")


@dataclass(frozen=True)
class AssumedInput:
    """One assumed input: its key, range (SI), distribution and reason."""

    key: str
    low: float
    high: float
    distribution: str
    reason: str

    def shown_range(self) -> str:
        unit = field_unit(self.key)
        return f"[{self.low:g}, {self.high:g}]" + (f" {unit}" if unit else "")

    def contains(self, value: float) -> bool:
        return self.low <= value <= self.high


def assumed_input(key: str, table: Any, where: str) -> AssumedInput:
    """The ``[assumed.KEY]`` ``table`` of ``where`` (a preset file, a command's option), checked: a numeric key,
    every field and no other, low < high within the key's bounds, and a known distribution."""
    name = f"{where}: [assumed.{key}]"
    field = Parameters.model_fields.get(key)
    if field is None or field.annotation is not float:
        raise ParameterError(f"{name}: {key!r} is not a numeric key of a single value; only those can be assumed")
    if not isinstance(table, Mapping) or set(table) != set(TABLE_FIELDS):
        raise ParameterError(f"{name}: give exactly {', '.join(TABLE_FIELDS)}")
    low, high, distribution, reason = (table[field] for field in TABLE_FIELDS)
    if not all(isinstance(bound, (int, float)) and math.isfinite(bound) for bound in (low, high)) or not low < high:
        raise ParameterError(f"{name}: low and high must be finite numbers with low < high, not {low!r}, {high!r}")
    allowed = bounds(key)
    if not (allowed.contains(low) and allowed.contains(high)):
        raise ParameterError(f"{name}: [{low:g}, {high:g}] leaves {key}'s allowed range {allowed}")
    if distribution not in DISTRIBUTIONS or (distribution == "log-uniform" and low <= 0):
        raise ParameterError(f"{name}: distribution must be one of {', '.join(DISTRIBUTIONS)} (log-uniform needs low > 0)")
    if not isinstance(reason, str) or not reason.strip():
        raise ParameterError(f"{name}: give the reason for the range")
    return AssumedInput(key, float(low), float(high), str(distribution), reason)


def check_holds(assumed: AssumedInput, value: float, where: str) -> None:
    """A preset's own value of an assumed input lies in the range it states."""
    if not assumed.contains(float(value)):
        raise ParameterError(f"{where}: [assumed.{assumed.key}]: the preset's {assumed.key} = {value:g} lies outside "
                             f"its range {assumed.shown_range()}; state its own [assumed.{assumed.key}]")


def inherited_assumed(base: Mapping[str, AssumedInput], tables: Mapping[str, Any], values: Mapping[str, Any],
                      fitted: tuple[str, ...], reader: Reader, where: str) -> dict[str, AssumedInput]:
    """A preset's assumed inputs: those of its ``base`` and its own ``tables`` (which replace the base's), less the
    keys it ``fitted`` and those its run (``reader``) does not read; each checked against the preset's ``values``."""
    own = {key: assumed_input(key, table, where) for key, table in tables.items()}
    kept = {key: assumed for key, assumed in {**base, **own}.items() if key not in fitted and reader.not_read(key) is None}
    for key, assumed in kept.items():
        check_holds(assumed, values[key], where)
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
    table = {"low": low, "high": high, "distribution": parts[2] if len(parts) == 3 else "uniform",
             "reason": "the user's range (--assume)"}
    return assumed_input(key, table, "--assume")
