"""The one sampler: emcee's affine-invariant ensemble (Foreman-Mackey et al. 2013) over whatever coordinates a study's
log-probability takes, seeded so that a posterior is reproducible, the first half of its steps burn-in."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

# A log-probability of one point (walkers one by one) or of an array of them (vectorized): -inf outside the prior.
LogProbability = Callable[[np.ndarray], Any]
# How often the sampler says how far it is: a sampling takes minutes.
PROGRESS_STEPS = 1000


@dataclass(frozen=True)
class Chain:
    """What a run of the sampler kept: ``samples`` (kept, dimensions) evenly thinned from the steps after burn-in,
    the walkers' mean acceptance, the longest integrated autocorrelation time (steps) and the steps after burn-in."""

    samples: np.ndarray
    acceptance: float
    autocorrelation_steps: float
    steps: int


def sample(
    log_probability: LogProbability,
    start: np.ndarray,
    steps: int,
    kept: int,
    seed: int,
    *,
    vectorize: bool = False,
    moves: Sequence[tuple[Any, float]] | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> Chain:
    """Run the ensemble from ``start`` (walkers, dimensions) for ``steps`` steps and keep ``kept`` samples of the
    second half. ``moves``: emcee's proposals and their weights (its stretch move without).

    emcee prints a traceback of whatever the log-probability raises (a Ctrl-C, a spent budget) before raising it
    again: the first is kept, every later call refused at once, and it is raised after the sampler, with nothing
    printed; the sampler stops at the step it was raised in. ``progress(step, steps)`` is told every
    PROGRESS_STEPS steps."""
    import emcee

    raised: list[BaseException] = []

    def guarded(points: np.ndarray) -> Any:
        refused = np.full(len(points), -np.inf) if vectorize else -np.inf
        if raised:
            return refused
        try:
            return log_probability(points)
        except BaseException as exc:  # noqa: BLE001 - raised again below, after the sampler
            raised.append(exc)
            return refused

    walkers, dimensions = start.shape
    sampler = emcee.EnsembleSampler(
        walkers, dimensions, guarded, vectorize=vectorize, moves=None if moves is None else list(moves)
    )
    sampler.random_state = np.random.RandomState(seed).get_state()
    for step, _ in enumerate(sampler.sample(start, iterations=steps), start=1):
        if raised:
            break
        if progress is not None and (step % PROGRESS_STEPS == 0 or step == steps):
            progress(step, steps)
    if raised:
        raise raised[0]
    burn_in = steps // 2
    chain = sampler.get_chain(discard=burn_in, flat=True)
    # tol=0: the estimate is returned however short the chain; Posterior.converged judges it.
    tau = float(np.max(sampler.get_autocorr_time(discard=burn_in, quiet=True, tol=0)))
    return Chain(
        chain[np.linspace(0, len(chain) - 1, kept).astype(int)],
        float(np.mean(sampler.acceptance_fraction)),
        tau,
        steps - burn_in,
    )
