"""The averaged solver's batch-means error before and after its batches were grouped until uncorrelated (issue 36,
MODEL.md §14.2).

Each preset's mechanics run for a fixed span in the batches the preset ships (``averaging_batch_periods``), and the
same batches are judged twice: *before*, as the averaged solver did until issue 36 (MSER's cut, then the standard
error of the batch means as if they were independent), and *after*, as it does now (the batches grouped, 1, 2, 4, …
a group, until the lag-1 autocorrelation of the group means of the total heat power and of the balls' mean
velocity term is insignificant, with at least ``averaging_min_batches`` groups). It prints, per preset, the lag-1
autocorrelation of the batches as shipped, the grouping found, both errors of the heat power and their ratio, and
whether the grouped means drift between their halves.

    .venv/bin/python benchmarks/bench_batch_means.py                       # pulverisette7, pm100, 5 SPEX balls
    .venv/bin/python benchmarks/bench_batch_means.py --presets pm100 --span 8
"""

from __future__ import annotations

import argparse
import resource

import numpy as np

import shakermill as sm
from shakermill.analysis.batch_means import (
    batch_rates,
    drifts,
    grouped,
    lag1_autocorrelation,
    mser_truncation,
    normalised,
    relative_error,
    standard_error,
    uncorrelated_grouping,
)
from shakermill.engines.budget import RunBudget
from shakermill.engines.registry import engine_named

# (preset, overrides, simulated seconds of mechanics): spans of ~40-70 batches as shipped.
RUNS = {
    "pulverisette7": ({}, 12.0),
    "pm100": ({}, 12.0),
    "spex8000m-3d": ({"n_balls": 5}, 40.0),
}


def cpu_seconds() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def batch_totals(params: sm.Parameters, span: float) -> tuple[np.ndarray, float]:
    """Each batch's total heat power (W) and balls' mean velocity term over ``span`` s of mechanics."""
    engine = engine_named(params.engine)(params, RunBudget.unlimited(), np.zeros(1), span)
    batch = params.averaging_batch_periods * params.period
    cumulative = []
    for index in range(int(span / batch) + 1):
        if index:
            engine.advance(index * batch, None)
        measured = engine.measured()
        cumulative.append([measured.heat.sum(), measured.terms.mean()])
    return batch_rates(np.array(cumulative), batch), batch


def judge(name: str, overrides: dict, span: float) -> None:
    params = sm.default_parameters(name, record_windows=(), **overrides)
    started = cpu_seconds()
    rates, batch = batch_totals(params, span)
    cut = max(mser_truncation(normalised(column)) for column in rates.T)
    kept = rates[cut:]
    heat = kept[:, 0]
    grouping = uncorrelated_grouping([kept], params.averaging_min_batches)
    after = grouped(kept, grouping.size)
    before_error, after_error = standard_error(heat), standard_error(after[:, 0])
    print(
        f"\n{name} {overrides or ''}: {span:g} s of mechanics in {len(rates)} batches of {batch:.3g} s "
        f"({cpu_seconds() - started:.0f} CPU-s); MSER cut {cut} batches"
    )
    print(
        f"  lag-1 autocorrelation of the batches as shipped: heat {lag1_autocorrelation([heat]):+.2f}, "
        f"velocity term {lag1_autocorrelation([kept[:, 1]]):+.2f} (insignificant below {2 / np.sqrt(len(kept)):.2f})"
    )
    print(f"  before: {heat.mean():.4g} ± {before_error:.2g} W ({relative_error(heat):.2%}), {len(kept)} batches")
    verdict = "uncorrelated" if grouping.uncorrelated else "still correlated: more mechanics needed"
    print(
        f"  after:  {after[:, 0].mean():.4g} ± {after_error:.2g} W ({relative_error(after[:, 0]):.2%}), "
        f"{grouping.groups} groups of {grouping.size} batches ({grouping.size * batch:.3g} s), "
        f"|r1| {grouping.autocorrelation:.2f}, {verdict}"
    )
    print(
        f"  error after / before: {after_error / before_error:.2f}; the halves drift: "
        f"{any(drifts(column) for column in after.T)}"
    )
    # The solver's own rule: a column whose batch means spread less than the target error is known well enough
    # whatever their correlation (the variance of a mean never exceeds its values').
    target = params.dem_averaging_rel_error
    spread = kept.std(axis=0) / np.abs(kept.mean(axis=0))
    solver = uncorrelated_grouping([kept], params.averaging_min_batches, target)
    print(
        f"  the solver's verdict (target {target:g}): batch spread {spread[0]:.2%} (heat), {spread[1]:.2%} (term); "
        f"{'accepted' if solver.uncorrelated else 'not yet'}: {solver.groups} groups of {solver.size}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--presets", nargs="+", default=list(RUNS), choices=list(RUNS))
    parser.add_argument("--span", type=float, help="seconds of mechanics (default: the preset's span above)")
    arguments = parser.parse_args()
    for name in arguments.presets:
        overrides, span = RUNS[name]
        judge(name, overrides, arguments.span or span)


if __name__ == "__main__":
    main()
