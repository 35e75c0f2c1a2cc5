"""Where the balls of the 'dem' engine start: a deterministic, non-overlapping placement in the vial.

Pure geometry in the vial frame (x along the axis, z up; SI units). The balls start at rest, filled
in from the bottom of the vial, so that gravity has little to do before the drive takes over; the
same configuration always gives the same placement.
"""

from __future__ import annotations

import numpy as np

# Candidate centres lie on a grid this fine, in units of the largest radius (fine enough to find
# staggered arrangements in a narrow bore), coarsened where it would have more than MAX_CANDIDATES.
GRID_STEP = 0.2
MAX_CANDIDATES = 200_000
# Starting gaps between balls and from the walls, in units of each radius: no contact at t = 0.
CLEARANCE = 0.01


def placement(radii: np.ndarray, vial_length: float, vial_diameter: float) -> np.ndarray | None:
    """Centres (N, 3) in m of balls of ``radii``, bottom layer first (none in an empty mill), or None when they do not
    all fit."""
    if radii.size == 0:
        return np.zeros((0, 3))
    centres = packed(radii, vial_length, vial_diameter)
    return centres if len(centres) == radii.size else None


def packed(radii: np.ndarray, vial_length: float, vial_diameter: float) -> np.ndarray:
    """Centres (k, 3) in m of the first k balls of ``radii`` that fit, placed one after another until one does not.

    Each ball goes to the first free candidate whatever comes after it, so the first k balls of any longer list
    lie where k balls alone would: ``len(packed(...))`` is how many of these balls the vial takes. A placed ball
    changes only the candidates within its padded radius plus the largest padded radius of it, a box of the grid,
    so that placing thousands of balls costs thousands of small boxes, not thousands of sweeps over the grid.
    """
    step = max(GRID_STEP * float(np.max(radii)), (vial_length * vial_diameter**2 / MAX_CANDIDATES) ** (1.0 / 3.0))
    axis = _centred_grid(0.5 * vial_length, step)
    across = _centred_grid(0.5 * vial_diameter, step)
    x, y, z = np.meshgrid(axis, across, across, indexing="ij")
    candidates = np.column_stack([x.ravel(), y.ravel(), z.ravel()])
    # Bottom first, then from the vial's left end, then from its back: a stable, reproducible order.
    order = np.lexsort((candidates[:, 1], candidates[:, 0], candidates[:, 2]))
    rank = np.empty_like(order)
    rank[order] = np.arange(order.size)
    candidates = candidates[order]
    centres = np.empty((radii.size, 3))
    largest = float(np.max(radii)) * (1.0 + CLEARANCE)
    # Distance from each candidate to the nearest placed ball's surface, its clearance included, where that is
    # under the largest padded radius (elsewhere it does not matter, and it is left at its last value).
    room = np.full(len(candidates), np.inf)
    inside = {}
    for ball, radius in enumerate(radii):
        padded = radius * (1.0 + CLEARANCE)
        if padded not in inside:
            inside[padded] = _inside(candidates, padded, vial_length, vial_diameter)
        free = inside[padded] & (room >= padded)
        first = int(np.argmax(free))
        if not free[first]:
            return centres[:ball]
        centres[ball] = candidates[first]
        near = rank[_box(centres[ball], padded + largest, (axis, across, across)).ravel()]
        surface = np.linalg.norm(candidates[near] - centres[ball], axis=1) - padded
        room[near] = np.minimum(room[near], surface)
    return centres


def _box(centre: np.ndarray, reach: float, grids: tuple[np.ndarray, np.ndarray, np.ndarray]) -> np.ndarray:
    """Flat indices (in meshgrid 'ij' order) of the grid points within ``reach`` of ``centre`` along every axis."""
    ranges = [
        np.arange(np.searchsorted(grid, c - reach), np.searchsorted(grid, c + reach, side="right"))
        for grid, c in zip(grids, centre, strict=True)
    ]
    sizes = [grid.size for grid in grids]
    i, j, k = np.meshgrid(*ranges, indexing="ij")
    return (i * sizes[1] + j) * sizes[2] + k


def _centred_grid(half_extent: float, step: float) -> np.ndarray:
    count = int(half_extent // step)
    return np.arange(-count, count + 1) * step


def _inside(points: np.ndarray, radius: float, vial_length: float, vial_diameter: float) -> np.ndarray:
    """Whether a ball of ``radius`` centred at each point lies inside the vial."""
    axial = np.abs(points[:, 0]) <= 0.5 * vial_length - radius
    radial = np.hypot(points[:, 1], points[:, 2]) <= 0.5 * vial_diameter - radius
    return axial & radial
