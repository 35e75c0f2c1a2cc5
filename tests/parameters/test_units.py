"""Unit parsing at the edges (shakermill.parameters.units.to_si), against hand conversions."""

from __future__ import annotations

import math
import time

import pytest

from shakermill.parameters.guards import USER_TEMPERATURE_KEYS
from shakermill.parameters.keys import FIELD_NAMES, field_unit
from shakermill.parameters.units import TEMPERATURE_DIFFERENCE_KEYS, UnitError, from_si, to_si, unit_written


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
        ("3 kg", "m", "'3 kg' has the wrong dimension (read as kilogram); expected a length such as m or mm"),
        ("3 kg", "", "wrong dimension (read as kilogram); expected a dimensionless number"),
        (
            "1 m",
            "rad/s",
            "'1 m' has the wrong dimension (read as meter); expected a frequency such as rad/s, Hz or rpm",
        ),
        (
            "25 C",
            "rad/s",
            "wrong dimension (read as coulomb)",
        ),  # °C only where a temperature is expected: here it is coulombs
        ("3 N", "J/(kg*K)", "wrong dimension (read as newton); expected a quantity in J/(kg*K)"),
        ("abc xyz", "m", "cannot parse 'abc xyz': unknown unit 'abc'; expected a length"),
        (
            "1060 rmp",
            "rad/s",
            "cannot parse '1060 rmp': unknown unit 'rmp'; expected a frequency such as rad/s, Hz or rpm",
        ),
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
    started = time.process_time()
    with pytest.raises(UnitError, match="cannot read .* as a number with a unit"):
        to_si(value, "m", key="k")
    assert time.process_time() - started < 0.1


@pytest.mark.parametrize(
    ("value", "unit", "expected"),
    [
        ("9.81 m/s^2", "m/s^2", 9.81),
        ("9.81 m/s**2", "m/s^2", 9.81),
        ("461 J/(kg*K)", "J/(kg*K)", 461.0),
        ("1 / min", "1/s", 1 / 60),
    ],
)
def test_single_digit_powers_and_reciprocals_of_units_are_read(value: str, unit: str, expected: float) -> None:
    assert to_si(value, unit, key="k") == pytest.approx(expected, rel=1e-12)


def test_a_value_longer_than_any_number_is_refused_before_it_is_parsed() -> None:
    started = time.process_time()
    with pytest.raises(UnitError, match="k: a value of 100000 characters is too long; allowed at most 100"):
        to_si("1" * 100_000, "m", key="k")
    assert time.process_time() - started < 0.1
    assert to_si("1" * 100, "m", key="k") == pytest.approx(1.111111111111111e99, rel=1e-12)


@pytest.mark.parametrize("value", ["inf", "-inf", "nan", "1e400", "1e308 km", math.inf, math.nan, 10**400])
def test_non_finite_values_are_refused(value: object) -> None:
    with pytest.raises(UnitError, match="^k: .* is not a finite number$"):
        to_si(value, "m", key="k")


@pytest.mark.parametrize(
    "spelling",
    ["C", "c", "degC", "deg C", "°C", "° C", "ºC", "℃", "celsius", "Celsius", "degree_Celsius", "degrees celsius"],
)
def test_a_temperature_in_degrees_celsius_is_read_in_any_spelling(spelling: str) -> None:
    assert to_si(f"25 {spelling}", "K", key="ambient_temperature") == pytest.approx(298.15, rel=1e-15)
    assert to_si(f"25{spelling}", "K", key="initial_temperature") == pytest.approx(298.15, rel=1e-15)


@pytest.mark.parametrize("spelling", ["F", "degF", "°F", "℉", "fahrenheit"])
def test_a_temperature_in_degrees_fahrenheit_is_read(spelling: str) -> None:
    assert to_si(f"77 {spelling}", "K", key="ambient_temperature") == pytest.approx(298.15, rel=1e-12)
    assert to_si(f"-40 {spelling}", "K", key="ambient_temperature") == pytest.approx(
        233.15, rel=1e-12
    )  # -40 °F = -40 °C


def test_a_temperature_difference_in_degrees_takes_no_offset() -> None:
    assert to_si("1e-3 degC", "K", key="atol_temperature") == pytest.approx(1e-3, rel=1e-15)
    assert to_si("1 °C", "K", key="sutherland") == 1.0
    assert to_si("9 F", "K", key="sutherland") == pytest.approx(5.0, rel=1e-15)


def test_every_key_in_kelvin_is_a_temperature_or_a_difference_of_temperatures() -> None:
    # A new key in K must be placed: '25 C' is 298.15 K for a temperature, 25 K for a difference.
    in_kelvin = {key for key in FIELD_NAMES if field_unit(key) == "K"}
    temperatures = {*USER_TEMPERATURE_KEYS, "air_reference_temperature"}
    assert in_kelvin == temperatures | TEMPERATURE_DIFFERENCE_KEYS
    assert not temperatures & TEMPERATURE_DIFFERENCE_KEYS


@pytest.mark.parametrize(
    "value",
    [
        "1060 rpm",
        "1060 RPM",
        "1060 Rpm",
        "1060rpm",
        "17.666666666666668 Hz",
        "17.666666666666668 hz",
        "17.666666666666668 HZ",
    ],
)
def test_rpm_and_hertz_are_read_in_any_case(value: str) -> None:
    assert to_si(value, "rad/s", key="omega") == pytest.approx(1060 * 2 * math.pi / 60, rel=1e-12)


@pytest.mark.parametrize(
    ("written", "unit", "si_unit", "key"),
    [
        ("5 mm", "mm", "m", "amplitude"),
        ("25 C", "C", "K", "ambient_temperature"),
        ("77 degF", "degF", "K", "initial_temperature"),
        ("1060 RPM", "RPM", "rad/s", "omega"),
        ("15 Hz", "Hz", "rad/s", "omega"),
        ("60 min", "min", "s", "duration"),
    ],
)
def test_a_value_read_back_in_the_unit_it_was_written_in_is_the_number_written(
    written: str, unit: str, si_unit: str, key: str
) -> None:
    assert unit_written(written) == unit
    assert from_si(to_si(written, si_unit, key=key), unit, si_unit, key=key) == pytest.approx(
        float(written.split()[0]), rel=1e-12
    )


@pytest.mark.parametrize("value", ["0.005", 0.005, "steel", ""])
def test_a_bare_number_or_a_name_has_no_unit_written(value: object) -> None:
    assert unit_written(value) == ""
