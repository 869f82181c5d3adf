"""Candidate contact facets: detection along the obstacle path keeps every contact facet."""

import numpy as np
import pytest
from dolfinx import mesh

from mpi4py import MPI

from benchmarks import cases
from fenics_contact.model.candidates import boundary_facets, detect_candidate_facets
from fenics_contact.model.obstacles import RigidBall
from fenics_contact.model.scaling import scaled_atol
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings
from fenics_contact.solvers.stepping import solve_load_path


def solved(scene):
    problem = cases.build(scene, 1.0, comm=MPI.COMM_WORLD)
    settings = SolverSettings(atol=scaled_atol(problem), max_iterations=60)
    path = solve_load_path(make_strategy("gnrm", problem, settings), scene.solver.steps)
    assert path.converged
    return problem


def contact_points(problem):
    """Reference coordinates of every node in contact (gathered on all ranks)."""
    state = problem.contact_state()
    local = problem.nodal_coordinates()[state.active]
    return np.concatenate(problem.comm.allgather(local))


def facet_points(domain, facets):
    nodes = mesh.entities_to_geometry(domain, domain.topology.dim - 1, facets)
    return domain.geometry.x[nodes.ravel()]


@pytest.mark.parametrize("family", [lambda **kw: cases.hertz_cylinder(0.02, **kw),
                                    cases.bar_on_cradle], ids=["hertz", "bar"])
def test_detection_keeps_every_node_a_whole_boundary_run_brings_into_contact(family):
    whole = solved(family(candidates="boundary"))
    touched = contact_points(whole)
    assert touched.shape[0] > 0
    detected = solved(family(candidates="detected"))
    kept = np.concatenate(
        MPI.COMM_WORLD.allgather(facet_points(detected.domain, detected.surface.facets))
    )
    for point in touched:
        assert np.min(np.linalg.norm(kept - point, axis=1)) < 1e-12, point
    # fewer multipliers, same answer
    assert detected.surface.num_dofs < whole.surface.num_dofs
    f_whole = whole.contact_state().contact_force
    f_detected = detected.contact_state().contact_force
    assert f_detected == pytest.approx(f_whole, rel=1e-9)


@pytest.mark.mpi
def test_a_moving_ball_sweeps_the_lower_face_only():
    """A ball sliding under a unit square reaches the lower face along its path."""
    domain = mesh.create_unit_square(MPI.COMM_WORLD, 8, 8)
    ball = RigidBall(domain, [-1.0, -0.45], 0.5)
    fdim = 1
    lower = set(mesh.locate_entities_boundary(domain, fdim, lambda x: np.isclose(x[1], 0.0)))
    found = detect_candidate_facets(domain, ball, [3.0, 0.0], 0.0, samples=7)
    assert lower <= set(found)
    # kept: facets with a vertex within the half-step margin 0.25 of the path (the
    # lower face and the lowest side facets), nothing above
    assert np.all(facet_points(domain, found)[:, 1].reshape(-1, 2).min(axis=1) <= 0.25)
    # two samples only: the half-step margin (0.75) still covers the lower face
    assert lower <= set(detect_candidate_facets(domain, ball, [3.0, 0.0], 0.0, samples=2))
    # the obstacle is back where it was; a fixed far ball finds nothing
    assert np.allclose(ball.point.value, [-1.0, -0.45])
    assert detect_candidate_facets(domain, ball, None, 0.1).size == 0
    total = domain.comm.allreduce(boundary_facets(domain).size, op=MPI.SUM)
    assert total == 32
