"""Shared fixtures: the paper's tables, parameter sets for analytic cases and one cached default run."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

import shakermill as sm
from shakermill.parameters.keys import Parameters

# The paper's tables as data: a verbatim copy of ../shared/reference-data/paper.toml, kept in the
# repository so that the tests comparing with it run in a clone with no ../shared beside it.
PAPER_TOML = Path(__file__).parent / "data" / "paper.toml"
SHARED_PAPER_TOML = Path(__file__).resolve().parents[2] / "shared" / "reference-data" / "paper.toml"


@pytest.fixture(name="paper", scope="session")
def paper_fixture() -> dict:
    with PAPER_TOML.open("rb") as handle:
        return tomllib.load(handle)


# The tightest tolerances allowed: ~30,000 steps per simulated second (an hour: ~10⁸ steps), so a run that
# is slow while every key stays valid (budgets, Ctrl-C within a chunk).
TIGHTEST_TOLERANCES = {"rtol": 1e-8, "atol_position": 1e-12, "atol_momentum": 1e-12, "atol_temperature": 1e-12}


# A vial amplitude this small makes the walls effectively stationary (velocity ~1e-10 m/s) while
# keeping the parameter valid (amplitude must be positive).
RESTING_WALL_AMPLITUDE = 1e-12


def single_impact_parameters(speed: float, restitution: float = 0.7, **overrides) -> Parameters:
    """The ball leaves the vial centre at ``speed`` towards the right wall, which is at rest.

    The run lasts until shortly after the rebound, so exactly one impact happens.
    """
    base = sm.default_parameters()
    gap = base.vial_length / 2.0 - base.ball_radius
    settings = dict(
        amplitude=RESTING_WALL_AMPLITUDE,
        restitution=restitution,
        ball_momentum=base.ball_mass * speed,
        duration=1.5 * gap / speed,
        record_windows=(),
        # Absolute tolerances far below the motion's scale so that rtol alone controls the error.
        atol_position=1e-12,
        atol_momentum=1e-12,
    )
    settings.update(overrides)
    return base.replace(**settings)


@pytest.fixture(name="single_impact")
def single_impact_fixture():
    return single_impact_parameters


@pytest.fixture(scope="session")
def default_run_20s() -> sm.Result:
    """The default preset over 20 simulated seconds (shared by several tests)."""
    return sm.simulate(sm.default_parameters(duration=20.0))


def assert_one_error_line(stderr: str, *fragments: str) -> None:
    """A command refused its input as the brief asks: one ``error:`` line naming every fragment, no traceback."""
    lines = stderr.strip().splitlines()
    assert len(lines) == 1, stderr
    assert lines[0].startswith("error: ")
    for fragment in fragments:
        assert fragment in lines[0], (fragment, lines[0])
    assert "Traceback" not in stderr
