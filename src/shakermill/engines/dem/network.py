"""The thermal network of the 'dem' engine: a node per ball, the vial and the air (MODEL.md §§4–6, 12.5).

One function gives the heat flows between the nodes; the compiled stepping advances the network with
it on its own clock, and the averaged solver and the steady state (MODEL.md §11) solve it with the
mechanics replaced by its means.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from shakermill.engines.dem.model import Constants
from shakermill.physics import thermal


@njit(cache=True)
def flows(theta: np.ndarray, velocity_terms: np.ndarray, k: Constants, out: np.ndarray) -> None:
    """Heat flows (W) into ``out``: ball i → air for each ball, then vial → air, then vial → surroundings.

    ``theta`` holds the balls', the vial's and the air's temperatures (K); ``velocity_terms`` each ball's
    mean Whitaker term 0.4 Re^{1/2} + 0.06 Re^{2/3}, so Sutherland's factor is taken at the ball's own
    temperature here.
    """
    n = k.n_balls
    for i in range(n):
        ratio = thermal.sutherland_viscosity(theta[i], k.mu_ref, k.t_ref, k.sutherland) / k.mu_ref
        nusselt = thermal.nusselt_from_velocity_term(velocity_terms[i], k.prandtl, ratio)
        h_ball = thermal.heat_transfer_coefficient(nusselt, k.air_conductivity, k.radius[i])
        out[i] = thermal.ball_air_heat_flow(k.radius[i], k.beta, h_ball, theta[i], theta[n + 1])
    out[n] = thermal.newton_cooling(k.h_inner, k.inner_area, theta[n], theta[n + 1])
    out[n + 1] = thermal.newton_cooling(k.h_outer, k.outer_area, theta[n], k.t_ambient)


def rates(theta: np.ndarray, heat_powers: np.ndarray, velocity_terms: np.ndarray, k: Constants) -> np.ndarray:
    """dθ/dt (K/s) of the N + 2 nodes with mean heat powers (W) into each ball and the vial."""
    n = k.n_balls
    flow = np.empty(n + 2)
    flows(theta, velocity_terms, k, flow)
    derivative = np.empty(n + 2)
    derivative[:n] = (heat_powers[:n] - flow[:n]) / k.capacity_ball
    derivative[n] = (heat_powers[n] - flow[n] - flow[n + 1]) / k.capacity_vial
    derivative[n + 1] = (flow[:n].sum() + flow[n]) / k.capacity_air
    return derivative
