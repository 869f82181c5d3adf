"""Friction on a curved rigid obstacle: the contact's forces balance the supports.

A block pressed by a rigid cylinder, straight down or also sideways, mu =
0.4, in one step: the nodes enter contact within it. The body's equilibrium,
support reactions + int -p n ds - int T tau ds = 0, must hold. Before the
slip was measured between the obstacle's closest points, the derivative of
the frame acted on a node's approach along the normal, and the reported
forces missed 0.17 % of the reaction.
"""

from __future__ import annotations

import numpy as np
import pytest
import ufl
from dolfinx import fem

from mpi4py import MPI

from fenics_contact import load_scene, run_scene

SCENE = """[scene]
name = "cylinder-friction"
dimension = 2
[mesh]
generator = "rectangle"
size = [1.0, 0.5]
cells = [20, 10]
[material]
law = "neo-hookean"
E = 1000.0
nu = 0.3
[[dirichlet]]
tag = "bottom"
value = [0.0, 0.0]
[obstacle]
type = "ball"
centre = [0.5, 1.0]
radius = 0.5
motion = [{dx}, -0.04]
[contact]
tag = "top"
mu = 0.4
[solver]
method = "gnrm"
steps = {steps}
[output]
pictures = false
"""


def _normal_resultant(problem) -> np.ndarray:
    """int -p n ds: the obstacle's normal force on the body (force per thickness)."""
    contact = problem.contacts[0]
    x = ufl.SpatialCoordinate(contact.domain) + contact.solid.u
    n = contact.obstacle.normal_at(x)
    forms = [fem.form(-contact.pressure * n[i] * contact.surface.ds,
                      entity_maps=contact.surface.entity_maps) for i in range(2)]
    return np.array([MPI.COMM_WORLD.allreduce(fem.assemble_scalar(f), op=MPI.SUM)
                     for f in forms])


@pytest.mark.parametrize("dx", [0.0, 0.01])
def test_the_contact_forces_on_a_curved_obstacle_balance_the_supports(tmp_path, dx):
    path = tmp_path / "scene.toml"
    path.write_text(SCENE.format(dx=dx, steps=1))  # every node enters contact in the step
    outcome = run_scene(load_scene(path), tmp_path / "out", comm=MPI.COMM_SELF,
                        pictures=False)
    assert outcome.path.status == "converged", outcome.path.steps[-1].message
    problem = outcome.problem
    state = problem.contact_state()
    assert state.slip_count >= 1 and state.active_count >= 4  # friction is at work
    assert state.tangential_magnitude > 0.05 * state.contact_force
    friction = problem.tangential_force_vector()
    normal = _normal_resultant(problem)
    assert np.linalg.norm(normal) == pytest.approx(state.contact_force, rel=2e-2)
    total = np.asarray(problem.support_total())
    # what remains is the frame's derivative on the chord of the obstacle between the
    # closest points (second order in the slip of the step; 1.6e-3 of the force before)
    assert np.abs(total + normal - friction).max() < 1e-6 * state.contact_force
