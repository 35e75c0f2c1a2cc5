"""The sensitivity of a run to the assumed amplitudes of a named vial motion (studies/validation/kinematics.py)."""

from __future__ import annotations

import math

import pytest

import shakermill as sm
from shakermill.parameters.errors import ParameterError
from shakermill.studies.validation.kinematics import MEASURES, kinematic_sensitivity

DURATION = 0.2  # s: a few drive periods, enough for the table's shape and its determinism


@pytest.fixture(scope="module")
def spex():
    params = sm.default_parameters("spex8000m-3d", n_balls=3, duration=DURATION, solver="full")
    calls = []
    study = kinematic_sensitivity(params, progress=lambda done, total: calls.append((done, total)))
    return params, study, calls


@pytest.mark.slow
def test_each_assumed_amplitude_is_halved_and_raised_by_half(spex):
    params, study, calls = spex
    assert [(row.key, row.factor) for row in study.rows] == [
        ("lateral_amplitude", 0.5),
        ("lateral_amplitude", 1.5),
        ("yaw_amplitude", 0.5),
        ("yaw_amplitude", 1.5),
    ]
    assert study.rows[1].value == pytest.approx(1.5 * params.lateral_amplitude, rel=1e-12)
    assert calls == [(done, 5) for done in range(1, 6)]
    for row in study.rows:
        for name in MEASURES:
            assert row.relative_change[name] == pytest.approx(
                row.measures[name] / study.baseline[name] - 1.0, rel=1e-12
            )


@pytest.mark.slow
def test_the_table_has_the_baseline_first_and_a_change_per_measure(spex):
    _, study, _ = spex
    table = study.table()
    assert list(table["key"]) == ["baseline"] + [row.key for row in study.rows]
    assert set(MEASURES) | {f"{name}_change" for name in MEASURES} <= set(table.columns)
    assert (table.loc[0, [f"{name}_change" for name in MEASURES]] == 0.0).all()
    assert all(math.isfinite(value) and value > 0 for value in study.baseline.values())


@pytest.mark.slow
def test_the_same_inputs_give_the_same_table(spex):
    params, study, _ = spex
    again = kinematic_sensitivity(params, keys=("yaw_amplitude",), factors=(1.5,))
    assert again.baseline == study.baseline
    assert again.rows[0] == study.rows[3]


def test_a_factor_beyond_a_keys_bounds_is_refused():
    params = sm.default_parameters("mm400", duration=DURATION, solver="full")
    with pytest.raises(ParameterError, match="amplitude"):
        kinematic_sensitivity(params, keys=("amplitude",), factors=(100.0,))


@pytest.mark.slow
def test_other_summary_keys_can_be_measured(spex):
    params, study, _ = spex
    again = kinematic_sensitivity(params, keys=("yaw_amplitude",), factors=(1.5,), measures=("ball_C", "heat_power_W"))
    assert again.baseline["heat_power_W"] == study.baseline["heat_power_W"]
    assert again.rows[0].relative_change["ball_C"] == pytest.approx(
        again.rows[0].measures["ball_C"] / again.baseline["ball_C"] - 1.0
    )
    assert again.as_dict()["rows"][0]["key"] == "yaw_amplitude" and again.as_dict()["solver"] == "full"
