"""Contact patch tests with exact answers, in 2D plane strain and in 3D.

A block resting on a rigid plane (gap exactly zero at the start: grazing
contact), its top face pushed down by delta and free to slide laterally
(symmetry conditions on two faces). Frictionless contact makes the stress
uniaxial: with linear elasticity the nodal pressure is uniform and equals
-E' delta / H (E' = E in 3D, E/(1 - nu^2) in plane strain).
"""

import numpy as np
import pytest
from dolfinx import mesh

from mpi4py import MPI

from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.materials import LinearElastic, NeoHookean
from fenics_contact.model.obstacles import RigidPlane
from fenics_contact.model.problem import (
    PrescribedDisplacement,
    one_body_problem,
)
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings
from fenics_contact.solvers.stepping import solve_load_path

E, NU, DELTA = 100.0, 0.3, 1e-3


def block(dim, law, method="gnrm", quadrature="nodal"):
    if dim == 2:
        domain = mesh.create_unit_square(MPI.COMM_WORLD, 4, 4)
    else:
        domain = mesh.create_unit_cube(MPI.COMM_WORLD, 3, 3, 3)
    fdim = dim - 1
    top_axis = dim - 1

    def side(axis, value):
        return mesh.locate_entities_boundary(domain, fdim, lambda x: np.isclose(x[axis], value))

    free = (None,) * dim
    prescribed = [
        PrescribedDisplacement(side(top_axis, 1.0), (*free[:-1], -DELTA)),
        PrescribedDisplacement(side(0, 0.0), (0.0, *free[1:])),
    ]
    if dim == 3:
        prescribed.append(PrescribedDisplacement(side(1, 0.0), (None, 0.0, None)))
    normal = np.eye(dim)[top_axis]
    plane = RigidPlane(domain, np.zeros(dim), normal)
    problem = one_body_problem(
        domain, law, plane, side(top_axis, 0.0),
        ContactSettings(r=10.0, quadrature=quadrature), prescribed=prescribed,
    )
    strategy = make_strategy(method, problem, SolverSettings(atol=1e-10))
    return problem, solve_load_path(strategy, 2, max_cutbacks=0)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("quadrature", ["nodal", "gauss"])
def test_linear_block_carries_uniform_uniaxial_pressure(dim, quadrature):
    problem, path = block(dim, LinearElastic(E, NU), quadrature=quadrature)
    assert path.converged
    modulus = E if dim == 3 else E / (1 - NU**2)
    state = problem.contact_state()
    assert np.allclose(state.multiplier, -modulus * DELTA, rtol=1e-8)
    assert state.contact_force == pytest.approx(modulus * DELTA, rel=1e-8)
    assert state.max_penetration < 1e-12


@pytest.mark.mpi
def test_neo_hookean_block_in_3d_balances_forces():
    problem, path = block(3, NeoHookean(E, NU))
    assert path.converged
    state = problem.contact_state()
    assert np.all(state.active)
    # uniform stress: every node carries the same pressure; small strain ~ E delta
    spread = problem.comm.allreduce(np.ptp(state.multiplier), op=MPI.MAX)
    assert spread < 1e-8 * E * DELTA
    assert state.contact_force == pytest.approx(E * DELTA, rel=5 * DELTA)
