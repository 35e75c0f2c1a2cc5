"""The regime of a charge is named from its settled motion, never its start-up, and from impacts as MODEL.md §14.4
defines them (issue 50): `pulverisette7` for 1.5 s at full resolution is a pack at friction 0.3, whose start-up was
active, and active at 0.5."""

from __future__ import annotations

import numpy as np
import pytest

import shakermill as sm
from shakermill.analysis.regime import ACTIVE, PACK


def planetary(friction: float) -> sm.Result:
    return sm.simulate(
        sm.default_parameters(
            "pulverisette7", engine="dem", solver="full", duration=1.5, friction=friction, record_windows=()
        )
    )


@pytest.mark.slow
def test_a_planetary_charge_at_friction_03_is_a_pack_though_its_start_up_was_active():
    result = planetary(0.3)
    summary, charge = result.summary, result.summary.charge
    assert charge is not None and charge.regime == PACK and charge.regime_from_s == pytest.approx(0.75)
    assert charge.regime_fast_impact_rate_hz == 0.0 and charge.regime_lasting_share > 0.9
    # Over the whole run the start-up's fast impacts count: what the label was read from before.
    assert summary.impacts.fast_rate_hz > result.params.n_balls * result.params.frequency
    settled = result.contacts(since=0.75)
    # The settled pack's contact records are mostly chatter and touches: a few dozen impacts a second among thousands.
    assert settled.record_count > 20 * settled.impact_count > 0
    assert np.all(settled.impacts["impact_speed"] >= result.params.touch_speed)


@pytest.mark.slow
def test_the_same_charge_at_friction_05_is_active_for_its_first_seconds():
    charge = planetary(0.5).summary.charge
    assert charge is not None and charge.regime == ACTIVE
    assert charge.regime_fast_impact_rate_hz > 1000.0 and charge.regime_lasting_share < 0.5
