"""Which free sets of the 3-D calibration follow the one-ball curve, and what each predicts for five balls.

Each free set is fitted to the experiment's one-ball curve (48 − 28·exp(−t/16.7 min) °C) from the
``spex8000m-3d`` preset, exactly as ``shakermill calibrate --preset spex8000m-3d --free ...`` does; then the
same preset with five balls and the fitted values, nothing refitted, runs the experiment's hour. The
shipped ``spex8000m-3d-calibrated`` is the engine's default free set (``DEM_DEFAULT_FREE``), chosen before
the five-ball comparison was made: picking a set by its five-ball numbers would fit the held-out data.

The mechanics are measured once for one ball and once for five (``solvers.simulate.thermal_variants``);
each fit then only integrates thermal networks. Run by hand (~6 min here); figures go into
benchmarks/README.md and README.md.
"""

from __future__ import annotations

import time

import shakermill as sm
from shakermill.parameters.defaults import DEM_DEFAULT_FREE
from shakermill.solvers.simulate import thermal_variants
from shakermill.studies.held_out import FIVE_BALLS, five_ball_rows

FREE_SETS = (("beta", "vial_mass"), DEM_DEFAULT_FREE, ("beta", "vial_mass", "outer_area"), ("beta", "h_outer"))


def main() -> None:
    base = sm.default_parameters("spex8000m-3d", record_windows=())
    started = time.perf_counter()
    five = thermal_variants(base.replace(n_balls=FIVE_BALLS))
    print(f"five-ball mechanics measured in {time.perf_counter() - started:.0f} s")
    print("| free keys | fitted | one-ball curve RMS | five balls: ball rise (exp. 46 K) | vial rise (exp. 21 K) | ratio (exp. 0.46) |")
    print("|---|---|---|---|---|---|")
    for free in FREE_SETS:
        started = time.perf_counter()
        calibration = sm.calibrate(base, free)
        rows = five_ball_rows(five(base.replace(n_balls=FIVE_BALLS, **calibration.fitted)).summary)
        fitted = ", ".join(f"{key} {value:.3g}" + (" (edge)" if key in calibration.at_bounds else "") for key, value in calibration.fitted.items())
        cells = [f"{row.predicted:.3g} ({100 * row.relative_error:+.0f} %)" for row in rows]
        print(f"| {', '.join(free)} | {fitted} | {calibration.curve_rms_K:.2f} K | {' | '.join(cells)} |  ({time.perf_counter() - started:.0f} s)")


if __name__ == "__main__":
    main()
