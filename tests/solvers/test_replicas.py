"""Replicas of the averaged solver's mechanics (solvers/replicas.py): pooled, deterministic, on any number of
threads."""

from __future__ import annotations

import threading
import time

import numpy as np
import pytest

import shakermill as sm
from shakermill.engines.dem import model
from shakermill.engines.dem.engine import DemEngine
from shakermill.parameters.environment import THREADS_VARIABLE
from shakermill.parameters.errors import ParameterError
from shakermill.solvers.averaged import full_resolution_instead, least_mechanics, settle_mechanics
from shakermill.solvers.driver import least_rounds
from shakermill.solvers.replicas import ReplicaSet, replica_threads
from shakermill.solvers.result import INTERRUPTED

# Five balls knock each other about a wide bore (the cheapest chaotic case); batches of 4 periods and a loose target
# keep the mechanics to a few simulated seconds.
BALLS = {
    "engine": "dem",
    "n_balls": 5,
    "vial_diameter": "38 mm",
    "record_windows": (),
    "solver": "averaged",
    "dem_averaging_rel_error": 0.05,
    "averaging_batch_periods": 4,
    "averaging_min_batches": 6,
    "duration": 600.0,
    "averaging_fallback": "fail",
}


@pytest.fixture(name="params", scope="module")
def params_fixture():
    return sm.default_parameters(**BALLS, dem_replicas=2)


def _pooled_run(params, monkeypatch, threads: int):
    monkeypatch.setenv(THREADS_VARIABLE, str(threads))
    assert replica_threads(params.dem_replicas) == threads
    return sm.simulate(params)


@pytest.mark.slow
def test_two_replicas_give_the_same_numbers_on_one_thread_and_on_two(params, monkeypatch):
    one, two = (_pooled_run(params, monkeypatch, threads) for threads in (1, 2))
    assert one.success and one.averages.converged and one.averages.replicas == 2
    for name in (
        "heat_power",
        "heat_power_stderr",
        "velocity_term",
        "transient",
        "window",
        "batches",
        "impact_interval",
    ):
        assert getattr(one.averages, name) == getattr(two.averages, name), name
    np.testing.assert_array_equal(one.history["theta_balls"], two.history["theta_balls"])
    assert one.counters == two.counters


@pytest.mark.slow
def test_the_replicas_pool_independent_batches_and_the_first_is_the_run_without_replicas(params):
    alone = settle_mechanics(params.replace(dem_replicas=1), DemEngine)
    pooled = settle_mechanics(params, DemEngine)
    assert alone.means.averages.converged and pooled.means.averages.converged
    # The first replica is the configured start: for as long as both ran, it moved as the run without replicas did.
    t = min(alone.engine.t, pooled.engine.t)
    alone_impacts, first_impacts = (m.engine.impact_columns() for m in (alone, pooled))
    np.testing.assert_array_equal(
        alone_impacts["time"][alone_impacts["time"] <= t], first_impacts["time"][first_impacts["time"] <= t]
    )
    # Each replica ran at least its share of the least batches, and more batches were pooled than the first kept.
    batch = params.averaging_batch_periods * params.period
    assert pooled.engine.t >= least_rounds(params, 2) * batch * (1 - 1e-12)
    assert pooled.means.averages.batches > pooled.means.averages.window / batch + 0.5


def test_a_replica_starts_where_the_run_does_with_each_ball_kicked_by_its_own_seed(params):
    start = DemEngine(params).state
    kicked = [DemEngine(params, replica=number).state for number in (1, 1, 2)]
    np.testing.assert_array_equal(kicked[0].position, start.position)
    np.testing.assert_allclose(
        np.linalg.norm(kicked[0].velocity - start.velocity, axis=1), model.REPLICA_KICK, rtol=1e-12
    )
    np.testing.assert_array_equal(kicked[0].velocity, kicked[1].velocity)  # the same number, the same start
    assert not np.allclose(kicked[0].velocity, kicked[2].velocity)


def test_the_threads_are_capped_by_the_variable_and_the_replicas(monkeypatch):
    monkeypatch.setenv(THREADS_VARIABLE, "3")
    assert [replica_threads(count) for count in (1, 2, 8)] == [1, 2, 3]
    monkeypatch.delenv(THREADS_VARIABLE)
    assert 1 <= replica_threads(64) <= 64


@pytest.mark.parametrize("setting", ["not a number", "0", "-1", "2.5", "1e3", "99999"])
def test_a_threads_variable_that_is_not_a_number_of_threads_is_refused_in_one_line(monkeypatch, setting):
    monkeypatch.setenv(THREADS_VARIABLE, setting)
    with pytest.raises(ParameterError) as caught:
        replica_threads(2)
    assert str(caught.value).startswith(f"{THREADS_VARIABLE}: {setting!r} is not a number of threads; allowed")


class _Stepping:
    """An engine stand-in whose advance takes ~10 ms calls until told to stop through its heartbeat."""

    def __init__(self, fail_after: float | None = None) -> None:
        self.t, self.fail_after, self.calls = 0.0, fail_after, 0

    def advance(self, t_stop, heartbeat=None):
        while self.t < t_stop:
            time.sleep(0.01)
            self.t = min(t_stop, self.t + 0.01)
            self.calls += 1
            if self.fail_after is not None and self.t >= self.fail_after:
                raise FloatingPointError("the replica's own failure")
            if heartbeat is not None:
                heartbeat(self.t)
        return 0


def test_an_error_in_one_replica_stops_the_others_and_is_raised_as_itself():
    engines = [_Stepping(), _Stepping(fail_after=0.05)]
    with ReplicaSet(engines, 2) as replicas, pytest.raises(FloatingPointError, match="own failure"):
        replicas.advance(100.0, None)
    assert engines[0].t < 5.0  # stopped within a call of the failure, not run to the end


def test_ctrl_c_while_the_replicas_run_stops_them_all():
    engines = [_Stepping(), _Stepping()]

    def interrupt(t):
        if t > 0.05:
            raise KeyboardInterrupt

    with ReplicaSet(engines, 2) as replicas, pytest.raises(KeyboardInterrupt):
        replicas.advance(100.0, interrupt)
    assert all(engine.t < 5.0 for engine in engines)
    assert not any(thread.name.startswith("shakermill-replica") for thread in threading.enumerate())


@pytest.mark.slow
def test_ctrl_c_in_the_mechanics_of_replicas_keeps_the_first_replica(params, monkeypatch):
    monkeypatch.setenv(THREADS_VARIABLE, "2")
    calls = []

    def progress(done, total):
        calls.append(done)
        if len(calls) == 3:
            raise KeyboardInterrupt

    mechanics = settle_mechanics(params, DemEngine, progress)
    assert mechanics.status == INTERRUPTED and mechanics.means is None and mechanics.engine.t > 0.0


def test_the_least_mechanics_counts_every_replica_and_its_floor_of_batches(params):
    batch = params.averaging_batch_periods * params.period
    one = params.replace(dem_replicas=1)
    # Twice averaging_min_batches in all, shared among the replicas, but never under 4 batches each.
    assert least_mechanics(one) == pytest.approx(2 * params.averaging_min_batches * batch)
    assert least_mechanics(params.replace(dem_replicas=8)) == pytest.approx(8 * 4 * batch)
    short = params.replace(dem_replicas=8, duration=8 * 4 * batch * 0.99)
    assert "4 batches of averaging_batch_periods drive periods in each of 8 replicas" in full_resolution_instead(short)
