"""The hard bounds of a numeric key: compared with a relative tolerance and printed so that they never
contradict the value they refuse.

A bound written with a unit ("25 um") reaches SI through a multiplication that may land one rounding step
beside it (2.4999999999999998e-05): a value within :data:`RELATIVE_TOLERANCE` of a closed bound is that bound.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

# Far above the rounding of a unit conversion (~1e-16), far below any difference a user means.
RELATIVE_TOLERANCE = 1e-9
# Digits of :g first; more only where they are needed to tell a value from a bound.
SHORT_DIGITS = 6
EXACT_DIGITS = 17


def number(value: float, beside: float | None = None, accepted: Callable[[float], bool] = lambda shown: True) -> str:
    """``value`` in as few significant digits (at least six) as tell it from ``beside`` and make the number shown
    ``accepted``: 1.5708 against π/2 reads 1.570796, so that a value shown inside a range is inside it."""
    for digits in range(SHORT_DIGITS, EXACT_DIGITS + 1):
        shown = f"{value:.{digits}g}"
        tells = beside is None or beside == value or not math.isfinite(value) or _same_side(float(shown), value, beside)
        if tells and accepted(float(shown)):
            return shown
    return repr(value)


def _same_side(shown: float, value: float, beside: float) -> bool:
    return (shown < beside) == (value < beside) and shown != beside


@dataclass(frozen=True)
class Bounds:
    """The hard bounds of a numeric key in its SI unit; ``str`` gives them in interval notation."""

    low: float
    high: float
    low_open: bool
    high_open: bool

    def __str__(self) -> str:
        return self.shown()

    def shown(self, value: float | None = None) -> str:
        """The interval, each bound in enough digits to tell it from ``value`` (the one refused) and, where it is
        closed, to be accepted as written: π/3 reads 1.047198, since 1.0472 lies beyond it."""
        low, high = self._bound_text(self.low, self.low_open, value), self._bound_text(self.high, self.high_open, value)
        return f"{'(' if self.low_open else '['}{low}, {high}{')' if self.high_open else ']'}"

    def _bound_text(self, bound: float, is_open: bool, value: float | None) -> str:
        if is_open or not math.isfinite(bound):
            return number(bound, value)
        return number(bound, value, accepted=lambda shown: self.contains(self.snapped(shown)))

    def contains(self, value: float) -> bool:
        above = value > self.low if self.low_open else value >= self.low
        below = value < self.high if self.high_open else value <= self.high
        return above and below

    def snapped(self, value: float) -> float:
        """``value``, or the closed bound it lies within :data:`RELATIVE_TOLERANCE` of."""
        for bound, is_open in ((self.low, self.low_open), (self.high, self.high_open)):
            if not is_open and math.isfinite(bound) and abs(value - bound) <= RELATIVE_TOLERANCE * abs(bound):
                return bound
        return value
