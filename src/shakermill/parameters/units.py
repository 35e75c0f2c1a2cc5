"""Parse user-supplied values that may carry units ("25 mm", "1060 rpm", "60 min").

Inside the package everything is SI; this module is the only place where units
are interpreted, so that the physics never sees anything but plain floats.
"""

from __future__ import annotations

import math
import numbers
import re
from functools import lru_cache
from typing import TYPE_CHECKING

from shakermill.support.limits import MAX_VALUE_LENGTH, quoted

if TYPE_CHECKING:
    import pint


class UnitError(ValueError):
    """A value that cannot be read as a finite number in the key's unit (unparseable, too long, wrong dimension)."""


@lru_cache(maxsize=1)
def _registry() -> pint.UnitRegistry:
    import pint  # 0.3 s: only when a value carries a unit

    registry = pint.UnitRegistry(autoconvert_offset_to_baseunit=True)
    return registry


# pint evaluates what it parses as Python arithmetic: '10**10**10 rad/s' would compute a number of ten
# billion digits before any check could see it. So a string reaches pint only as a quantity of the form
# users write: one leading number, then unit names joined by *, / and parentheses, with single-digit
# powers (m^2, m**3) and a lone 1 as a numerator (1/s). That leaves no digit for arithmetic to grow.
_LEADING_NUMBER = re.compile(r"^\s*[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
_UNIT_POWER = re.compile(r"(?<=[^\W\d]|\))\s*(?:\*\*|\^)\s*[-+]?\d(?![\d.]|\s*(?:\*\*|\^))")
_RECIPROCAL_ONE = re.compile(r"(?<![\w.)])1(?=\s*/)")
_ARITHMETIC = re.compile(r"\d|\*\*|\^")


def _is_number_with_unit(text: str) -> bool:
    unit = _RECIPROCAL_ONE.sub("", _UNIT_POWER.sub("", _LEADING_NUMBER.sub("", text, count=1)))
    return _ARITHMETIC.search(unit) is None


def _finite(number: float, value: object, key: str) -> float:
    if not math.isfinite(number):
        raise UnitError(f"{key}: {quoted(value)} is not a finite number")
    return number


def _has_angle_unit(quantity: pint.Quantity) -> bool:
    return any(name == "radian" for name, _ in quantity.to_root_units().unit_items())


def to_si(value: object, unit: str, *, key: str) -> float:
    """Return ``value`` in the SI ``unit`` of ``key``.

    Numbers are taken as already SI. Strings are parsed with pint. For angular
    rates (``unit == "rad/s"``) a unit without an angle, such as Hz or 1/s, is
    read as cycles per second, because a mill's "17.7 Hz" means 17.7 shakes per
    second, i.e. 2π·17.7 rad/s; pint alone would treat Hz as 1 rad/s.
    """
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        try:
            return _finite(float(value), value, key)
        except OverflowError:  # an integer beyond the largest float
            raise UnitError(f"{key}: {quoted(value)} is not a finite number") from None
    if not isinstance(value, str):
        raise UnitError(f"{key}: expected a number or a quantity with units, got {quoted(value)}")
    text = value.strip()
    if len(text) > MAX_VALUE_LENGTH:
        raise UnitError(
            f"{key}: a value of {len(text)} characters is too long; allowed at most {MAX_VALUE_LENGTH}, "
            "a number with its unit such as '1060 rpm'"
        )
    try:
        number = float(text)
    except ValueError:
        number = None
    if number is not None:
        return _finite(number, value, key)
    if not _is_number_with_unit(text):
        raise UnitError(
            f"{key}: cannot read {quoted(value)} as a number with a unit; write one number and a unit such as "
            "'25 mm' or '461 J/(kg*K)' (powers as single digits on units: m^2)"
        )
    return _finite(_quantity_to_si(text, value, unit, key), value, key)


def _quantity_to_si(text: str, value: str, unit: str, key: str) -> float:
    import pint  # loaded once a value carries a unit (see _registry)

    registry = _registry()
    try:
        quantity = registry.Quantity(text)
    except Exception as exc:  # pint raises several unrelated exception types
        raise UnitError(f"{key}: cannot parse {quoted(value)} as a quantity ({type(exc).__name__})") from None
    if not isinstance(quantity, pint.Quantity):
        return float(quantity)
    target = registry.Unit(unit) if unit else registry.dimensionless
    if unit == "rad/s" and quantity.check("1/[time]") and not _has_angle_unit(quantity):
        return float(quantity.to("1/s").magnitude) * 2.0 * math.pi
    try:
        return float(quantity.to(target).magnitude)
    except pint.DimensionalityError:
        expected = unit or "a dimensionless number"
        raise UnitError(f"{key}: {quoted(value)} has units of {quantity.units:~}, expected {expected}") from None
