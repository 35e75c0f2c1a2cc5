"""The quantities derived from a run's keys that more than one module reads (MODEL.md sections 1 and 6), as a base
class of :class:`~shakermill.parameters.keys.Parameters`: they are read as ``params.ball_mass``, but kept out of the
module that declares the keys."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from shakermill.parameters.engine_keys import ENGINE_KEYS, EngineKeys
from shakermill.parameters.geometry import ball_volume, end_faces_area, vial_volume
from shakermill.parameters.groups import CoreKeys

if TYPE_CHECKING:
    import numpy


class DerivedQuantities(CoreKeys):
    """Periods, masses, areas and volumes of a run, where its balls start and how its convection takes their speed,
    from the core keys of the ``Parameters`` that inherit them."""

    @property
    def engine_keys(self) -> EngineKeys:
        """What the run's engine (the key ``engine``) takes and reads (``engine_keys.py``): the engine that every
        layer below the engines knows of a run, without asking for it by name."""
        return ENGINE_KEYS[self.engine]

    @property
    def period(self) -> float:
        """2π/ω: one drive period (s)."""
        return 2.0 * math.pi / self.omega

    @property
    def frequency(self) -> float:
        """ω/2π: drive cycles per second (Hz)."""
        return self.omega / (2.0 * math.pi)

    @property
    def ball_mass(self) -> float:
        """m_b = ρ_b·4/3·π R³ (kg)."""
        return self.ball_density * 4.0 / 3.0 * math.pi * self.ball_radius**3

    def ball_masses(self) -> tuple[float, ...]:
        """Each ball's mass ρ·4/3·π R³ (kg), from its per-ball values or the scalar ones."""
        radii, densities = self.ball_values("ball_radius"), self.ball_values("ball_density")
        return tuple(density * 4.0 / 3.0 * math.pi * radius**3 for radius, density in zip(radii, densities))

    @property
    def end_face_area(self) -> float:
        """2·π·d_v²/4: both circular end faces (m²), MODEL.md section 1; the paper's A_i = A_o."""
        return end_faces_area(self.vial_diameter)

    @property
    def vial_volume(self) -> float:
        """π d_v²/4·l_v: the vial's inner volume (m³)."""
        return vial_volume(self.vial_length, self.vial_diameter)

    @property
    def balls_volume(self) -> float:
        """Σ 4/3·π R³ over every ball of the 'dem' engine, or the one ball of the 1-D engine (m³)."""
        radii = self.ball_values("ball_radius") if self.engine_keys.several_balls else (self.ball_radius,)
        return sum(ball_volume(radius) for radius in radii)

    @property
    def fill_fraction(self) -> float:
        """The fraction of the vial's inner volume the balls take (dimensionless): what ``fill`` asks, as achieved
        by a whole number of balls."""
        return self.balls_volume / self.vial_volume

    @property
    def air_mass(self) -> float:
        """m_a = ρ_a·(π d_v²/4·l_v − Σ 4/3·π R³) (kg), MODEL.md section 6 (every ball of the 'dem' engine)."""
        return self.air_density * (self.vial_volume - self.balls_volume)

    @property
    def air_heat_capacity(self) -> float:
        """c_a = c_p,a/γ: the trapped air is heated at constant volume (J/(kg·K))."""
        return self.air_cp / self.air_heat_capacity_ratio

    @property
    def relative_convection(self) -> bool:
        """Whether Re takes the ball's speed relative to the vial (MODEL.md §§4, 12.5): by default where the air moves
        with the vial, as the engine says (``engine_keys``)."""
        if self.convection_velocity == "auto":
            return self.engine_keys.air_moves_with_vial
        return self.convection_velocity == "relative"

    def initial_positions(self) -> numpy.ndarray | None:
        """Ball centres (n_balls, 3) in the vial frame at t = 0 (m): one ball at ``ball_position`` on the axis,
        several (or none) filled in from the bottom (:mod:`shakermill.parameters.packing`); None if they do not fit."""
        import numpy as np

        from shakermill.parameters.packing import placement

        if self.n_balls == 1:
            return np.array([[self.ball_position, 0.0, 0.0]])
        return placement(np.array(self.ball_values("ball_radius")), self.vial_length, self.vial_diameter)
