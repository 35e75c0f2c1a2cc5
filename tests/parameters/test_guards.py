"""Guards against unit slips and unphysical results: warnings, refusals, echoes and statuses."""

from __future__ import annotations

import json

import pytest
from typer.testing import CliRunner

import shakermill as sm
from shakermill import cli
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.keys import unit_slip_warnings
from shakermill.solvers.result import OUT_OF_PHYSICAL_BOUNDS

runner = CliRunner()


@pytest.mark.parametrize(
    ("key", "value", "meant"),
    [
        ("omega", 1060, "did you mean 1060 rpm?"),
        ("omega", 17.7, "did you mean 17.7 Hz?"),
    ],
)
def test_a_bare_number_far_outside_what_mills_use_warns_with_the_likely_unit(key, value, meant):
    lines = unit_slip_warnings(sm.default_parameters(**{key: value}))
    assert len(lines) == 1
    assert lines[0].startswith(f"{key} = {value:g} ")
    assert meant in lines[0]


@pytest.mark.parametrize(
    ("key", "value", "refusal", "meant"),
    [
        ("amplitude", 25, "amplitude: 25 is out of range; allowed (0, 0.5] m", "did you mean 25 mm?"),
        ("vial_length", 58, "vial_length: 58 is out of range; allowed [0.001, 1] m", "did you mean 58 mm?"),
        ("ball_radius", 6.35, "ball_radius: 6.35 is out of range; allowed [2.5e-05, 0.1] m", "did you mean 6.35 mm?"),
    ],
)
def test_a_bare_number_beyond_the_hard_bounds_is_refused_with_the_likely_unit(key, value, refusal, meant):
    with pytest.raises(ParameterError) as error:
        sm.default_parameters(**{key: value})
    message = str(error.value)
    assert message.startswith(refusal)
    assert meant in message


def test_the_default_preset_draws_no_unit_warning():
    assert unit_slip_warnings(sm.default_parameters()) == []
    assert unit_slip_warnings(sm.default_parameters(omega="1200 rpm", amplitude="20 mm")) == []


def test_an_implausible_temperature_with_a_unit_warns_without_refusal():
    lines = unit_slip_warnings(sm.default_parameters(ambient_temperature="150 K"))
    assert len(lines) == 1 and lines[0].startswith("ambient_temperature = 150 K")


@pytest.mark.parametrize("key", ["ambient_temperature", "initial_temperature"])
@pytest.mark.parametrize("value", [20, "20", 20.0, 199.9])
def test_a_bare_temperature_below_200_is_refused_with_both_spellings(key, value):
    with pytest.raises(ParameterError) as error:
        sm.default_parameters(**{key: value})
    message = str(error.value)
    assert message.startswith(f"{key}: ")
    number = float(value)
    assert f"'{number:g} degC'" in message and f"'{number + 273.15:g} K'" in message


def test_temperatures_with_units_are_understood():
    params = sm.default_parameters(ambient_temperature="20 degC", initial_temperature="25 degC")
    assert params.ambient_temperature == pytest.approx(293.15)
    assert params.initial_temperature == pytest.approx(298.15)


def test_cli_refuses_a_bare_temperature_with_exit_2_and_one_line(tmp_path):
    outcome = runner.invoke(cli.app, ["run", "--set", "ambient_temperature=20", "--out", str(tmp_path / "run")])
    assert outcome.exit_code == 2
    lines = outcome.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ambient_temperature:")
    assert "20 degC" in lines[0] and "293.15 K" in lines[0]
    assert not (tmp_path / "run").exists()


@pytest.mark.slow
def test_cli_warns_once_and_echoes_what_was_understood(tmp_path):
    outcome = runner.invoke(
        cli.app,
        [
            "run",
            "--set",
            "omega=1060",
            "--set",
            "duration=1",
            "--set",
            "record_windows=",
            "--no-plots",
            "--json",
            "--out",
            str(tmp_path / "run"),
        ],
    )
    slips = [line for line in outcome.stderr.splitlines() if "did you mean" in line]
    assert len(slips) == 1 and slips[0].startswith("warning: omega = 1060 rad/s")
    assert "1060 rpm" in slips[0]
    summary = json.loads(outcome.stdout)
    assert summary["omega_rad_s"] == pytest.approx(1060.0)
    assert summary["omega_rpm"] == pytest.approx(1060.0 * 60.0 / (2 * 3.141592653589793))
    assert any("did you mean 1060 rpm?" in line for line in summary["warnings"])


def test_json_echo_of_rpm_and_millimetres(tmp_path):
    outcome = runner.invoke(
        cli.app,
        [
            "run",
            "--set",
            "omega=1060 rpm",
            "--set",
            "amplitude=24 mm",
            "--set",
            "ambient_temperature=25 degC",
            "--set",
            "duration=1",
            "--set",
            "record_windows=",
            "--no-plots",
            "--json",
            "--out",
            str(tmp_path / "run"),
        ],
    )
    summary = json.loads(outcome.stdout)
    assert summary["omega_rpm"] == pytest.approx(1060.0)
    assert summary["omega_hz"] == pytest.approx(1060.0 / 60.0)
    assert summary["amplitude_mm"] == pytest.approx(24.0)
    assert summary["ambient_temperature_C"] == pytest.approx(25.0)
    assert "did you mean" not in outcome.stderr


def test_human_table_shows_omega_in_three_units(tmp_path):
    outcome = runner.invoke(
        cli.app,
        [
            "run",
            "--set",
            "omega=1060 rpm",
            "--set",
            "duration=1",
            "--set",
            "record_windows=",
            "--no-plots",
            "--out",
            str(tmp_path / "run"),
        ],
    )
    assert "111 rad/s = 17.67 Hz = 1060" in outcome.stdout


def test_a_run_whose_ball_exceeds_the_material_limit_is_not_ok():
    # 1060 rad/s (rpm meant): ~1 kW of heat melts the ball within seconds.
    result = sm.simulate(sm.default_parameters(omega=1060, duration=30.0, record_windows=()))
    assert result.status == OUT_OF_PHYSICAL_BOUNDS
    assert not result.success and result.summary.success is False
    assert "ball_temperature_limit" in result.message
    assert float(result.timeseries["theta_ball"].max()) > result.params.ball_temperature_limit


def test_a_lower_material_limit_is_respected():
    params = sm.default_parameters(duration=120.0, record_windows=(), ball_temperature_limit="30 degC")
    result = sm.simulate(params)
    assert result.status == OUT_OF_PHYSICAL_BOUNDS
    within = sm.simulate(params.replace(ball_temperature_limit="1400 degC"))
    assert within.success
