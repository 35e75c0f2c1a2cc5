"""The real mill: the balls' mean temperature after an hour in a SPEX 8000M in 3-D (issue 15).

The study a researcher would run: a 30-point sweep over the number of balls (1-5), their diameter (8, 10 and
12.7 mm) and their material (hardened steel, tungsten carbide), one simulated hour each with the averaged
solver, through the public sweep API (``shakermill.sweep``) into a resumable folder, so an interrupted run
goes on where it stopped. Every combination fits the Ø38 x 58 mm bore (five 12.7-mm balls take 8 % of it).
It prints one table per material (rows: number of balls, columns: ball diameter, cells: the balls' mean
temperature after 1 h in °C), the wall time per point (median) and in total, and draws the same numbers
into ``docs/figures/mill-study.png``. A second part runs one hour of five 12.7-mm balls at the preset's own
settings and prints its wall time, heat power and the balls' and vial's temperatures.

The preset is ``spex8000m-3d-calibrated-paper`` (the paper's three-node network), fitted to the one-ball curve
only. A point whose mechanics do not converge within ``averaging_max_time`` fails with its reason
(``averaging_fallback = 'fail'``) instead of falling back to a full-resolution hour, which would take hours for a
lone ball.

    .venv/bin/python benchmarks/bench_mill_study.py                          # all 30 points and the five-ball hour
    .venv/bin/python benchmarks/bench_mill_study.py --rel-error 0.02         # a quarter of the mechanics per point
    .venv/bin/python benchmarks/bench_mill_study.py --counts 4,5 --only sweep  # the cheap points alone
    .venv/bin/python benchmarks/bench_mill_study.py --only report            # tables and figure of the folder so far

Cost (2026-11-23, 2 shared cores, --rel-error 0.02): four or five balls ~130-150 s a point, three ~500 s or more,
one or two balls far more (a ball that rolls on the bore steps at the contact step: ~10-20 wall-s per simulated
second, and its means converge slowly). Ctrl-C keeps the finished points; the same command computes the rest.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import sys
import time
from pathlib import Path

import pandas as pd

import shakermill as sm
from shakermill.studies.sweeps.executor import Progress
from shakermill.studies.sweeps.storage import load_sweep

ROOT = Path(__file__).resolve().parents[1]
FIGURE = ROOT / "docs" / "figures" / "mill-study.png"
PRESET = "spex8000m-3d-calibrated-paper"
BALL_COUNTS = (1, 2, 3, 4, 5)
DIAMETERS_MM = (8.0, 10.0, 12.7)
MATERIALS = ("hardened-steel", "tungsten-carbide")
HOUR_S = 3600.0


def study_parameters(preset: str, rel_error: float | None, max_time: float | None = None) -> sm.Parameters:
    """One simulated hour, averaged, no full-resolution fall-back and no record windows (they cost mechanics)."""
    settings = {"solver": "averaged", "duration": HOUR_S, "averaging_fallback": "fail", "record_windows": ()}
    if rel_error is not None:
        settings["dem_averaging_rel_error"] = rel_error
    if max_time is not None:
        settings["averaging_max_time"] = max_time
    return sm.default_parameters(preset, **settings)


def grid(counts: list[int]) -> dict[str, list]:
    """The number of balls slowest and most first: many balls knock each other off the bore and cost least, so an
    interrupted study has whole rows of its tables."""
    return {
        "n_balls": sorted(counts, reverse=True),
        "ball_material": list(MATERIALS),
        "ball_radius": [f"{diameter / 2:g} mm" for diameter in DIAMETERS_MM],
    }


def report_progress(started: float):
    def report(progress: Progress) -> None:
        print(
            f"\r  points {progress.done}/{progress.total} done, {progress.failed} failed, {progress.running} running, "
            f"{time.perf_counter() - started:.0f} s",
            end="" if progress.done < progress.total else "\n",
            file=sys.stderr,
            flush=True,
        )

    return report


def temperature_tables(table: pd.DataFrame) -> dict[str, pd.DataFrame]:
    """Per material: the balls' mean temperature after 1 h (°C), rows n_balls, columns the diameter in mm."""
    table = table.assign(
        diameter_mm=(2e3 * table["ball_radius"]).round(1), ball_C=table["ball_C"].where(table["error"].isna())
    )
    return {
        material: rows.pivot(index="n_balls", columns="diameter_mm", values="ball_C")
        for material, rows in table.groupby("ball_material", sort=False)
    }


def print_tables(tables: dict[str, pd.DataFrame]) -> None:
    for material, cells in tables.items():
        print(f"\n{material}: the balls' mean temperature after 1 h (°C); '-': no result (failed or not finished)")
        print("n_balls | " + " | ".join(f"Ø{diameter:g} mm".rjust(8) for diameter in cells.columns))
        print("-" * (10 + 11 * len(cells.columns)))
        for count, row in cells.iterrows():
            print(f"{count:7d} | " + " | ".join("-".rjust(8) if pd.isna(value) else f"{value:8.1f}" for value in row))


def print_costs(table: pd.DataFrame, elapsed: float) -> None:
    times = table["wall_time_s"].dropna()
    unfinished = table["error"].str.startswith("not finished", na=False)
    sweep = "" if math.isnan(elapsed) else f"; the sweep {elapsed:.0f} s on {os.cpu_count()} cores"
    print(
        f"\nwall time per point: median {statistics.median(times):.1f} s (min {times.min():.1f}, max "
        f"{times.max():.1f}); "
        f"Σ points {times.sum():.0f} s over {len(times)} points{sweep} (points of an earlier run of this folder keep "
        "their times)"
    )
    if unfinished.any():
        print(f"not finished: {int(unfinished.sum())} of {len(table)} points")
    for _, row in table[table["error"].notna() & ~unfinished].iterrows():
        print(f"failed: {row['ball_material']}, {row['n_balls']} x Ø{2e3 * row['ball_radius']:g} mm: {row['error']}")


def draw(tables: dict[str, pd.DataFrame], preset: str, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axes = plt.subplots(1, len(tables), figsize=(10, 4), sharey=True, constrained_layout=True)
    for axis, (material, cells) in zip(axes, tables.items()):
        for diameter in cells.columns:
            axis.plot(cells.index, cells[diameter], marker="o", label=f"Ø{diameter:g} mm")
        axis.set_title(material)
        axis.set_xlabel("number of balls")
        axis.set_xticks(list(cells.index))
        axis.grid(alpha=0.3)
    axes[0].set_ylabel("ball temperature after 1 h (°C)")
    axes[0].legend(title="ball diameter")
    figure.suptitle(f"SPEX 8000M in 3-D ({preset}), averaged solver: the balls' mean temperature after 1 h")
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path, dpi=120)
    plt.close(figure)


def five_balls(base: sm.Parameters, preset: str) -> None:
    """One hour of five 12.7-mm steel balls at the preset's own averaging target."""
    params = base.replace(n_balls=5, dem_averaging_rel_error=sm.default_parameters(preset).dem_averaging_rel_error)
    started = time.perf_counter()
    result = sm.simulate(params)
    wall = time.perf_counter() - started
    summary = result.summary
    print(
        f"\nfive 12.7-mm steel balls, one hour, averaged (dem_averaging_rel_error {params.dem_averaging_rel_error:g}):"
    )
    print(f"  status {result.status}: {result.message}")
    print(
        f"  wall {wall:.1f} s; heat power {summary.heat_power_W:.3f} W; balls {summary.ball_C:.1f} °C, "
        f"vial {summary.vial_C:.1f} °C after 1 h"
    )


def run_study(
    base: sm.Parameters, preset: str, counts: list[int], out: Path, workers: int
) -> tuple[pd.DataFrame, float]:
    """The sweep's table and its wall time; Ctrl-C ends it with the points finished so far (a re-run goes on)."""
    started = time.perf_counter()
    try:
        table = sm.sweep(base, grid(counts), out, workers=workers, progress=report_progress(started), preset=preset)
    except KeyboardInterrupt:
        table = load_sweep(out).table
        print("\ninterrupted: the tables hold the finished points; the same command computes the others", flush=True)
    return table, time.perf_counter() - started


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument(
        "--out", type=Path, help="sweep folder (resumable; default results/mill-study-<preset>-<counts>-<target>)"
    )
    parser.add_argument("--workers", type=int, default=2, help="local processes")
    parser.add_argument("--rel-error", type=float, help="dem_averaging_rel_error of the sweep (default: the preset's)")
    parser.add_argument("--max-time", type=float, help="averaging_max_time of the sweep, s (default: the preset's)")
    parser.add_argument("--figure", type=Path, default=FIGURE, help="PNG of the study")
    parser.add_argument("--counts", default=",".join(map(str, BALL_COUNTS)), help="numbers of balls, comma-separated")
    parser.add_argument(
        "--only", choices=("sweep", "five-balls", "report"),
        help="one part: the sweep, the five-ball hour, or the tables and figure of the sweep folder as it stands",
    )  # fmt: skip
    args = parser.parse_args()
    counts = [int(item) for item in args.counts.split(",")]

    preset = PRESET
    base = study_parameters(preset, args.rel_error, args.max_time)
    # A folder holds one sweep: another choice of counts or target gets a folder of its own.
    out = (
        args.out
        or ROOT / "results" / f"mill-study-{preset}-{'-'.join(map(str, counts))}-{base.dem_averaging_rel_error:g}"
    )
    print(
        f"preset {preset}; averaged solver, {HOUR_S:g} s, dem_averaging_rel_error {base.dem_averaging_rel_error:g}, "
        f"averaging_max_time {base.averaging_max_time:g} s; {len(counts) * len(DIAMETERS_MM) * len(MATERIALS)} "
        f"points into {out}"
    )
    if args.only != "five-balls":
        if args.only == "report":
            table, elapsed = load_sweep(out).table, math.nan
        else:
            table, elapsed = run_study(base, preset, counts, out, args.workers)
        tables = temperature_tables(table)
        print_tables(tables)
        print_costs(table, elapsed)
        draw(tables, preset, args.figure)
        print(f"figure: {args.figure}")
    if args.only in (None, "five-balls"):
        five_balls(base, preset)


if __name__ == "__main__":
    main()
