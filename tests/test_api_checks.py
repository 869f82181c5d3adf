"""The Python API without a scene: a problem built from public names, and misuse named early.

A block pressed onto a frictionless rigid plane (plane strain, its left side
on rollers): the pressure is uniform, p = E/(1 - nu^2) * strain, and the
force p W, exact for P1 with nodal contact and for P2 with Gauss contact.
"""

from __future__ import annotations

import numpy as np
import pytest
from dolfinx import mesh

from mpi4py import MPI

from fenics_contact import (
    Body,
    ContactProblem,
    ContactSettings,
    ObstacleContact,
    PrescribedDisplacement,
    RigidPlane,
    Solid,
    SolverSettings,
    make_strategy,
    material,
    solve_load_path,
)

E, NU, W, H, PUSH = 210.0, 0.3, 2.0, 1.0, 0.01
FORCE = E / (1 - NU**2) * PUSH / H * W


def block(degree: int = 1, quadrature: str = "nodal", top: bool = True) -> ContactProblem:
    domain = mesh.create_rectangle(MPI.COMM_WORLD, [[0.0, 0.0], [W, H]], [8, 4],
                                   mesh.CellType.quadrilateral)

    def side(where):
        return mesh.locate_entities_boundary(domain, 1, where)

    loaded = side(lambda x: np.isclose(x[1], H)) if top else np.zeros(0, np.int32)
    solid = Solid(domain, [Body("block", None, material("linear", E, NU))], degree=degree,
                  prescribed=[PrescribedDisplacement(loaded, (None, -PUSH), "top"),
                              PrescribedDisplacement(side(lambda x: np.isclose(x[0], 0.0)),
                                                     (0.0, None), "left")])
    floor = ObstacleContact(RigidPlane(domain, [0.0, 0.0], [0.0, 1.0]),
                            side(lambda x: np.isclose(x[1], 0.0)),
                            ContactSettings(r=10.0, quadrature=quadrature), name="floor")
    return ContactProblem(solid, [floor])


@pytest.mark.parametrize(("degree", "quadrature"), [(1, "nodal"), (2, "gauss")])
def test_a_block_built_in_python_carries_the_exact_force(degree, quadrature):
    problem = block(degree, quadrature)
    record = solve_load_path(make_strategy("gnrm", problem, SolverSettings(atol=1e-10)), 2)
    assert record.converged
    assert record.contact_force == pytest.approx(FORCE, rel=1e-8)
    top = problem.support_reactions()["top"]
    assert top[1] == pytest.approx(-FORCE, rel=1e-8)


def test_nodal_contact_with_quadratic_displacement_is_refused():
    """Its mid-edge nodes would pass through the plane unchecked (a force 19 % low)."""
    with pytest.raises(ValueError, match=r"quadrature = 'nodal'.*degree 2.*quadrature='gauss'"):
        block(degree=2, quadrature="nodal")


def test_a_solved_problem_is_not_solved_again_silently():
    problem = block()
    strategy = make_strategy("gnrm", problem, SolverSettings(atol=1e-10))
    assert solve_load_path(strategy, 2).converged
    with pytest.raises(ValueError, match="Nothing to solve: the problem is at load factor 1"):
        solve_load_path(strategy, 2)


def test_misuse_is_named():
    with pytest.raises(ValueError, match="Prescribed displacement 'top' holds no facet"):
        block(top=False)
    problem = block()
    with pytest.raises(TypeError, match="give a SolverSettings"):
        make_strategy("gnrm", problem, None)
    strategy = make_strategy("gnrm", problem, SolverSettings())
    with pytest.raises(TypeError, match="needs a strategy"):
        solve_load_path(problem, 2)
    with pytest.raises(TypeError, match="whole number of load steps"):
        solve_load_path(strategy, 2.5)
    with pytest.raises(TypeError, match="r = '10' must be a number"):
        ContactSettings(r="10")
    with pytest.raises(TypeError, match="one entry per component"):
        PrescribedDisplacement(np.arange(3, dtype=np.int32), -0.01)


def test_a_free_component_is_spelt_as_in_scenes_too():
    """'free' (the scene's word) and None both leave a component free; other words are refused."""
    facets = np.arange(3, dtype=np.int32)
    assert PrescribedDisplacement(facets, ("free", -0.01)).value == (None, -0.01)
    assert PrescribedDisplacement(facets, [" Free", 0.0, None]).at(0.5) == (None, 0.0, None)
    with pytest.raises(ValueError, match=r"'fixed' is neither a number nor free"):
        PrescribedDisplacement(facets, ("fixed", 0.0))


def test_a_body_tag_without_cell_tags_and_a_facet_mask_are_named():
    """Both ran before and failed late: a tagged body with no cell tags integrated no cell
    (every step "diverged"); a boolean mask was read as the facets 0 and 1."""
    domain = mesh.create_unit_square(MPI.COMM_WORLD, 2, 2)
    law = material("linear", E, NU)
    with pytest.raises(ValueError, match=r"Body 'b' has cell tag 3, but no cell tags were given"):
        Solid(domain, [Body("b", 3, law)])
    plane = RigidPlane(domain, [0.0, 0.0], [0.0, 1.0])
    with pytest.raises(TypeError, match=r"facets must be facet indices.*np.flatnonzero\(mask\)"):
        ObstacleContact(plane, [True, False], ContactSettings())


def _facet_problem(contact_of):
    """A block of 8 x 4 quadrilaterals (76 facets) with ``contact_of(domain, bottom)``."""
    domain = mesh.create_rectangle(MPI.COMM_WORLD, [[0.0, 0.0], [W, H]], [8, 4],
                                   mesh.CellType.quadrilateral)
    bottom = mesh.locate_entities_boundary(domain, 1, lambda x: np.isclose(x[1], 0.0))
    solid = Solid(domain, [Body("block", None, material("linear", E, NU))])
    return ContactProblem(solid, [contact_of(domain, bottom)])


def test_out_of_range_facets_are_named_with_the_valid_range():
    """Before: numpy's "IndexError: index 1000000 is out of bounds for axis 0 with size 76"."""
    from fenics_contact import MortarContact, NodeToSegmentContact

    settings = ContactSettings(r=10.0)
    cases = {
        "ObstacleContact 'floor': facets": lambda d, b: ObstacleContact(
            RigidPlane(d, [0.0, 0.0], [0.0, 1.0]), np.array([3, 10**6]), settings, name="floor"),
        "NodeToSegmentContact 'nts': target_facets": lambda d, b: NodeToSegmentContact(
            b, np.array([-1, 10**6, 76]), settings, name="nts"),
        "MortarContact 'mortar': striker_facets": lambda d, b: MortarContact(
            np.array([76]), b, settings, name="mortar"),
    }
    said = {}
    for where, contact_of in cases.items():
        with pytest.raises(ValueError) as err:
            _facet_problem(contact_of)
        said[where] = str(err.value)
        assert said[where].startswith(f"{where}: ")
        assert "local facet indices run from 0 to 75" in said[where]
    nts = said["NodeToSegmentContact 'nts': target_facets"]
    assert "3 facet index(es) out of range (-1, 76, 1000000)" in nts
