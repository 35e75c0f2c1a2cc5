"""An averaged run's replicas on a Dask cluster (solvers/replicas.py, issue 38): the same numbers as on threads, and
a scheduler a run would not use refused in one line."""

from __future__ import annotations

import pytest
from conftest import assert_one_error_line
from typer.testing import CliRunner

import shakermill as sm
from shakermill import cli
from shakermill.solvers.replicas import RemoteReplica, replicas_of, replicas_on

distributed = pytest.importorskip("distributed")

# Two balls, three replicas, at most 12 s of mechanics in each: enough rounds that any difference would show.
REPLICATED = {
    "n_balls": 2,
    "dem_replicas": 3,
    "averaging_max_time": 12.0,
    "averaging_min_batches": 4,
    "averaging_fallback": "fail",
    "record_windows": (),
    "duration": 600.0,
}


@pytest.fixture(scope="module")
def client():
    with (
        distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster,
        distributed.Client(cluster) as client,
    ):
        yield client


@pytest.mark.slow
def test_replicas_on_a_two_worker_cluster_give_the_numbers_of_replicas_on_threads(client):
    params = sm.default_parameters("spex8000m-3d", **REPLICATED)
    on_threads = sm.simulate(params)
    with replicas_on(client):
        on_the_cluster = sm.simulate(params)
    assert on_the_cluster.averages == on_threads.averages
    assert (
        on_the_cluster.averages.replicas == 3 and 0 < on_the_cluster.averages.impact_interval < 1.0
    )  # impacts counted in every replica
    # By name through the schema: a misspelt key fails (this list once said impact_rate_per_s and compared two Nones).
    for key in ("heat_power_W", "impact_rate_hz", "ball_steady_C"):
        assert on_the_cluster.summary.value(key) == on_threads.summary.value(key), key
    assert on_the_cluster.counters["steps"] == on_threads.counters["steps"]


def test_only_the_replicas_after_the_first_leave_and_each_waits_on_a_thread_of_its_own(client):
    params = sm.default_parameters("spex8000m-3d", **REPLICATED)
    from shakermill.engines.dem.engine import DemEngine

    engines = [DemEngine(params, replica=number) for number in range(3)]
    here, threads = replicas_of(engines[0], engines[1:])
    assert here == engines and threads <= 3
    with replicas_on(client):
        sent, threads = replicas_of(engines[0], engines[1:])
    assert sent[0] is engines[0] and all(isinstance(replica, RemoteReplica) for replica in sent[1:]) and threads == 3
    # A round there is the same engine's round here.
    sent[1].advance(0.05)
    engines[1].advance(0.05)
    assert sent[1].t == engines[1].t and (sent[1].measured().heat == engines[1].measured().heat).all()


def test_a_scheduler_for_a_run_that_sends_nothing_is_refused_in_one_line(tmp_path):
    result = CliRunner().invoke(
        cli.app, ["run", "--set", "duration=1", "--scheduler", "tcp://127.0.0.1:1", "--out", str(tmp_path / "run")]
    )
    assert result.exit_code == 2
    assert_one_error_line(result.stderr, "--scheduler: this run sends nothing to a cluster", "dem_replicas >= 2")
    assert not (tmp_path / "run").exists()
