"""Is what is counted converged with the step? Impacts as MODEL.md §14.4 defines them against the contact records
(issue 50, point 2).

Each case runs ``--replicas`` replicas of ``pulverisette7`` (its start with every ball kicked by a few mm/s in a seeded
direction, as the averaged solver's replicas start) at full resolution, at the default steps and with every step
halved (``contact_step_fraction``, ``enduring_step_fraction``, ``max_flight_step``), and compares over each replica's
settled second half: the impact rate, the rate above 1 m/s, the lasting contacts, and the stress energy's median,
90th percentile and energy-weighted median; beside them the contact records a second, which follow the step. A
charge's motion is chaotic: halving the step changes its trajectory as much as a kick of its start does, so one
trajectory against another says nothing, and the statistical error of a figure is its spread over the replicas in
the case's regime (rates: their standard error; percentiles: a bootstrap over those replicas, their impacts pooled).
Each change is given in units of the two settings' errors combined (σ): within 1σ is "less than its statistical
error"; of six figures compared, about two beyond 1σ (and rarely one beyond 2σ) is what chance alone gives.

Cases: ``pack``, friction 0.3 (a pack from ~0.3 s on for the configured start; some kicked starts stay active), and
``active``, friction 0.5 (active for its first ~5 s); each keeps the replicas whose settled half is in its regime. The
intermittent charge of friction 0.5 switches every few seconds and needs tens of simulated seconds a replica: not
measured here (issue 50).

Part ``--averaged``: the averaged run of ``pulverisette7`` at friction 0.5 as shipped, which switches between active
and pack before it settles: its status, regime, message and the lag-1 autocorrelation of the batches it used.

    .venv/bin/python benchmarks/bench_impact_counts.py                   # both cases, 6 replicas each (~6 CPU-min)
    .venv/bin/python benchmarks/bench_impact_counts.py --cases pack --replicas 12 --duration 3
    .venv/bin/python benchmarks/bench_impact_counts.py --cases "" --averaged   # ~4 CPU-min
"""

from __future__ import annotations

import argparse
import math
import resource

import numpy as np

import shakermill as sm
from shakermill.analysis.impacts import Contacts
from shakermill.engines.budget import RunBudget
from shakermill.engines.dem.engine import DemEngine
from shakermill.solvers.driver import run_until, sample_times, stop_message
from shakermill.solvers.full import concluded

CASES = {"pack": ({"friction": 0.3}, "pack"), "active": ({"friction": 0.5}, "active")}
SEED = 50


def cpu_seconds() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def replica_run(case: str, halved: bool, replica: int, duration: float) -> sm.Result:
    """One replica of the case at full resolution (replica 0: the configured start)."""
    params = sm.default_parameters(
        "pulverisette7", engine="dem", solver="full", duration=duration, record_windows=(), **CASES[case][0]
    )
    if halved:
        params = params.replace(
            contact_step_fraction=params.contact_step_fraction / 2,
            enduring_step_fraction=params.enduring_step_fraction / 2,
            max_flight_step=params.max_flight_step / 2,
        )
    engine = DemEngine(params, RunBudget.of(params), sample_times(params), params.duration, replica=replica)
    status = run_until(engine, params.duration, None)
    return concluded(engine, status, stop_message(engine, status), 0.0)


def energy_figures(energies: np.ndarray) -> dict[str, float]:
    """The stress energy's median, 90th percentile and energy-weighted median (mJ) of ``energies`` (J)."""
    energies = np.sort(energies)
    if not energies.size:
        return dict.fromkeys(ENERGY_FIGURES, math.nan)
    carried = np.cumsum(energies)
    weighted = energies[np.searchsorted(carried, 0.5 * carried[-1])] if carried[-1] > 0 else math.nan
    return dict(zip(ENERGY_FIGURES, 1e3 * np.array([np.median(energies), np.percentile(energies, 90), weighted])))


ENERGY_FIGURES = ("median stress energy mJ", "p90 stress energy mJ", "weighted median mJ")


def measures(contacts: Contacts, records: np.ndarray, start: float, length: float) -> dict[str, float]:
    """The counted figures of the contacts that began in [start, start + length): rates a second, and the stress
    energies of the impacts that did not last."""
    time = contacts.columns["time"]
    chosen = (time >= start) & (time < start + length)
    impact = chosen & ~contacts.touch
    return {
        "impacts /s": np.count_nonzero(impact) / length,
        "impacts >= 1 m/s /s": np.count_nonzero(impact & (contacts.columns["impact_speed"] >= 1.0)) / length,
        "lasting contacts /s": np.count_nonzero(chosen & contacts.lasting) / length,
        "contact records /s": np.count_nonzero((records >= start) & (records < start + length)) / length,
        **energy_figures(contacts.columns["dissipated_energy"][impact & ~contacts.lasting]),
    }


def in_regime(
    case: str, halved: bool, replicas: int, duration: float
) -> tuple[list[dict[str, float]], list[np.ndarray], int]:
    """The settled half's measures and the stress energies of the impacts of each replica in the case's regime, and
    how many replicas ran."""
    kept, energies = [], []
    for replica in range(replicas):
        before = cpu_seconds()
        result = replica_run(case, halved, replica, duration)
        regime = result.summary.charge.regime
        print(f"  replica {replica}: {regime}, {result.counters['steps']} steps, {cpu_seconds() - before:.1f} CPU-s")
        if regime != CASES[case][1]:
            continue
        contacts = result.contacts()
        half = 0.5 * result.t_end
        kept.append(measures(contacts, result.impact_columns["time"], half, half))
        brief = ~contacts.touch & ~contacts.lasting & (contacts.columns["time"] >= half)
        energies.append(contacts.columns["dissipated_energy"][brief])
    return kept, energies, replicas


def with_errors(kept: list[dict[str, float]], energies: list[np.ndarray]) -> tuple[dict[str, float], dict[str, float]]:
    """The replicas' mean rates with their standard errors, and the pooled percentiles with a bootstrap over the
    replicas."""
    rates = [name for name in kept[0] if name.endswith("/s")]
    means = {name: float(np.mean([each[name] for each in kept])) for name in rates}
    errors = {
        name: float(np.std([each[name] for each in kept], ddof=1) / math.sqrt(len(kept))) if len(kept) > 1 else math.nan
        for name in rates
    }
    means.update(energy_figures(np.concatenate(energies)))
    if sum(each.size > 0 for each in energies) < 2:
        # One replica's impacts say nothing of how the percentiles spread between pack configurations.
        errors.update(dict.fromkeys(ENERGY_FIGURES, math.nan))
        return means, errors
    draws = np.random.default_rng(SEED).integers(0, len(kept), size=(200, len(kept)))
    samples = [energy_figures(np.concatenate([energies[index] for index in draw])) for draw in draws]
    errors.update({name: float(np.nanstd([sample[name] for sample in samples], ddof=1)) for name in ENERGY_FIGURES})
    return means, errors


def compare(case: str, replicas: int, duration: float) -> None:
    figures = []
    for halved in (False, True):
        print(f"{case}, {'halved steps' if halved else 'default steps'}:")
        kept, energies, _ = in_regime(case, halved, replicas, duration)
        if len(kept) < 2:
            print(f"  only {len(kept)} of {replicas} replicas in the {CASES[case][1]} regime: no error to compare with")
            return
        figures.append((len(kept), *with_errors(kept, energies)))
    (count, default, default_error), (count_halved, halved, halved_error) = figures
    print(
        f"\n{case}: the settled second half ({duration / 2:g} s) of {count} and {count_halved} of {replicas} replicas "
        f"in the {CASES[case][1]} regime"
    )
    print(f"{'':>26} {'default':>17} {'halved steps':>17} {'change':>10} {'change/σ':>8}")
    for name in default:
        change = halved[name] - default[name]
        combined = math.hypot(default_error[name], halved_error[name])
        sigmas = abs(change) / combined if combined > 0 else math.nan
        shown = "(step)" if name == "contact records /s" else (f"{sigmas:.2f}" if math.isfinite(sigmas) else "n/a")
        print(
            f"{name:>26} {default[name]:>9.4g} ±{default_error[name]:<6.2g} {halved[name]:>9.4g} "
            f"±{halved_error[name]:<6.2g} {change:>+10.3g} {shown:>8}"
        )
    print()


def averaged_run() -> None:
    before = cpu_seconds()
    result = sm.simulate(sm.default_parameters("pulverisette7", engine="dem", solver="averaged", friction=0.5))
    summary = result.summary
    print(f"averaged pulverisette7 at friction 0.5: status {result.status}, {cpu_seconds() - before:.0f} CPU-s")
    print(f"  {result.message}")
    if summary.charge is not None and summary.averaging is not None:
        print(
            f"  charge_regime {summary.charge.regime} from {summary.charge.regime_from_s:.3g} s; heat power "
            f"{summary.averaging.heat_power_W:.5g} ± {summary.averaging.heat_power_stderr_W:.2g} W; lag-1 "
            f"autocorrelation {summary.averaging.batch_autocorrelation:.2f} of {summary.averaging.batches} batches "
            f"of {summary.averaging.batch_s:.3g} s"
        )
    for warning in result.warnings:
        print(f"  warning: {warning}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", default=",".join(CASES), help="comma-separated: " + ", ".join(CASES))
    parser.add_argument("--replicas", type=int, default=6, help="replicas of each case and step")
    parser.add_argument("--duration", type=float, default=1.5, help="simulated seconds of each replica (s)")
    parser.add_argument("--averaged", action="store_true", help="also the averaged run at friction 0.5")
    arguments = parser.parse_args()
    cases = [case for case in arguments.cases.split(",") if case]
    unknown = [case for case in cases if case not in CASES]
    if unknown:
        parser.error(f"--cases: {unknown[0]!r} is none of {', '.join(CASES)}")
    for case in cases:
        compare(case, arguments.replicas, arguments.duration)
    if arguments.averaged:
        averaged_run()


if __name__ == "__main__":
    main()
