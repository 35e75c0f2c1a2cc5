"""Both directions of the SPEX experiments (issue 36 point 4), as ``validate --full`` runs them: fitted over every
uncertain input on the one-ball curve, is the five-ball measurement inside the 90 % posterior-predictive interval;
fitted on the five-ball point, is the one-ball curve inside. It prints the wall time of each phase, each emulator's
Q² on runs it did not see, the posterior of every freed input, and every measured point against its interval.

    .venv/bin/python benchmarks/bench_cross_prediction.py                 # ~10 min on 2 cores
    .venv/bin/python benchmarks/bench_cross_prediction.py --members 64    # twice the runs: does the answer move?
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from shakermill.studies.validation.cross_prediction import MEMBERS, THERMAL_DRAWS, cross_prediction
from shakermill.views.validation_page import cross_rows, cross_statement


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--members", type=int, default=MEMBERS)
    parser.add_argument("--thermal-draws", type=int, default=THERMAL_DRAWS)
    parser.add_argument("--json", type=Path, help="also write the whole result here")
    arguments = parser.parse_args()
    started = time.perf_counter()
    last = [started]

    def progress(done: int, total: int) -> None:
        now = time.perf_counter()
        print(f"  run {done}/{total}: {now - last[0]:.1f} s", flush=True)
        last[0] = now

    found = cross_prediction(members=arguments.members, thermal_draws=arguments.thermal_draws, progress=progress)
    wall = time.perf_counter() - started
    print(
        f"\nwall time {wall:.0f} s for {2 * arguments.members} mechanical runs x {arguments.thermal_draws} network "
        "points, the emulators and two posteriors"
    )
    for name, emulator in found.emulators.items():
        print(
            f"{name}: held-out Q² "
            + ", ".join(f"{key} {value:.2f}" for key, value in emulator.q2.items())
            + (f"; failed runs: {emulator.failed}" if emulator.failed else "")
        )
    for direction in found.directions:
        print(
            f"\nfitted on {direction.fitted_on.name} (acceptance {direction.posterior.acceptance:.2f}, "
            f"autocorrelation {direction.posterior.autocorrelation_steps:.0f} steps, "
            f"{'converged' if direction.posterior.converged else 'NOT converged'}):"
        )
        for key, (low, middle, high) in direction.posterior.quantiles().items():
            print(f"  {key:20s} {low:10.4g} {middle:10.4g} {high:10.4g}")
        for point in direction.fitted:
            print(
                f"  fitted point {point.observable.label}: measured {point.measured_K:.3g} K, 90 % "
                f"{point.quantiles[0]:.3g} to {point.quantiles[2]:.3g} K, {'inside' if point.inside else 'OUTSIDE'}"
            )
    print()
    for row in cross_rows(found):
        print(" | ".join(row))
    print(cross_statement(found))
    if arguments.json is not None:
        arguments.json.write_text(json.dumps(found.as_dict(), indent=1, default=str), encoding="utf-8")


if __name__ == "__main__":
    main()
