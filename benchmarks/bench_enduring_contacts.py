"""Enduring contacts stepped by their own period (issue "The real mill in minutes"): cost and convergence.

A contact of the 'dem' engine that has lasted two of its periods (a ball rolling, sliding or resting on the bore)
steps at ``enduring_step_fraction`` of its period instead of the impact's fraction (0.05/9.5 of it). The smallest
value allowed, 0.001, is below the impact's fraction, so it gives the stepping from before: the reference, run in the
same process as the others.

Prints, for each mill and each fraction:

* the CPU time of one simulated second at full resolution, its steps and the share of them inside contacts
  (``--second``);
* the averaged solver's heat power with its batch-means standard error, the impact rate and the mean impact speed
  of the settled motion, and the difference of each from the reference in units of their combined standard error
  (heat power) or as a relative difference (the hit statistics, whose errors the solver does not estimate).

Run by hand on a quiet machine; the figures go into benchmarks/README.md.
"""

from __future__ import annotations

import argparse
import math
import time

import shakermill as sm
from shakermill.solvers.summary import Summary

MILLS = {
    "spex8000m-3d, 1 ball": ("spex8000m-3d", {}),
    "spex8000m-3d, 5 balls": ("spex8000m-3d", {"n_balls": 5}),
    "mm400, 2 balls": ("mm400", {}),
}
BEFORE = 0.001  # below the impact's fraction of a period: the stepping from before
FRACTIONS = (BEFORE, 0.02, 0.05, 0.1)


def one_second(preset: str, settings: dict, fraction: float) -> tuple[float, Summary]:
    params = sm.default_parameters(
        preset, **settings, duration=1.0, solver="full", record_windows=(), enduring_step_fraction=fraction
    )
    started = time.process_time()
    result = sm.simulate(params)
    return time.process_time() - started, result.summary


def averaged(preset: str, settings: dict, fraction: float) -> tuple[float, Summary]:
    params = sm.default_parameters(preset, **settings, attractor_starts=1, enduring_step_fraction=fraction)
    started = time.process_time()
    result = sm.simulate(params)
    return time.process_time() - started, result.summary


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mills", nargs="*", default=list(MILLS), help="which of: " + "; ".join(MILLS))
    parser.add_argument("--no-averaged", action="store_true", help="only the cost of one simulated second")
    parser.add_argument("--no-second", action="store_true", help="only the averaged solver's means")
    parser.add_argument("--fractions", type=float, nargs="*", default=FRACTIONS, help="enduring_step_fraction values")
    parser.add_argument(
        "--rel-error", type=float, help="dem_averaging_rel_error of the averaged rows (default: the preset's)"
    )
    parser.add_argument("--replicas", type=int, default=1, help="dem_replicas of the averaged rows")
    options = parser.parse_args()
    tighter = (
        {}
        if options.rel_error is None
        else {"dem_averaging_rel_error": options.rel_error, "averaging_max_time": 3600.0}
    )
    sm.simulate(sm.default_parameters("spex8000m-3d", duration=0.01, solver="full", record_windows=()))  # compile
    for mill in options.mills:
        preset, settings = MILLS[mill]
        print(f"\n{mill}")
        if not options.no_second:
            print("  one simulated second at full resolution:")
            for fraction in options.fractions:
                cpu, summary = one_second(preset, settings, fraction)
                print(
                    f"    enduring_step_fraction {fraction:<5g}  {cpu:6.2f} CPU-s  {summary.steps:>9,} steps  "
                    f"{summary.impacts.count:>5} impacts"
                )
        if options.no_averaged:
            continue
        print("  averaged solver (the preset's hour):")
        reference = None
        for fraction in options.fractions:
            cpu, summary = averaged(preset, {**settings, **tighter, "dem_replicas": options.replicas}, fraction)
            power, error = summary.averaging.heat_power_W, summary.averaging.heat_power_stderr_W
            rate, speed = summary.impacts.rate_hz, summary.impacts.mean_speed_m_s
            line = (
                f"    enduring_step_fraction {fraction:<5g}  {cpu:6.1f} CPU-s  heat {power:.4g} ± {error:.2g} W  "
                f"impacts {rate:.4g} /s  mean impact speed {speed:.4g} m/s  mechanics "
                f"{summary.averaging.window_s:.3g} s"
            )
            if reference is None:
                reference = (power, error, rate, speed)
            else:
                combined = math.hypot(error, reference[1])
                line += (
                    f"  | heat {(power - reference[0]) / combined:+.2f} σ, impacts {rate / reference[2] - 1:+.1%}, "
                    f"speed {speed / reference[3] - 1:+.1%}"
                )
            print(line, flush=True)


if __name__ == "__main__":
    main()
