"""A contact node whose gap a prescribed displacement fixes (a clamped side on a floor).

Its Alart-Curnier row r g = 0 has no derivative once it is in contact (the
displacement along the normal is held): the linear solve failed at the first
step, every cut-back too. The node now transmits no pressure and its support
holds it: the run converges and the reactions balance the load and the contact.
"""

from __future__ import annotations

import numpy as np
import pytest

from mpi4py import MPI

from fenics_contact import load_scene, run_scene

SCENE = """[scene]
name = "clamped-on-floor"
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
tag = "left"
value = {left}
[[traction]]
tag = "top"
value = [3.0, -20.0]
[obstacle]
type = "plane"
point = [0.0, 0.0]
normal = [0.0, 1.0]
[contact]
tag = "bottom"
{quadrature}
[solver]
method = "gnrm"
steps = 4
[output]
pictures = false
"""


def _run(tmp_path, name: str, left: str, quadrature: str = ""):
    path = tmp_path / f"{name}.toml"
    path.write_text(SCENE.format(left=left, quadrature=quadrature))
    outcome = run_scene(load_scene(path), tmp_path / name, comm=MPI.COMM_SELF, pictures=False)
    assert outcome.path.status == "converged", outcome.path.steps[-1].message
    return outcome


def test_a_clamped_corner_on_a_floor_is_held_by_its_support(tmp_path):
    outcome = _run(tmp_path, "clamped", '[0.0, 0.0]')
    contact = outcome.problem.contacts[0]
    assert contact.held_nodes == 1  # the bottom-left corner
    state = outcome.problem.contact_state()
    corner = np.argmin(np.linalg.norm(outcome.problem.nodal_coordinates(), axis=1))
    assert state.pressure[corner] == 0.0 and state.gap[corner] == 0.0
    assert state.active_count == 20  # every other node of the bottom presses
    # the load (3, -20) per unit thickness is carried by the clamp and the floor
    total = outcome.problem.support_total()
    assert total[0] == pytest.approx(-3.0, rel=1e-9)
    assert total[1] + state.contact_force == pytest.approx(20.0, rel=1e-9)
    # the Gauss rule, which has no row at the corner, splits the load nearly alike
    gauss = _run(tmp_path, "gauss", '[0.0, 0.0]', 'quadrature = "gauss"')
    assert gauss.problem.contacts[0].normal_mask is None
    assert state.contact_force == pytest.approx(gauss.problem.contact_state().contact_force,
                                                rel=2e-2)

