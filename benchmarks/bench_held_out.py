"""Which network structure follows the one-ball curve with physical couplings, and what each predicts for five balls.

Each structure of ``studies.validation_matrix.STRUCTURES`` is fitted to the experiment's one-ball curve
(48 − 28·exp(−t/16.7 min) °C) from its uncalibrated preset, exactly as ``shakermill calibrate --preset P --free
...`` does; then five balls with the fitted values, nothing refitted, run the experiment's hour. The bar (issue 23,
point 7): the curve within 2 K RMS, every free key strictly inside its range, every computed path at its
correlation's value. The shipped ``spex8000m-3d-calibrated`` is the physical structure that comes closest; the
choice uses the one-ball curve and the ranges alone, never the five-ball numbers.

Then the validation matrix: each thermal model's calibrated preset against each experiment file, with 90 %
intervals. The mechanics are measured once for one ball and once for five (``solvers.simulate.thermal_variants``).
Run by hand (~10 min here); figures go into benchmarks/README.md and README.md.
"""

from __future__ import annotations

import time

from shakermill.studies.held_out import FIVE_BALL_BALL_RISE_K, FIVE_BALL_VIAL_RISE_K
from shakermill.studies.validation_matrix import structure_study, validation_matrix


def main() -> None:
    started = time.perf_counter()
    matrix = validation_matrix()
    print(f"validation matrix in {time.perf_counter() - started:.0f} s")
    print("| preset (thermal model) | experiment | node | t | role | measured | predicted [90 % interval] | error | inside |")
    print("|---|---|---|---|---|---|---|---|---|")
    for row in matrix.rows:
        measured = "—" if row.point.rise_K is None else f"{row.point.rise_K:.3g} K"
        error = "—" if row.point.rise_K is None else f"{100 * row.error:+.0f} %"
        inside = {None: "—", True: "yes", False: "no"}[row.inside]
        print(f"| {row.preset} ({row.thermal_model}) | {row.experiment.name} | {row.point.node} | {row.point.time_s / 60:g} min "
              f"| {row.role} | {measured} | {row.predicted_K:.3g} K [{row.low_K:.3g}, {row.high_K:.3g}] | {error} | {inside} |")
    started = time.perf_counter()
    outcomes = structure_study()
    print(f"\nstructure study in {time.perf_counter() - started:.0f} s")
    print(f"| structure | fitted | one-ball RMS | edges | meets the bar | 5 balls: ball ({FIVE_BALL_BALL_RISE_K:g} K) | vial ({FIVE_BALL_VIAL_RISE_K:g} K) |")
    print("|---|---|---|---|---|---|---|")
    for outcome in outcomes:
        fitted = ", ".join(f"{key} {value:.3g}" for key, value in outcome.fitted.items())
        ball, vial = outcome.ball_rise_K, outcome.vial_rise_K
        print(f"| {outcome.structure.label} | {fitted} | {outcome.curve_rms_K:.2f} K | {', '.join(outcome.edges) or 'none'} "
              f"| {'yes' if outcome.meets_point_7 else 'no'} | {ball:.3g} K ({100 * (ball / FIVE_BALL_BALL_RISE_K - 1):+.0f} %) "
              f"| {vial:.3g} K ({100 * (vial / FIVE_BALL_VIAL_RISE_K - 1):+.0f} %) |")


if __name__ == "__main__":
    main()
