"""Whether a fit can determine its free keys: before it, enough informative values for them; after it, a Jacobian
that every direction of the keys moves. A fit that cannot is refused, or says "undetermined", never "fitted"."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from shakermill.parameters.errors import ParameterError
from shakermill.studies.measured import Curve


def informative_points(curve: Curve) -> int:
    """The points of ``curve`` that a fitted key can move: a point at t = 0 is the start, the same for any key."""
    return int((curve.times > 0).sum())


def check_determinable(free: Sequence[str], targets: Mapping[str, float], curves: Sequence[Curve]) -> None:
    """Refuse a fit of more free keys than it has informative values (targets and curve points after t = 0): it
    would meet them exactly with a whole family of values, and report that as a fit."""
    counts = [f"{len(targets)} target{'s' * (len(targets) != 1)}"] if targets else []
    counts += [f"{informative_points(measured)} of {measured.source or 'the curve'}" for measured in curves]
    informative = len(targets) + sum(informative_points(measured) for measured in curves)
    if informative < len(free):
        raise ParameterError(
            f"free: {len(free)} keys ({', '.join(free)}) cannot be determined by {informative} informative "
            f"value{'s' * (informative != 1)} ({'; '.join(counts)} after t = 0); allowed at most {informative} free "
            f"key{'s' * (informative != 1)} (--free), or more measured points"
        )


# A direction of the free keys whose singular value is below this fraction of the largest moves the residuals less
# than the finite-difference noise of the Jacobian (JACOBIAN_STEP on a solver error of ~1e-4): the data leave it free.
SINGULAR_FRACTION = 1e-6


def undetermined_keys(jacobian: np.ndarray, free: Sequence[str]) -> str:
    """Why the data leave keys of ``free`` undetermined, from the fit's Jacobian (rows: residuals, columns: the
    logarithms of ``free``), in words; "" when every direction of the keys moves the residuals. A column of zeros is
    a key the residuals do not depend on; a nearly singular Jacobian a combination (the keys it leans on named)."""
    jacobian = np.asarray(jacobian, dtype=float)
    if jacobian.size == 0 or not np.all(np.isfinite(jacobian)):
        return ""
    scale = float(np.abs(jacobian).max())
    dead = [
        key
        for column, key in enumerate(free)
        if scale == 0 or np.abs(jacobian[:, column]).max() <= SINGULAR_FRACTION * scale
    ]
    if dead:
        return f"undetermined: the fitted values do not depend on {', '.join(dead)} (sensitivity 0)"
    _, singular, directions = np.linalg.svd(jacobian, full_matrices=False)
    if singular.size < len(free) or singular[-1] <= SINGULAR_FRACTION * singular[0]:
        weights = np.abs(directions[-1]) if singular.size == len(free) else np.ones(len(free))
        leaning = [key for key, weight in zip(free, weights) if weight >= 0.2 * weights.max()]
        return (
            f"undetermined: the data fix no more than a combination of {', '.join(leaning)} (a singular "
            "Jacobian); fix one of them or add a measurement that separates them"
        )
    return ""


# A key whose standard error in log space exceeds this (one standard error spans a factor e: the error is larger than
# the value) is not determined by the data, however well the fit follows them: an overfit of few points.
LOOSE_LOG_ERROR = 1.0


def loosely_determined(covariance: np.ndarray | None, free: Sequence[str], on_bounds: Sequence[str] = ()) -> str:
    """Why the data leave keys of ``free`` statistically undetermined, from the covariance of their logarithms, in
    words; "" when every key's standard error is below its value (or there is no covariance to judge by). A key that
    ended on a bound (``on_bounds``) is held there by its range, not left free: its linear error means nothing."""
    if covariance is None:
        return ""
    errors = np.sqrt(np.clip(np.diag(np.asarray(covariance, dtype=float)), 0.0, None))
    loose = [key for key, error in zip(free, errors) if not error <= LOOSE_LOG_ERROR and key not in on_bounds]
    if not loose:
        return ""
    determined = [key for key, error in zip(free, errors) if error <= LOOSE_LOG_ERROR]
    keep = f" (e.g. --free {','.join(determined)})" if determined else ""
    return (
        f"undetermined: the data leave {', '.join(loose)} free (a standard error larger than the value: "
        f"{len(free)} keys on too few or too similar points); free fewer keys{keep}"
    )
