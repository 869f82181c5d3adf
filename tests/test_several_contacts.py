"""Several contacts in one problem: a block squeezed between two rigid plates.

A unit block (linear elastic, plane strain) rests on a fixed plane (y = 0)
and is pressed by a second plane (y = 1) moved down by D; its left edge
slides on a symmetry roller (u_x = 0) and nothing else holds it: the two
contacts alone fix its vertical position. The exact answer is uniaxial
stress, sigma_yy = -E / (1 - nu^2) D / H, so each plate carries the force
E / (1 - nu^2) D W / H (per unit thickness) and the pressure is uniform.
Each contact has its own r (1 and 100 E/h): the converged nodal answer
does not depend on either.
"""

from __future__ import annotations

import numpy as np
import pytest
from dolfinx import mesh

from mpi4py import MPI

from fenics_contact.model.body import Body, PrescribedDisplacement, Solid
from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.materials import material
from fenics_contact.model.obstacle_contact import ObstacleContact
from fenics_contact.model.obstacles import RigidPlane
from fenics_contact.model.problem import ContactProblem
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings
from fenics_contact.solvers.stepping import solve_load_path

E, NU, D, STEPS = 210.0, 0.3, 0.01, 4
#: Exact force per unit thickness on each plate of the unit block (W = H = 1).
EXACT_FORCE = E / (1 - NU**2) * D


def squeezed_block(r_floor: float = 1.0, r_top: float = 100.0) -> ContactProblem:
    """The block, its roller and its two contacts (floor first, then the pressing plate)."""
    domain = mesh.create_rectangle(MPI.COMM_WORLD, [[0.0, 0.0], [1.0, 1.0]], [6, 6],
                                   mesh.CellType.quadrilateral)
    fdim = domain.topology.dim - 1

    def facets(marker):
        return mesh.locate_entities_boundary(domain, fdim, marker)

    bottom = facets(lambda x: np.isclose(x[1], 0.0))
    top = facets(lambda x: np.isclose(x[1], 1.0))
    left = facets(lambda x: np.isclose(x[0], 0.0))
    solid = Solid(domain, [Body("block", None, material("linear", E, NU))],
                  prescribed=[PrescribedDisplacement(left, (0.0, None))])
    floor = ObstacleContact(RigidPlane(domain, [0.0, 0.0], [0.0, 1.0]), bottom,
                            ContactSettings(r=r_floor), name="floor")
    plate = ObstacleContact(RigidPlane(domain, [0.0, 1.0], [0.0, -1.0]), top,
                            ContactSettings(r=r_top), motion=(0.0, -D), name="plate")
    return ContactProblem(solid, [floor, plate])


def squeeze(method: str, **kwargs):
    problem = squeezed_block(**kwargs)
    strategy = make_strategy(method, problem,
                             SolverSettings(atol=1e-10, rtol=0.0, max_iterations=60))
    return problem, solve_load_path(strategy, STEPS, max_cutbacks=0)


@pytest.mark.mpi
@pytest.mark.parametrize("method", ["gnrm", "auto", "nua"])
def test_each_plate_carries_the_exact_force_with_uniform_pressure(method):
    problem, run = squeeze(method)
    assert run.converged
    states = problem.contact_states()
    assert list(states) == ["floor", "plate"]
    for name, state in states.items():
        assert state.contact_force == pytest.approx(EXACT_FORCE, rel=1e-9), name
        pressure = np.concatenate(MPI.COMM_WORLD.allgather(state.pressure))
        assert pressure.size == 7 and state.active_count == 7, name
        # nodal rule: lumped areas 1/12 at the corners, 1/6 inside
        assert np.allclose(pressure, -EXACT_FORCE, rtol=1e-9), name
        assert state.max_penetration < 1e-12, name
    # the record's force is the sum over the contacts
    assert run.steps[-1].contact_force == pytest.approx(2 * EXACT_FORCE, rel=1e-9)
    assert run.steps[-1].active_count == 14


@pytest.mark.mpi
def test_gnrm_iterations_and_answer_do_not_depend_on_the_contacts_r():
    reference, run = squeeze("gnrm")
    # linear material and planes: semismooth Newton finds both active sets in
    # the first step; each later step is one linear solve
    assert [s.iterations for s in run.steps] == [3, 1, 1, 1]
    u_ref = reference.u.x.array.copy()
    for r_floor, r_top in ((1e-2, 1e-2), (1e4, 1.0)):
        problem, other = squeeze("gnrm", r_floor=r_floor, r_top=r_top)
        assert other.converged, (r_floor, r_top)
        assert np.max(np.abs(problem.u.x.array - u_ref)) < 1e-12, (r_floor, r_top)


def test_simultaneous_uzawa_reports_cycling_on_a_body_held_by_contacts_alone():
    """With the multipliers fixed and one contact open, nothing holds the block.

    SUA's single Newton step per update then throws the block from one plate
    to the other (measured: 13 updates, then the cycling test stops it); NUA
    solves each primal problem to the end and converges. A status, no error.
    """
    _, run = squeeze("sua")
    assert run.status == "cycling" and run.steps[-1].iterations == 13
    assert "cycling at load factor 0.25" in run.steps[-1].message


def test_each_contact_keeps_its_own_r_and_auto_keeps_their_ratio():
    problem = squeezed_block(r_floor=1.0, r_top=100.0)
    floor, plate = problem.contacts
    assert float(plate.r.value) / float(floor.r.value) == pytest.approx(100.0)
    assert problem.r_ratios() == pytest.approx([1.0, 100.0])
    problem.rescale_r(5.0)
    assert float(floor.r.value) == pytest.approx(5.0)
    assert float(plate.r.value) == pytest.approx(500.0)
    with pytest.raises(AttributeError, match="2 contacts"):
        _ = problem.lam


@pytest.mark.mpi
def test_penalty_plates_balance_and_penetrate_by_p_over_r():
    problem, run = squeeze("penalty", r_floor=1e4, r_top=1e4)
    assert run.converged
    floor, plate = problem.contact_states().values()
    # the block is in equilibrium between the plates whatever the penetration
    assert floor.contact_force == pytest.approx(plate.contact_force, rel=1e-10)
    # each plate's penetration is p / r (uniform), and the two add to the
    # approach the elastic block did not take up
    r = 1e4 * problem.contacts[0].stiffness_scale
    assert floor.max_penetration == pytest.approx(floor.contact_force / r, rel=1e-8)
    compression = D - floor.max_penetration - plate.max_penetration
    assert floor.contact_force == pytest.approx(E / (1 - NU**2) * compression, rel=1e-9)
