"""Three-vector arithmetic for the compiled stepping, in place and without temporary arrays."""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def dot(a: np.ndarray, b: np.ndarray) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit(cache=True)
def cross_into(a: np.ndarray, b: np.ndarray, out: np.ndarray) -> None:
    x = a[1] * b[2] - a[2] * b[1]
    y = a[2] * b[0] - a[0] * b[2]
    z = a[0] * b[1] - a[1] * b[0]
    out[0], out[1], out[2] = x, y, z


@njit(cache=True)
def norm(a: np.ndarray) -> float:
    return math.sqrt(dot(a, a))


@njit(cache=True)
def scaled_into(a: np.ndarray, scale: float, out: np.ndarray) -> None:
    """out = scale·a, without a temporary array."""
    for axis in range(3):
        out[axis] = scale * a[axis]


@njit(cache=True)
def copy_into(a: np.ndarray, out: np.ndarray) -> None:
    """out = a, without the overlap test of a slice assignment."""
    for axis in range(3):
        out[axis] = a[axis]


@njit(cache=True)
def difference_into(a: np.ndarray, b: np.ndarray, out: np.ndarray) -> None:
    for axis in range(3):
        out[axis] = a[axis] - b[axis]


@njit(cache=True)
def squared_distance(a: np.ndarray, b: np.ndarray) -> float:
    dx, dy, dz = a[0] - b[0], a[1] - b[1], a[2] - b[2]
    return dx * dx + dy * dy + dz * dz


@njit(cache=True)
def distance(a: np.ndarray, b: np.ndarray) -> float:
    return math.sqrt(squared_distance(a, b))
