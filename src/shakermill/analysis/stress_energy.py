"""The stress-energy spectrum of a run: how the energy of its impacts is distributed, which is what process engineers
compare between mills rather than one mean speed (Kwade's stress energy and stress number; Burmeister & Kwade,
Chem. Soc. Rev. 42 (2013) 7660).

A stress event is one impact of a ball on a wall or on another ball: one of a run's impacts as MODEL.md §14.4 defines
them (analysis/impacts.py: a contact's chatter merged, touches left out), not one row of its contact records. Its
stress energy is the energy the contact dissipated over that impact (J), the DEM practice the review describes for
the energy available to stress the powder caught between the surfaces. It has a normal part, from the damping of
the normal force, and a tangential part, from tangential damping, sliding and rolling resistance (MODEL.md §12.4);
the 1-D engine's impacts are head-on, all normal. A ball's kinetic energy before an impact bounds the normal part
from above; it is not what is reported.

Beside it, the stress energy as Kwade's group defines it: the relative normal kinetic energy of the colliding pair at
first touch, ½·m*·v_n², with m* = m_i·m_j/(m_i + m_j) for two balls and the ball's own mass on the vial (Burmeister &
Kwade 2013; read as the review summarises it, not re-derived from its sources). It is the ``kinetic`` component: what
an impact brings, of which the dissipated energy is the part the contact turned into heat (1 − e² of it, head-on).

A contact that lasts (a ball rolling or sliding on the wall under a planetary jar's centrifugal load for a good part
of a second) is recorded too, with all it dissipated while it lasted, and only once it ends: it is no stress event but
a steady grinding, and it would put joules into the spectrum's tail. A contact longer than
:data:`~shakermill.analysis.impacts.LASTING_CONTACT_S` is left out of the spectrum, and the power of the lasting
contacts is the run's dissipated power less that of its impacts and touches, so that a contact still running when the
records end counts too.

Beside the percentiles by count, the energy-weighted ones: the stress energy below which impacts carrying half (90 %)
of the impacts' energy lie. Many small impacts pull the median by count down; the weighted median says which impacts
bring the energy.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Annotated

import numpy as np
from numpy.typing import ArrayLike
from pydantic import Field

from shakermill.analysis.impacts import Contacts
from shakermill.analysis.sections import Joules, Key, PerSecond, Seconds, Section, Watts

# The energy dissipated per impact (total, its normal and tangential parts) and Kwade's stress energy ½·m*·v_n².
COMPONENTS = ("total", "normal", "tangential", "kinetic")
# What was hit: the vial (its end faces or, in three dimensions, its side) or another ball.
TARGETS = ("all", "wall", "ball")
# The percentiles of the stress energies the summary reports.
MEDIAN, P90 = 50.0, 90.0
# The 'dem' engine's channels that make up the tangential part (engines/dem/model.py, TOTAL_NAMES).
TANGENTIAL_CHANNELS = ("dissipated_tangential", "dissipated_sliding", "dissipated_rolling")


def threshold_name(threshold: float) -> str:
    """How a threshold (J) appears in the summary's names: 0.001 -> '0.001J', with as many digits as tell it apart
    from every other number (0.0010000001 -> '0.0010000001J'), so that distinct thresholds never share a key."""
    digits = next(digits for digits in range(6, 18) if float(f"{threshold:.{digits}g}") == threshold)
    return f"{threshold:.{digits}g}J"


class StressSection(Section):
    """The summary's keys of the stress-energy spectrum (:meth:`StressSpectrum.as_summary`; guide: planetary)."""

    stress_window_s: Seconds
    """The seconds over which the impacts were resolved (the averaged solver: its mechanics)."""
    stress_lasting_power_W: Watts
    """The power the contacts lasting over 1 ms dissipated (rolling, sliding, resting under load)."""
    stress_lasting_share: float
    """The share of the dissipated power in those lasting contacts, which no median below describes."""
    stress_lasting_contacts_hz: PerSecond
    """Contacts per second that lasted over 1 ms."""
    stress_energy_median_J: Joules
    """Median stress energy of the impacts (the energy each dissipated); NaN without impacts."""
    stress_energy_p90_J: Joules
    """90th percentile of the impacts' stress energy."""
    stress_energy_weighted_median_J: Joules
    """Energy-weighted median: the impacts below this stress energy carry half of the impacts' energy."""
    stress_energy_weighted_p90_J: Joules
    """Energy-weighted 90th percentile: the impacts below it carry 90 % of the impacts' energy."""
    stress_energy_normal_median_J: Joules
    """Median of the normal part (damping of the normal force)."""
    stress_energy_normal_p90_J: Joules
    """90th percentile of the normal part."""
    stress_energy_tangential_median_J: Joules
    """Median of the tangential part (tangential damping, sliding, rolling resistance)."""
    stress_energy_tangential_p90_J: Joules
    """90th percentile of the tangential part."""
    stress_energy_kinetic_median_J: Joules
    """Median of Kwade's stress energy ½·m*·v_n² at first touch."""
    stress_energy_kinetic_p90_J: Joules
    """90th percentile of Kwade's stress energy."""
    stress_energy_wall_median_J: Joules
    """Median stress energy of the impacts on the vial; NaN without any."""
    stress_energy_wall_p90_J: Joules
    """90th percentile of the impacts on the vial."""
    stress_energy_ball_median_J: Joules
    """Median stress energy of the impacts between balls; NaN without any."""
    stress_energy_ball_p90_J: Joules
    """90th percentile of the impacts between balls."""
    stress_events_above_hz: Annotated[dict[str, PerSecond], Key("stress_events_above_{threshold}_hz")] = Field(
        default_factory=dict
    )
    """Impacts per second at or above each threshold of ``stress_energy_thresholds``, by the threshold's name
    (``0.001J``)."""
    stress_power_above_W: Annotated[dict[str, Watts], Key("stress_power_above_{threshold}_W")] = Field(
        default_factory=dict
    )
    """The power of those impacts, by threshold."""


@dataclass(frozen=True)
class StressSpectrum:
    """The stress energies of the contacts over ``window`` seconds: each one's normal, tangential and total energy (J),
    whether it hit the vial or another ball, whether it lasted, and whether it was a touch (MODEL.md §14.4)."""

    energies: Mapping[str, np.ndarray]
    hit_ball: np.ndarray
    lasting: np.ndarray
    touch: np.ndarray
    window: float
    thresholds: tuple[float, ...] = ()
    dissipated_power: float = math.nan  # W: all the contacts dissipated over the window, recorded or not

    def of(self, component: str = "total", target: str = "all") -> np.ndarray:
        """The stress energies (J) of ``component`` of the impacts (the contacts that were no touch and did not last) on
        ``target`` (:data:`COMPONENTS`, :data:`TARGETS`)."""
        chosen = ~self.lasting & ~self.touch
        if target != "all":
            chosen &= self.hit_ball if target == "ball" else ~self.hit_ball
        return self.energies[component][chosen]

    def lasting_power(self) -> float:
        """The energy per second (W) the lasting contacts dissipated, rolling, sliding and resting under load: the
        dissipated power less the impacts' and the touches' (those recorded, without a dissipated power)."""
        if math.isfinite(self.dissipated_power):
            brief = ~self.lasting & self.touch
            return self.dissipated_power - self.power() - self._per_second(float(self.energies["total"][brief].sum()))
        return self._per_second(float(self.energies["total"][self.lasting].sum()))

    def lasting_share(self) -> float:
        """The share of the dissipated power that the lasting contacts took, left out of the spectrum (NaN without a
        dissipated power): a median over impacts describes only the rest."""
        if not (math.isfinite(self.dissipated_power) and self.dissipated_power > 0):
            return math.nan
        return self.lasting_power() / self.dissipated_power

    def lasting_per_second(self) -> float:
        """Contacts per second (1/s) that lasted, among those recorded."""
        return self._per_second(float(np.count_nonzero(self.lasting)))

    def _per_second(self, amount: float) -> float:
        return amount / self.window if self.window > 0 else math.nan

    def percentile(self, q: float, component: str = "total", target: str = "all") -> float:
        """The ``q``-th percentile (J) of :meth:`of`; NaN without impacts."""
        energies = self.of(component, target)
        return float(np.percentile(energies, q)) if energies.size else math.nan

    def weighted_percentile(self, q: float, component: str = "total") -> float:
        """The stress energy (J) below which the impacts carry ``q`` % of the impacts' energy of ``component``; NaN
        without impacts or energy."""
        energies = np.sort(self.of(component))
        carried = np.cumsum(energies)
        if not energies.size or carried[-1] <= 0:
            return math.nan
        return float(energies[np.searchsorted(carried, q / 100.0 * carried[-1])])

    def events_per_second(self, above: float = 0.0, component: str = "total", target: str = "all") -> float:
        """Stress events per second (1/s) of at least ``above`` J: Kwade's stress frequency above an energy."""
        return self._per_second(float(np.count_nonzero(self.of(component, target) >= above)))

    def power(self, above: float = 0.0, component: str = "total", target: str = "all") -> float:
        """The energy per second (W) of the stress events of at least ``above`` J."""
        energies = self.of(component, target)
        return self._per_second(float(energies[energies >= above].sum()))

    def as_summary(self) -> StressSection:
        """The summary's section: the median and 90th percentile of the total, of each part and for each target, and
        per threshold the events per second and their power."""
        return StressSection(
            stress_window_s=self.window,
            stress_lasting_power_W=self.lasting_power(),
            stress_lasting_share=self.lasting_share(),
            stress_lasting_contacts_hz=self.lasting_per_second(),
            stress_energy_median_J=self.percentile(MEDIAN),
            stress_energy_p90_J=self.percentile(P90),
            stress_energy_weighted_median_J=self.weighted_percentile(MEDIAN),
            stress_energy_weighted_p90_J=self.weighted_percentile(P90),
            stress_energy_normal_median_J=self.percentile(MEDIAN, "normal"),
            stress_energy_normal_p90_J=self.percentile(P90, "normal"),
            stress_energy_tangential_median_J=self.percentile(MEDIAN, "tangential"),
            stress_energy_tangential_p90_J=self.percentile(P90, "tangential"),
            stress_energy_kinetic_median_J=self.percentile(MEDIAN, "kinetic"),
            stress_energy_kinetic_p90_J=self.percentile(P90, "kinetic"),
            stress_energy_wall_median_J=self.percentile(MEDIAN, target="wall"),
            stress_energy_wall_p90_J=self.percentile(P90, target="wall"),
            stress_energy_ball_median_J=self.percentile(MEDIAN, target="ball"),
            stress_energy_ball_p90_J=self.percentile(P90, target="ball"),
            stress_events_above_hz={threshold_name(above): self.events_per_second(above) for above in self.thresholds},
            stress_power_above_W={threshold_name(above): self.power(above) for above in self.thresholds},
        )


def collision_energy(impacts: Mapping[str, ArrayLike], masses: Sequence[float]) -> np.ndarray:
    """Kwade's stress energy of each impact (J): ½·m*·v_n² of the pair at first touch, m* the reduced mass of two balls
    (``other_ball`` ≥ 0) or the ball's mass on the vial; ``masses`` (kg) by ball index (a one-ball engine has no
    ``ball`` column: ball 0)."""
    speed = np.asarray(impacts["impact_speed"], dtype=float)
    mass = np.asarray(masses, dtype=float)
    ball = np.asarray(impacts["ball"], dtype=np.int64) if "ball" in impacts else np.zeros(speed.size, dtype=np.int64)
    other = np.asarray(impacts["other_ball"], dtype=np.int64) if "other_ball" in impacts else np.full(speed.size, -1)
    on_ball = other >= 0
    m_i, m_j = mass[ball], mass[np.where(on_ball, other, ball)]
    reduced = np.where(on_ball, m_i * m_j / (m_i + m_j), m_i)
    return 0.5 * reduced * speed**2


def stress_spectrum(
    contacts: Contacts,
    window: float,
    thresholds: Sequence[float] = (),
    dissipated_power: float = math.nan,
    masses: Sequence[float] | None = None,
) -> StressSpectrum:
    """The spectrum of a run's ``contacts`` (analysis/impacts.py) over ``window`` s, in which they dissipated
    ``dissipated_power`` (W) in all; with the balls' ``masses`` (kg) also Kwade's stress energy of each impact
    (:func:`collision_energy`; NaN without them)."""
    columns = contacts.columns
    total = np.asarray(columns["dissipated_energy"], dtype=float)
    if "dissipated_normal" in columns:
        normal = np.asarray(columns["dissipated_normal"], dtype=float)
        tangential = sum(
            (np.asarray(columns[channel], dtype=float) for channel in TANGENTIAL_CHANNELS), np.zeros_like(total)
        )
    else:
        normal, tangential = total, np.zeros_like(total)
    hit_ball = np.asarray(columns["target"]) == "ball" if "target" in columns else np.zeros(total.size, dtype=bool)
    kinetic = collision_energy(columns, masses) if masses is not None else np.full(total.size, math.nan)
    energies = {"total": total, "normal": normal, "tangential": tangential, "kinetic": kinetic}
    return StressSpectrum(
        energies,
        hit_ball,
        contacts.lasting,
        contacts.touch,
        float(window),
        tuple(sorted(thresholds)),
        float(dissipated_power),
    )
