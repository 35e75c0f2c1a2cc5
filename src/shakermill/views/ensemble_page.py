"""The page and the rows of an uncertainty ensemble (``shakermill uncertainty``): each headline's 5/50/95 % points
and the inputs that decide it, the regimes, and the assumed inputs with their reasons."""

from __future__ import annotations

import math
from pathlib import Path

from shakermill.studies.ensembles.ensemble import (
    ASSUMED_PART,
    LEAST_Q2,
    NOISE_PART,
    POSTERIOR_PART,
    Ensemble,
    HeadlineSpread,
)
from shakermill.support.version import __version__
from shakermill.views.html import (
    check_page_target,
    paragraph,
    section,
    table,
    write_page,
)
from shakermill.views.notebook import esc

HEADLINE_HEADERS = (
    "headline",
    "unit",
    "5 %",
    "50 %",
    "95 %",
    "surrogate Q²",
    "deciding inputs (total Sobol' index)",
    "variance: assumed; posterior; unexplained",
)
INPUT_HEADERS = ("input", "range", "distribution", "reason")
REGIME_NOTE = (
    "pack: lasting contacts (over 1 ms) take most of the dissipation and the balls hit at over 1 m/s less "
    "than once a turn each; active: otherwise (MODEL.md §14.2)."
)
NO_REGIMES = "No regimes: this engine's runs have no lasting contacts to tell a pack from an active charge."
REGIME_HEADERS = ("regime", "members", "share", "heat power (W)", "stress energy, median (J)", "balls' rise (K)")


def _value(value: float) -> str:
    return f"{value:.4g}" if math.isfinite(value) else "n/a"


def deciding_text(spread: HeadlineSpread, most: int = 3) -> str:
    if not spread.varies:
        return "none: every member gave the same value"
    if not spread.total:
        return f"not computed: the surrogate predicts held-out members with Q² < {LEAST_Q2:g}"
    return ", ".join(f"{key} {spread.total[key]:.2f}" for key in spread.deciding[:most])


def parts_text(spread: HeadlineSpread) -> str:
    """The interval's parts (MODEL.md §14.1): the assumed inputs', the fitted keys' posterior's and the unexplained
    (averaging noise, surrogate error) shares of the variance."""
    if not spread.parts:
        return "n/a"
    return "; ".join(
        f"{spread.parts[part]:.2f}" if part in spread.parts else "—"
        for part in (ASSUMED_PART, POSTERIOR_PART, NOISE_PART)
    )


def headline_rows(ensemble: Ensemble) -> list[tuple[str, ...]]:
    return [
        (
            spread.label,
            spread.unit,
            *map(_value, spread.quantiles),
            _value(spread.surrogate_q2),
            deciding_text(spread),
            parts_text(spread),
        )
        for spread in ensemble.headlines
    ]


def input_rows(ensemble: Ensemble) -> list[tuple[str, ...]]:
    rows: list[tuple[str, ...]] = [
        (item.key, item.shown_range(), item.distribution, item.reason) for item in ensemble.inputs
    ]
    if ensemble.posterior is not None:
        rows += [
            (
                name,
                f"median {fitted['median']:.4g}, σ(ln) {fitted['log_sd']:.3g}",
                "log-normal, correlated",
                "the calibration's posterior samples, as a Gaussian in the logarithms",
            )
            for name, fitted in zip(ensemble.posterior.names, ensemble.posterior.as_dict().values())
        ]
    return rows


def regime_rows(ensemble: Ensemble) -> list[tuple[str, ...]]:
    rows = []
    for name, regime in ensemble.regimes.items():
        medians = regime["medians"]
        rows.append(
            (
                name,
                str(regime["members"]),
                f"{regime['share']:.0%}",
                *(
                    _value(medians.get(key, math.nan))
                    for key in ("heat_power_W", "stress_energy_median_J", "ball_rise_K")
                ),
            )
        )
    return rows


def render_ensemble_page(ensemble: Ensemble, title: str) -> str:
    from shakermill.views.report import STYLE

    failed = f" {ensemble.failed} failed and are left out." if ensemble.failed else ""
    sections = [
        f"<h1>{esc(title)}</h1>",
        paragraph(
            f"{ensemble.members} members of a scrambled Sobol' design over {len(ensemble.inputs)} assumed inputs"
            f"{'' if ensemble.posterior is None else ' and the posterior of the fitted keys'} (MODEL.md §14.1)."
            f"{failed} The 5, 50 and 95 % points are the members'; the Sobol' indices are "
            "computed on a Gaussian-process surrogate of the members, and reported only where it predicts "
            f"members it did not see with Q² ≥ {LEAST_Q2:g}. The variance of a headline is split into the "
            "total index of the assumed inputs together and of the fitted keys' posterior together, scaled by "
            "Q², and the 1 − Q² the surrogate does not explain: the members' own averaging noise and its own "
            "error, which held-out members cannot tell apart.",
            "note",
        ),
        section("Headlines", table(HEADLINE_HEADERS, headline_rows(ensemble), numeric=(2, 3, 4, 5, 7))),
        section(
            "Regimes",
            paragraph(REGIME_NOTE),
            table(REGIME_HEADERS, regime_rows(ensemble), numeric=(1, 2, 3, 4, 5))
            if ensemble.regimes
            else paragraph(NO_REGIMES),
        ),
        section("Assumed inputs", table(INPUT_HEADERS, input_rows(ensemble))),
    ]
    return (
        '<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n'
        f"<title>{esc(title)}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n"
        + "\n".join(sections)
        + f'\n<p class="note">Written by shakermill {esc(__version__)}.</p>\n</body>\n</html>\n'
    )


def save_ensemble_page(ensemble: Ensemble, title: str, target: Path) -> Path:
    check_page_target(target)
    return write_page(target, render_ensemble_page(ensemble, title))
