"""An answer over its assumed inputs (MODEL.md §14.1, issue 36): a quasi-random ensemble, its 5/50/95 % points,
the variance-based sensitivity of each headline, and the motion regimes its members fell into.

The members are a scrambled Sobol' design (``scipy.stats.qmc``) over the assumed inputs' ranges, each mapped
through its distribution, run as the points of a sweep (``studies/sweeps/sweep.py``: in parallel, on the local pool or a
Dask cluster, stored one file a member, resumable, the same numbers whatever the number of workers). The
headlines' 5, 50 and 95 % points are those of the members: the design samples the inputs' distribution evenly.
Sobol' indices need far more runs than an ensemble can afford (N·(d + 2) for d inputs), so they are computed
(SALib, Saltelli's design and Jansen's estimators) on a Gaussian-process surrogate fitted to the members
(``studies.inference.surrogate``), whose own error is measured on members it did not see (k-fold cross-validation):
an index of a headline the surrogate does not predict is not reported.

A calibrated preset's fitted keys are not assumed inputs but they are uncertain: their posterior joins the design
(MODEL.md §14.1: the interval of a calibrated prediction carries the posterior of the fitted keys, the assumed inputs
not fitted, and the averaging error of the mechanics, the members' own noise). It enters as a Gaussian in the
keys' logarithms with the mean and covariance of the calibration's posterior samples
(``studies.inference.posterior.LogNormal``), drawn through independent normals ξ (log v = mean + L·ξ, L its Cholesky
factor), so that each ξ is an input of its own: "KEY (fitted)", the part of that key's spread the keys before it do
not explain.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Collection, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from shakermill.analysis.regime import ACTIVE, PACK
from shakermill.io.runs import ENSEMBLE_KIND
from shakermill.parameters.assumed import AssumedInput, keeping_moves, parse_assumption, with_derived
from shakermill.parameters.defaults import DEFAULT_SCHEDULER_TIMEOUT_S
from shakermill.parameters.engine_keys import reader_of
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.file_models import DERIVED_FROM
from shakermill.parameters.keys import Parameters
from shakermill.parameters.presets import Preset
from shakermill.solvers.summary import declared_names, family_members
from shakermill.studies.inference.design import design_seed, sobol
from shakermill.studies.inference.posterior import FITTED_SUFFIX, QUANTILES, LogNormal, Posterior
from shakermill.studies.inference.prior import Prior
from shakermill.studies.inference.surrogate import LEAST_Q2, Surrogate, fit_surrogate
from shakermill.studies.sweeps.executor import ProgressCallback
from shakermill.studies.sweeps.sweep import sweep

# The headlines an ensemble reports: summary key -> (what it is, unit). Rises are computed from the end and
# steady temperatures and the run's starting temperature.
HEADLINES: dict[str, tuple[str, str]] = {
    "ball_rise_K": ("balls' mean rise at the end", "K"),
    "vial_rise_K": ("vial's rise at the end", "K"),
    "air_rise_K": ("air's rise at the end", "K"),
    "ball_steady_rise_K": ("balls' mean rise at steady state", "K"),
    "vial_steady_rise_K": ("vial's rise at steady state", "K"),
    "heat_power_W": ("heat power", "W"),
    "impact_rate_hz": ("impact rate", "1/s"),
    "fast_impact_rate_hz": ("impacts above 1 m/s", "1/s"),
    "stress_energy_median_J": ("stress energy, median", "J"),
    "stress_energy_p90_J": ("stress energy, 90th percentile", "J"),
    "stress_lasting_share": ("share of the dissipation in lasting contacts", ""),
}
RISES = dict(
    zip(
        ("ball_rise_K", "vial_rise_K", "air_rise_K", "ball_steady_rise_K", "vial_steady_rise_K"),
        declared_names(("ball_C", "vial_C", "air_C", "ball_steady_C", "vial_steady_C")),
        strict=True,
    )
)
# The sweep table's columns read here besides: summary keys, their names checked against solvers/summary.py.
START, REGIME = declared_names(("initial_temperature_C", "charge_regime"))
# The powers above each stress-energy threshold: a family of summary keys, one per threshold.
POWER_ABOVE = "stress_power_above_{threshold}_W"
# The surrogate's folds of cross-validation (its indices are not reported below LEAST_Q2).
FOLDS = 5
# A headline whose members spread less than this share of its size does not depend on the inputs: a part in a
# million is the integrators' tolerance, not a sensitivity.
STEADY_SPREAD = 1e-6
# The headlines that are shares of a whole (a fraction of the dissipation): their size is 1, not their members'.
SHARE_SUFFIX = "_share"
# Base samples of Saltelli's design on the surrogate: N·(d + 2) predictions.
SALTELLI_BASE = 1024
# The fewest members (a power of two) and the most.
LEAST_MEMBERS, MOST_MEMBERS = 8, 4096


@dataclass(frozen=True)
class HeadlineSpread:
    """One headline over the ensemble: its quantiles, and its Sobol' indices per input where the surrogate
    predicts it (``surrogate_q2`` ≥ LEAST_Q2)."""

    key: str
    label: str
    unit: str
    quantiles: tuple[float, float, float]
    surrogate_q2: float
    first: Mapping[str, float] = field(default_factory=dict)
    total: Mapping[str, float] = field(default_factory=dict)
    # False where every member gave the same value (to round-off): no input decides it.
    varies: bool = True
    # The interval's parts (MODEL.md §14.1): the total Sobol' index of the assumed inputs together and of the
    # fitted keys' posterior together, as shares of the variance the surrogate explains (Q²), and the share it does
    # not: the members' own averaging noise and the surrogate's error, which held-out members cannot tell apart.
    parts: Mapping[str, float] = field(default_factory=dict)

    @property
    def deciding(self) -> list[str]:
        """The inputs by total Sobol' index, largest first (none without a surrogate that predicts)."""
        return sorted(self.total, key=lambda key: -self.total[key])

    def as_dict(self) -> dict[str, Any]:
        return {
            "label": self.label,
            "unit": self.unit,
            **dict(zip(("p5", "p50", "p95"), self.quantiles)),
            "surrogate_q2": self.surrogate_q2,
            "sobol_first": dict(self.first),
            "sobol_total": dict(self.total),
            "deciding": self.deciding[:3],
            "varies": self.varies,
            "parts": dict(self.parts),
        }


@dataclass(frozen=True)
class Ensemble:
    """What an ensemble found: its inputs, members, headlines, regimes and the folder that holds its members."""

    inputs: tuple[AssumedInput, ...]
    posterior: LogNormal | None
    members: int
    failed: int
    headlines: tuple[HeadlineSpread, ...]
    regimes: Mapping[str, Mapping[str, Any]]
    folder: Path
    table: pd.DataFrame = field(repr=False)

    def headline(self, key: str) -> HeadlineSpread:
        return next(spread for spread in self.headlines if spread.key == key)

    def as_dict(self) -> dict[str, Any]:
        """Everything as plain JSON: a number that is not finite (a quantile of no member, an unmeasured Q²) is null."""
        return _finite(
            {
                "members": self.members,
                "failed": self.failed,
                "inputs": [{"key": item.key, **item.table()} for item in self.inputs],
                "fitted": None if self.posterior is None else self.posterior.as_dict(),
                "headlines": {spread.key: spread.as_dict() for spread in self.headlines},
                "regimes": {name: dict(regime) for name, regime in self.regimes.items()},
                "folder": str(self.folder),
            }
        )


def _finite(value: Any) -> Any:
    if isinstance(value, dict):
        return {key: _finite(item) for key, item in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite(item) for item in value]
    return None if isinstance(value, float) and not math.isfinite(value) else value


def ensemble_inputs(
    preset: Preset, params: Parameters, assume: Sequence[str], vary: Sequence[str], explicit: Collection[str] = ()
) -> tuple[list[AssumedInput], LogNormal | None, list[str]]:
    """What an ensemble of ``params`` varies, and notes for the user: the assumed inputs ``preset`` states that the
    run reads, replaced or joined by the user's ranges (``assume``: ``KEY=LOW:HIGH[:DIST]``), only those named in
    ``vary`` where it names some; and, varying all, the posterior of the keys the preset's calibration fitted
    (:func:`fitted_keys_posterior`; ``explicit``: the keys the user set)."""
    reader = reader_of(params)
    stated = {key: item for key, item in preset.assumed.items() if reader.not_read(key) is None}
    users = [keeping_moves(parse_assumption(text, reader), stated) for text in assume]
    inputs = {**stated, **{item.key: item for item in users}}
    unfelt = [key for key in preset.assumed if key not in stated]
    notes = (
        [f"not varied, as this run does not read them: the preset's ranges of {', '.join(unfelt)}"] if unfelt else []
    )
    missing = [key for key in vary if key not in inputs]
    if missing:
        raise ParameterError(
            f"--vary {missing[0]}: no range is stated for it; give one with --assume "
            f"{missing[0]}=LOW:HIGH (stated: {', '.join(inputs) or 'none'})"
        )
    chosen = [inputs[key] for key in dict.fromkeys(vary)] if vary else list(inputs.values())
    _check_none_derived(chosen)
    if vary:
        return chosen, None, []
    posterior, fitted_notes = fitted_keys_posterior(preset, params, explicit)
    return chosen, posterior, notes + fitted_notes


def _check_none_derived(inputs: Sequence[AssumedInput]) -> None:
    """No input varies on its own where another's range moves it (a member's bowl derives it again)."""
    for item in inputs:
        mover = next((other for other in inputs if item.key in other.moves), None)
        if mover is not None:
            raise ParameterError(
                f"{item.key}: its value is derived from {DERIVED_FROM[item.key]}, which the range of {mover.key} "
                f"moves; it takes no range of its own here: vary {mover.key}, or {item.key} alone with --vary"
            )


def fitted_keys_posterior(
    preset: Preset, params: Parameters, explicit: Collection[str] = ()
) -> tuple[LogNormal | None, list[str]]:
    """The posterior of the keys ``preset``'s calibration fitted, as an ensemble draws it, and notes for the user: a
    key the user sets (``explicit``), or the run changes, keeps the run's value (it asks about that value, not the
    calibration's), and the other fitted keys are drawn from their marginal posterior. A calibration that recorded
    no samples gives its covariance about the fitted values."""
    recorded = _recorded_posterior(preset)
    if recorded is None:
        return None, []
    pinned = [key for key in preset.fitted if key in explicit or getattr(params, key) != preset.values[key].value]
    drawn = [key for key in preset.fitted if key not in pinned]
    notes = []
    if preset.posterior is None:
        notes.append(
            f"the calibration of {preset.name} recorded no posterior samples: its fitted keys are drawn from its "
            "covariance (covariance_log), a Gaussian in their logarithms about the fitted values"
        )
    if pinned:
        rest = f"{', '.join(drawn)} drawn from their marginal posterior" if drawn else "no fitted key is drawn"
        notes.append(
            f"{', '.join(pinned)}: the run's own value, not drawn from the posterior of {preset.name}'s "
            f"calibration; {rest}"
        )
    return (recorded.marginal(drawn) if drawn else None), notes


def _recorded_posterior(preset: Preset) -> LogNormal | None:
    """The posterior a calibrated ``preset`` records: its samples' mean and covariance, or else its covariance."""
    if not preset.fitted:
        return None
    if preset.posterior is not None:
        return Posterior.of_logarithms(preset.fitted, preset.posterior).log_normal()
    if preset.covariance is None:
        return None
    values = [float(preset.values[key].value) for key in preset.fitted]
    try:
        return LogNormal.of_covariance(preset.fitted, values, preset.covariance)
    except ValueError as exc:
        raise ParameterError(f"{preset.name}: [provenance] covariance_log: {exc}") from None


def design(
    inputs: Sequence[AssumedInput], members: int, seed: int, posterior: LogNormal | None = None
) -> list[dict[str, float]]:
    """``members`` points (a power of two) of a scrambled Sobol' design over ``inputs`` and the ``posterior``'s
    normals, each value drawn through its input's distribution."""
    fitted = () if posterior is None else posterior.keys
    unit = sobol(len(inputs) + len(fitted), members, seed)
    values = Prior(tuple(inputs)).values(unit[:, : len(inputs)])
    if posterior is not None:
        values = np.column_stack([values, posterior.values(unit[:, len(inputs) :])])
    keys = [item.key for item in inputs] + list(fitted)
    return [{key: float(value) for key, value in zip(keys, row)} for row in values]


def check_members(members: int) -> None:
    if members < LEAST_MEMBERS or members > MOST_MEMBERS or members & (members - 1):
        raise ParameterError(
            f"members: {members} is not allowed; a power of two in [{LEAST_MEMBERS}, {MOST_MEMBERS}]"
            " (a Sobol' design is balanced at powers of two)"
        )


def run_ensemble(
    base: Parameters,
    inputs: Sequence[AssumedInput],
    out_dir: Path | str,
    members: int,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: ProgressCallback | None = None,
    *,
    preset: str,
    posterior: LogNormal | None = None,
    announce: Callable[[str], None] | None = None,
    on_start: Callable[[], None] | None = None,
    scheduler_timeout: float = DEFAULT_SCHEDULER_TIMEOUT_S,
) -> Ensemble:
    """Run ``base`` at ``members`` points of a Sobol' design over ``inputs`` and the fitted keys' ``posterior`` (a
    sweep stored in ``out_dir``, resumed where an earlier run of the same ensemble stopped) and analyse the members
    (:func:`analyse`). ``announce`` is told what runs and when the members are being analysed, which takes a while
    (a surrogate cross-validated for each headline); ``on_start`` is told with the first, once every check of the
    folder and the workers has passed. ``scheduler_timeout`` bounds each wait for the ``scheduler``."""
    check_members(members)
    if not inputs and posterior is None:
        raise ParameterError(
            "assumed inputs: none to vary; the preset states none that this run reads, give some "
            "with --assume KEY=LOW:HIGH"
        )
    seed = design_seed(base, inputs) + (0 if posterior is None else 1)
    points = [with_derived(base, inputs, point) for point in design(inputs, members, seed, posterior)]
    say = announce or (lambda _: None)
    fitted = "" if posterior is None else f" and the posterior of {', '.join(posterior.keys)}"
    over = f"{members} members over {', '.join(item.key for item in inputs) or 'no assumed input'}{fitted}"
    table = sweep(
        base,
        points,
        out_dir,
        workers=workers,
        scheduler=scheduler,
        scheduler_timeout=scheduler_timeout,
        progress=progress,
        preset=preset,
        kind=ENSEMBLE_KIND,
        announce=announce,
        on_start=lambda: _started(say, over, on_start),
    )
    say("analysing the members: a surrogate and Sobol' indices for each headline")
    return analyse(table, inputs, Path(out_dir), posterior)


def _started(say: Callable[[str], None], over: str, on_start: Callable[[], None] | None) -> None:
    if on_start is not None:
        on_start()
    say(over)


def analyse(
    table: pd.DataFrame, inputs: Sequence[AssumedInput], folder: Path, posterior: LogNormal | None = None
) -> Ensemble:
    """The quantiles, Sobol' indices and regimes of an ensemble's members (the sweep ``table``)."""
    finished = table[table["error"].isna()].copy() if "error" in table else table.copy()
    for rise, end in RISES.items():
        if end in finished:
            finished[rise] = finished[end] - finished[START]
    keys = [key for key in (*HEADLINES, *sorted(family_members(finished, POWER_ABOVE))) if key in finished]
    unit = Prior(tuple(inputs)).unit(finished[[item.key for item in inputs]].to_numpy(dtype=float))
    names = [item.key for item in inputs]
    if posterior is not None:
        unit = np.column_stack([unit, posterior.unit(finished[list(posterior.keys)].to_numpy(dtype=float))])
        names += posterior.names
    headlines = tuple(_spread(key, finished[key].to_numpy(dtype=float), unit, names) for key in keys)
    return Ensemble(
        tuple(inputs),
        posterior,
        len(table),
        len(table) - len(finished),
        headlines,
        _regimes(finished, keys),
        folder,
        finished,
    )


def _spread(key: str, values: np.ndarray, unit: np.ndarray, names: Sequence[str]) -> HeadlineSpread:
    label, symbol = HEADLINES[key] if key in HEADLINES else (_power_label(key), "W")
    good = np.isfinite(values)
    low, middle, high = (float(q) for q in np.quantile(values[good], QUANTILES)) if good.any() else (math.nan,) * 3
    quantiles = (low, middle, high)
    varies = bool(good.any()) and np.ptp(values[good]) > STEADY_SPREAD * _size(key, values[good])
    if not varies:
        return HeadlineSpread(key, label, symbol, quantiles, math.nan, varies=False)
    q2, first, total, parts = _sensitivity(unit[good], values[good], names)
    return HeadlineSpread(key, label, symbol, quantiles, q2, first, total, parts=parts)


def _size(key: str, values: np.ndarray) -> float:
    """What a headline's spread is measured against: a share's whole, else its members' largest value. A share zero
    to round-off is no share at all, however its round-off spreads."""
    return 1.0 if key.endswith(SHARE_SUFFIX) else float(np.max(np.abs(values)))


def _power_label(key: str) -> str:
    return f"power in impacts above {family_members([key], POWER_ABOVE)[key]}"


ASSUMED_PART, POSTERIOR_PART, NOISE_PART = "assumed inputs", "fitted keys' posterior", "unexplained"


def _sensitivity(
    unit: np.ndarray, values: np.ndarray, names: Sequence[str]
) -> tuple[float, dict[str, float], dict[str, float], dict[str, float]]:
    """The surrogate's cross-validated Q² and, where it reaches LEAST_Q2, the first and total Sobol' indices of
    each input computed on it, and the interval's parts (:attr:`HeadlineSpread.parts`)."""
    if len(values) < FOLDS:
        return math.nan, {}, {}, {}
    surrogate = fit_surrogate(unit, values, FOLDS, least_q2=LEAST_Q2)
    q2 = surrogate.q2
    if surrogate.model is None:
        return q2, {}, {}, {}
    first, total = _sobol(surrogate, list(names))
    groups = [POSTERIOR_PART if name.endswith(FITTED_SUFFIX) else ASSUMED_PART for name in names]
    by_group = _sobol(surrogate, list(names), groups)[1] if len(set(groups)) > 1 else {groups[0]: 1.0}
    parts = {group: q2 * share for group, share in by_group.items()} | {NOISE_PART: 1.0 - q2}
    return q2, first, total, parts


def _sobol(
    surrogate: Surrogate, names: list[str], groups: list[str] | None = None
) -> tuple[dict[str, float], dict[str, float]]:
    """First and total Sobol' indices (SALib: Saltelli's design, Jansen's estimators) of the ``surrogate``'s mean over
    the unit cube of ``names``, of each input or, with ``groups``, of each group of them."""
    from SALib.analyze import sobol as sobol_analyse
    from SALib.sample import sobol as sobol_sample

    problem: dict[str, Any] = {"num_vars": len(names), "names": names, "bounds": [[0.0, 1.0]] * len(names)}
    if groups is not None:
        problem["groups"] = groups
    samples = sobol_sample.sample(problem, SALTELLI_BASE, calc_second_order=False, seed=1)
    indices = sobol_analyse.analyze(problem, surrogate.mean(samples), calc_second_order=False, seed=1)
    labels = list(dict.fromkeys(groups)) if groups is not None else names
    return dict(zip(labels, map(float, indices["S1"]))), dict(zip(labels, map(float, indices["ST"])))


def _regimes(finished: pd.DataFrame, keys: Sequence[str]) -> dict[str, dict[str, Any]]:
    """Each regime's share of the members, as their summaries name it (``charge_regime``: an engine of several
    balls), and its headlines' medians (MODEL.md §14.2)."""
    if finished.empty or REGIME not in finished:
        return {}
    named = finished[REGIME].to_numpy()
    regimes = {}
    for name in (ACTIVE, PACK):
        members = named == name
        if members.any():
            chosen = finished[members]
            regimes[name] = {
                "share": float(members.mean()),
                "members": int(members.sum()),
                "medians": {key: float(chosen[key].median()) for key in keys},
            }
    return regimes
