"""The shipped three-dimensional calibration with its uncertainty, timed: target ≤ 10 min on this machine (2 cores).

Fits ``spex8000m-3d-calibrated``'s free keys to the one-ball curve from ``spex8000m-3d-mill-head``, as
``shakermill calibrate --preset spex8000m-3d-mill-head --free drive_heat,clamp_heat_capacity,clamp_loss`` does:
the mechanics of one ball measured once (the averaged solver's means), then each evaluation integrates the
thermal network alone, and the covariance comes from ``least_squares``' Jacobian. Prints the wall time, the fit,
each key's standard error and posterior range, and the 90 % intervals a run of the fitted preset reports (from the
posterior). Run by hand.
"""

from __future__ import annotations

import math
import time

import numpy as np

import shakermill as sm
from shakermill.parameters.presets import PRESETS
from shakermill.solvers.simulate import thermal_variants
from shakermill.studies.calibration.intervals import Uncertainty, intervals

TARGET_S = 600.0


def main() -> None:
    free = PRESETS["spex8000m-3d-calibrated"].fitted
    base = sm.default_parameters("spex8000m-3d-mill-head")
    started = time.perf_counter()
    calibration = sm.calibrate(base, free)
    elapsed = time.perf_counter() - started
    print(
        f"calibration with its covariance: {elapsed:.0f} s (target <= {TARGET_S:.0f} s: "
        f"{'met' if elapsed <= TARGET_S else 'MISSED'}); "
        f"{calibration.evaluations} network evaluations"
    )
    print(f"curve RMS {calibration.curve_rms_K:.2f} K; on a range edge: {', '.join(calibration.at_bounds) or 'none'}")
    covariance = np.array(calibration.covariance)
    ranges = calibration.posterior_ranges
    for index, key in enumerate(free):
        print(
            f"  {key} = {calibration.fitted[key]:.4g} ± {calibration.parameter_stderr[key]:.3g} "
            f"(σ of its logarithm {math.sqrt(covariance[index, index]):.3g}); posterior 90 %: "
            f"{ranges[key][0]:.4g} to {ranges[key][1]:.4g}"
        )
    correlation = covariance / np.sqrt(np.outer(np.diag(covariance), np.diag(covariance)))
    print("correlation of the logarithms:\n" + np.array2string(correlation, precision=4))
    fitted = base.replace(**calibration.fitted)
    result = thermal_variants(fitted)(fitted)
    found = intervals(result, Uncertainty(free, covariance, calibration.posterior))
    for key in found.centre:
        low, high = found.bounds(key)
        print(f"  {key}: {found.centre[key]:.2f} °C, 90 % interval {low:.2f} to {high:.2f} °C")


if __name__ == "__main__":
    main()
