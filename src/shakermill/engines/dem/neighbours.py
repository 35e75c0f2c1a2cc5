"""The neighbour list of the 'dem' engine, compiled: the pairs of balls near enough to touch before it is next built
(``model.Neighbours``), found through a grid of cubic cells in O(N), so that a step's contact search grows with
the number of balls and not with its square. Knows positions and radii only; the contacts that the pairs carry
move to their new entries in ``contacts.rebuild_neighbours``."""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def _cell_index(position: np.ndarray, centre: np.ndarray, k, axis: int) -> int:
    """The cell along ``axis`` of a ball at ``position`` (the grid is fixed to the lab's axes about ``centre``); a
    ball beyond the grid, which only a failed step puts there, counts in its edge cell."""
    cell = int(math.floor((position[axis] - centre[axis] + k.grid_reach) / k.cell_size))
    return min(max(cell, 0), k.cells_per_side - 1)


@njit(cache=True)
def build(k, position: np.ndarray, centre: np.ndarray, nb) -> bool:
    """List every pair of balls whose centres lie within r_i + r_j + skin (every pair for an infinite skin) and note
    each ball's centre relative to the vial's ``centre`` (m); False if the entries would exceed the list's
    capacity (``model.pair_capacity`` bounds them, so only balls far deeper in each other than a run allows can)."""
    n = k.n_balls
    side = k.cells_per_side
    nb.cell_head[:] = -1
    for i in range(n):
        cell = (_cell_index(position[i], centre, k, 0) * side + _cell_index(position[i], centre, k, 1)) * side
        cell += _cell_index(position[i], centre, k, 2)
        nb.cell_next[i] = nb.cell_head[cell]
        nb.cell_head[cell] = i
        for axis in range(3):
            nb.reference[i, axis] = position[i, axis] - centre[axis]
    capacity = nb.first_ball.size
    count = 0
    for i in range(n):
        nb.first[i] = count
        if not math.isfinite(k.skin):
            for j in range(i + 1, n):
                nb.first_ball[count], nb.second_ball[count] = i, j
                count += 1
            continue
        home = (
            _cell_index(position[i], centre, k, 0),
            _cell_index(position[i], centre, k, 1),
            _cell_index(position[i], centre, k, 2),
        )
        for x in range(max(home[0] - 1, 0), min(home[0] + 2, side)):
            for y in range(max(home[1] - 1, 0), min(home[1] + 2, side)):
                for z in range(max(home[2] - 1, 0), min(home[2] + 2, side)):
                    j = nb.cell_head[(x * side + y) * side + z]
                    while j >= 0:
                        if j > i and _within(position, i, j, k.radius[i] + k.radius[j] + k.skin):
                            if count == capacity:
                                return False
                            nb.first_ball[count], nb.second_ball[count] = i, j
                            count += 1
                        j = nb.cell_next[j]
    nb.first[n] = count
    nb.entries[0] = count
    return True


@njit(cache=True, inline="always")
def _within(position: np.ndarray, i: int, j: int, reach: float) -> bool:
    squared = 0.0
    for axis in range(3):
        gap = position[i, axis] - position[j, axis]
        squared += gap * gap
    return squared < reach * reach


@njit(cache=True, inline="always")
def moved_since_build(ball: int, position: np.ndarray, centre: np.ndarray, nb) -> float:
    """How far ``ball`` has moved relative to the vial's ``centre`` since the list was built (m). A common motion of
    every ball changes no pair's distance, so that the vial's own travel, centimetres a cycle, never forces a
    rebuild."""
    squared = 0.0
    for axis in range(3):
        moved = position[ball, axis] - centre[axis] - nb.reference[ball, axis]
        squared += moved * moved
    return math.sqrt(squared)


@njit(cache=True, inline="always")
def needs_rebuild(k, position: np.ndarray, centre: np.ndarray, nb) -> bool:
    """Whether a ball has moved a quarter of the skin since the build: the steps ahead keep every ball within half
    of it, so a pair left out stays a skin's width apart less what the two have moved."""
    if not math.isfinite(k.skin):
        return False
    for ball in range(k.n_balls):
        if moved_since_build(ball, position, centre, nb) > 0.25 * k.skin:
            return True
    return False


@njit(cache=True)
def entry_of(nb, i: int, j: int) -> int:
    """The entry of the pair (i, j), i < j, or −1 if the list does not hold it."""
    for entry in range(nb.first[i], nb.first[i + 1]):
        if nb.second_ball[entry] == j:
            return entry
    return -1
