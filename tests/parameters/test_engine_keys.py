"""Each engine lists the keys it reads (``EngineKeys.reads``), from groups stated once and its own keys; a key set
explicitly that the run's engine does not list is refused, whichever the engine (issue 39)."""

from __future__ import annotations

import pytest

import shakermill as sm
from shakermill.parameters import engine_keys
from shakermill.parameters.config import load_config
from shakermill.parameters.engine_keys import BUILT_IN, ENGINE_KEYS, NETWORK_ONLY, POWDER, motion_keys
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.keys import FIELD_NAMES
from shakermill.parameters.kinematic_models import KINEMATIC_MODELS

GROUPS = {
    name: value
    for name, value in vars(engine_keys).items()
    if name.isupper() and isinstance(value, frozenset) and all(isinstance(key, str) for key in value)
}


def test_every_group_and_every_list_names_keys_of_parameters_and_every_key_is_read_by_an_engine():
    assert {"RUN_CONTROL", "PAPER_THERMAL", "MILL_HEAD_THERMAL", "POWDER", "SEVERAL_BALLS"} <= set(GROUPS)
    for name, group in GROUPS.items():
        assert group <= set(FIELD_NAMES), (name, sorted(group - set(FIELD_NAMES)))
    read = set().union(*(ENGINE_KEYS[engine].reads for engine in BUILT_IN))
    assert read == set(FIELD_NAMES), sorted(set(FIELD_NAMES) - read)
    # Each network's own keys are in the groups of the engines that take the network.
    for engine in BUILT_IN:
        keys = ENGINE_KEYS[engine]
        for network in keys.networks:
            assert NETWORK_ONLY[network] <= keys.reads, (engine, network)
        assert motion_keys(keys.kinematics) <= keys.reads
    assert motion_keys(("axial",)) == {"amplitude"} and "kinematics" in motion_keys(KINEMATIC_MODELS)


def test_the_run_control_and_the_papers_network_are_read_by_every_built_in_engine():
    for engine in BUILT_IN:
        assert engine_keys.RUN_CONTROL | engine_keys.PAPER_THERMAL <= ENGINE_KEYS[engine].reads


def test_the_powder_is_read_by_the_dem_engine_and_refused_on_the_one_d_engine():
    assert POWDER <= ENGINE_KEYS["dem"].reads and not POWDER & ENGINE_KEYS["1d"].reads
    with pytest.raises(ParameterError) as raised:
        load_config(overrides=["powder_mass=0.001"])
    assert str(raised.value) == (
        "powder_mass: set explicitly, but the 1-D engine (engine = '1d') does not read it; it applies to engine = 'dem'"
    )


@pytest.mark.parametrize(
    ("engine", "setting", "where"),
    [("1d", "gravity=false", "engine = 'dem'"), ("dem", "atol_momentum=1e-6", "engine = '1d'")],
)
def test_a_key_an_engine_does_not_list_is_refused_on_each_built_in_engine(engine, setting, where):
    key = setting.partition("=")[0]
    assert key not in ENGINE_KEYS[engine].reads
    with pytest.raises(
        ParameterError, match=rf"^{key}: set explicitly, but .* does not read it; it applies to {where}$"
    ):
        load_config(preset="spex8000m-3d" if engine == "dem" else None, overrides=[setting])


def test_parameters_carry_their_engines_keys():
    assert sm.default_parameters().engine_keys is ENGINE_KEYS["1d"]
    assert sm.default_parameters(engine="dem").engine_keys is ENGINE_KEYS["dem"]
    assert sm.default_parameters(engine="dem").engine_keys.thermal_only_keys
    assert sm.default_parameters(engine="dem").engine_keys.replicas_key == "dem_replicas"
