"""Sweep throughput: the issue-5 target, a 9 × 7 grid of ω × amplitude, 60 simulated minutes each.

Target: the whole grid with the averaged solver in at most 30 s on the project's 2-core machine.
Times the sweep with 1 worker (in process) and 2 workers (local process pool, its start-up
included: that is what a user waits for) into fresh folders, repeats each and prints medians, the
speed-up from 1 to 2 workers, the time per point, how many points fell back to full resolution or
failed and how much of the time they took, and whether the tables agree. Numba's cache is warmed
first (one simulate call). Run by hand; figures go into benchmarks/README.md.
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from pathlib import Path

import pandas as pd
from pandas.testing import assert_frame_equal

import shakermill as sm
from shakermill.studies.sweeps.plan import plan_sweep
from shakermill.studies.sweeps.storage import comparable_columns, failed_points
from shakermill.studies.sweeps.sweep import sweep as run_sweep

TARGET_S = 30.0


def _timed_sweep(base: sm.Parameters, plan, workers: int, repeats: int) -> tuple[list[float], pd.DataFrame]:
    times, table = [], None
    for _ in range(repeats):
        with tempfile.TemporaryDirectory(prefix="bench_sweep_") as folder:
            started = time.perf_counter()
            table = run_sweep(base, plan, Path(folder) / "sweep", workers=workers)
            times.append(time.perf_counter() - started)
    return times, table


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=3, help="repetitions of each timing (median)")
    parser.add_argument("--omega", default="90:130:9", help="START:STOP:N of the omega grid (rad/s)")
    parser.add_argument("--amplitude", default="23mm:29mm:7", help="START:STOP:N of the amplitude grid")
    parser.add_argument("--duration", type=float, default=3600.0, help="simulated seconds per point")
    parser.add_argument("--workers", default="1,2", help="comma-separated pool sizes to time")
    args = parser.parse_args()
    worker_counts = [int(item) for item in args.workers.split(",")]

    grids = [f"omega={args.omega}", f"amplitude={args.amplitude}"]
    plan = plan_sweep(grids)
    base = sm.default_parameters(solver="averaged", duration=args.duration)
    started = time.perf_counter()
    sm.simulate(base.replace(duration=1.0))  # load Numba's cache (or compile) in this process
    print(f"grid {' × '.join(grids)}: {len(plan.points)} points, {args.duration:g} simulated s each, averaged solver")
    print(f"machine: {os.cpu_count()} cores; warm-up {time.perf_counter() - started:.2f} s; median of {args.repeats}")
    print()

    header = (
        f"{'workers':>7} | {'median s':>8} {'min s':>6} {'max s':>6} | {'s/point':>7} | {'Σ point s':>9} | "
        f"target ≤ {TARGET_S:g} s"
    )
    print(header)
    print("-" * len(header))
    medians, tables = {}, {}
    for workers in worker_counts:
        times, table = _timed_sweep(base, plan, workers, args.repeats)
        medians[workers], tables[workers] = statistics.median(times), table
        verdict = "met" if medians[workers] <= TARGET_S else "MISSED"
        print(
            f"{workers:7d} | {medians[workers]:8.2f} {min(times):6.2f} {max(times):6.2f} | "
            f"{medians[workers] / len(plan.points):7.3f} | {table['wall_time_s'].sum():9.2f} | {verdict}"
        )
    print("Σ point s: the points' own run times (last repeat), summed over workers; the rest is the sweep's own")
    print(
        "work (regime classification, attractor probes, point files, table) and, with workers > 1, the pool's start-up."
    )
    print()

    if 1 in medians:
        for workers in worker_counts:
            if workers != 1:
                print(f"speed-up 1 → {workers} workers: {medians[1] / medians[workers]:.2f}× (ideal {workers}×)")

    reference = tables[worker_counts[0]]
    fallback = reference["solver"] == "full"
    failed = failed_points(reference)
    print(
        f"points that fell back to full resolution: {int(fallback.sum())} of {len(reference)}, "
        f"{reference.loc[fallback, 'wall_time_s'].sum():.2f} s of the {reference['wall_time_s'].sum():.2f} s "
        f"of point time ({worker_counts[0]} worker{'s' if worker_counts[0] > 1 else ''})"
    )
    for _, row in reference[fallback].iterrows():
        print(
            f"  ω {row['omega']:6.2f} rad/s, X {row['amplitude'] * 1e3:5.2f} mm: {row['regime']}, "
            f"{row['wall_time_s']:.2f} s"
        )
    print(f"failed points: {len(failed)}")
    for _, row in failed.iterrows():
        print(f"  {row['point_id']}: {row['error']}")

    columns = comparable_columns(reference)
    for workers in worker_counts[1:]:
        assert_frame_equal(tables[workers][columns], reference[columns])
        print(f"tables with {worker_counts[0]} and {workers} workers equal on {len(columns)} comparable columns: yes")


if __name__ == "__main__":
    main()
