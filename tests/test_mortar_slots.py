"""The target facets a 2D mortar striker node may see (its slots): chosen, measured, warned.

A node's weighted gap integrates over its two striker facets cut at the
target facets that overlap them; the compiled forms hold a fixed number of
those per node. With too few (a coarse striker over a fine target) the gap
leaves part of the support out and jumps as the kept facets change: an
ironing run with a target three times as fine as its striker (h = 0.02 at
the indenter against the block's 0.06) cycled at load step 36 of 50 with
GNRM and `auto` alike; with the slots chosen from the facet sizes (8) every
step converges (`benchmarks/validation/ironing_mortar.py --h-indenter 0.02
--h-block 0.06 --steps 50`).
"""

from __future__ import annotations

import warnings
from types import SimpleNamespace

import numpy as np
import pytest

from benchmarks import cases
from fenics_contact.model.segments import slots_needed
from fenics_contact.scene.checks import SceneWarning
from fenics_contact.scene.slot_overflow import (
    slot_shortfall,
    warn_slot_overflow,
    warn_slots_capped,
)
from tests.test_mortar import BLOCKS, SLOTS, _mesh, _problem, _solve


def _line(x0: float, x1: float, size: float, y: float, facing_up: bool) -> SimpleNamespace:
    """A straight polyline from x0 to x1 at height y in facets of ``size``."""
    n = round((x1 - x0) / size)
    X = np.stack([np.linspace(x0, x1, n + 1), np.full(n + 1, y)], axis=1)
    fv = np.stack([np.arange(n), np.arange(1, n + 1)], axis=1)
    return SimpleNamespace(X=X, facet_vertex=fv if facing_up else fv[:, ::-1])


@pytest.mark.parametrize(("target_size", "expected"), [(0.06, 4), (0.04, 4), (0.02, 8),
                                                       (0.01, 16)])
def test_slots_needed_counts_the_target_facets_under_a_striker_support(
        target_size: float, expected: int) -> None:
    """Striker facets 0.06 (support 0.12, with a 1.25 stretch 0.15) over finer targets."""
    striker = _line(-1.0, 1.0, 0.06, 0.0, facing_up=False)
    target = _line(-1.2, 1.2, target_size, -1e-3, facing_up=True)
    assert slots_needed(striker, target) == expected


def test_slots_needed_looks_where_the_surfaces_first_meet() -> None:
    """A target fine only far from where the surfaces meet does not raise the count."""
    striker = _line(-1.0, 1.0, 0.06, 0.0, facing_up=False)
    near = _line(-1.0, 0.0, 0.06, -1e-3, facing_up=True)
    far = _line(0.0, 1.0, 0.01, -0.5, facing_up=True)  # 0.5 below: met only much later
    target = SimpleNamespace(X=np.vstack([near.X, far.X]),
                             facet_vertex=np.vstack([near.facet_vertex,
                                                     far.facet_vertex + len(near.X)]))
    assert slots_needed(striker, target) == 4


def test_default_slots_of_the_patch_test_stay_four() -> None:
    """The shipped non-matching blocks (8/11) keep four slots: one set of compiled forms."""
    problem = _problem(_mesh(cases.block_on_block(8, 11)), BLOCKS, "mortar")
    contact = problem.contacts[0]
    assert contact.mortar.slots == SLOTS
    assert contact.slot_use().wanted == SLOTS


def test_a_coarse_striker_over_a_fine_target_with_too_few_slots_is_named() -> None:
    """Striker facets 0.25 on target facets 0.05 with four slots: each node overlaps more.

    The start says how many the meshes want. With four, even this flat patch
    test cycles (the kept facets change from one iterate to the next); the
    nodes in contact are measured, and the warning and the failure advice
    give the slots that would do.
    """
    from fenics_contact.solvers import make_strategy
    from fenics_contact.solvers.diagnostics import SolverSettings

    problem = _problem(_mesh(cases.block_on_block(4, 20)), BLOCKS, "mortar")
    contact = problem.contacts[0]
    start = contact.slot_use()
    assert start.slots == SLOTS
    assert start.wanted == 14  # radius 1.25 x 0.5 / 2 = 0.3125 over facets of 0.05
    with pytest.warns(SceneWarning, match=r"overlap up to 14 target facets, and the pair keeps 4"):
        warn_slots_capped(problem)
    problem.set_load(1.0)
    result = make_strategy("gnrm", problem, SolverSettings()).solve()
    assert not result.converged
    use = contact.slot_use()
    assert use.now > SLOTS and use.most == 0  # no converged state yet
    with pytest.warns(SceneWarning, match=r"in the last state a striker node in contact "
                      rf"overlaps {use.now} target facets with 4 slots") as record:
        warn_slot_overflow(problem)
    assert f"set [[pair]] slots = {use.now + 1}" in str(record[0].message)
    assert f"overlapped {use.now} target facets with 4 slots" in slot_shortfall(problem)


def test_only_converged_states_count_towards_the_most_overlaps() -> None:
    """An iterate far from the answer may stretch a striker facet over many target facets.

    A grazing mortar pair under the penalty method read 17 in an iterate of a
    failed step and was told to use 18 slots; what counts is the converged states.
    """
    problem = _problem(_mesh(cases.block_on_block(8, 11)), BLOCKS, "mortar")
    contact = problem.contacts[0]
    _solve(problem, "gnrm", 1)
    problem.commit()
    assert contact.slot_use().most == contact.slot_use().now <= SLOTS
    contact.mortar.overlaps_now = 17  # as an iterate far from the answer reads
    assert contact.slot_use().most <= SLOTS


def test_enough_slots_warn_nothing() -> None:
    problem = _problem(_mesh(cases.block_on_block(8, 11)), BLOCKS, "mortar")
    _solve(problem, "gnrm", 1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        warn_slots_capped(problem)
        warn_slot_overflow(problem)
    assert slot_shortfall(problem) is None


@pytest.mark.parametrize(("extra", "message"), [
    ('discretisation = "node-to-segment"\nslots = 6', "needs discretisation"),
    ('discretisation = "mortar"\nslots = 1', "integer >= 2"),
    ('discretisation = "mortar"\nslots = 40', "at most 32"),
])
def test_slots_key_errors(tmp_path, extra: str, message: str) -> None:
    from fenics_contact.scene.schema import SceneError, load_scene
    from tests.test_mortar import _scene_text

    path = tmp_path / "bad.toml"
    path.write_text(_scene_text(lambda s: s.replace(
        'target = "target_face"', f'target = "target_face"\n{extra}')))
    with pytest.raises(SceneError, match="slots") as err:
        load_scene(path)
    assert message in str(err.value)


def test_slots_key_reaches_the_pair(tmp_path) -> None:
    from fenics_contact.scene.schema import load_scene
    from tests.test_mortar import _scene_text

    path = tmp_path / "ok.toml"
    path.write_text(_scene_text(lambda s: s.replace(
        'target = "target_face"', 'target = "target_face"\ndiscretisation = "mortar"\n'
        'slots = 6')))
    assert load_scene(path).pairs[0].slots == 6
