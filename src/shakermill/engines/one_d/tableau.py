"""The Runge–Kutta method of the 1-D engine as data (:class:`ButcherTableau`, its order conditions checked at
construction) and its step-size controller (:class:`StepController`): Bogacki–Shampine 3(2), the method of
MATLAB's ``ode23`` and SciPy's ``RK23``, with SciPy's RK23 constants."""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np


@dataclass(frozen=True)
class ButcherTableau:
    """An explicit, first-same-as-last embedded Runge–Kutta pair.

    ``b`` gives the propagated solution (order ``order``), ``b_hat`` the
    embedded one (order ``error_order``); their difference estimates the error.
    The order conditions up to ``order`` are checked at construction.
    """

    name: str
    order: int
    error_order: int
    a: tuple[tuple[Fraction, ...], ...]
    b: tuple[Fraction, ...]
    b_hat: tuple[Fraction, ...]
    c: tuple[Fraction, ...]

    def __post_init__(self) -> None:
        stages = len(self.c)
        if len(self.a) != stages or any(len(row) != stages for row in self.a):
            raise ValueError(f"{self.name}: a must be {stages}x{stages}")
        for i, row in enumerate(self.a):
            if any(row[j] != 0 for j in range(i, stages)):
                raise ValueError(f"{self.name}: a must be strictly lower triangular for an explicit method")
            if sum(row) != self.c[i]:
                raise ValueError(f"{self.name}: row {i} of a does not sum to c[{i}]")
        if tuple(self.a[-1]) != tuple(self.b) or self.c[-1] != 1:
            raise ValueError(f"{self.name}: not first-same-as-last (last row of a must equal b, c[-1] = 1)")
        self._check_order(self.b, self.order, "b")
        self._check_order(self.b_hat, self.error_order, "b_hat")

    def _check_order(self, weights: tuple[Fraction, ...], order: int, label: str) -> None:
        a, c = self.a, self.c
        ac = [sum(a[i][j] * c[j] for j in range(len(c))) for i in range(len(c))]
        conditions = {
            1: [(sum(weights), Fraction(1))],
            2: [(sum(w * ci for w, ci in zip(weights, c)), Fraction(1, 2))],
            3: [
                (sum(w * ci * ci for w, ci in zip(weights, c)), Fraction(1, 3)),
                (sum(w * aci for w, aci in zip(weights, ac)), Fraction(1, 6)),
            ],
        }
        if order > max(conditions):
            raise ValueError(f"{self.name}: order conditions above {max(conditions)} are not implemented")
        for level in range(1, order + 1):
            for value, expected in conditions[level]:
                if value != expected:
                    raise ValueError(f"{self.name}: {label} violates an order-{level} condition")

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(a, b, error weights b − b_hat, c) as float arrays for the compiled loop."""
        a = np.array([[float(v) for v in row] for row in self.a])
        b = np.array([float(v) for v in self.b])
        error = np.array([float(bi - bh) for bi, bh in zip(self.b, self.b_hat)])
        c = np.array([float(v) for v in self.c])
        return a, b, error, c


_F = Fraction


BOGACKI_SHAMPINE = ButcherTableau(
    name="Bogacki-Shampine 3(2)",
    order=3,
    error_order=2,
    a=(
        (_F(0), _F(0), _F(0), _F(0)),
        (_F(1, 2), _F(0), _F(0), _F(0)),
        (_F(0), _F(3, 4), _F(0), _F(0)),
        (_F(2, 9), _F(1, 3), _F(4, 9), _F(0)),
    ),
    b=(_F(2, 9), _F(1, 3), _F(4, 9), _F(0)),
    b_hat=(_F(7, 24), _F(1, 4), _F(1, 3), _F(1, 8)),
    c=(_F(0), _F(1, 2), _F(3, 4), _F(1)),
)


@dataclass(frozen=True)
class StepController:
    """Elementary error-per-step controller with SciPy's RK23 constants."""

    safety: float = 0.9
    min_factor: float = 0.2
    max_factor: float = 10.0
