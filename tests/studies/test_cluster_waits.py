"""A Dask cluster that does not answer is answered (issue 49): a handshake Ctrl-C ends at once, a scheduler without
workers is refused within --scheduler-timeout, and a cluster that finishes nothing is bounded by a run's time."""

from __future__ import annotations

import _thread
import socket
import threading
import time

import pytest

from shakermill.parameters.errors import ParameterError
from shakermill.parameters.presets import default_parameters
from shakermill.studies.sweeps import backends
from shakermill.studies.sweeps.backends import ClusterStalled, _Cluster, connect
from shakermill.studies.sweeps.plan import plan_sweep
from shakermill.studies.sweeps.sweep import sweep

distributed = pytest.importorskip("distributed")


@pytest.fixture
def silent_server():
    """A loopback server that accepts connections and never speaks: a handshake with it waits out its timeout."""
    listener = socket.create_server(("127.0.0.1", 0))
    held = []

    def accept() -> None:
        while True:
            try:
                held.append(listener.accept()[0])
            except OSError:
                return

    threading.Thread(target=accept, daemon=True).start()
    yield f"tcp://127.0.0.1:{listener.getsockname()[1]}"
    for item in (*held, listener):
        item.close()


@pytest.fixture
def workerless_cluster():
    cluster = distributed.LocalCluster(n_workers=0, host="127.0.0.1", dashboard_address=None)
    try:
        yield cluster
    finally:
        cluster.close()


def test_ctrl_c_while_connecting_is_answered_without_waiting_out_the_handshake(silent_server):
    threading.Timer(0.5, _thread.interrupt_main).start()
    with pytest.raises(KeyboardInterrupt):
        connect(silent_server, timeout=300)
    # The handshake, bounded by 600 s, is still waiting in its daemon thread: the interrupt did not wait for it.
    assert any(thread.name == "scheduler-probe" and thread.is_alive() for thread in threading.enumerate())


def test_a_scheduler_without_workers_is_refused_in_one_line_within_its_timeout(workerless_cluster, tmp_path):
    lines: list[str] = []
    started = time.process_time()
    with pytest.raises(ParameterError) as caught:
        sweep(
            default_parameters(solver="averaged", duration=1.0),
            plan_sweep(("omega=100:120:2",)),
            tmp_path / "sweep",
            scheduler=workerless_cluster.scheduler_address,
            scheduler_timeout=1,
            announce=lines.append,
        )
    message = str(caught.value)
    assert message.startswith(f"scheduler: {workerless_cluster.scheduler_address} has no workers (waited 1 s")
    assert "\n" not in message
    # Polled in slices, not spun: the wait costs little CPU, and no folder was claimed.
    assert time.process_time() - started < 5
    assert not (tmp_path / "sweep").exists()


def test_a_long_wait_for_workers_says_so(workerless_cluster, monkeypatch):
    monkeypatch.setattr(backends, "WAITING_LINE_S", 0.3)
    lines: list[str] = []
    with distributed.Client(workerless_cluster.scheduler_address, set_as_default=False) as client:
        with pytest.raises(ParameterError, match="has no workers"):
            backends.wait_for_workers(client, workerless_cluster.scheduler_address, 1.0, lines.append)
    assert lines and lines[0].startswith(f"waiting for a worker to join {workerless_cluster.scheduler_address}, 0 min")


class _NeverDone:
    status = "pending"

    def done(self) -> bool:
        return False


class _StuckClient:
    def submit(self, *_: object, **__: object) -> _NeverDone:
        return _NeverDone()


def test_a_cluster_that_finishes_nothing_within_a_round_stops_with_one_line():
    cluster = _Cluster(_StuckClient(), 1, round_limit_s=0.5)  # type: ignore[arg-type]
    with pytest.raises(ClusterStalled) as caught:
        list(cluster.outcomes(lambda values: values, [("a", {}), ("b", {})]))
    message = str(caught.value)
    assert message.startswith("scheduler: no task finished on the cluster for") and "2 unfinished" in message
