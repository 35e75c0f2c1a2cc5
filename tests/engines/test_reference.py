"""The compiled integrator against the same right-hand side through scipy.integrate.solve_ivp (RK23)."""

from __future__ import annotations

import math

import pytest

import shakermill as sm
from shakermill.engines.one_d.reference import simulate_scipy

SETTLING_TIME = 3.0  # s: the start from rest at the centre is over after ~1 s
COMPARISON_TIME = 10.0  # s
RTOL = 1e-5


@pytest.fixture(scope="module")
def settled_parameters() -> sm.Parameters:
    """Default parameters restarted from the settled motion.

    The first second after a start from rest is a transient in which tiny numerical differences shift the
    impact sequence by whole drive periods; both integrators are compared on the motion that follows.
    """
    base = sm.default_parameters(rtol=RTOL, record_windows=())
    settled = sm.simulate(base.replace(duration=SETTLING_TIME))
    last = settled.timeseries.isel(time=-1)
    phase = base.omega * SETTLING_TIME + base.phase
    return base.replace(
        duration=COMPARISON_TIME,
        phase=math.fmod(phase, 2 * math.pi),
        ball_position=float(last["x"]) - base.amplitude * math.sin(phase),
        ball_momentum=float(last["p"]),
    )


@pytest.mark.slow
def test_compiled_and_scipy_paths_agree(settled_parameters: sm.Parameters) -> None:
    compiled = sm.simulate(settled_parameters)
    reference = simulate_scipy(settled_parameters)
    assert compiled.success and reference.status == 0
    assert reference.t_end == pytest.approx(COMPARISON_TIME)
    assert reference.impact_rate == pytest.approx(compiled.summary.impacts.rate_hz, rel=0.01)
    assert reference.heat_power == pytest.approx(compiled.summary.heat_power_W, rel=0.01)
    # The impacts happen at the same times, not only at the same rate.
    first_impacts = compiled.impacts["time"].to_numpy()[:20]
    assert reference.impact_times[:20] == pytest.approx(first_impacts, abs=1e-3)
