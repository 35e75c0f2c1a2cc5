"""Each built-in engine's description says what its runs hold: the files, figures and studies above the engines
read these names and nothing else, so a name that is not in the run would break them there."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import shakermill as sm
from shakermill.engines.registry import describe
from shakermill.parameters.keys import FIELD_NAMES


@pytest.fixture(scope="module", params=["1d", "dem"])
def run(request):
    return sm.simulate(sm.default_parameters(engine=request.param, duration=0.3, record_windows=((0.0, 0.3),)))


def test_the_declared_per_ball_variables_are_those_with_a_ball_dimension(run):
    history = run.history
    with_balls = {name for name in history.variables if "ball" in history.dims(name)}
    assert with_balls == set(describe(run.params.engine).per_ball)


def test_every_declared_variable_and_column_is_in_the_run(run):
    description = describe(run.params.engine)
    variables = set(run.history.variables) | {"time"}
    for declared in (
        description.motion,
        description.averaged_flows,
        description.heat_variables,
        description.term_variables,
        description.read_back,
    ):
        assert set(declared) <= variables, declared
    assert set(run.impact_columns) == set(description.impact_units)
    assert description.impact_target in description.impact_units
    # Each impact's dissipation by channel, where there is more than one (one channel: dissipated_energy is it).
    if len(description.channels) > 1:
        assert {f"dissipated_{channel}" for channel in description.channels} <= set(description.impact_units)


ENGINE_PACKAGES = {"1d": "one_d", "dem": "dem"}


@pytest.mark.parametrize("engine", sorted(ENGINE_PACKAGES))
def test_no_key_an_engine_does_not_list_as_read_is_read_by_its_package(engine):
    # `shakermill keys --engine` and the report leave these keys out: an engine that starts reading one must say so.
    reads = describe(engine).keys.reads
    assert reads <= set(FIELD_NAMES)
    unread = set(FIELD_NAMES) - reads
    package = Path(sm.__file__).parent / "engines" / ENGINE_PACKAGES[engine]
    source = "\n".join(path.read_text(encoding="utf-8") for path in package.glob("*.py"))
    read = sorted(key for key in unread if re.search(rf"\.{key}\b|[\"']{key}[\"']", source))
    assert read == [], f"the {engine} engine reads {read}"


@pytest.mark.parametrize(
    ("engine", "changes"),
    [
        ("1d", {"friction": 0.1, "gravity": False, "contact_step_fraction": 0.1, "vial_conductivity": 10.0}),
        ("dem", {"rtol": 1e-3, "atol_temperature": 1e-3, "heat_model": "paper", "energy_projection": False}),
    ],
)
def test_a_key_an_engine_does_not_read_leaves_its_run_as_it_was(run, engine, changes):
    if run.params.engine != engine:
        pytest.skip("the other engine's run")
    assert not set(changes) & describe(engine).keys.reads
    again = sm.simulate(run.params.replace(**changes))
    assert again.summary.heat_power_W == run.summary.heat_power_W
    for name in run.history.variables:
        assert np.array_equal(again.history[name], run.history[name], equal_nan=True), name
