"""Each built-in engine's description says what its runs hold: the files, figures and studies above the engines
read these names and nothing else, so a name that is not in the run would break them there."""

from __future__ import annotations

import pytest

import shakermill as sm
from shakermill.engines.registry import describe


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
    for declared in (description.motion, description.averaged_flows, description.heat_variables,
                     description.term_variables, description.read_back):
        assert set(declared) <= variables, declared
    assert set(run.impact_columns) == set(description.impact_units)
    assert description.impact_target in description.impact_units
    # Each impact's dissipation by channel, where there is more than one (one channel: dissipated_energy is it).
    if len(description.channels) > 1:
        assert {f"dissipated_{channel}" for channel in description.channels} <= set(description.impact_units)
