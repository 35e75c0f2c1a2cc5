"""What an impact is (MODEL.md §14.4): a run's contact records merged into contacts and each contact named an impact,
a touch or a lasting contact.

An engine records a contact each time two bodies begin to touch. In a pack rolling on a planetary jar's wall, balls
part and touch again within microseconds, thousands of times a second: each is a record, none is an impact, and their
number follows the step rather than the physics (benchmarks/README.md, what is counted). So records of one pair that
begin again within ``chatter_factor`` Hertz durations of the approach of the record before are one contact, its
chatter merged; a contact that begins slower than ``touch_speed`` is a touch; one that lasts over
:data:`LASTING_CONTACT_S` rolls, slides or rests. The rest are impacts. An engine whose records carry no Hertz duration
(the 1-D engine's ball, which bounces between two walls) has nothing to merge: its records are its contacts.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from shakermill.engines.records import HERTZ_SCALE

# A Hertz impact of steel balls of 5-40 mm lasts 20-600 µs from 10 m/s down to 1 mm/s (its duration grows as R·v^-1/5):
# a contact of more than a millisecond rolls, slides or rests.
LASTING_CONTACT_S = 1e-3
# Summed over a contact's records; the rest are of its first record (its approach), but the force and overlap, which
# are the largest of its records, and its duration, from its first record's start to its last one's end.
_SUMMED = ("dissipated_", "heat_", "conduction")
_LARGEST = ("peak_force", "max_overlap")


@dataclass(frozen=True)
class Contacts:
    """A run's contacts (its records merged, :func:`contacts_of`) as columns in time order: whether each is a
    ``touch`` (it began slower than the touch speed) and whether it is ``lasting``, and the number of ``records`` each
    merged. Its impacts are the contacts that are not touches, lasting or not: a ball thrown onto the wall that then
    rolls on it was an impact."""

    columns: dict[str, np.ndarray]
    touch: np.ndarray
    lasting: np.ndarray
    records: np.ndarray

    @property
    def impacts(self) -> dict[str, np.ndarray]:
        """The columns of the impacts alone."""
        return {name: values[~self.touch] for name, values in self.columns.items()}

    @property
    def impact_count(self) -> int:
        return int(np.count_nonzero(~self.touch))

    @property
    def touch_count(self) -> int:
        return int(np.count_nonzero(self.touch))

    @property
    def record_count(self) -> int:
        return int(self.records.sum())

    def since(self, start: float) -> Contacts:
        """The contacts that began at ``start`` (s) or later."""
        chosen = self.columns["time"] >= start
        return Contacts(
            {name: values[chosen] for name, values in self.columns.items()},
            self.touch[chosen],
            self.lasting[chosen],
            self.records[chosen],
        )


def contacts_of(records: Mapping[str, ArrayLike], touch_speed: float = 0.0, chatter_factor: float = 0.0) -> Contacts:
    """The contacts of an engine's contact ``records`` (its impact columns): records of one pair that begin within
    ``chatter_factor`` Hertz durations (at the approach of the record before, and at least ``touch_speed``) of the
    end of the one before merged, and each contact named (module docstring)."""
    columns = {name: np.asarray(values) for name, values in records.items()}
    size = len(next(iter(columns.values()), ()))
    if HERTZ_SCALE in columns and chatter_factor > 0 and size:
        order, first = _chains(columns, touch_speed, chatter_factor)
        merged = _merged(columns, order, first)
        records_per_contact = np.diff(np.append(first, order.size))
    else:
        merged, records_per_contact = columns, np.ones(size, dtype=np.int64)
    by_time = np.argsort(merged["time"], kind="stable") if "time" in merged else np.arange(size)
    merged = {name: values[by_time] for name, values in merged.items()}
    duration = merged["duration"].astype(float) if "duration" in merged else np.zeros(by_time.size)
    speed = merged["impact_speed"].astype(float) if "impact_speed" in merged else np.full(by_time.size, np.inf)
    return Contacts(merged, speed < touch_speed, duration > LASTING_CONTACT_S, records_per_contact[by_time])


def _chains(columns: Mapping[str, np.ndarray], touch_speed: float, chatter_factor: float) -> tuple[np.ndarray, ...]:
    """The records in pair order (``order``) and the index in it of each contact's first record (``first``)."""
    pair = _pair_codes(columns)
    starts = columns["time"].astype(float)
    order = np.lexsort((starts, pair))
    start, end = starts[order], (starts + columns["duration"])[order]
    approach = np.maximum(columns["impact_speed"][order], touch_speed)
    reach = chatter_factor * columns[HERTZ_SCALE][order] * approach**-0.2
    continues = (pair[order][1:] == pair[order][:-1]) & (start[1:] - end[:-1] <= reach[:-1])
    return order, np.flatnonzero(np.concatenate([[True], ~continues]))


def _pair_codes(columns: Mapping[str, np.ndarray]) -> np.ndarray:
    """One integer per record that names its two bodies: a ball and another ball, or a ball and a wall."""
    ball = columns["ball"].astype(np.int64)
    other = columns["other_ball"].astype(np.int64)
    walls, wall = np.unique(columns["target"], return_inverse=True)
    bodies = int(max(ball.max(initial=0), other.max(initial=0))) + 1 + walls.size
    return ball * bodies + np.where(other >= 0, other, bodies - 1 - wall.reshape(ball.shape))


def _merged(columns: Mapping[str, np.ndarray], order: np.ndarray, first: np.ndarray) -> dict[str, np.ndarray]:
    """One row per contact: its records' energies summed, their force and overlap the largest, its duration from its
    first start to its last end, the rest its first record's."""
    merged = {}
    for name, values in columns.items():
        sorted_values = values[order]
        if name.startswith(_SUMMED):
            merged[name] = np.add.reduceat(sorted_values, first)
        elif name in _LARGEST:
            merged[name] = np.maximum.reduceat(sorted_values, first)
        else:
            merged[name] = sorted_values[first]
    ends = (columns["time"] + columns["duration"])[order]
    merged["duration"] = np.maximum.reduceat(ends, first) - merged["time"]
    return merged
