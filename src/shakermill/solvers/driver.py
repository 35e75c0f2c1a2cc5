"""The one run driver of every engine and solver: a run advanced in chunks with its budget, progress and Ctrl-C
(:func:`run_until`), and the mechanics advanced batch by batch until the means that drive the thermal network
converge (:func:`measure_means`, the averaged solver's batch means: MSER truncation, White 1997)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from shakermill.analysis.batch_means import (
    DRIFT_SIGMAS,
    Grouping,
    batch_rates,
    drifts,
    grouped,
    lag1_autocorrelation,
    mser_truncation,
    normalised,
    power_of_two_at_least,
    relative_error,
    significant_autocorrelation,
    standard_error,
    uncorrelated_grouping,
)
from shakermill.analysis.impacts import contacts_of
from shakermill.analysis.regime import ACTIVE, Switching
from shakermill.engines.interface import Engine, Measured, ProgressCallback
from shakermill.engines.status import BUDGET_EXCEEDED, REACHED_STOP
from shakermill.engines.thermal.network import NetworkLoad
from shakermill.parameters.keys import Parameters, bounds
from shakermill.solvers.replicas import Replica, ReplicaSet
from shakermill.solvers.result import (
    INTERRUPTED,
    INTERRUPTED_MESSAGE,
    MechanicsAverages,
    counting_rules,
    window_regime,
)

# Simulated seconds per chunk: the granularity of progress reports (tiny steps hand back control sooner,
# engines/calls.py). Chunk ends shorten a step, so this is part of what makes a run's numbers.
CHUNK_SECONDS = 10.0


def sample_times(params: Parameters) -> np.ndarray:
    """The output grid of a run: every ``output_interval`` from 0, and the end (s)."""
    count = int(math.floor(params.duration / params.output_interval + 1e-9))
    times = np.arange(count + 1) * params.output_interval
    if times[-1] < params.duration:
        times = np.append(times, params.duration)
    return times


def run_until(engine: Engine, end: float, progress: ProgressCallback | None) -> int:
    """Advance ``engine`` to ``end`` (s) in chunks, telling ``progress(t, end)``; the engine's status, INTERRUPTED for
    Ctrl-C, or BUDGET_EXCEEDED as soon as its pace says it cannot end within its wall-clock budget
    (:meth:`~shakermill.engines.budget.RunBudget.outpaced`), with everything computed so far kept in the engine."""

    def heartbeat(t: float) -> None:
        if engine.budget.outpaced(t, end):
            raise _Outpaced
        if progress is not None:
            progress(t, end)

    status = REACHED_STOP
    try:
        while engine.t < end and status == REACHED_STOP:
            status = engine.advance(min(end, engine.t + CHUNK_SECONDS), heartbeat)
            heartbeat(engine.t)
    except KeyboardInterrupt:
        status = INTERRUPTED
    except _Outpaced:
        status = BUDGET_EXCEEDED
    return status


class _Outpaced(Exception):
    """Raised between two compiled calls, where the engine's state is whole, to stop a run that cannot end in time."""


def stop_message(engine: Engine, status: int) -> str:
    """What ``status`` means, and for a run that stopped early where it stopped."""
    message = INTERRUPTED_MESSAGE if status == INTERRUPTED else engine.explain(status)
    if status < 0 or status == INTERRUPTED:
        message = f"{message} Stopped at t = {engine.t:.6g} s; results up to then are kept."
    return message


@dataclass(frozen=True)
class Means:
    """The settled mechanics: the load of the thermal network, and the averages with their errors."""

    load: NetworkLoad
    averages: MechanicsAverages


def _flat(measured: Measured) -> np.ndarray:
    return np.concatenate([measured.heat, measured.terms, measured.conduction, [measured.dissipated]])


def measure_means(
    params: Parameters, engines: Sequence[Replica], progress: ProgressCallback | None, threads: int = 1
) -> tuple[Means, int]:
    """Run the mechanics of ``engines`` (independent replicas of one run, solvers/replicas.py) batch by batch, side by
    side on ``threads`` threads, until their pooled means converge (or :func:`mechanics_limit`); returns the means and
    the last status. ``progress(t, mechanics_limit)`` is told how far the first replica has got.

    Converged: after each replica's start-up transient (MSER on its total heat power and its balls' mean velocity
    term), at least ``averaging_min_batches`` batches in all, and every total, source and ball mean of the pooled
    batches known to the engine's target relative standard error (``description.averaging_error_key``). The
    replicas advance in rounds to the same time, so the numbers do not depend on ``threads``.
    """
    key = engines[0].description.averaging_error_key
    target = getattr(params, key)
    batch = params.averaging_batch_periods * params.period
    first = engines[0].measured()
    sources, balls = first.heat.size, first.terms.size
    if balls == 0:
        return _nothing_moves(engines[0], first), REACHED_STOP
    cumulative = [[_flat(engine.measured())] for engine in engines]
    labels: list[str] = []
    limit, limit_name = mechanics_limit(params)
    heartbeat = None if progress is None else lambda t: progress(t, limit)
    status, converged, as_it_stands, message, settled = REACHED_STOP, False, False, "", None
    with ReplicaSet(engines, threads) as replicas:
        while True:
            t = engines[0].t + batch
            status = next((status for status in replicas.advance(t, heartbeat) if status != REACHED_STOP), REACHED_STOP)
            if status != REACHED_STOP:
                message = f"the mechanics failed: {engines[0].explain(status)}"
                break
            if heartbeat is not None:
                heartbeat(t)
            for series, engine in zip(cumulative, engines):
                series.append(_flat(engine.measured()))
            labels.append(batch_regime(params, engines[0], cumulative[0], batch))
            if len(cumulative[0]) > least_rounds(params, len(engines)):
                settled = _settled(cumulative, batch, sources, balls, params.averaging_min_batches, target, labels)
                if settled.ready and all(relative_error(c) <= target for c in settled.checked.T):
                    converged = True
                    message = f"converged after {t:.3g} s of mechanics{_in_each(engines)} ({settled.batches_said()})"
                    break
            if t + batch > limit and settled is not None and settled.averaged_as_it_stands():
                message, as_it_stands = settled.as_it_stands(target, t, limit_name, limit), True
                break
            if t + batch > limit:
                message = (
                    f"the averages did not converge to a relative standard error of {target:g} ({key}) in "
                    "uncorrelated, "
                    f"stationary batches within {limit_name} = {limit:g} s{_in_each(engines)} (irregular or slowly "
                    f"settling motion){_longer_window_hint(settled, t, target, limit_name)}"
                )
                break
    if settled is None:
        # Stopped before convergence was first tested; once tested, the batches have not changed since.
        settled = _settled(cumulative, batch, sources, balls, params.averaging_min_batches, target, labels)
    means = _means(engines, settled, sources, balls, len(cumulative[0]) - 1, converged, message)
    return replace(means, averages=replace(means.averages, as_it_stands=as_it_stands)), status


def batch_regime(params: Parameters, engine: Replica, cumulative: list[np.ndarray], batch: float) -> str:
    """The regime of the last batch of ``engine`` (the first replica, which keeps its records), from its contacts and
    its dissipation (the last column of :func:`_flat`); :data:`ACTIVE` where the share is not known."""
    start = engine.t - batch
    contacts = contacts_of(engine.impact_columns(since=start), *counting_rules(params))
    dissipated_power = (cumulative[-1][-1] - cumulative[-2][-1]) / batch
    return window_regime(params, contacts, batch, float(dissipated_power))[2] or ACTIVE


@dataclass(frozen=True)
class Settled:
    """The batches of every replica after its start-up transient (``cuts``, in batches of ``base`` s), grouped to
    uncorrelated means of ``batch`` s (``grouping``) and pooled in ``rates``; ``checked`` holds the columns held to
    the target error (total heat, mean velocity term, each source and ball). ``ready``: enough uncorrelated
    groups, and no drift between the halves of the settled window."""

    rates: np.ndarray
    checked: np.ndarray
    cuts: list[int]
    base: float
    grouping: Grouping
    drifting: bool
    transient_heat_power: float
    switching: Switching
    switches_before: int = 0

    @property
    def batch(self) -> float:
        return self.base * self.grouping.size

    @property
    def ready(self) -> bool:
        return self.grouping.uncorrelated and not self.drifting

    def batches_said(self) -> str:
        """The batches averaged over, in words, with their lag-1 autocorrelation as measured: uncorrelated, or
        correlated with a spread within the target (whose variance of the mean is no more than their own)."""
        grouping = self.grouping
        kind = (
            "correlated" if significant_autocorrelation(grouping.autocorrelation, grouping.groups) else "uncorrelated"
        )
        return (
            f"{grouping.groups} {kind} batches of {self.batch:.3g} s, lag-1 autocorrelation "
            f"{grouping.autocorrelation:.2f}"
        )

    def averaged_as_it_stands(self) -> bool:
        """Whether an intermittent charge whose target error is out of reach within its mechanics is averaged as it
        stands: over at least INTERMITTENT_GROUPS groups that each hold several switches (MODEL.md §14.2)."""
        holding = self.grouping.size >= self.switching.batches_holding_switches()
        return self.switching.intermittent and holding and self.grouping.groups >= INTERMITTENT_GROUPS

    def as_it_stands(self, target: float, t: float, limit_name: str, limit: float) -> str:
        """What :meth:`averaged_as_it_stands` averaged, and the error it stands at beside the ``target``."""
        worst = max(relative_error(column) for column in self.checked.T)
        switching = self.switching
        return (
            f"intermittent charge (active {switching.share(ACTIVE):.0%} of the time, switching every "
            f"{switching.switch_interval:.3g} s): averaged as it stands after {t:.3g} s of mechanics ({limit_name} = "
            f"{limit:g} s) over {self.grouping.groups} batches of {self.batch:.3g} s holding about "
            f"{self.batch / switching.switch_interval:.2g} switches each, lag-1 autocorrelation "
            f"{self.grouping.autocorrelation:.2f}; its largest relative standard error, {worst:.3g}, is above the "
            f"target {target:g}"
        )


def _settled(
    cumulative: list[list[np.ndarray]],
    base: float,
    sources: int,
    balls: int,
    least: int,
    target: float,
    labels: Sequence[str],
) -> Settled:
    """Cut each replica's transient (MSER on its total heat power and its balls' mean velocity term, White 1997),
    group its batches until their means are uncorrelated, and test the totals for drift (MODEL.md §14.2); a
    spread or drift within the ``target`` relative error is no concern. A charge whose batches (``labels``, the first
    replica's regimes) still switch back and forth after that cut is intermittent: once its batches fill
    INTERMITTENT_GROUPS groups that each hold several switches, its regimes are its motion, so only its first batch,
    the start-up, is cut. One that stopped switching
    before the cut (a planetary charge that tried a pack once, turned active again and stayed a pack) is of the regime
    it stayed in."""
    every = [batch_rates(np.array(series), base) for series in cumulative]
    columns = (_totals(rates, sources, balls).T for rates in every)
    cuts, smallest = [max(mser_truncation(normalised(column)) for column in each) for each in columns], 1
    switching = Switching(tuple(labels[cuts[0] :]), base)
    whole = Switching(tuple(labels[1:]), base)
    if switching.intermittent and _groups_of_switches(whole) >= INTERMITTENT_GROUPS:
        switching, cuts, smallest = whole, [1] * len(every), whole.batches_holding_switches()
    kept = [rates[cut:] for rates, cut in zip(every, cuts)]
    grouping = uncorrelated_grouping([_totals(rates, sources, balls) for rates in kept], least, target, smallest)
    rates = np.concatenate([grouped(part, grouping.size) for part in kept])
    # The batches that fill no group are left out of the averages, so they count as transient.
    cuts = [cut + len(part) % grouping.size for cut, part in zip(cuts, kept)]
    totals = _totals(rates, sources, balls)
    first = every[0][: cuts[0], :sources].sum(axis=1)
    return Settled(
        rates=rates,
        checked=np.column_stack([totals, rates[:, : sources + balls]]),
        cuts=cuts,
        base=base,
        grouping=grouping,
        drifting=grouping.uncorrelated and any(drifts(column, target) for column in totals.T),
        transient_heat_power=_mean(first),
        switching=switching,
        switches_before=Switching(tuple(labels[1 : cuts[0]]), base).switches,
    )


def _groups_of_switches(switching: Switching) -> int:
    """How many groups that each hold several switches (a power of two batches, as grouped) the batches fill."""
    return len(switching.labels) // power_of_two_at_least(switching.batches_holding_switches())


def _longer_window_hint(settled: Settled | None, t: float, target: float, limit_name: str) -> str:
    """Where averaging_max_time cut short batches that were uncorrelated and steady but too few, how much mechanics
    would reach ``target``: a standard error falls as one over the root of the window."""
    if settled is None or not settled.ready or limit_name != "averaging_max_time":
        return ""
    worst = max(relative_error(column) for column in settled.checked.T)
    if not math.isfinite(worst) or worst <= target:
        return ""
    transient = settled.cuts[0] * settled.base
    needed = transient + (t - transient) * (worst / target) ** 2
    most = bounds(limit_name).high
    if needed > most:
        return (
            f"; its largest relative error was {worst:.3g}, so about {needed:.3g} s would reach it, more than "
            f"{limit_name} allows ({most:g} s)"
        )
    return (
        f"; its largest relative error was {worst:.3g}, so about {needed:.3g} s would reach it: allowed "
        f"{limit_name} >= {math.ceil(min(1.2 * needed, most))}"
    )


def _in_each(engines: Sequence[Replica]) -> str:
    return f" in each of {len(engines)} replicas" if len(engines) > 1 else ""


def _totals(rates: np.ndarray, sources: int, balls: int) -> np.ndarray:
    """Each batch's total heat power and its balls' mean velocity term, from rates with the columns of ``_flat``."""
    return np.column_stack([rates[:, :sources].sum(axis=1), rates[:, sources : sources + balls].mean(axis=1)])


def least_batches(params: Parameters) -> int:
    """The fewest batches :func:`measure_means` tests for convergence: twice ``averaging_min_batches``, since the
    start-up transient that MSER cuts off may take up to half of them."""
    return 2 * params.averaging_min_batches


def least_rounds(params: Parameters, replicas: int) -> int:
    """The fewest batches of each of ``replicas`` replicas before convergence is tested: :func:`least_batches`
    shared among them, but never under LEAST_BATCHES_PER_REPLICA, so that MSER can tell each one's transient."""
    return max(math.ceil(least_batches(params) / replicas), LEAST_BATCHES_PER_REPLICA)


# MSER needs a few batches of a replica to tell its transient from its settled motion.
LEAST_BATCHES_PER_REPLICA = 4


def mechanics_limit(params: Parameters) -> tuple[float, str]:
    """The longest mechanics an averaged run may take (s) and the key that sets it: ``averaging_max_time``, or the
    run's ``duration`` when shorter, since mechanics longer than the run cost more than the run at full resolution."""
    if params.duration < params.averaging_max_time:
        return params.duration, "duration"
    return params.averaging_max_time, "averaging_max_time"


def _means(
    engines: Sequence[Replica], settled: Settled, sources: int, balls: int, rounds: int, converged: bool, message: str
) -> Means:
    """The means of the settled, grouped batch rates of every replica (columns: each source's heat, each ball's
    term, each contact conductance, the dissipation). The conductances are averaged but not held to the target
    error: a pair of balls that rarely touch has a noisy one, and a small one. ``rounds``: the batches each replica
    ran. The transient and window are the first replica's, whose motion and impacts a result shows."""
    rates = settled.rates
    heat, terms, conductances = rates[:, :sources], rates[:, sources : sources + balls], rates[:, sources + balls : -1]
    total_heat, mean_terms = heat.sum(axis=1), terms.mean(axis=1)
    impacts = sum(
        len(engine.impact_columns(since=cut * settled.base)["time"]) for engine, cut in zip(engines, settled.cuts)
    )
    pooled_window = sum(rounds - cut for cut in settled.cuts) * settled.base
    averages = MechanicsAverages(
        heat_power=_mean(total_heat),
        heat_power_stderr=correlated_error(total_heat),
        dissipated_power=_mean(rates[:, -1]),
        velocity_term=_mean(mean_terms),
        velocity_term_stderr=correlated_error(mean_terms),
        transient=settled.cuts[0] * settled.base,
        window=(rounds - settled.cuts[0]) * settled.base,
        batches=len(rates),
        impact_interval=pooled_window / impacts if impacts else math.inf,
        converged=converged,
        message=message + _change(settled, _mean(total_heat), standard_error(total_heat)),
        replicas=len(engines),
        batch_length=settled.batch,
        batch_autocorrelation=settled.grouping.autocorrelation,
        transient_heat_power=settled.transient_heat_power,
        switching=settled.switching,
    )
    load = engines[0].load(*(np.array([_mean(column) for column in part.T]) for part in (heat, terms, conductances)))
    return Means(load, averages)


def correlated_error(values: np.ndarray) -> float:
    """The standard error of the mean of batch means ``values``, widened by √((1 + r₁)/(1 − r₁)) where their lag-1
    autocorrelation r₁ is positive and significant (an AR(1) memory): correlated batches, averaged because their
    spread is within the target, know their mean less well than their count says (MODEL.md §14.2)."""
    r1 = lag1_autocorrelation([values]) if values.size > 2 else 0.0
    correlated = 0.0 < r1 < 1.0 and significant_autocorrelation(r1, values.size)
    return standard_error(values) * (math.sqrt((1.0 + r1) / (1.0 - r1)) if correlated else 1.0)


def _change(settled: Settled, heat_power: float, error: float) -> str:
    """What the run says of a change of regime: a transient whose mean heat power differs from the settled one by
    more than CHANGE_SHARE and by more than DRIFT_SIGMAS standard errors lasted past the start-up
    (LEAST_BATCHES_PER_REPLICA batches) is a motion of its own, not the start from rest (MODEL.md §14.2)."""
    before, cut = settled.transient_heat_power, settled.cuts[0]
    if cut < LEAST_BATCHES_PER_REPLICA or not (math.isfinite(before) and math.isfinite(heat_power)):
        return ""
    if abs(before - heat_power) <= max(CHANGE_SHARE * abs(heat_power), DRIFT_SIGMAS * error):
        return ""
    switched = settled.switches_before
    tried = f", having switched between active and pack {switched} times before" if switched > 1 else ""
    return (
        f"; the motion changed at t = {cut * settled.base:.3g} s (heat power {before:.3g} W before, "
        f"{heat_power:.3g} W after{tried}): the averages are of the motion after the change"
    )


# The fewest groups of several switches each an intermittent charge is averaged over when its target is out of reach.
INTERMITTENT_GROUPS = 5
# A transient whose heat power differs from the settled motion's by more than this share is reported as a change.
CHANGE_SHARE = 0.1


def _nothing_moves(engine: Replica, first: Measured) -> Means:
    """The means of an empty mill (n_balls = 0): no contact heats anything, so there is nothing to average."""
    averages = MechanicsAverages(
        heat_power=0.0,
        heat_power_stderr=0.0,
        dissipated_power=0.0,
        velocity_term=math.nan,
        velocity_term_stderr=0.0,
        transient=0.0,
        window=0.0,
        batches=0,
        impact_interval=math.inf,
        converged=True,
        message="no balls: no mechanics to average",
    )
    return Means(engine.load(np.zeros_like(first.heat), np.zeros(0), np.zeros_like(first.conduction)), averages)


def _mean(values: np.ndarray) -> float:
    return float(values.mean()) if values.size else math.nan
