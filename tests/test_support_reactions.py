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


def solve_linear_elasticity(solid) -> None:
    """One Newton step from u = 0: exact for the linear law (no contact)."""
    import ufl
    from dolfinx.fem.petsc import LinearProblem

    v, du = ufl.TestFunction(solid.V), ufl.TrialFunction(solid.V)
    residual = ufl.derivative(solid.strain_energy(), solid.u, v)
    solid.u.x.array[:] = 0.0
    problem = LinearProblem(ufl.derivative(residual, solid.u, du), -residual, bcs=solid.bcs,
                            petsc_options={"ksp_type": "preonly", "pc_type": "lu"},
                            petsc_options_prefix="reactions_")
    solid.u.x.array[:] = problem.solve().x.array


def test_the_total_counts_a_component_two_supports_share_once():
    """A block on a fixed base with a symmetry side (ux = 0), pressed from above: the base
    and the side share the corner's x. The supports' sum counts it twice; the total, once,
    balances to zero (no other external force)."""
    from dolfinx import mesh

    from mpi4py import MPI

    from fenics_contact import Body, PrescribedDisplacement, Solid, material

    domain = mesh.create_rectangle(MPI.COMM_WORLD, [[0.0, 0.0], [1.0, 1.0]], [6, 6],
                                   mesh.CellType.triangle)
    side = lambda where: mesh.locate_entities_boundary(domain, 1, where)  # noqa: E731
    solid = Solid(domain, [Body("block", None, material("linear", 100.0, 0.3))], prescribed=[
        PrescribedDisplacement(side(lambda x: np.isclose(x[1], 0.0)), (0.0, 0.0), "base"),
        PrescribedDisplacement(side(lambda x: np.isclose(x[0], 0.0)), (0.0, None), "symmetry"),
        PrescribedDisplacement(side(lambda x: np.isclose(x[1], 1.0)), (None, -0.05), "top")])
    solid.set_load(1.0)
    solve_linear_elasticity(solid)
    reactions = solid.support_reactions()
    doubled = sum(r[0] for r in reactions.values())
    total = solid.support_total()
    assert abs(reactions["base"][0]) > 0.1  # the base restrains the Poisson spread
    assert abs(doubled) > 1e-3 * abs(reactions["top"][1])  # the shared corner, twice
    assert np.allclose(total, 0.0, atol=1e-9 * abs(reactions["top"][1]))
