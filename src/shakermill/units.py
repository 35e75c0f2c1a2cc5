"""Parse user-supplied values that may carry units ("25 mm", "1060 rpm", "60 min").

Inside the package everything is SI; this module is the only place where units
are interpreted, so that the physics never sees anything but plain floats.
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import pint


class UnitError(ValueError):
    """A value whose unit cannot be parsed or does not match the key's dimension."""


@lru_cache(maxsize=1)
def _registry() -> pint.UnitRegistry:
    import pint  # 0.3 s: only when a value carries a unit

    registry = pint.UnitRegistry(autoconvert_offset_to_baseunit=True)
    return registry


def _has_angle_unit(quantity: pint.Quantity) -> bool:
    return any(name == "radian" for name, _ in quantity.to_root_units().unit_items())


def to_si(value: object, unit: str, *, key: str) -> float:
    """Return ``value`` in the SI ``unit`` of ``key``.

    Numbers are taken as already SI. Strings are parsed with pint. For angular
    rates (``unit == "rad/s"``) a unit without an angle, such as Hz or 1/s, is
    read as cycles per second, because a mill's "17.7 Hz" means 17.7 shakes per
    second, i.e. 2π·17.7 rad/s; pint alone would treat Hz as 1 rad/s.
    """
    if isinstance(value, bool):
        raise UnitError(f"{key}: expected a number or a quantity with units, got {value!r}")
    if isinstance(value, (int, float)):
        return float(value)
    if not isinstance(value, str):
        raise UnitError(f"{key}: expected a number or a quantity with units, got {value!r}")
    text = value.strip()
    try:
        return float(text)
    except ValueError:
        pass
    import pint  # loaded once a value carries a unit (see _registry)

    registry = _registry()
    try:
        quantity = registry.Quantity(text)
    except Exception as exc:  # pint raises several unrelated exception types
        raise UnitError(f"{key}: cannot parse {value!r} as a quantity ({type(exc).__name__})") from None
    if not isinstance(quantity, pint.Quantity):
        return float(quantity)
    target = registry.Unit(unit) if unit else registry.dimensionless
    if unit == "rad/s" and quantity.check("1/[time]") and not _has_angle_unit(quantity):
        return float(quantity.to("1/s").magnitude) * 2.0 * math.pi
    try:
        return float(quantity.to(target).magnitude)
    except pint.DimensionalityError:
        expected = unit or "a dimensionless number"
        raise UnitError(f"{key}: {value!r} has units of {quantity.units:~}, expected {expected}") from None
