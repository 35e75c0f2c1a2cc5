"""An impact stepped at its own pace (issue 38): restitution, cost and convergence of the 'dem' engine's impact step.

An impact steps at ``contact_step_fraction`` × 0.4 of its own period (1/100 of it at the default), its start and
release at the contact step (engines/dem/model.py, IMPACT_STEP_SCALE); before, every impact of 0.1 m/s and faster
stepped at the contact step throughout (~1/380 of its period).

Part ``restitution`` (this tree): |e measured − e| of head-on steel impacts, e = 0.7, at 40 speeds over 0.1–5 m/s,
on the end face and on a ball at rest, at three values of ``contact_step_fraction``.

Part ``second``: one simulated second at full resolution of ``pulverisette7``, ``pm100`` (ten Ø10-mm balls from
the start) and five ``spex8000m-3d`` balls, CPU time, steps, impacts and heat power, in a fresh process per tree:
the reference commit (``--reference``, checked out into a temporary git worktree) and this tree.

Part ``averaged``: the averaged solver's settled motion of each mill (``attractor_starts = 1``), heat power with its
batch-means standard error, impact rate, mean impact speed and the stress-energy spectrum's median and 90th
percentile, for the reference commit, this tree, and this tree at half the contact step fraction (the convergence
reference: every step halved); differences from the last in units of the combined standard error (heat) or
relative (the rest, whose errors the solver does not estimate).

    .venv/bin/python benchmarks/bench_impact_step.py --reference d50a126     # all parts (~25 min on 2 cores)
    .venv/bin/python benchmarks/bench_impact_step.py --only restitution

Run by hand on a quiet machine; the figures go into benchmarks/README.md.
"""

from __future__ import annotations

import argparse
import json
import math
import resource
from contextlib import ExitStack

from reference_tree import ROOT, measured_in, reference_tree

SPEEDS = (0.1, 5.0, 40)
FRACTIONS = (0.05, 0.025, 0.0125)
SECOND_MILLS = {
    "pulverisette7, 10 balls": ("pulverisette7", {}),
    "pm100, 10 balls": ("pm100", {}),
    "spex8000m-3d, 5 balls": ("spex8000m-3d", {"n_balls": 5}),
}
AVERAGED_MILLS = {
    "spex8000m-3d, 5 balls": ("spex8000m-3d", {"n_balls": 5}),
    "pulverisette7, 10 balls": ("pulverisette7", {}),
    "mm400, 2 balls": ("mm400", {}),
}
AVERAGED_KEYS = (
    "averaged_heat_power_W",
    "averaged_heat_power_stderr_W",
    "impact_rate_hz",
    "mean_impact_speed_m_s",
    "stress_energy_median_J",
    "stress_energy_p90_J",
    "averaging_window_s",
)


def restitution_part() -> None:
    import numpy as np

    import shakermill as sm
    from shakermill.solvers.impact import single_impact

    speeds = np.geomspace(*SPEEDS)
    print(f"|e - 0.7| of head-on steel impacts at {SPEEDS[2]} speeds over {SPEEDS[0]:g}-{SPEEDS[1]:g} m/s, max (mean)")
    for fraction in FRACTIONS:
        params = sm.default_parameters(restitution=0.7, pair_restitution=0.7, contact_step_fraction=fraction)
        cells = []
        for target in ("wall", "ball"):
            errors = np.abs([single_impact(params, speed, target=target).normal_restitution - 0.7 for speed in speeds])
            cells.append(f"{target} {errors.max():.2e} ({errors.mean():.2e})")
        print(f"  contact_step_fraction {fraction:<7g} " + "   ".join(cells), flush=True)


def cpu_seconds() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def measure_second() -> dict:
    import shakermill as sm

    sm.simulate(sm.default_parameters("spex8000m-3d", duration=0.001, solver="full", record_windows=()))  # compile
    figures = {}
    for mill, (preset, settings) in SECOND_MILLS.items():
        params = sm.default_parameters(preset, **settings, duration=1.0, solver="full", record_windows=())
        started = cpu_seconds()
        result = sm.simulate(params)
        figures[mill] = {
            "cpu": cpu_seconds() - started,
            "steps": result.counters["steps"],
            "impacts": result.counters["impacts"],
            "heat": result.summary.heat_power_W,
        }
    return figures


def measure_averaged(fraction_scale: float) -> dict:
    import shakermill as sm

    figures = {}
    for mill, (preset, settings) in AVERAGED_MILLS.items():
        params = sm.default_parameters(preset, **settings, attractor_starts=1)
        params = params.replace(contact_step_fraction=params.contact_step_fraction * fraction_scale)
        started = cpu_seconds()
        summary = sm.simulate(params).summary
        figures[mill] = {key: summary.value(key) for key in AVERAGED_KEYS}
        figures[mill]["cpu"] = cpu_seconds() - started
    return figures


def second_part(trees: dict) -> None:
    runs = {name: measured_in(tree, __file__, "--measure", "second") for name, tree in trees.items()}
    print("one simulated second at full resolution from the start")
    for mill in SECOND_MILLS:
        for name, figures in runs.items():
            row = figures[mill]
            print(
                f"  {mill:<26} {name:<22} {row['cpu']:6.2f} CPU-s {row['steps']:>10,} steps "
                f"{row['impacts']:>6} impacts heat {row['heat']:.4g} W"
            )
        if len(runs) == 2:
            before, after = (figures[mill] for figures in runs.values())
            print(
                f"  {mill:<26} {'ratio':<22} {before['cpu'] / after['cpu']:6.2f}x less CPU, "
                f"{before['steps'] / after['steps']:.2f}x fewer steps"
            )


def averaged_part(trees: dict) -> None:
    runs = {name: measured_in(tree, __file__, "--measure", "averaged", "1") for name, tree in trees.items()}
    runs["this tree, steps halved"] = measured_in(ROOT, __file__, "--measure", "averaged", "0.5")
    reference = runs["this tree, steps halved"]
    print("averaged solver, settled motion (attractor_starts = 1); differences from 'this tree, steps halved'")
    for mill in AVERAGED_MILLS:
        base = reference[mill]
        for name, figures in runs.items():
            row = figures[mill]
            line = (
                f"  {mill:<24} {name:<24} {row['cpu']:6.1f} CPU-s  heat {row['averaged_heat_power_W']:.4g} "
                f"± {row['averaged_heat_power_stderr_W']:.2g} W  impacts {row['impact_rate_hz']:.4g}/s  "
                f"speed {row['mean_impact_speed_m_s']:.4g} m/s  stress energy median "
                f"{1e6 * row['stress_energy_median_J']:.4g} µJ, p90 {1e6 * row['stress_energy_p90_J']:.4g} µJ  "
                f"mechanics {row['averaging_window_s']:.3g} s"
            )
            if row is not base:
                combined = math.hypot(row["averaged_heat_power_stderr_W"], base["averaged_heat_power_stderr_W"])
                shifts = ", ".join(
                    f"{label} {row[key] / base[key] - 1:+.1%}"
                    for label, key in (
                        ("impacts", "impact_rate_hz"),
                        ("speed", "mean_impact_speed_m_s"),
                        ("median", "stress_energy_median_J"),
                        ("p90", "stress_energy_p90_J"),
                    )
                )
                sigmas = (row["averaged_heat_power_W"] - base["averaged_heat_power_W"]) / combined
                line += f"\n  {'':<24} {'':<24} heat {sigmas:+.2f} σ, {shifts}"
            print(line, flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reference", help="commit of the stepping before (a git worktree of it is made and removed)")
    parser.add_argument("--only", choices=("restitution", "second", "averaged"))
    parser.add_argument("--measure", nargs="+", help=argparse.SUPPRESS)
    options = parser.parse_args()
    if options.measure:
        part, *scale = options.measure
        print(json.dumps(measure_second() if part == "second" else measure_averaged(float(scale[0]))))
        return
    if options.only in (None, "restitution"):
        restitution_part()
    with ExitStack() as stack:
        trees = {}
        if options.reference:
            trees[f"before ({options.reference})"] = stack.enter_context(reference_tree(options.reference))
        trees["this tree"] = ROOT
        if options.only in (None, "second"):
            second_part(trees)
        if options.only in (None, "averaged"):
            averaged_part(trees)


if __name__ == "__main__":
    main()
