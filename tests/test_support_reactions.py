"""Support reactions in summary.json: every support's force per step, by its scene tag.

Checked by equilibrium: the reactions of the supports balance each other and
the contact force (block on block: a flat interface, the normal force is the
resultant), step by step.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from fenics_contact import load_scene, run_scene

SCENES = Path(__file__).parents[1] / "scenes"


def test_block_on_block_reactions_balance_the_contact_force(tmp_path):
    scene = load_scene(SCENES / "block_on_block.toml")
    run_scene(scene, tmp_path, pictures=False)
    summary = json.loads((tmp_path / "summary.json").read_text())
    steps = summary["steps"]
    assert len(steps) == scene.solver.steps
    for step in steps:
        reactions = step["reactions"]
        assert set(reactions) == {"bottom", "symmetry", "top"}
        total = np.sum([reactions[name] for name in reactions], axis=0)
        force = step["contact_force"]
        assert force > 0.0
        assert np.all(np.abs(total) < 1e-10 * force)  # the bodies are in equilibrium
        assert reactions["top"][1] == pytest.approx(-force, rel=1e-10)
        assert reactions["bottom"][1] == pytest.approx(force, rel=1e-10)
        assert reactions["top"][0] == 0.0  # a free component



@pytest.mark.mpi
def test_a_rigid_obstacle_problem_reads_its_supports_from_the_solver(tmp_path_factory):
    """``block_slide_friction.toml`` (a rigid plane, no deformable pair: the plain Newton
    kernel gives the supports' residual on demand): the top's reaction is the contact's
    normal and friction force at every step of the slide."""
    from mpi4py import MPI

    comm = MPI.COMM_WORLD
    out = Path(comm.bcast(str(tmp_path_factory.mktemp("slide")) if comm.rank == 0 else None))
    scene = load_scene(SCENES / "block_slide_friction.toml")
    outcome = run_scene(scene, out, pictures=False)
    assert outcome.path.converged
    comm.barrier()
    steps = json.loads((out / "summary.json").read_text())["steps"]
    for step in steps[1:]:
        top = step["reactions"]["top"]
        assert top[1] == pytest.approx(-step["contact_force"], rel=1e-8)
    state = outcome.problem.contact_state()
    assert state.tangential_force > 1.0
    assert abs(outcome.problem.support_reactions()["top"][0]) == pytest.approx(
        state.tangential_force, rel=1e-8)
