"""Run configuration: precedence of preset, file and --set; errors; exact TOML round trip."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

from shakermill.parameters import presets as params_module
from shakermill.parameters.config import load_config, parse_overrides, write_config_toml
from shakermill.parameters.defaults import DEFAULT_PRESET
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.presets import Cited, Preset, default_parameters, preset_values


def write_toml(tmp_path: Path, text: str, name: str = "run.toml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


@pytest.fixture(name="other_preset")
def other_preset_fixture(monkeypatch: pytest.MonkeyPatch) -> str:
    """A second preset, differing from the default in restitution and duration."""
    values = dict(params_module.PRESETS[DEFAULT_PRESET].values)
    values["restitution"] = Cited(0.5, "test")
    values["duration"] = Cited(7.0, "test")
    monkeypatch.setitem(params_module.PRESETS, "other", Preset("other", "test preset", values))
    return "other"


def test_no_file_no_overrides_gives_the_default_preset():
    config = load_config()
    assert config.params == default_parameters()
    assert config.preset == DEFAULT_PRESET
    assert config.source is None


def test_file_overrides_preset_and_set_overrides_file(tmp_path):
    path = write_toml(
        tmp_path,
        'restitution = 0.8\nduration = "2 min"\nomega = 100\nrecord_windows = [[0, "200 ms"], [30, 0.1]]\n',
    )
    config = load_config(path, overrides=["restitution=0.6", "vial_mass=40 g"])
    assert config.params.restitution == 0.6  # --set beats the file
    assert config.params.duration == pytest.approx(120.0)  # file with units beats the preset
    assert config.params.omega == 100.0
    assert config.params.vial_mass == pytest.approx(0.04)
    assert config.params.record_windows == ((0.0, pytest.approx(0.2)), (30.0, 0.1))
    assert config.params.eta == default_parameters().eta  # untouched keys come from the preset
    assert config.source == path


def test_preset_named_in_file_is_used(tmp_path, other_preset):
    path = write_toml(tmp_path, f'preset = "{other_preset}"\neta = 0.5\n')
    config = load_config(path)
    assert config.preset == other_preset
    assert (config.params.restitution, config.params.duration, config.params.eta) == (0.5, 7.0, 0.5)


def test_command_line_preset_beats_the_file_preset(tmp_path, other_preset):
    path = write_toml(tmp_path, f'preset = "{DEFAULT_PRESET}"\n')
    config = load_config(path, preset=other_preset)
    assert config.preset == other_preset
    assert config.params.restitution == 0.5


def test_unknown_preset_is_reported(tmp_path):
    with pytest.raises(ParameterError, match=r"unknown preset 'nope'.*spex8000m"):
        load_config(write_toml(tmp_path, 'preset = "nope"\n'))


def test_preset_entry_must_be_a_string(tmp_path):
    with pytest.raises(ParameterError, match="preset must be a string"):
        load_config(write_toml(tmp_path, "preset = 3\n"))


def test_malformed_toml_names_file_line_and_column(tmp_path):
    path = write_toml(tmp_path, "duration = 2\nrestitution = \n", name="broken.toml")
    with pytest.raises(ParameterError) as caught:
        load_config(path)
    message = str(caught.value)
    assert "broken.toml" in message and "malformed TOML" in message
    assert "line 2" in message and "column" in message
    assert "\n" not in message


def test_missing_file_is_one_clear_line(tmp_path):
    with pytest.raises(ParameterError, match="no such configuration file"):
        load_config(tmp_path / "absent.toml")


def test_unknown_key_in_file_suggests_the_right_one(tmp_path):
    with pytest.raises(ParameterError, match="restitutoin: unknown parameter; did you mean 'restitution'"):
        load_config(write_toml(tmp_path, "restitutoin = 0.5\n"))


def test_window_with_wrong_unit_in_file_names_the_key(tmp_path):
    with pytest.raises(
        ParameterError, match="record_windows: .*wrong dimension \\(read as .*\\); expected a time such as s"
    ):
        load_config(write_toml(tmp_path, 'record_windows = [[0, "1 kg"]]\n'))


def test_provenance_table_is_ignored_on_loading(tmp_path):
    path = write_toml(tmp_path, 'eta = 0.7\n[provenance]\nshakermill_version = "0.0"\nanything = 1\n')
    assert load_config(path).params.eta == 0.7


@pytest.mark.parametrize("item", ["duration", "=3", " = 3"])
def test_set_item_without_key_and_equals_sign_is_rejected(item):
    with pytest.raises(ParameterError, match="expected KEY=VALUE"):
        parse_overrides([item])


def test_later_set_items_win_and_values_keep_their_spaces_and_equals_signs():
    assert parse_overrides(["eta=0.5", " eta = 0.6 ", "heat_model=a=b"]) == {"eta": "0.6", "heat_model": "a=b"}


@pytest.mark.parametrize(
    "changes",
    [
        # Floats without a short decimal form, changed options and the opposite booleans.
        dict(
            ball_radius=1e-2 / 3,
            omega=2 * 3.141592653589793 * 17.7,
            phase=-0.1,
            ball_momentum=-1e-7,
            energy_projection=False,
            no_tension=True,
            heat_model="paper",
            convection_velocity="relative",
            record_windows=((0.1 / 3, 0.7), (12.5, 1e-3)),
        ),
        dict(record_windows=()),
    ],
)
def test_written_config_loads_back_to_identical_parameters(tmp_path, changes):
    original = default_parameters().replace(**changes)
    path = write_config_toml(original, tmp_path / "config.toml", preset=DEFAULT_PRESET)
    loaded = load_config(path)
    assert loaded.params == original
    assert loaded.params.model_dump() == original.model_dump()
    assert loaded.preset == DEFAULT_PRESET


def test_written_config_has_provenance_and_no_leftover_temporary_file(tmp_path):
    path = write_config_toml(
        default_parameters(),
        tmp_path / "config.toml",
        preset=DEFAULT_PRESET,
        extra_provenance={"status": 0, "config_file": None, "overrides": ["eta=0.5"]},
    )
    document = tomllib.loads(path.read_text(encoding="utf-8"))
    provenance = document["provenance"]
    assert provenance["preset"] == DEFAULT_PRESET
    assert provenance["shakermill_version"]
    assert "SI" in provenance["units"]
    assert provenance["created_utc"].endswith("+00:00")
    assert provenance["status"] == 0 and provenance["overrides"] == ["eta=0.5"]
    assert "config_file" not in provenance  # None has no TOML form and is left out
    assert [entry.name for entry in tmp_path.iterdir()] == ["config.toml"]


# --- hostile files (issue 12) ---------------------------------------------------------------------


def test_a_byte_order_mark_is_read_as_utf8(tmp_path):
    path = tmp_path / "bom.toml"
    path.write_text("eta = 0.7\n", encoding="utf-8-sig")
    assert path.read_bytes().startswith(b"\xef\xbb\xbf")
    assert load_config(path).params.eta == 0.7


@pytest.mark.parametrize("encoding", ["latin-1", "utf-16"])
def test_a_file_in_another_encoding_is_one_line_naming_it(tmp_path, encoding):
    path = tmp_path / "other.toml"
    path.write_text("# für die Mühle\neta = 0.7\n", encoding=encoding)
    with pytest.raises(
        ParameterError, match=r"other.toml: not UTF-8 text \(byte 0x.. at offset \d+\); save it as UTF-8"
    ):
        load_config(path)


def test_a_file_larger_than_any_configuration_is_refused_unread(tmp_path):
    path = write_toml(tmp_path, "#" * 1_000_001 + "\n")
    with pytest.raises(ParameterError, match="larger than 1,000,000 bytes"):
        load_config(path)


@pytest.mark.parametrize(
    ("text", "fragments"),
    [
        ("omega = inf\n", ("omega: inf is not a finite number", "allowed [1, 10000] rad/s")),
        ("phase = nan\n", ("phase: nan is not a finite number",)),
        (
            "attractor_starts = true\n",
            ("attractor_starts: expected a whole number, got True", "allowed a whole number"),
        ),
        ("duration = false\n", ("duration: expected a number or a quantity with units, got False",)),
        ("no_tension = 1\n", ("no_tension: expected true or false, got 1",)),
        ("duration = " + "9" * 5000 + "\n", ("malformed TOML: a number too long to read",)),
        ("record_windows = [[0.0, inf]]\n", ("record_windows: inf is not a finite number",)),
    ],
)
def test_bad_values_in_a_file_are_one_line_naming_the_key(tmp_path, text, fragments):
    with pytest.raises(ParameterError) as info:
        load_config(write_toml(tmp_path, text))
    for fragment in fragments:
        assert fragment in str(info.value)


def test_windows_with_units_in_a_file_are_converted(tmp_path):
    path = write_toml(tmp_path, 'record_windows = [["0 s", "100 ms"], [600, "1 min"]]\n')
    assert load_config(path).params.record_windows == ((0.0, 0.1), (600.0, 60.0))


def test_a_balls_diameter_is_taken_as_twice_its_radius_from_the_command_line_and_a_file(tmp_path):
    """Issue 37, point 6: `--set ball_diameter="10 mm"` answered "did you mean 'vial_diameter'?"."""
    from shakermill.parameters.config import load_config
    from shakermill.parameters.errors import ParameterError

    assert load_config(preset="spex8000m-3d", overrides=["ball_diameter=10 mm"]).params.ball_radius == pytest.approx(
        0.005
    )
    assert load_config(preset="spex8000m-3d", overrides=["ball_diameter=0.0127"]).params.ball_radius == pytest.approx(
        0.00635
    )
    mine = tmp_path / "mine.toml"
    mine.write_text('preset = "spex8000m-3d"\nball_diameter = "8 mm"\n', encoding="utf-8")
    assert load_config(mine).params.ball_radius == pytest.approx(0.004)
    with pytest.raises(
        ParameterError, match=r"^ball_diameter: give ball_radius or ball_diameter \(twice ball_radius\), not both$"
    ):
        load_config(overrides=["ball_diameter=10 mm", "ball_radius=5 mm"])
    with pytest.raises(
        ParameterError, match=r"^ball_diameter: .*allowed a length from 5e-05 to 0.2 m \(twice ball_radius\)$"
    ):
        load_config(overrides=["ball_diameter=10 kg"])
    # Out of range, the diameter is refused as the diameter the user gave, not as a radius they never typed.
    with pytest.raises(
        ParameterError,
        match=r"^ball_diameter: 1 m is out of range; allowed a length from 5e-05 to 0.2 m \(twice ball_radius\)$",
    ):
        load_config(overrides=["ball_diameter=1 m"])


def test_a_fitted_files_run_says_the_presets_caveat_is_of_the_preset_as_shipped():
    """Issue 37, point 1: the guide's fitted file was told 'its thermal network is not calibrated' by its base
    preset."""
    from shakermill.parameters.presets import PRESETS

    preset = PRESETS["spex8000m-3d"]
    values = preset_values("spex8000m-3d")
    assert preset.caveat_for(values) == preset.caveat
    refitted = preset.caveat_for(values, refitted=("beta", "vial_mass", "h_outer"))
    assert refitted.startswith(preset.caveat) and "refits beta, vial_mass, h_outer" in refitted
    assert "of the preset as shipped" in refitted
