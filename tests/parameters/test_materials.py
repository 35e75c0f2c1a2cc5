"""The materials library (parameters/materials.toml) and the keys that select from it."""

from __future__ import annotations

import pint
import pytest

import shakermill as sm
from shakermill.parameters import materials
from shakermill.parameters.config import load_config, write_config_toml
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.presets import PRESETS, load_preset_file
from shakermill.studies.sweeps.plan import plan_sweep

TWO_BALLS = {"engine": "dem", "n_balls": 2, "vial_diameter": "38 mm"}
# Room-temperature solids that milling media are made of, in SI.
PLAUSIBLE = {
    "density": (1000.0, 20_000.0),
    "youngs_modulus": (1e9, 1e12),
    "poisson_ratio": (0.0, 0.5),
    "heat_capacity": (100.0, 2000.0),
    "conductivity": (0.1, 500.0),
}
LIBRARY = list(materials.library().values())


def test_the_library_holds_the_media_the_brief_names():
    assert {
        "hardened-steel",
        "stainless-steel-440c",
        "stainless-steel-304",
        "tungsten-carbide",
        "zirconia",
        "alumina",
        "silicon-nitride",
        "agate",
    } <= set(materials.names())


@pytest.mark.parametrize("found", LIBRARY, ids=lambda found: found.name)
def test_every_value_has_a_source_a_unit_pint_reads_and_a_plausible_size(found):
    registry = pint.UnitRegistry()
    for key, sourced in found.properties().items():
        assert sourced.source.strip(), (found.name, key)
        registry.Quantity(1.0, sourced.unit)  # raises on a unit pint does not know
        assert registry.Quantity(1.0, sourced.unit).to_base_units().magnitude == pytest.approx(1.0), (found.name, key)
    for key, (low, high) in PLAUSIBLE.items():
        assert low < getattr(found, key).value < high, (found.name, key)
    for key in materials.RANGES:
        low, high = getattr(found, key).value
        assert 0.0 < low <= high <= 1.0, (found.name, key)
    if found.melting_point is not None:
        assert 1000.0 < found.melting_point.value < 4000.0, found.name


def test_a_powder_node_is_bounded_by_its_materials_melting_point_where_it_is_below_the_ceiling():
    from shakermill.engines.dem.model import network_of
    from shakermill.solvers.result import PHYSICAL_CEILING, node_ceiling

    charge = {"powder_mass": "5 g", "record_windows": ()}

    def powder_of(material):
        params = sm.default_parameters("spex8000m-3d", **charge, powder_material=material)
        return next(node for node in network_of(params).others if node.name == "powder")

    iron = powder_of("iron")
    assert node_ceiling(iron) == (1811.0, "1538 °C, the melting point of its material (iron)")
    # Zirconia melts above the ceiling every node has, and silicon nitride decomposes before it melts.
    assert node_ceiling(powder_of("zirconia"))[0] == PHYSICAL_CEILING
    assert powder_of("silicon-nitride").melting_point is None
    assert node_ceiling(powder_of("silicon-nitride"))[0] == PHYSICAL_CEILING


def test_hardened_steel_is_the_papers_steel_so_selecting_it_changes_nothing():
    assert sm.default_parameters(ball_material="steel", vial_material="steel") == sm.default_parameters(
        ball_material="hardened-steel", vial_material="hardened-steel"
    )
    default, steel = sm.default_parameters(), sm.default_parameters(ball_material="steel")
    assert steel.model_dump() == {**default.model_dump(), "ball_material": "hardened-steel"}


def test_a_material_fills_the_ball_keys_and_the_engines_per_ball_values():
    params = sm.default_parameters(ball_material="tungsten-carbide")
    wc = materials.material("tungsten-carbide")
    assert (params.ball_density, params.ball_youngs_modulus, params.ball_poisson_ratio) == (15000.0, 630e9, 0.24)
    assert (params.ball_heat_capacity, params.ball_conductivity) == (wc.heat_capacity.value, wc.conductivity.value)
    assert sm.default_parameters(**TWO_BALLS, ball_material="wc").ball_values("ball_density") == (15000.0, 15000.0)
    # The contact pair's restitution and friction stay the preset's.
    assert (params.restitution, params.friction) == (0.7, 0.3)


def test_an_explicit_key_wins_over_the_material_set_with_it_or_before_it(tmp_path):
    assert sm.default_parameters(ball_material="wc", ball_density="14 g/cm^3").ball_density == pytest.approx(14000.0)
    path = tmp_path / "wc.toml"
    path.write_text('ball_material = "tungsten-carbide"\nball_density = 14500\n')
    assert load_config(path).params.ball_density == 14500.0
    assert load_config(path, overrides=["ball_density=14000"]).params.ball_density == 14000.0
    # A material named later replaces the values of the layers below it: the file's density, the preset's.
    path.write_text("ball_density = 8000\n")
    assert load_config(path, overrides=["ball_material=zirconia"]).params.ball_density == 6050.0


def test_replace_re_resolves_a_changed_material_and_keeps_the_values_otherwise():
    params = sm.default_parameters(ball_material="wc", ball_density=14000.0)
    assert params.replace(ball_radius="5 mm").ball_density == 14000.0
    assert params.replace(ball_material="zirconia").ball_density == 6050.0


def test_per_ball_materials_fill_the_per_ball_lists_of_a_dem_run():
    params = sm.default_parameters(**TWO_BALLS, ball_materials="wc, zirconia")
    assert params.ball_materials == ("tungsten-carbide", "zirconia")
    assert params.ball_values("ball_density") == (15000.0, 6050.0)
    assert params.ball_values("ball_conductivity") == (85.0, 2.5)
    assert params.ball_values("ball_youngs_modulus") == (630e9, 205e9)
    mixed = sm.default_parameters(**TWO_BALLS, ball_materials=["wc", "zirconia"], ball_densities=[15600, 6000])
    assert mixed.ball_values("ball_density") == (15600.0, 6000.0)
    assert mixed.ball_values("ball_heat_capacity") == (280.0, 500.0)


def test_a_short_dem_run_uses_each_balls_material():
    params = sm.default_parameters(**TWO_BALLS, ball_materials="wc, agate", duration=0.01, record_windows=())
    result = sm.simulate(params)
    assert result.success, result.message


def test_vial_material_fills_the_vial_keys():
    params = sm.default_parameters(vial_material="stainless-steel-304")
    assert (params.vial_density, params.vial_youngs_modulus, params.vial_poisson_ratio, params.vial_heat_capacity) == (
        7900.0,
        200e9,
        0.29,
        500.0,
    )
    assert params.ball_density == 7800.0


def test_a_configuration_with_materials_round_trips(tmp_path):
    params = sm.default_parameters(
        **TWO_BALLS,
        ball_material="wc",
        ball_materials="zirconia, alumina",
        vial_material="aisi-440c",
        ball_density=14000.0,
    )
    path = tmp_path / "config.toml"
    write_config_toml(params, path, preset="spex8000m")
    assert load_config(path).params == params


@pytest.mark.parametrize(
    ("settings", "fragments"),
    [
        ({"ball_material": "gold"}, ["ball_material: unknown material 'gold'", "tungsten-carbide", "agate"]),
        ({"vial_material": "Pyrex"}, ["vial_material: unknown material 'Pyrex'", "allowed one of"]),
        ({**TWO_BALLS, "ball_materials": "wc, unobtainium"}, ["ball_materials: unknown material 'unobtainium'"]),
        ({**TWO_BALLS, "ball_materials": "wc"}, ["ball_materials: 1 names for n_balls = 2"]),
        ({"ball_materials": 5}, ["ball_materials: expected a list of material names"]),
    ],
)
def test_bad_material_names_are_one_line_listing_the_names(settings, fragments):
    with pytest.raises(ParameterError) as caught:
        sm.default_parameters(**settings)
    message = str(caught.value)
    assert "\n" not in message
    for fragment in fragments:
        assert fragment in message, (fragment, message)


def test_a_preset_naming_a_material_cites_the_materials_sources(tmp_path):
    path = tmp_path / "zirconia-balls.toml"
    path.write_text('preset = "spex8000m"\nball_material = "zirconia"\nball_heat_capacity = 450\n')
    preset = load_preset_file(path, PRESETS)
    assert preset.values["ball_density"].value == 6050.0
    assert preset.values["ball_density"].source.startswith("material zirconia: ")
    assert "vinayaktechnoceramics" in preset.values["ball_density"].source
    assert preset.values["ball_heat_capacity"].value == 450
    assert preset.values["vial_density"].source == PRESETS["spex8000m"].values["vial_density"].source


def test_a_sweep_over_the_ball_material_resolves_each_points_values():
    plan = plan_sweep(["ball_material=steel,wc,zirconia"])
    assert [point["ball_material"] for point in plan.points] == ["hardened-steel", "tungsten-carbide", "zirconia"]
    base = sm.default_parameters(solver="averaged")
    densities = [base.replace(**point).ball_density for point in plan.points]
    assert densities == [7800.0, 15000.0, 6050.0]
    with pytest.raises(ParameterError, match="grid 'ball_material=steel,gold': ball_material: unknown material"):
        plan_sweep(["ball_material=steel,gold"])
