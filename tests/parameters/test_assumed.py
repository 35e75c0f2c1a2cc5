"""Assumed inputs stated with the presets: a range, a distribution and a reason for every value no source fixes
(MODEL.md §14.1, issue 36)."""

from __future__ import annotations

import pytest

from shakermill.parameters.assumed import (
    assumed_input,
    check_holds,
    inherited_assumed,
    parse_assumption,
    with_derived,
)
from shakermill.parameters.config import load_config
from shakermill.parameters.engine_keys import Reader
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.presets import PRESETS, default_parameters
from shakermill.studies.ensembles.ensemble import ensemble_inputs

CONTACT = {"friction", "pair_friction", "restitution", "pair_restitution", "rolling_friction", "lam"}
HEAD = {"emissivity", "clamp_heat_capacity", "clamp_conductance", "clamp_loss"}
BOWL = {"vial_diameter", "vial_length", "outer_diameter", "outer_length"}
TABLE = {"low": 0.1, "high": 0.6, "distribution": "uniform", "reason": "assumed"}
SPEX_3D = Reader(engine="dem", solver="averaged", thermal_model="paper", kinematics="spex8000m")


@pytest.mark.parametrize(
    ("name", "expected"),
    [
        ("spex8000m-3d", CONTACT | {"lateral_amplitude", "yaw_amplitude"}),
        ("spex8000m-3d-mill-head", CONTACT | HEAD | {"lateral_amplitude", "yaw_amplitude"}),
        # A planetary jar has no SPEX clamp's figure of eight: the amplitudes are not its inputs.
        ("pulverisette7", CONTACT | HEAD | BOWL),
        ("pm100", CONTACT | HEAD | BOWL),
        ("mm400", CONTACT | {"amplitude", "swing_radius"}),
        # What a calibration fitted has its posterior, not an assumed range.
        (
            "spex8000m-3d-calibrated",
            CONTACT | {"emissivity", "clamp_conductance", "lateral_amplitude", "yaw_amplitude"},
        ),
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
        ("friction", {**TABLE, "distribution": "normal"}, 0.3, "distribution: must be one of uniform, log-uniform"),
        ("rolling_friction", {**TABLE, "low": 0.0, "distribution": "log-uniform"}, 0.0, "log-uniform needs low > 0"),
        ("friction", {**TABLE, "reason": " "}, 0.3, "give the reason"),
        (
            "friction",
            {k: v for k, v in TABLE.items() if k != "reason"},
            0.3,
            "give exactly low, high, distribution, reason",
        ),
        ("friction", {**TABLE, "moves": ["vial_mass"]}, 0.3, "moves lists keys derived from the vial's dimensions"),
        (
            "vial_diameter",
            {**TABLE, "low": 0.01, "moves": ["omega"]},
            0.02,
            "moves: lists keys derived from the vial's dimensions (inner_area, vial_mass)",
        ),
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
    with pytest.raises(
        ParameterError, match=r"child.toml: \[assumed.friction\]: the preset's friction = 0.8 lies outside"
    ):
        inherited_assumed(base, {}, {"friction": 0.8}, (), SPEX_3D, "child.toml")
    restated = inherited_assumed(
        base, {"friction": {**TABLE, "high": 1.0}}, {"friction": 0.8}, (), SPEX_3D, "child.toml"
    )
    assert restated["friction"].high == 1.0
    # Fitted, it is no longer assumed, wherever it ended.
    assert inherited_assumed(base, {}, {"friction": 0.8}, ("friction",), SPEX_3D, "child.toml") == {}


def test_a_users_range_from_the_command_line():
    narrowed = parse_assumption("friction=0.4:0.5", SPEX_3D)
    assert (narrowed.low, narrowed.high, narrowed.distribution) == (0.4, 0.5, "uniform")
    assert (
        parse_assumption(
            "clamp_loss=1:10:log-uniform",
            Reader(engine="dem", solver="averaged", thermal_model="mill-head", kinematics="spex8000m"),
        ).distribution
        == "log-uniform"
    )
    for text, refused in (
        ("friction=0.4", "write KEY=LOW:HIGH"),
        ("friction=a:b", "must be numbers"),
        ("swing_radius=0.05:0.1", "kinematics = 'spex8000m' does not read it"),
        ("friction=0.5:0.4", "low < high"),
    ):
        with pytest.raises(ParameterError, match=None) as caught:
            parse_assumption(text, SPEX_3D)
        assert refused in str(caught.value), text


def test_a_planetary_bowls_dimensions_move_its_inner_area_and_wall_mass_with_them():
    """Ø40 x 28.5 mm bore in a Ø70 x 55 mm outside, by hand: π·40·28.5 + 2·π·40²/4 = 6094.7 mm²; steel
    π/4·(70²·55 − 40²·28.5) = 175,855 mm³ against the preset's π/4·(70²·50 − 45²·28.5) = 147,098 mm³, so the wall's
    1.14734 kg becomes 1.37163 kg at the same density."""
    preset = PRESETS["pulverisette7"]
    params = default_parameters("pulverisette7")
    moved = with_derived(params, list(preset.assumed.values()), {"vial_diameter": 0.04, "outer_length": 0.055})
    assert moved["inner_area"] == pytest.approx(6094.69e-6, rel=1e-5)
    assert moved["vial_mass"] == pytest.approx(1.147343 * 175_855.0 / 147_098.0, rel=1e-4)
    assert moved["vial_mass"] == pytest.approx(1.37163, rel=1e-4)
    # An input that moves nothing derived leaves the member as it is.
    assert with_derived(params, list(preset.assumed.values()), {"friction": 0.2}) == {"friction": 0.2}
    # A user's own range of a bowl key keeps what the preset's range of it moves.
    inputs, _, _ = ensemble_inputs(preset, params, ["vial_diameter=0.042:0.048"], ["vial_diameter"])
    assert inputs[0].moves == ("inner_area", "vial_mass") and inputs[0].low == 0.042


def test_a_bowl_whose_inner_area_is_not_its_bores_cannot_move_it(tmp_path):
    # A vial whose inner area was set apart from its bore (here by hand): a range of its diameter may not move it.
    config = tmp_path / "mine.toml"
    config.write_text(
        'preset = "spex8000m-3d"\ninner_area = 0.005\n[assumed.vial_diameter]\nlow = 0.035\nhigh = 0.041\n'
        'distribution = "uniform"\nreason = "ours"\nmoves = ["inner_area"]\n',
        encoding="utf-8",
    )
    with pytest.raises(
        ParameterError,
        match=r"mine.toml: \[assumed.vial_diameter\]: moves inner_area, but the preset's "
        r"inner_area = 0.005 is not the 0.00919\d* its vial's dimensions give",
    ):
        load_config(config)


def test_a_users_range_of_a_key_the_run_does_not_read_is_refused(tmp_path):
    config = tmp_path / "mine.toml"
    config.write_text(
        'preset = "spex8000m-3d"\n[assumed.swing_radius]\nlow = 0.05\nhigh = 0.1\n'
        'distribution = "uniform"\nreason = "ours"\n',
        encoding="utf-8",
    )
    with pytest.raises(ParameterError, match=r"swing_radius.*kinematics = 'spex8000m' does not read it"):
        load_config(config)
