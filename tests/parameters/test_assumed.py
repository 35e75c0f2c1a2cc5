"""Assumed inputs stated with the presets: a range, a distribution and a reason for every value no source fixes
(MODEL.md §14.1, issue 36)."""

from __future__ import annotations

import pytest

from shakermill.parameters.assumed import (
    assumed_input,
    check_holds,
    inherited_assumed,
    parse_assumption,
)
from shakermill.parameters.engine_keys import Reader
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.presets import PRESETS

CONTACT = {"friction", "pair_friction", "restitution", "pair_restitution", "rolling_friction", "lam"}
HEAD = {"emissivity", "clamp_heat_capacity", "clamp_conductance", "clamp_loss"}
TABLE = {"low": 0.1, "high": 0.6, "distribution": "uniform", "reason": "assumed"}
SPEX_3D = Reader("dem", "averaged", "paper", "spex8000m")


@pytest.mark.parametrize(
    ("name", "expected"),
    [
        ("spex8000m-3d", CONTACT | {"lateral_amplitude", "yaw_amplitude"}),
        ("spex8000m-3d-mill-head", CONTACT | HEAD | {"lateral_amplitude", "yaw_amplitude"}),
        # A planetary jar has no SPEX clamp's figure of eight: the amplitudes are not its inputs.
        ("pulverisette7", CONTACT | HEAD),
        ("pm100", CONTACT | HEAD),
        ("mm400", CONTACT | {"amplitude", "swing_radius"}),
        # What a calibration fitted has its posterior, not an assumed range.
        ("spex8000m-3d-calibrated", CONTACT | {"emissivity", "clamp_conductance", "lateral_amplitude", "yaw_amplitude"}),
    ],
)
def test_every_3d_preset_states_its_assumed_inputs(name, expected):
    preset = PRESETS[name]
    assert set(preset.assumed) == expected
    for key, assumed in preset.assumed.items():
        assert assumed.low <= preset.values[key].value <= assumed.high, key
        assert assumed.reason.strip() and assumed.distribution in ("uniform", "log-uniform")


def test_lambda_spans_the_paper_and_the_effusivity_rule():
    lam = PRESETS["spex8000m-3d"].assumed["lam"]
    assert (lam.low, lam.high) == (0.368, 0.5)


@pytest.mark.parametrize(
    ("key", "table", "value", "refused"),
    [
        ("friction", {**TABLE, "low": 0.7}, 0.3, "low < high"),
        ("friction", {**TABLE, "high": 6.0}, 0.3, "leaves friction's allowed range [0, 5]"),
        ("friction", {**TABLE, "distribution": "normal"}, 0.3, "distribution must be one of uniform, log-uniform"),
        ("rolling_friction", {**TABLE, "low": 0.0, "distribution": "log-uniform"}, 0.0, "log-uniform needs low > 0"),
        ("friction", {**TABLE, "reason": " "}, 0.3, "give the reason"),
        ("friction", {k: v for k, v in TABLE.items() if k != "reason"}, 0.3, "give exactly low, high, distribution, reason"),
        ("friction", TABLE, 0.8, "the preset's friction = 0.8 lies outside its range [0.1, 0.6]"),
        ("kinematics", TABLE, "planetary", "not a numeric key"),
        ("frction", TABLE, None, "not a numeric key"),
        ("n_balls", TABLE, 5, "not a numeric key"),
    ],
)
def test_a_bad_assumed_table_is_refused_in_one_line_naming_it(key, table, value, refused):
    with pytest.raises(ParameterError, match=None) as caught:
        check_holds(assumed_input(key, table, "mine.toml"), value, "mine.toml")
    message = str(caught.value)
    assert message.startswith(f"mine.toml: [assumed.{key}]") and refused in message and "\n" not in message


def test_a_preset_that_moves_an_inherited_input_outside_its_range_must_restate_it():
    base = {"friction": assumed_input("friction", TABLE, "base.toml")}
    with pytest.raises(ParameterError, match=r"child.toml: \[assumed.friction\]: the preset's friction = 0.8 lies outside"):
        inherited_assumed(base, {}, {"friction": 0.8}, (), SPEX_3D, "child.toml")
    restated = inherited_assumed(base, {"friction": {**TABLE, "high": 1.0}}, {"friction": 0.8}, (), SPEX_3D, "child.toml")
    assert restated["friction"].high == 1.0
    # Fitted, it is no longer assumed, wherever it ended.
    assert inherited_assumed(base, {}, {"friction": 0.8}, ("friction",), SPEX_3D, "child.toml") == {}


def test_a_users_range_from_the_command_line():
    narrowed = parse_assumption("friction=0.4:0.5", SPEX_3D)
    assert (narrowed.low, narrowed.high, narrowed.distribution) == (0.4, 0.5, "uniform")
    assert parse_assumption("clamp_loss=1:10:log-uniform", Reader("dem", "averaged", "mill-head", "spex8000m")).distribution == "log-uniform"
    for text, refused in (("friction=0.4", "write KEY=LOW:HIGH"), ("friction=a:b", "must be numbers"),
                          ("swing_radius=0.05:0.1", "kinematics = 'spex8000m' does not read it"),
                          ("friction=0.5:0.4", "low < high")):
        with pytest.raises(ParameterError, match=None) as caught:
            parse_assumption(text, SPEX_3D)
        assert refused in str(caught.value), text
