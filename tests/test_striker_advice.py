"""The advice on which surface of a two-body pair strikes, from the facet sizes where it touches.

The shipped sphere on a block (coarser hemisphere striking) gets none; the
same scene with the roles swapped (the finer block striking) is told to swap
them back. Node-to-segment gets no advice, its coarser arc striking or not.
"""

from __future__ import annotations

import dataclasses
import warnings
from pathlib import Path

import pytest

from fenics_contact import build_problem, load_scene, scene_strategy, solve_load_path
from fenics_contact.scene.striker_advice import advise_striker, touching_sizes

SCENES = Path(__file__).parents[1] / "scenes"


def _solved(name: str, swap: bool, **mesh: float):
    scene = load_scene(SCENES / name)
    pair = scene.pairs[0]
    if swap:
        pair = dataclasses.replace(pair, striker=pair.target, target=pair.striker)
    scene = dataclasses.replace(scene, pairs=(pair,), mesh=dataclasses.replace(
        scene.mesh, parameters={**scene.mesh.parameters, **mesh}))
    problem = build_problem(scene)
    path = solve_load_path(scene_strategy(scene, problem), scene.solver.steps)
    assert path.converged
    return scene, problem


@pytest.mark.parametrize("swap", [False, True])
def test_mortar_3d_is_told_to_strike_with_the_coarser_surface(swap):
    scene, problem = _solved("sphere_on_block_3d.toml", swap, h_sphere=0.04, h_block=0.03,
                             fine_radius=0.25)
    sizes = touching_sizes(problem, problem.contacts[0])
    # where they touch, the hemisphere's facets are the coarser (about 0.04 against 0.03)
    hemisphere, block = (sizes.target, sizes.striker) if swap else (sizes.striker, sizes.target)
    assert hemisphere > 1.2 * block
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        advice = advise_striker(scene, problem)
    if swap:
        assert len(advice) == 1 and "swap striker and target" in advice[0]
        assert "coarser surface striking" in advice[0]
        assert any("Which surface strikes" in str(w.message) for w in caught)
    else:
        assert advice == []


def test_node_to_segment_gets_no_striker_advice_either_way():
    """No size rule holds for node-to-segment: none is given.

    The equal cylinders' interior error doubles with the coarser arc
    striking; a user's dissimilar cylinders (R 0.8 / 1.6, E 300 / 100) halve
    it the same way (L2 inside 0.8 a: 2.5 % against 5.5 %), and a user's
    shrink fit, told to let the finer disk strike, scattered 31 % against
    5.4 %. Before, the coarser striker was told to swap.
    """
    for swap in (True, False):
        scene, problem = _solved("two_cylinders_node_to_segment.toml", swap, h_contact=0.02)
        sizes = touching_sizes(problem, problem.contacts[0])
        if swap:  # the coarser arc strikes: its target's arc is 1.37 h
            assert sizes.striker > 1.25 * sizes.target
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            assert advise_striker(scene, problem) == []
        assert not any("swap striker and target" in str(w.message) for w in caught)


def test_the_rim_of_a_striker_in_contact_is_seen_and_symmetry_cuts_are_no_rim():
    """No swap is advised for a 3D mortar pair whose striker touches up to its rim (swapped,
    the coarser surface would strike past the finer one's rim: a frictional block dragged
    on a larger block did not survive it). The 3D patch test touches up to the rim; the
    quarter sphere's block face, cut by two symmetry planes through the contact, does not."""
    from fenics_contact.scene.striker_advice import rim_in_contact

    _, problem = _solved("block_on_block_3d.toml", False)
    contact = problem.contacts[0]
    assert rim_in_contact(problem, contact, touching_sizes(problem, contact).striker)
    _, problem = _solved("sphere_on_block_3d.toml", True, h_sphere=0.04, h_block=0.03,
                         fine_radius=0.25)
    contact = problem.contacts[0]
    assert not rim_in_contact(problem, contact, touching_sizes(problem, contact).striker)
