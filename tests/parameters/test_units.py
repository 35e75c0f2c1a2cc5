"""Unit parsing at the edges (shakermill.parameters.units.to_si), against hand conversions."""

from __future__ import annotations

import math
import time

import pytest

from shakermill.parameters.units import UnitError, to_si


@pytest.mark.parametrize(
    "value, unit, expected",
    [
        ("25 mm", "m", 0.025),
        ("6.35 mm", "m", 6.35e-3),
        ("60 min", "s", 3600.0),
        ("1 h", "s", 3600.0),
        ("20 degC", "K", 293.15),  # 20 + 273.15
        ("68 degF", "K", 293.15),  # (68 − 32)·5/9 = 20 °C
        ("200 GPa", "Pa", 200e9),
        ("1.716e-5 Pa*s", "Pa*s", 1.716e-5),
        ("461 J/(kg*K)", "J/(kg*K)", 461.0),
        ("7.8 g/cm^3", "kg/m^3", 7800.0),  # 7.8e-3 kg / 1e-6 m³
        ("2 rad/s", "rad/s", 2.0),
    ],
)
def test_strings_with_units_are_converted_to_si(value: str, unit: str, expected: float) -> None:
    assert to_si(value, unit, key="k") == pytest.approx(expected, rel=1e-12)


def test_rpm_is_revolutions_per_minute() -> None:
    # 1060 · 2π / 60 = 111.00294 rad/s
    assert to_si("1060 rpm", "rad/s", key="omega") == pytest.approx(111.0, abs=0.01)
    assert to_si("1060 rpm", "rad/s", key="omega") == pytest.approx(111.00294, rel=1e-6)


def test_hertz_is_read_as_cycles_per_second_for_angular_rates() -> None:
    # 2π · 17.7 = 111.21238 rad/s (pint alone would give 17.7)
    assert to_si("17.7 Hz", "rad/s", key="omega") == pytest.approx(2.0 * math.pi * 17.7, rel=1e-12)
    assert to_si("120 1/s", "rad/s", key="omega") == pytest.approx(2.0 * math.pi * 120.0, rel=1e-12)


def test_plain_numbers_are_taken_as_si() -> None:
    assert to_si(0.025, "m", key="k") == 0.025
    assert to_si(3, "s", key="k") == 3.0
    assert isinstance(to_si(3, "s", key="k"), float)
    assert to_si("0.7", "", key="k") == pytest.approx(0.7, rel=1e-15)
    assert to_si(" 12.5 ", "m", key="k") == pytest.approx(12.5, rel=1e-15)


def test_dimensionless_quantities() -> None:
    assert to_si("50 percent", "", key="k") == pytest.approx(0.5, rel=1e-12)


@pytest.mark.parametrize(
    "value, unit, fragment",
    [
        ("3 kg", "m", "expected m"),
        ("3 kg", "", "dimensionless"),
        ("1 m", "rad/s", "expected rad/s"),
        ("abc xyz", "m", "cannot parse"),
        (True, "m", "expected a number"),
        (None, "m", "expected a number"),
        ([1.0], "m", "expected a number"),
    ],
)
def test_bad_values_raise_a_unit_error_naming_the_key(value: object, unit: str, fragment: str) -> None:
    with pytest.raises(UnitError) as info:
        to_si(value, unit, key="my_key")
    message = str(info.value)
    assert message.startswith("my_key:")
    assert fragment in message


def test_unit_error_is_a_value_error() -> None:
    assert issubclass(UnitError, ValueError)


@pytest.mark.parametrize(
    "value",
    [
        "10**10**10 rad/s",  # 10 to the ten billion: pint would compute it
        "9**9**9",
        "(((((((10**9)**9)**9)**9)**9)**9)**9) m",
        "m**9**9**9",
        "10 ** 9 m",
        "2^2^2^2^2^2 kg",
        "(1 m)**9",
        "1e5e5 m",
        "0x10 m",
    ],
)
def test_arithmetic_in_a_quantity_is_refused_before_pint_sees_it(value: str) -> None:
    started = time.perf_counter()
    with pytest.raises(UnitError, match="cannot read .* as a number with a unit"):
        to_si(value, "m", key="k")
    assert time.perf_counter() - started < 0.1


@pytest.mark.parametrize(
    ("value", "unit", "expected"),
    [("9.81 m/s^2", "m/s^2", 9.81), ("9.81 m/s**2", "m/s^2", 9.81), ("461 J/(kg*K)", "J/(kg*K)", 461.0), ("1 / min", "1/s", 1 / 60)],
)
def test_single_digit_powers_and_reciprocals_of_units_are_read(value: str, unit: str, expected: float) -> None:
    assert to_si(value, unit, key="k") == pytest.approx(expected, rel=1e-12)


def test_a_value_longer_than_any_number_is_refused_before_it_is_parsed() -> None:
    started = time.perf_counter()
    with pytest.raises(UnitError, match="k: a value of 100000 characters is too long; allowed at most 100"):
        to_si("1" * 100_000, "m", key="k")
    assert time.perf_counter() - started < 0.1
    assert to_si("1" * 100, "m", key="k") == pytest.approx(1.111111111111111e99, rel=1e-12)


@pytest.mark.parametrize("value", ["inf", "-inf", "nan", "1e400", "1e308 km", math.inf, math.nan, 10**400])
def test_non_finite_values_are_refused(value: object) -> None:
    with pytest.raises(UnitError, match="^k: .* is not a finite number$"):
        to_si(value, "m", key="k")
