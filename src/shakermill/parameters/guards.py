"""Units and guards: user values with units turned into SI or a key's type, each refused in one line when it is
none (:class:`~shakermill.parameters.units.UnitError`), and the guards against unit slips: a bare temperature that
can only be °C is refused, and values outside what mills and laboratories use are named with the unit likely meant."""

from __future__ import annotations

import numbers
from dataclasses import dataclass
from typing import Any

from shakermill.parameters.errors import ParameterError
from shakermill.parameters.motions import MOTION_COORDINATES
from shakermill.parameters.units import UnitError, to_si
from shakermill.support.limits import MAX_RECORD_WINDOWS, quoted

# Guards against unit slips. Bare numbers are SI, but people give temperatures in °C, lengths in mm and
# frequencies in rpm or Hz: a bare temperature below this many kelvin is almost surely °C, and is refused.
BARE_TEMPERATURE_MINIMUM = 200.0
USER_TEMPERATURE_KEYS = ("ambient_temperature", "initial_temperature", "ball_temperature_limit")


@dataclass(frozen=True)
class PlausibleRange:
    """Values real mills and laboratories use, in the key's SI unit, and the units people slip into."""

    low: float
    high: float
    users: str
    likely_units: tuple[str, ...]


PLAUSIBLE_RANGES: dict[str, PlausibleRange] = {
    # Mixer mills shake at 3-35 Hz (3 Hz = 18.8 rad/s), planetary mills turn at up to ~1100 rpm of the sun wheel.
    "omega": PlausibleRange(18.0, 400.0, "shaker and planetary mills", ("rpm", "Hz")),
    "amplitude": PlausibleRange(1e-3, 0.1, "shaker mills", ("mm",)),
    "ball_radius": PlausibleRange(2.5e-4, 0.05, "milling balls", ("mm",)),
    "vial_length": PlausibleRange(5e-3, 0.5, "milling vials", ("mm",)),
    "vial_diameter": PlausibleRange(5e-3, 0.5, "milling vials", ("mm",)),
    "ambient_temperature": PlausibleRange(250.0, 330.0, "laboratories", ("degC",)),
    "initial_temperature": PlausibleRange(250.0, 400.0, "laboratories", ("degC",)),
}


def unit_slip(key: str, value: float, unit: str) -> str | None:
    """Why ``value`` (SI, in ``unit``) of ``key`` looks like a unit slip, naming the unit likely meant; None if
    plausible."""
    plausible = PLAUSIBLE_RANGES.get(key)
    if plausible is None or plausible.low <= value <= plausible.high:
        return None
    meant = next((alt for alt in plausible.likely_units if _plausible_in(alt, value, key, unit)), None)
    hint = f"; did you mean {value:g} {meant}? Write {key}='{value:g} {meant}'" if meant else ""
    return (
        f"{key} = {value:g} {unit} is outside what {plausible.users} use "
        f"({plausible.low:g} to {plausible.high:g} {unit}); bare numbers are SI{hint}"
    )


def _plausible_in(alternative: str, value: float, key: str, unit: str) -> bool:
    """Whether ``value`` read in ``alternative`` is plausible for ``key`` (SI ``unit``; 1e308 Hz is no frequency at
    all)."""
    plausible = PLAUSIBLE_RANGES[key]
    try:
        return plausible.low <= to_si(f"{value:g} {alternative}", unit, key=key) <= plausible.high
    except UnitError:
        return False


def _is_bare_number(value: Any) -> bool:
    if isinstance(value, bool):
        return False
    if isinstance(value, (int, float)):
        return True
    try:
        float(str(value).strip())
    except ValueError:
        return False
    return True


def quantity(key: str, value: Any, unit: str) -> float:
    """``value`` of ``key`` in SI ``unit``; a bare temperature below BARE_TEMPERATURE_MINIMUM is refused."""
    number = to_si(value, unit, key=key)
    if key in USER_TEMPERATURE_KEYS and _is_bare_number(value) and number < BARE_TEMPERATURE_MINIMUM:
        raise ParameterError(
            f"{key}: a bare {number:g} is read as {number:g} K ({number - 273.15:.2f} °C); bare temperatures below "
            f"{BARE_TEMPERATURE_MINIMUM:g} are refused: write '{number:g} degC' or '{number + 273.15:g} K'"
        )
    return number


def whole_number(key: str, value: Any) -> int:
    """``value`` of a count key as an int; :class:`UnitError` for anything else."""
    # A TOML `true` is not 1, and 2.5 starts are not 2.
    if isinstance(value, bool):
        raise UnitError(f"{key}: expected a whole number, got {value!r}")
    if isinstance(value, numbers.Integral):
        return int(value)
    number = to_si(value, "", key=key)
    if not number.is_integer():
        raise UnitError(f"{key}: expected a whole number, got {quoted(value)}")
    return int(number)


def switch(key: str, value: Any) -> bool:
    """true, false and their spellings (1, yes, on, ...)."""
    if isinstance(value, bool):
        return value
    lowered = value.strip().lower() if isinstance(value, str) else None
    if lowered in {"true", "1", "yes", "on"}:
        return True
    if lowered in {"false", "0", "no", "off"}:
        return False
    raise UnitError(f"{key}: expected true or false, got {quoted(value)}")


def windows(value: Any) -> tuple[tuple[float, float], ...]:
    """Windows from "0:1,600:0.1" (the command line; "" means none) or from (start, length) pairs (TOML, Python)."""
    if isinstance(value, str):
        pairs: Any = [item.split(":") for item in value.split(",") if item.strip()]
    elif isinstance(value, (list, tuple)):
        pairs = value
    else:
        raise UnitError(f"record_windows: expected (start, length) pairs, got {quoted(value)}")
    if len(pairs) > MAX_RECORD_WINDOWS:
        raise UnitError(f"record_windows: {len(pairs)} windows are too many")
    return tuple(_window(pair) for pair in pairs)


def _window(pair: Any) -> tuple[float, float]:
    if not isinstance(pair, (list, tuple)) or len(pair) != 2:
        raise UnitError(f"record_windows: expected START:LENGTH (or [start, length]) in seconds, got {quoted(pair)}")
    start, length = (to_si(item, "s", key="record_windows") for item in pair)
    return start, length


def per_ball(key: str, value: Any, unit: str) -> tuple[float, ...]:
    """Per-ball values in SI ``unit`` from "6 mm, 5 mm" (the command line; "" means none) or a list (TOML, Python)."""
    return quantity_list(key, value, unit, "a list of values, one per ball")


def quantity_list(key: str, value: Any, unit: str, expected: str) -> tuple[float, ...]:
    """Values in SI ``unit`` from "1 mJ, 10 mJ" (the command line; "" means none) or a list (TOML, Python);
    ``expected`` says what the error names when ``value`` is neither."""
    items = [item for item in value.split(",") if item.strip()] if isinstance(value, str) else value
    if not isinstance(items, (list, tuple)):
        raise UnitError(f"{key}: expected {expected}, got {quoted(value)}")
    return tuple(to_si(item, unit, key=key) for item in items)


def motion(value: Any) -> tuple[tuple[str, int, float, float], ...]:
    """Harmonics from "x:1:0:25 mm, yaw:2:0.1:0" (the command line) or (coordinate, k, cos, sin) lists (TOML)."""
    terms: Any = [item.split(":") for item in value.split(",") if item.strip()] if isinstance(value, str) else value
    if not isinstance(terms, (list, tuple)):
        raise UnitError(f"motion: expected (coordinate, k, cos, sin) terms, got {quoted(value)}")
    return tuple(_harmonic(term) for term in terms)


def _harmonic(term: Any) -> tuple[str, int, float, float]:
    if not isinstance(term, (list, tuple)) or len(term) != 4 or str(term[0]).strip() not in MOTION_COORDINATES:
        raise UnitError(
            f"motion: expected COORDINATE:K:COS:SIN with a coordinate of {', '.join(MOTION_COORDINATES)}, got "
            f"{quoted(term)}"
        )
    coordinate = str(term[0]).strip()
    unit = "rad" if coordinate in ("roll", "pitch", "yaw") else "m"
    harmonic = whole_number("motion", term[1])
    return coordinate, harmonic, to_si(term[2], unit, key="motion"), to_si(term[3], unit, key="motion")
