"""Replicas of the averaged solver's mechanics on every core (issue "The real mill in minutes"): wall time and numbers.

The averaged five-ball hour of ``spex8000m-3d-calibrated`` (the issue's target: <= 10 s of wall time on 2 cores),
run with one replica (the solver as it was: the reference, in the same process) and with several, on one thread
and on as many as the machine gives. Prints for each row the wall and CPU time, the simulated mechanics of each
replica, the pooled batches, the heat power with its batch-means standard error and its difference from the
reference in units of the two errors combined, and the balls' temperature after the hour. The rows of one
replica count on one thread and on several must agree to the last digit (the threads change the speed, not
the numbers); ``--repeats`` gives the median wall time of each row. ``--reference COMMIT`` times the hour first
with that commit's code (a git worktree of it), in the same run.

Run by hand on a quiet machine; the figures go into benchmarks/README.md.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import time

from reference_tree import measured_in, reference_tree

import shakermill as sm
from shakermill.parameters.environment import THREADS_VARIABLE

PRESET = "spex8000m-3d-calibrated"


def run(replicas: int, threads: int, settings: dict) -> tuple[float, float, sm.Result]:
    os.environ[THREADS_VARIABLE] = str(threads)
    params = sm.default_parameters(PRESET, n_balls=5, dem_replicas=replicas, record_windows=(), **settings)
    wall, cpu = time.perf_counter(), time.process_time()
    result = sm.simulate(params)
    return time.perf_counter() - wall, time.process_time() - cpu, result


def reference_row(commit: str, settings: dict, repeats: int) -> None:
    """The five-ball hour with ``commit``'s code (one replica: the solver as it was), in fresh processes."""
    with reference_tree(commit) as tree:
        figures = [measured_in(tree, __file__, "--measure-reference", json.dumps(settings)) for _ in range(repeats)]
    print(
        f"reference {commit}: wall {statistics.median(f['wall'] for f in figures):6.1f} s  "
        f"heat {figures[0]['heat']:.5g} ± {figures[0]['stderr']:.2g} W  balls {figures[0]['ball_C']:.1f} °C",
        flush=True,
    )


def measure_reference(settings: dict) -> None:
    """One five-ball hour with the code on the path, which may predate replicas: its figures as JSON."""
    params = sm.default_parameters(PRESET, n_balls=5, record_windows=(), **settings)
    sm.simulate(params.replace(duration=1.0, solver="full"))  # compile, load the caches
    wall = time.perf_counter()
    result = sm.simulate(params)
    print(
        json.dumps(
            {
                "wall": time.perf_counter() - wall,
                "heat": result.averages.heat_power,
                "stderr": result.averages.heat_power_stderr,
                "ball_C": result.summary.ball_C,
            }
        )
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reference", help="a commit whose code times the hour first (a git worktree of it)")
    parser.add_argument("--measure-reference", help=argparse.SUPPRESS)
    parser.add_argument("--replicas", type=int, nargs="*", default=[1, 2, 4], help="replica counts to time")
    parser.add_argument(
        "--threads", type=int, default=len(os.sched_getaffinity(0)), help="threads of the parallel rows"
    )
    parser.add_argument("--repeats", type=int, default=1, help="runs per row (median wall time)")
    parser.add_argument("--rel-error", type=float, default=None, help="dem_averaging_rel_error (default: the preset's)")
    options = parser.parse_args()
    settings = {} if options.rel_error is None else {"dem_averaging_rel_error": options.rel_error}
    if options.measure_reference is not None:
        measure_reference(json.loads(options.measure_reference))
        return
    if options.reference:
        reference_row(options.reference, settings, options.repeats)
    run(1, 1, {**settings, "duration": 1.0, "solver": "full"})  # compile, load the caches
    print(
        f"{PRESET}, 5 balls, one hour, averaged; {os.cpu_count()} cores; threads of the parallel rows: "
        f"{options.threads}"
    )
    reference = None
    for replicas in options.replicas:
        for threads in sorted({1, min(options.threads, replicas)}):
            walls, cpus = [], []
            for _ in range(options.repeats):
                wall, cpu, result = run(replicas, threads, settings)
                walls.append(wall)
                cpus.append(cpu)
            averages = result.averages
            line = (
                f"replicas {replicas} threads {threads}: wall {statistics.median(walls):6.1f} s (CPU "
                f"{statistics.median(cpus):6.1f} s)  "
                f"mechanics {averages.transient + averages.window:5.1f} s "
                f"each, {averages.batches} batches pooled  heat {averages.heat_power:.5g} ± "
                f"{averages.heat_power_stderr:.2g} W  "
                f"balls {result.summary.ball_C:.1f} °C"
            )
            if reference is None:
                reference = averages
            else:
                combined = math.hypot(averages.heat_power_stderr, reference.heat_power_stderr)
                line += f"  | Δ heat {(averages.heat_power - reference.heat_power) / combined:+.2f} σ"
            print(line, flush=True)


if __name__ == "__main__":
    main()
