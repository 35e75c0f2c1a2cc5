"""The 'dem' engine's neighbour list (engines/dem/neighbours.py, issue 38): the same contacts as the search over
every pair, its bound on the entries, the contacts it carries through a rebuild, and the packing that starts a large
charge."""

from __future__ import annotations

import math

import numpy as np
import pytest

import shakermill as sm
from shakermill.engines.dem import model
from shakermill.engines.dem.contacts import rebuild_neighbours
from shakermill.engines.dem.engine import DemEngine
from shakermill.engines.dem.stepper import NEIGHBOUR_BUILDS
from shakermill.parameters.packing import packed

# A hundred and twenty balls of two sizes in a wide planetary jar: enough that a finite skin lists far fewer than
# every pair.
N_BALLS = 120
CHARGE = {
    "preset": "pulverisette7",
    "n_balls": N_BALLS,
    "ball_radii": (2.5e-3, 2.8e-3) * (N_BALLS // 2),
    "vial_diameter": 0.06,
    "vial_length": 0.03,
    "outer_diameter": 0.07,
    "outer_length": 0.04,
    "record_windows": (),
}


def parameters(**more) -> sm.Parameters:
    values = {**CHARGE, **more}
    return sm.default_parameters(values.pop("preset"), **values)


def random_packing(engine: DemEngine, seed: int) -> None:
    """The engine's packed balls (1 % apart), their order shuffled, moving at up to 3 m/s in random directions and
    spinning: impacts of every kind within microseconds, balls that cross cells, a list rebuilt many times."""
    k, s = engine.constants, engine.state
    rng = np.random.default_rng(seed)
    order = np.arange(k.n_balls)
    for size in (0, 1):  # shuffled among balls of one size, so that none lands in another's place too small for it
        order[size::2] = rng.permutation(order[size::2])
    s.position[:] = s.position[order]
    s.velocity[:] = rng.uniform(-3.0, 3.0, size=s.velocity.shape)
    s.spin[:] = rng.uniform(-300.0, 300.0, size=s.spin.shape)
    assert rebuild_neighbours(k, s, engine.scratch.coordinates[:3])
    engine.start = engine.row_now()  # the energy audit's start


def engine_of(params: sm.Parameters, monkeypatch, skin: float | None) -> DemEngine:
    """An engine of ``params`` whose neighbour list has ``skin`` (inf: every pair; None: the engine's own choice)."""
    if skin is not None:
        monkeypatch.setattr(model, "neighbour_skin", lambda radius: skin)
    engine = DemEngine(params, horizon=params.duration)
    monkeypatch.undo()
    return engine


def test_a_charge_of_a_hundred_and_twenty_lists_far_fewer_pairs_than_all_and_every_pair_a_list_can_need():
    params = parameters()
    k = DemEngine(params).constants
    assert math.isfinite(k.skin) and k.skin == pytest.approx(model.SKIN_FRACTION * 2.5e-3)
    capacity = model.pair_capacity(k.radius, k.skin)
    assert capacity < N_BALLS * (N_BALLS - 1) // 2
    # The bound: a ball's neighbours' cores (0.95 of each radius) lie disjoint within r_i + 1.95 r_max + skin.
    core, reach = 0.95 * 2.5e-3, k.radius + 1.95 * 2.8e-3 + k.skin
    assert capacity == math.ceil(np.sum(np.floor((reach / core) ** 3)) / 2)
    # A few balls list every pair, once and for all.
    assert model.neighbour_skin(np.full(3, 5e-3)) == math.inf
    assert model.pair_capacity(np.full(3, 5e-3), math.inf) == 3


@pytest.mark.parametrize("seed", [1, 2])
def test_the_neighbour_list_finds_the_contacts_of_the_search_over_every_pair(monkeypatch, seed):
    """Random packings with balls crossing cells: the list's run and the every-pair run step alike to round-off
    (forces summed in another order), through rebuilds that carry touching contacts to new entries."""
    params = parameters(duration=2e-4, gravity=False)
    runs = []
    for skin in (math.inf, None):
        engine = engine_of(params, monkeypatch, skin)
        random_packing(engine, seed)
        touching_at_start = int(engine.state.contacts.active.sum())
        assert engine.compiled_call(2e-4, 100_000) == 0
        runs.append(engine)
    every_pair, listed = runs
    assert math.isinf(every_pair.constants.skin) and math.isfinite(listed.constants.skin)
    assert listed.stepper_counters[NEIGHBOUR_BUILDS] >= 2 and every_pair.stepper_counters[NEIGHBOUR_BUILDS] == 0
    assert touching_at_start == 0 and every_pair.counters()["impacts"] > 20
    assert listed.t == every_pair.t == pytest.approx(2e-4)
    np.testing.assert_allclose(listed.state.position, every_pair.state.position, rtol=0, atol=1e-12)
    np.testing.assert_allclose(listed.state.velocity, every_pair.state.velocity, rtol=0, atol=1e-7)
    assert listed.counters()["impacts"] == every_pair.counters()["impacts"]
    assert listed.counters()["steps"] == every_pair.counters()["steps"]
    for engine in runs:
        audit = engine.energy_audit()
        supplied = audit.work_by_vial + audit.work_by_gravity + audit.work_by_stiffening
        stored = audit.kinetic_energy_change + audit.elastic_energy_change + audit.dissipated
        assert abs(supplied - stored) <= 1e-6 * audit.dissipated
    pairs = {
        engine.constants.skin: sorted(
            (int(engine.state.neighbours.first_ball[e]), int(engine.state.neighbours.second_ball[e]))
            for e in range(int(engine.state.neighbours.entries[0]))
            if engine.state.contacts.active[3 * N_BALLS + e]
        )
        for engine in runs
    }
    assert pairs[listed.constants.skin] == pairs[math.inf] and pairs[math.inf]


def test_a_rebuild_carries_each_touching_contact_to_its_new_entry_whole(monkeypatch):
    params = parameters(duration=1e-4, gravity=False)
    engine = engine_of(params, monkeypatch, None)
    random_packing(engine, 3)
    assert engine.compiled_call(5e-5, 100_000) == 0
    k, s = engine.constants, engine.state
    walls = 3 * k.n_balls

    def touching() -> dict[tuple[int, int], tuple[float, ...]]:
        nb = s.neighbours
        return {
            (int(nb.first_ball[e]), int(nb.second_ball[e])): (
                *s.contacts.spring[walls + e],
                s.contacts.started[walls + e],
                *s.contacts.dissipated[walls + e],
                s.contacts.peak_force[walls + e],
            )
            for e in range(int(nb.entries[0]))
            if s.contacts.active[walls + e]
        }

    before = touching()
    assert rebuild_neighbours(k, s, engine.scratch.coordinates[:3])  # the list of the balls where they are now
    assert touching() == before
    entries_before = (
        s.neighbours.first_ball[: s.neighbours.entries[0]].copy(),
        s.neighbours.second_ball[: s.neighbours.entries[0]].copy(),
    )
    # The grid moved by 0.4 of a cell: every ball in other cells, so the pairs are listed in another order.
    assert rebuild_neighbours(k, s, engine.scratch.coordinates[:3] + 0.4 * k.cell_size)
    entries_after = (
        s.neighbours.first_ball[: s.neighbours.entries[0]],
        s.neighbours.second_ball[: s.neighbours.entries[0]],
    )
    assert before and touching() == before
    # Which pairs are listed depends on their distances alone, not on the cells.
    assert set(zip(*map(list, entries_before))) == set(zip(*map(list, entries_after)))
    assert not all(np.array_equal(a, b) for a, b in zip(entries_before, entries_after))
    assert s.contacts.active[walls + int(s.neighbours.entries[0]) :].sum() == 0


def test_packing_a_thousand_balls_places_them_apart_and_inside_the_bowl():
    radius, length, diameter = 2.5e-3, 0.0637, 0.1
    centres = packed(np.full(1000, radius), length, diameter)
    assert centres.shape == (1000, 3)
    gaps = np.linalg.norm(centres[:, None] - centres[None], axis=-1) + np.eye(1000)
    assert gaps.min() >= 2 * radius * 1.01 - 1e-12
    assert np.all(np.abs(centres[:, 0]) <= 0.5 * length - radius)
    assert np.all(np.hypot(centres[:, 1], centres[:, 2]) <= 0.5 * diameter - radius)
    # Bottom first: the lowest layer fills before any ball sits higher.
    assert np.all(np.diff(centres[:, 2]) >= -1e-12)


def test_a_bowl_filled_with_small_balls_runs_on_its_neighbour_list():
    """Issue 38: ``fill`` of a planetary bowl with Ø5-mm balls makes a charge of hundreds, which starts apart, runs,
    rebuilds its list and closes its energy audit."""
    params = sm.default_parameters(
        "pulverisette7",
        fill=0.3,
        ball_radius="2.5 mm",
        duration=0.002,
        record_windows=(),
        output_interval=0.001,
        solver="full",
    )
    assert params.n_balls > 100  # hundreds of balls
    result = sm.simulate(params)
    assert result.success and result.counters["neighbour_builds"] > 0 and result.impact_count > 0
    audit = result.energy
    supplied = audit.work_by_vial + audit.work_by_gravity + audit.work_by_stiffening
    stored = audit.kinetic_energy_change + audit.elastic_energy_change + audit.dissipated
    assert abs(supplied - stored) <= 1e-6 * max(audit.dissipated, abs(supplied))
