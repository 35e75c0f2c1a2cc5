"""What the powder changes (engines/thermal/powder.py): the five-ball SPEX prediction with and without a stated
charge of powder beside the experiment, and the published ordering of a planetary mill with and without powder as a
check of the model's sign.

The five-ball experiment (Takacs & McHenry 2006, as Son 2025 quotes it) does not say whether it milled powder; its
balls are predicted ~2.3 times too hot without one, and the powder is the leading untested explanation. Every value of
the powder but its heat capacity is an assumption (the preset's sources); this study runs them at their stated
values, so it says which way the powder moves the answer and by how much there, not that it explains the gap.

The planetary ordering: El-Eskandarany, *Mechanical Alloying* (2nd ed., §10.9.1.1; recalled, not re-read): a Fritsch
P5's vial at ≈ 310 K after 30 min of balls alone and ≈ 320 K with powder, from ≈ 300 K. Only its sign is checked:
the vial warmer with powder than without.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from shakermill.parameters.presets import default_parameters
from shakermill.solvers.result import Result
from shakermill.solvers.simulate import simulate
from shakermill.studies.validation.held_out import (
    FIVE_BALL_BALL_RISE_K,
    FIVE_BALL_RATIO,
    FIVE_BALL_VIAL_RISE_K,
    five_ball_parameters,
)

# The stated charge: ~10:1 by mass against five ½-inch steel balls (5 × 8.4 g), a usual ball-to-powder ratio of
# a SPEX run; iron (the preset's powder_material).
FIVE_BALL_POWDER_KG = 0.004
PLANETARY_PRESET = "pulverisette7"
# ~10:1 against pulverisette7's charge; its 30 minutes as the published measurement.
PLANETARY_POWDER_KG = 0.01
PLANETARY_SECONDS = 1800.0
PLANETARY_SOURCE = (
    "El-Eskandarany, Mechanical Alloying, 2nd ed., §10.9.1.1 (recalled, not re-read): Fritsch P5 vial ≈ 310 K after "
    "30 min of balls alone, ≈ 320 K with powder (from ≈ 300 K)"
)
PLANETARY_VIAL_RISE_K = {"without powder": 10.0, "with powder": 20.0}


NAN = float("nan")


@dataclass(frozen=True)
class PowderRow:
    """One quantity predicted without and with the powder, and what was measured without and with it (NaN where
    nothing was; the same number in both where the experiment does not say whether it milled powder)."""

    label: str
    unit: str
    without: float
    with_powder: float
    measured_without: float = NAN
    measured_with: float = NAN


@dataclass(frozen=True)
class PowderComparison:
    """A mill run without and with ``powder_kg`` of powder: rows beside what was measured, and whether the vial is
    warmer with powder (the published ordering's sign)."""

    title: str
    preset: str
    powder_kg: float
    source: str
    rows: tuple[PowderRow, ...]

    @property
    def vial_row(self) -> PowderRow:
        return next(row for row in self.rows if row.label.startswith("vial rise"))

    @property
    def vial_warmer_with_powder(self) -> bool:
        return self.vial_row.with_powder > self.vial_row.without

    def as_dict(self) -> dict[str, Any]:
        return {
            "title": self.title,
            "preset": self.preset,
            "powder_kg": self.powder_kg,
            "source": self.source,
            "vial_warmer_with_powder": self.vial_warmer_with_powder,
            "rows": [row.__dict__ for row in self.rows],
        }


def rises(result: Result) -> tuple[float, float, float]:
    """The rises (K) of the balls' mean and the vial at the end of ``result``, and the powder's (NaN without)."""
    summary = result.summary
    start = summary.initial_temperature_C
    powder = summary.further_nodes().get("powder", (NAN, None))[0]
    return summary.ball_C - start, summary.vial_C - start, powder - start


def five_balls_with_powder(overrides: Mapping[str, Any] | None = None) -> PowderComparison:
    """The held-out five-ball prediction (:func:`held_out.five_ball_parameters`) without and with
    :data:`FIVE_BALL_POWDER_KG` of powder, beside the experiment's rises."""
    without, with_powder = (
        rises(simulate(five_ball_parameters({**(overrides or {}), "powder_mass": mass})))
        for mass in (0.0, FIVE_BALL_POWDER_KG)
    )
    # The experiment does not say whether it milled powder: its numbers stand beside both predictions.
    rows = (
        PowderRow("balls' rise after 1 h", "K", without[0], with_powder[0], *(FIVE_BALL_BALL_RISE_K,) * 2),
        PowderRow("vial rise after 1 h", "K", without[1], with_powder[1], *(FIVE_BALL_VIAL_RISE_K,) * 2),
        PowderRow(
            "vial/ball rise ratio",
            "",
            without[1] / without[0],
            with_powder[1] / with_powder[0],
            *(FIVE_BALL_RATIO,) * 2,
        ),
        PowderRow("powder rise after 1 h", "K", without[2], with_powder[2]),
    )
    return PowderComparison(
        "Five SPEX balls without and with powder",
        "spex8000m-3d-calibrated",
        FIVE_BALL_POWDER_KG,
        "Takacs & McHenry 2006 (J. Mater. Sci. 41, 5246) as quoted by Son 2025, section 4 (powder not stated)",
        rows,
    )


def planetary_ordering(overrides: Mapping[str, Any] | None = None) -> PowderComparison:
    """:data:`PLANETARY_PRESET` for :data:`PLANETARY_SECONDS` without and with :data:`PLANETARY_POWDER_KG` of powder
    (averaged solver), beside the published P5's rises."""
    settings = {"solver": "averaged", "record_windows": (), "duration": PLANETARY_SECONDS, **(overrides or {})}
    without, with_powder = (
        rises(simulate(default_parameters(PLANETARY_PRESET, **settings, powder_mass=mass)))
        for mass in (0.0, PLANETARY_POWDER_KG)
    )
    minutes = f"{settings['duration'] / 60:g} min"
    rows = (
        PowderRow(f"balls' rise after {minutes}", "K", without[0], with_powder[0]),
        PowderRow(f"vial rise after {minutes}", "K", without[1], with_powder[1], *PLANETARY_VIAL_RISE_K.values()),
        PowderRow(f"powder rise after {minutes}", "K", without[2], with_powder[2]),
    )
    return PowderComparison(
        "A planetary mill without and with powder (the published ordering's sign)",
        PLANETARY_PRESET,
        PLANETARY_POWDER_KG,
        PLANETARY_SOURCE,
        rows,
    )


POWDER_STUDIES = (five_balls_with_powder, planetary_ordering)
# The steps :func:`powder_studies` counts for a progress bar.
POWDER_STEPS = len(POWDER_STUDIES)


def powder_studies(
    overrides: Mapping[str, Any] | None = None, progress: Callable[[int, int], None] | None = None
) -> tuple[PowderComparison, ...]:
    """Both comparisons, ``progress(done, total)`` after each."""
    studies = []
    for done, study in enumerate(POWDER_STUDIES, start=1):
        studies.append(study(overrides))
        if progress is not None:
            progress(done, POWDER_STEPS)
    return tuple(studies)
