"""Each component of a run declares its keys once, in a key group (parameters/groups/), and every "who reads what" is
derived from the groups: each engine's keys, the keys of a thermal network or a vial motion, the keys that enter the
thermal network alone, the preset of the paper's values (issues 39 and 48)."""

from __future__ import annotations

import pytest

import shakermill as sm
from shakermill.parameters.config import load_config
from shakermill.parameters.engine_keys import (
    BUILT_IN,
    DECIDING,
    ENGINE_KEYS,
    SOLVER_KEYS,
    keys_decided_by,
    reads_of,
    thermal_only_of,
)
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.groups import COMPONENTS, CORE, GROUP_OF, GROUPS, CoreKeys, default_of, keys_of, marked
from shakermill.parameters.groups.paper_network import PaperNetwork
from shakermill.parameters.groups.powder import PowderCoating, PowderHeat
from shakermill.parameters.groups.run import RunControl
from shakermill.parameters.key_group import CONTACT_COATING, NETWORK_NODE, VIAL_MOTION, When
from shakermill.parameters.keys import FIELD_NAMES, Parameters, field_description, field_source, field_unit
from shakermill.parameters.kinematic_models import KINEMATIC_MODELS
from shakermill.parameters.presets import SPEX_8000M


def test_every_key_is_declared_by_one_group_with_its_unit_meaning_and_cited_default():
    assert sorted(GROUP_OF) == sorted(FIELD_NAMES)
    assert sum(len(group.keys()) for group in GROUPS) == len(FIELD_NAMES)
    for key in FIELD_NAMES:
        assert field_description(key), key
        assert field_source(key), key
        assert isinstance(field_unit(key), str)
    # The paper's preset is the keys' defaults, each with its field's source.
    assert {key: cited.value for key, cited in SPEX_8000M.values.items()} == {
        key: default_of(key) for key in FIELD_NAMES
    }
    assert SPEX_8000M.values["omega"].source == field_source("omega")
    for group in GROUPS:
        assert group.title and group.__doc__, group


def test_the_core_groups_are_typed_attributes_and_the_components_are_found_in_their_folder():
    assert set(CoreKeys.model_fields) == keys_of(*CORE)
    assert {group.role for group in CORE} == {None}
    assert {group.role for group in COMPONENTS} == {NETWORK_NODE, CONTACT_COATING, VIAL_MOTION}
    assert {PowderCoating, PowderHeat} <= set(COMPONENTS)
    params = sm.default_parameters("spex8000m-3d", powder_mass=0.004)
    assert isinstance(params, PowderHeat) and PowderHeat.of(params).powder_heat_share == params.powder_heat_share
    with pytest.raises(TypeError, match="does not hold the keys of PowderHeat"):
        PowderHeat.of(RunControl())


def test_every_key_is_read_by_an_engine_and_each_network_and_motion_by_the_engines_that_take_it():
    read = set().union(*(ENGINE_KEYS[engine].reads for engine in BUILT_IN))
    assert read == set(FIELD_NAMES), sorted(set(FIELD_NAMES) - read)
    for engine in BUILT_IN:
        keys = ENGINE_KEYS[engine]
        for network in keys.networks:
            assert keys_decided_by("thermal_model", network) <= keys.reads, (engine, network)
        assert {key for name in keys.kinematics for key in KINEMATIC_MODELS[name].keys} <= keys.reads
        assert keys_of(RunControl, PaperNetwork) <= keys.reads
    assert keys_decided_by("thermal_model", "paper") == {"h_outer", "outer_area"}
    assert "drive_heat" in keys_decided_by("thermal_model", "mill-head")
    assert {"averaging_max_time", "averaging_rel_error", "dem_replicas"} <= SOLVER_KEYS
    assert DECIDING[:2] == ("engine", "solver") and {"thermal_model", "kinematics", "powder_mass"} <= set(DECIDING)


def test_an_engine_reads_the_groups_it_names_and_every_component_of_the_kinds_it_takes():
    assert reads_of(RunControl) == keys_of(RunControl)
    assert keys_of(PowderCoating) <= reads_of(roles=(CONTACT_COATING,))
    assert not keys_of(PowderHeat) & reads_of(roles=(CONTACT_COATING,))
    assert reads_of(kinematics=("planetary",)) == {"revolution_radius", "speed_ratio", "jar_tilt"}
    # The 1-D engine writes its network out and moves its vial along the axis: it takes no component.
    assert not keys_of(*COMPONENTS) & ENGINE_KEYS["1d"].reads
    assert keys_of(*COMPONENTS) <= ENGINE_KEYS["dem"].reads


def test_the_keys_that_enter_the_thermal_network_alone_are_those_their_fields_mark():
    dem = ENGINE_KEYS["dem"]
    assert dem.thermal_only_keys == thermal_only_of(dem.reads)
    assert all(marked(key, "thermal_only") for key in dem.thermal_only_keys)
    assert {"h_inner", "beta", "duration", "drive_heat", "powder_contact_coefficient"} <= set(dem.thermal_only_keys)
    # What the stepping reads is never thermal-only: the heat split, the Reynolds number, the powder's share.
    assert not {"lam", "eta", "air_density", "ball_heat_capacity", "powder_heat_share"} & set(dem.thermal_only_keys)
    assert ENGINE_KEYS["1d"].thermal_only_keys == ()


def test_a_rule_reads_its_own_deciding_key_and_refuses_the_others_with_why():
    rule = PowderCoating.rule
    assert isinstance(rule, When) and rule.key == "powder_mass"
    assert rule.refusal("powder_mass", {"powder_mass": 0.0}) is None
    assert rule.refusal("powder_restitution", {"powder_mass": 0.0}).startswith("a run without powder")
    assert rule.refusal("powder_restitution", {"powder_mass": 0.004}) is None


def test_the_powder_is_read_by_the_dem_engine_and_refused_on_the_one_d_engine():
    with pytest.raises(ParameterError) as raised:
        load_config(overrides=["powder_mass=0.001"])
    assert str(raised.value) == (
        "powder_mass: set explicitly, but the 1-D engine (engine = '1d') does not read it; it applies to engine = 'dem'"
    )


@pytest.mark.parametrize(
    ("engine", "setting", "where"),
    [
        ("1d", "gravity=false", "engine = 'dem'"),
        ("dem", "atol_momentum=1e-6", "engine = '1d'"),
        # The 1-D engine never read the vial's density (the 'dem' engine's split of a contact's heat does).
        ("1d", "vial_density=7000", "engine = 'dem'"),
    ],
)
def test_a_key_an_engine_does_not_read_is_refused_on_each_built_in_engine(engine, setting, where):
    key = setting.partition("=")[0]
    assert key not in ENGINE_KEYS[engine].reads
    with pytest.raises(
        ParameterError, match=rf"^{key}: set explicitly, but .* does not read it; it applies to {where}$"
    ):
        load_config(preset="spex8000m-3d" if engine == "dem" else None, overrides=[setting])


def test_parameters_carry_their_engines_keys():
    assert sm.default_parameters().engine_keys is ENGINE_KEYS["1d"]
    assert sm.default_parameters(engine="dem").engine_keys is ENGINE_KEYS["dem"]
    assert sm.default_parameters(engine="dem").engine_keys.replicas_key == "dem_replicas"
    assert set(Parameters.model_fields) == set(FIELD_NAMES)
