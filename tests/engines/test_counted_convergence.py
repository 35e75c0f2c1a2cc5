"""What is counted is converged with the step (issue 50, point 2, at a cheap size): halving every step of the 'dem'
engine changes the impact rate and the median stress energy of five SPEX balls by less than their statistical errors,
the spread over replicas (a chaotic charge: one trajectory against another says nothing), while the contact records,
chatter included, need not agree. benchmarks/bench_impact_counts.py does the same for the planetary pack."""

from __future__ import annotations

import math

import numpy as np
import pytest

import shakermill as sm
from shakermill.engines.budget import RunBudget
from shakermill.engines.dem.engine import DemEngine
from shakermill.solvers.driver import run_until, sample_times, stop_message
from shakermill.solvers.full import concluded

REPLICAS = 8
DURATION = 2.0


def settled_counts(params: sm.Parameters) -> np.ndarray:
    """Per replica: impacts a second and the median stress energy (J) of its second half."""
    rows = []
    for replica in range(REPLICAS):
        engine = DemEngine(params, RunBudget.of(params), sample_times(params), params.duration, replica=replica)
        status = run_until(engine, params.duration, None)
        result = concluded(engine, status, stop_message(engine, status), 0.0)
        contacts = result.contacts(since=0.5 * params.duration)
        brief = ~contacts.touch & ~contacts.lasting
        rows.append(
            (
                contacts.impact_count / (0.5 * params.duration),
                float(np.median(contacts.columns["dissipated_energy"][brief])),
            )
        )
    return np.array(rows)


@pytest.mark.slow
def test_halving_every_step_changes_the_impact_rate_and_median_stress_energy_by_less_than_their_errors():
    params = sm.default_parameters("spex8000m-3d", n_balls=5, solver="full", duration=DURATION, record_windows=())
    halved = params.replace(
        contact_step_fraction=params.contact_step_fraction / 2,
        enduring_step_fraction=params.enduring_step_fraction / 2,
        max_flight_step=params.max_flight_step / 2,
    )
    default, fine = settled_counts(params), settled_counts(halved)
    means, finer_means = default.mean(axis=0), fine.mean(axis=0)
    errors = np.hypot(default.std(axis=0, ddof=1), fine.std(axis=0, ddof=1)) / math.sqrt(REPLICAS)
    assert np.all(errors > 0) and np.all(errors < 0.2 * means)  # the replicas resolve the figures
    np.testing.assert_array_less(np.abs(finer_means - means), errors)
