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

    registry: pint.UnitRegistry = pint.UnitRegistry(autoconvert_offset_to_baseunit=True)
    return registry


# pint evaluates what it parses as Python arithmetic: '10**10**10 rad/s' would compute a number of ten
# billion digits before any check could see it. So a string reaches pint only as a quantity of the form
# users write: one leading number, then unit names joined by *, / and parentheses, with single-digit
# powers (m^2, m**3) and a lone 1 as a numerator (1/s). That leaves no digit for arithmetic to grow.
_LEADING_NUMBER = re.compile(r"^\s*[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
_UNIT_POWER = re.compile(r"(?<=[^\W\d]|\))\s*(?:\*\*|\^)\s*[-+]?\d(?![\d.]|\s*(?:\*\*|\^))")
_RECIPROCAL_ONE = re.compile(r"(?<![\w.)])1(?=\s*/)")
_ARITHMETIC = re.compile(r"\d|\*\*|\^")


# How a temperature is written, case, spaces and underscores aside, and its kelvin as (scale, zero): a temperature
# t is (t + zero)·scale K, a difference d is d·scale K. pint alone reads "25 C" as coulombs and "25 F" as farads.
_CELSIUS, _FAHRENHEIT, _KELVIN = (1.0, 273.15), (5.0 / 9.0, 459.67), (1.0, 0.0)
TEMPERATURE_SPELLINGS = {
    **dict.fromkeys(
        ("c", "°c", "ºc", "℃", "degc", "degreec", "degreesc", "celsius", "degreecelsius", "degreescelsius"), _CELSIUS
    ),
    **dict.fromkeys(
        ("f", "°f", "ºf", "℉", "degf", "degreef", "degreesf", "fahrenheit", "degreefahrenheit", "degreesfahrenheit"),
        _FAHRENHEIT,
    ),
    **dict.fromkeys(("k", "kelvin", "kelvins"), _KELVIN),
}
# Keys in K that are differences of temperature: there "1 degC" is 1 K, not 274.15 K. Every other key in K is a
# temperature of something (tests/parameters/test_units.py holds every key in K to one of the two).
TEMPERATURE_DIFFERENCE_KEYS = frozenset({"atol_temperature", "sutherland"})
# Units people write in any case ("1060 RPM", "15 hz"); pint knows them in one, and "HZ" would be no unit at all.
_ANY_CASE_UNITS = re.compile(r"(?<![^\W\d_])(rpm|rps|hz)(?![^\W\d_])", re.IGNORECASE)
_CANONICAL_SPELLING = {"rpm": "rpm", "rps": "rps", "hz": "Hz"}
# What a key's SI unit measures, with units people write for it, for a value of another dimension.
EXPECTED_QUANTITY = {
    "": "a dimensionless number",
    "rad/s": "a frequency such as rad/s, Hz or rpm",
    "K": "a temperature such as K, degC or degF",
    "m": "a length such as m or mm",
    "m^2": "an area such as m^2 or mm^2",
    "s": "a time such as s, min or h",
    "kg": "a mass such as kg or g",
    "kg/m^3": "a density such as kg/m^3 or g/cm^3",
    "Pa": "a pressure such as Pa, MPa or GPa",
    "rad": "an angle such as rad or deg",
    "W": "a power such as W or mW",
}


def expected_quantity(unit: str) -> str:
    """What a value in SI ``unit`` is, for a message: 'a length such as m or mm'."""
    return EXPECTED_QUANTITY.get(unit, f"a quantity in {unit}")


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
    kelvin = _temperature_in_kelvin(text, key) if unit == "K" else None
    if kelvin is not None:
        return _finite(kelvin, value, key)
    in_pints_case = _ANY_CASE_UNITS.sub(lambda name: _CANONICAL_SPELLING[name[1].lower()], text)
    return _finite(_quantity_to_si(in_pints_case, value, unit, key), value, key)


def _temperature_in_kelvin(text: str, key: str) -> float | None:
    """A number and a spelling of °C, °F or K (:data:`TEMPERATURE_SPELLINGS`) in kelvin, as a temperature or, for
    :data:`TEMPERATURE_DIFFERENCE_KEYS`, as a difference; None for any other unit."""
    number = _LEADING_NUMBER.match(text)
    scale_and_zero = TEMPERATURE_SPELLINGS.get(re.sub(r"[\s_]", "", text[number.end() :]).lower()) if number else None
    if number is None or scale_and_zero is None:
        return None
    scale, zero = scale_and_zero
    magnitude = float(number[0])
    return magnitude * scale if key in TEMPERATURE_DIFFERENCE_KEYS else (magnitude + zero) * scale


def unit_written(value: object) -> str:
    """The unit written after the number of ``value`` ('5 mm' -> 'mm'); '' for a bare number or a name."""
    if not isinstance(value, str):
        return ""
    number = _LEADING_NUMBER.match(value)
    return value[number.end() :].strip() if number else ""


def from_si(number: float, unit: str, si_unit: str, *, key: str) -> float:
    """``number``, in the SI ``si_unit`` of ``key``, in ``unit``: the inverse of :func:`to_si` (affine for °C, °F)."""
    zero, one = (to_si(f"{probe} {unit}", si_unit, key=key) for probe in (0, 1))
    return (number - zero) / (one - zero)


def _quantity_to_si(text: str, value: str, unit: str, key: str) -> float:
    import pint  # loaded once a value carries a unit (see _registry)

    registry = _registry()
    try:
        quantity: pint.Quantity = registry.Quantity(text)
    except pint.UndefinedUnitError as exc:
        unknown = ", ".join(map(repr, exc.unit_names))
        raise UnitError(
            f"{key}: cannot parse {quoted(value)}: unknown unit {unknown}; expected {expected_quantity(unit)}"
        ) from None
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
        raise UnitError(
            f"{key}: {quoted(value)} has the wrong dimension (read as {quantity.units}); expected "
            f"{expected_quantity(unit)}"
        ) from None
