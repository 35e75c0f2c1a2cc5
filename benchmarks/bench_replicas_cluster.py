"""An averaged hour's replicas on a local Dask cluster (issue 38): wall time against workers, and the numbers.

The averaged five-ball hour of ``spex8000m-3d-calibrated`` with ``--replicas`` replicas (default 4), run first on
one thread of this process (the reference, in the same run: SHAKERMILL_THREADS=1), then with the replicas after
the first on a local Dask cluster of 1, 2, ... ``--workers`` worker processes (one thread each). Prints each row's
wall time, its speed-up over the reference and its parallel efficiency (speed-up over the processes working: the
workers and this one, which advances the first replica), and whether its heat power, balls' temperature and step
count equal the reference's to the last digit (they must: the cluster changes the speed, not the numbers).

Run by hand on a quiet machine; the figures go into benchmarks/README.md.
"""

from __future__ import annotations

import argparse
import os
import time

import shakermill as sm
from shakermill.parameters.environment import THREADS_VARIABLE
from shakermill.solvers.replicas import replicas_on

PRESET = "spex8000m-3d-calibrated"


def hour(replicas: int) -> tuple[float, sm.Result]:
    params = sm.default_parameters(PRESET, dem_replicas=replicas, record_windows=())
    started = time.perf_counter()
    result = sm.simulate(params)
    return time.perf_counter() - started, result


def fingerprint(result: sm.Result) -> tuple:
    return (result.summary.heat_power_W, result.summary.ball_C, result.counters["steps"])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--replicas", type=int, default=4)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    from distributed import Client, LocalCluster

    os.environ[THREADS_VARIABLE] = "1"
    reference_wall, reference = hour(args.replicas)
    del os.environ[THREADS_VARIABLE]
    print(f"# {PRESET}, averaged hour, {args.replicas} replicas; reference: one thread, {reference_wall:.1f} s wall")
    print(
        f"# reference: heat {reference.summary.heat_power_W:.6g} W, balls {reference.summary.ball_C:.6g} °C, "
        f"{reference.counters['steps']} steps; {reference.message[:120]}"
    )
    print(f"{'workers':>7} {'wall s':>8} {'speed-up':>9} {'efficiency':>10} {'same numbers':>13}")
    for workers in range(1, args.workers + 1):
        with (
            LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None) as cluster,
            Client(cluster) as client,
        ):
            client.run(lambda: __import__("shakermill.engines.dem.stepper"))  # compiled code loaded before the clock
            with replicas_on(client):
                wall, result = hour(args.replicas)
        speedup = reference_wall / wall
        print(
            f"{workers:>7} {wall:>8.1f} {speedup:>9.2f} {speedup / (workers + 1):>10.2f} "
            f"{str(fingerprint(result) == fingerprint(reference)):>13}",
            flush=True,
        )


if __name__ == "__main__":
    main()
