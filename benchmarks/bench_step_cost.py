"""The per-step cost of the 'dem' engine: this tree against a reference commit, measured in one run.

For each mill, one simulated second at full resolution (no record windows) after a warm-up of 10 ms that loads or
compiles the engine: the CPU time, the steps and the CPU time per step, each in a fresh process whose
``PYTHONPATH`` puts one tree first, the trees alternating over ``--repeats`` rounds (medians). The reference
commit is checked out into a temporary git worktree. A digest of each run's final state and contact records
says whether the two trees computed the same numbers.

    .venv/bin/python benchmarks/bench_step_cost.py --reference b68de3d --repeats 3

Run by hand on a quiet machine; the figures go into benchmarks/README.md.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import statistics
import time
from contextlib import ExitStack

from reference_tree import ROOT, measured_in, reference_tree

MILLS = {
    "spex8000m-3d, 1 ball": ("spex8000m-3d", 1),
    "spex8000m-3d-calibrated, 5 balls": ("spex8000m-3d-calibrated", 5),
    "mm400, 2 balls": ("mm400", 2),
}
SIMULATED_S = 1.0


def measure() -> dict[str, dict[str, float | str]]:
    """One simulated second of each mill in this process: CPU-s, steps and a digest of what it computed."""
    import numpy as np

    import shakermill as sm
    from shakermill.engines.budget import RunBudget
    from shakermill.engines.dem.engine import DemEngine

    figures = {}
    for mill, (preset, balls) in MILLS.items():
        params = sm.default_parameters(preset, n_balls=balls, solver="full", record_windows=(), duration=SIMULATED_S)
        engine = DemEngine(params, RunBudget.unlimited(), np.array([0.0, SIMULATED_S]), SIMULATED_S)
        engine.advance(0.01)
        steps, started = engine.steps_taken(), time.process_time()
        engine.advance(SIMULATED_S)
        cpu = time.process_time() - started
        digest = hashlib.sha256()
        for values in (engine.records, engine.state.position, engine.state.velocity, engine.state.totals):
            digest.update(np.ascontiguousarray(values).tobytes())
        figures[mill] = {"cpu": cpu, "steps": engine.steps_taken() - steps, "digest": digest.hexdigest()[:16]}
    return figures


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reference", help="commit to compare with (a git worktree of it is made and removed)")
    parser.add_argument("--repeats", type=int, default=1, help="rounds of both trees, alternating (medians)")
    parser.add_argument("--measure", action="store_true", help=argparse.SUPPRESS)
    options = parser.parse_args()
    if options.measure:
        print(json.dumps(measure()))
        return
    with ExitStack() as stack:
        trees = {"this tree": ROOT}
        if options.reference:
            trees = {f"reference {options.reference}": stack.enter_context(reference_tree(options.reference)), **trees}
        runs = {name: [] for name in trees}
        for _ in range(options.repeats):
            for name, tree in trees.items():
                runs[name].append(measured_in(tree, __file__, "--measure"))
    report(runs)


def report(runs: dict[str, list[dict]]) -> None:
    print(
        f"one simulated second at full resolution, CPU-s (median of {len(next(iter(runs.values())))}), steps, µs per "
        "step"
    )
    for mill in MILLS:
        medians = {}
        for name, repeats in runs.items():
            cpu = statistics.median(figures[mill]["cpu"] for figures in repeats)
            steps = repeats[0][mill]["steps"]
            medians[name] = cpu
            print(
                f"  {mill:<34} {name:<20} {cpu:6.2f} CPU-s {steps:>9,} steps {1e6 * cpu / steps:6.2f} µs/step  "
                f"state {repeats[0][mill]['digest']}"
            )
        if len(medians) == 2:
            before, after = medians.values()
            digests = {repeats[0][mill]["digest"] for repeats in runs.values()}
            same = "the same numbers" if len(digests) == 1 else "DIFFERENT numbers"
            print(f"  {mill:<34} {'ratio':<20} {before / after:6.2f}x faster, {same}")


if __name__ == "__main__":
    main()
