"""The one sampler: a Ctrl-C in the log-probability stops it at that step, with nothing printed (issue 49), and it
says how far it is."""

from __future__ import annotations

import numpy as np
import pytest

from shakermill.studies.inference import sampler
from shakermill.studies.inference.sampler import sample


def standard_normal(points: np.ndarray) -> np.ndarray:
    return -0.5 * np.sum(points**2, axis=1)


def test_a_ctrl_c_in_the_log_probability_stops_the_sampler_at_once_without_emcees_dump(capfd, monkeypatch):
    import emcee

    calls = []
    evaluations = []
    original = emcee.EnsembleSampler.compute_log_prob

    def counted(self, coords):
        evaluations.append(len(coords))
        return original(self, coords)

    monkeypatch.setattr(emcee.EnsembleSampler, "compute_log_prob", counted)

    def interrupted_at_the_fifth_call(points: np.ndarray) -> np.ndarray:
        calls.append(len(points))
        if len(calls) == 5:
            raise KeyboardInterrupt
        return standard_normal(points)

    start = np.random.default_rng(1).normal(size=(8, 2))
    with pytest.raises(KeyboardInterrupt):
        sample(interrupted_at_the_fifth_call, start, 10000, 10, seed=1, vectorize=True)
    # Each step calls it twice (two halves of the walkers): stopped within the step, not after 10 000 refused ones.
    assert len(calls) == 5 and len(evaluations) <= 6
    printed = capfd.readouterr()
    assert printed.out == "" and "emcee" not in printed.err


def test_the_sampler_says_how_far_it_is(monkeypatch):
    monkeypatch.setattr(sampler, "PROGRESS_STEPS", 10)
    told: list[tuple[int, int]] = []
    start = np.random.default_rng(2).normal(size=(8, 2))
    chain = sample(standard_normal, start, 40, 10, seed=2, vectorize=True, progress=lambda *at: told.append(at))
    assert told == [(10, 40), (20, 40), (30, 40), (40, 40)]
    assert chain.samples.shape == (10, 2) and chain.steps == 20
