"""The 1-D engine's own keys (MODEL.md section 7): its integrator's tolerances, the projection of each contact's
energy, how it makes heat, and its averaged solver's target error."""

from __future__ import annotations

from typing import Literal

from shakermill.parameters.fields import choice, quantity, switch
from shakermill.parameters.key_group import KeyGroup, only_with_solver


class OneDIntegrator(KeyGroup):
    """The 1-D engine's integration with error control (MODEL.md section 7): its tolerances, the projection of each
    contact's energy and how a contact makes heat."""

    title = "the 1-D engine's integrator"

    # The method is third order: rtol 1e-8 costs ~40 times the default's steps, and the contact step limit
    # bounds the error below that anyway. Above 0.1 the error control no longer resolves a contact.
    rtol: float = quantity(
        "",
        "relative tolerance of the integrator",
        default=1e-3,
        source="MATLAB ode23 default RelTol, as used by the paper",
        ge=1e-8,
        le=0.1,
    )
    # 1e-12: far below every scale of the motion (the single-impact tests use it); the upper bounds are
    # where the tolerance would exceed the quantity itself (a ball radius, a ball's momentum, a kelvin).
    atol_position: float = quantity(
        "m",
        "absolute tolerance on the ball position",
        default=1e-6,
        source="MATLAB ode23 default AbsTol (1e-6, in SI)",
        ge=1e-12,
        le=1e-3,
    )
    atol_momentum: float = quantity(
        "kg*m/s",
        "absolute tolerance on the ball momentum",
        default=1e-6,
        source="MATLAB ode23 default AbsTol (1e-6, in SI)",
        ge=1e-12,
        le=1e-2,
    )
    atol_temperature: float = quantity(
        "K",
        "absolute tolerance on temperatures",
        default=1e-6,
        source="MATLAB ode23 default AbsTol (1e-6, in SI)",
        ge=1e-12,
        le=1.0,
    )
    energy_projection: bool = switch(
        "enforce the mechanical energy balance of each contact step by projection",
        default=True,
        source="numerical choice: projection method (Hairer, Lubich & Wanner 2006, §IV.4)",
    )
    heat_model: Literal["relative", "paper"] = choice(
        "'relative': η·c·ζ̇² (default); 'paper': η·|F_d·v| as printed",
        default="relative",
        source="MODEL.md section 3: frame-invariant dissipation c·ζ̇²",
    )


class OneDAveraging(KeyGroup):
    """The 1-D engine's target error of the averaged solver."""

    title = "the 1-D engine's averaging"
    rule = only_with_solver("averaged")

    # Any target is safe: one that is never reached ends at averaging_max_time, and the run falls back.
    averaging_rel_error: float = quantity(
        "",
        "averaged solver: target relative standard error of the averages",
        default=1e-3,
        source="numerical choice: ±0.1 % on the mean heat rate, ~0.1 K on a 100 K rise",
        gt=0,
        lt=1,
    )
