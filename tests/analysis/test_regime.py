"""Regime classification from impact phases, and the bifurcation scan."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

import shakermill as sm
from shakermill.analysis.regime import IRREGULAR, NO_IMPACTS, classify, settled_impacts
from shakermill.studies.sweeps.bifurcation import bifurcation, write_bifurcation

OMEGA = 100.0
PERIOD = 2 * math.pi / OMEGA


def _fake_result(times: list[float], walls: list[str]) -> SimpleNamespace:
    impacts = pd.DataFrame({"time": times, "wall": walls})
    params = SimpleNamespace(omega=OMEGA, phase=0.0)
    return SimpleNamespace(impacts=impacts, params=params, solver="averaged", t_end=max(times, default=0.0))


def _repeat(pattern: list[tuple[float, str]], periods: int, every: int) -> SimpleNamespace:
    """Impacts at fractions of the drive period, the pattern repeating every ``every`` periods."""
    times, walls = [], []
    for k in range(0, periods, every):
        for fraction, wall in pattern:
            times.append((k + fraction) * PERIOD)
            walls.append(wall)
    return _fake_result(times, walls)


def test_period_one_and_period_two_are_recognised() -> None:
    assert classify(_repeat([(0.2, "left"), (0.7, "right")], 40, 1)) == ("period-1", 1)
    two = _repeat([(0.2, "left"), (0.7, "right"), (1.3, "left"), (1.75, "right")], 40, 2)
    assert classify(two) == ("period-2", 2)


def test_wall_sequence_matters_not_only_phases() -> None:
    result = _repeat([(0.2, "left"), (1.2, "right")], 40, 2)  # same phase, alternating walls
    assert classify(result) == ("period-2", 2)


def test_random_impacts_are_irregular_and_none_is_no_impacts() -> None:
    rng = np.random.default_rng(7)
    times = np.sort(rng.uniform(0, 60 * PERIOD, 150)).tolist()
    walls = rng.choice(["left", "right"], 150).tolist()
    assert classify(_fake_result(times, walls)) == (IRREGULAR, None)
    assert classify(_fake_result([], [])) == (NO_IMPACTS, None)


@pytest.mark.slow
def test_default_motion_is_periodic_and_bifurcation_records_phases() -> None:
    base = sm.default_parameters(solver="averaged", duration=60.0, record_windows=())
    label, period = classify(sm.simulate(base))
    assert label == f"period-{period}" and 1 <= period <= 4
    scan = bifurcation(base, [95.0, 111.0, 125.0])
    assert list(scan.regimes["omega"]) == [95.0, 111.0, 125.0]
    assert set(scan.regimes["regime"]) <= {IRREGULAR, *(f"period-{n}" for n in range(1, 17))}
    assert scan.phases["phase"].between(0.0, 2 * math.pi).all()
    assert set(scan.phases["omega"]) == {95.0, 111.0, 125.0}
    assert scan.regimes.loc[scan.regimes["omega"] == 111.0, "period"].item() == period


@pytest.mark.slow
def test_bifurcation_lists_every_attractor_with_basins_summing_to_one() -> None:
    # At a 23 mm stroke period-1 and period-2 coexist over the whole range (see test_attractors.py).
    base = sm.default_parameters(solver="averaged", duration=60.0, record_windows=(), amplitude=0.023)
    scan = bifurcation(base, [100.0, 110.0])
    attractors = scan.attractors
    assert list(attractors.columns[:7]) == [
        "omega",
        "attractor",
        "regime",
        "period",
        "basin_fraction",
        "impact_rate_hz",
        "heat_power_W",
    ]
    for omega, rows in attractors.groupby("omega"):
        assert rows["basin_fraction"].sum() == pytest.approx(1.0)
        assert list(rows["attractor"]) == list(range(len(rows)))
        assert scan.regimes.loc[scan.regimes["omega"] == omega, "n_attractors"].item() == len(rows)
        starts = sorted(int(start) for cell in rows["starts"] for start in cell.split())
        assert starts == list(range(base.attractor_starts))
    assert (scan.regimes.set_index("omega").loc[110.0, "n_attractors"]) == 2
    # Every start's settled impacts are in the phases table, labelled with its attractor.
    phases = scan.phases
    assert list(phases.columns) == ["omega", "start", "attractor", "phase", "wall"]
    for (omega, label), rows in phases.groupby(["omega", "attractor"]):
        listed = attractors[(attractors["omega"] == omega) & (attractors["attractor"] == label)]["starts"].item()
        assert sorted(set(rows["start"])) == sorted(int(start) for start in listed.split())


@pytest.mark.slow
def test_bifurcation_scans_any_numeric_key_and_writes_its_tables(tmp_path) -> None:
    base = sm.default_parameters(solver="averaged", duration=60.0, record_windows=())
    scan = bifurcation(base, [0.024, 0.026], key="amplitude")
    assert scan.key == "amplitude"
    assert list(scan.regimes["amplitude"]) == [0.024, 0.026]
    assert str(scan.regimes["period"].dtype) == "Int64"  # whole drive periods, missing for irregular motion
    paths = write_bifurcation(scan, tmp_path)
    assert sorted(path.name for path in paths) == sorted(
        f"bifurcation_{table}.{suffix}"
        for table in ("regimes", "attractors", "phases")
        for suffix in ("parquet", "csv")
    )
    pd.testing.assert_frame_equal(pd.read_parquet(tmp_path / "bifurcation_phases.parquet"), scan.phases)
    pd.testing.assert_frame_equal(pd.read_parquet(tmp_path / "bifurcation_attractors.parquet"), scan.attractors)
    assert list(pd.read_csv(tmp_path / "bifurcation_attractors.csv")["heat_power_W"]) == pytest.approx(
        list(scan.attractors["heat_power_W"])
    )


def test_settled_impacts_of_a_full_run_are_its_second_half() -> None:
    impacts = pd.DataFrame({"time": [0.1, 0.4, 0.6, 0.9], "wall": ["left", "right", "left", "right"]})
    assert settled_impacts(impacts, "full", 1.0)["time"].tolist() == [0.6, 0.9]
    assert settled_impacts(impacts, "averaged", 1.0)["time"].tolist() == [0.1, 0.4, 0.6, 0.9]


@pytest.mark.slow
def test_bifurcation_stops_at_ctrl_c_inside_a_run(monkeypatch) -> None:
    # simulate() turns Ctrl-C into status INTERRUPTED (a full run keeps what it computed); the scan
    # must raise it rather than go on to the next value.
    import sys

    from shakermill.solvers.result import INTERRUPTED

    simulate_module = sys.modules["shakermill.solvers.simulate"]
    real_simulate = simulate_module.simulate
    calls = []

    def interrupted_second_run(params, **budget):
        calls.append(params.omega)
        result = real_simulate(params, **budget)
        if len(calls) == 2:
            result.status = INTERRUPTED
        return result

    monkeypatch.setattr(simulate_module, "simulate", interrupted_second_run)
    base = sm.default_parameters(solver="averaged", duration=60.0, record_windows=())
    with pytest.raises(KeyboardInterrupt):
        bifurcation(base, [100.0, 110.0, 120.0])
    assert calls == [100.0, 110.0]


def test_a_bifurcation_of_more_values_than_a_diagram_can_show_is_refused_before_any_run(monkeypatch) -> None:
    import sys

    simulate_module = sys.modules["shakermill.solvers.simulate"]
    monkeypatch.setattr(simulate_module, "simulate", lambda params: pytest.fail("no run may start"))
    with pytest.raises(sm.ParameterError, match="bifurcation: 10,001 values; allowed at most 10,000"):
        bifurcation(sm.default_parameters(), np.linspace(90.0, 130.0, 10_001))
