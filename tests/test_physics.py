"""Unit checks of the UFL physics: energies, gaps, contact terms, nodal evaluation."""

import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh

from mpi4py import MPI

from fenics_contact.model.contact import (
    ContactSettings,
    ContactSurface,
    augmented_lagrangian_energy,
    penalty_energy,
)
from fenics_contact.model.materials import LinearElastic, NeoHookean, SaintVenantKirchhoff, material
from fenics_contact.model.obstacles import RigidBall, RigidPlane

E, NU = 210.0, 0.3


def _square():
    return mesh.create_unit_square(MPI.COMM_WORLD, 4, 4, mesh.CellType.quadrilateral)


def _energy(law, grad_u):
    """Integrate psi over the unit square for the homogeneous displacement u = G x."""
    domain = _square()
    V = fem.functionspace(domain, ("Lagrange", 1, (2,)))
    u = fem.Function(V)
    G = np.asarray(grad_u)
    u.interpolate(lambda x: G @ x[:2])
    value = fem.assemble_scalar(fem.form(law.strain_energy(u) * ufl.dx))
    return domain.comm.allreduce(value, op=MPI.SUM)


def test_svk_energy_matches_closed_form_for_uniaxial_stretch():
    stretch = 1.3
    e11 = 0.5 * (stretch**2 - 1)
    law = SaintVenantKirchhoff(E, NU)
    expected = 0.5 * law.lmbda * e11**2 + law.mu * e11**2
    assert _energy(law, [[stretch - 1, 0], [0, 0]]) == pytest.approx(expected, rel=1e-12)


def test_neo_hookean_energy_is_zero_at_rest_and_matches_closed_form():
    law = NeoHookean(E, NU)
    assert abs(_energy(law, [[0, 0], [0, 0]])) < 1e-12
    s = 1.2  # plane strain uniaxial: I1 = s^2 + 2, J = s
    expected = 0.5 * law.mu * (s**2 - 1) - law.mu * np.log(s) + 0.5 * law.lmbda * np.log(s) ** 2
    assert _energy(law, [[s - 1, 0], [0, 0]]) == pytest.approx(expected, rel=1e-12)


def test_all_laws_agree_at_small_strain():
    g = 1e-6 * np.array([[1.0, 0.3], [-0.2, 0.5]])
    linear = _energy(LinearElastic(E, NU), g)
    for law in (SaintVenantKirchhoff(E, NU), NeoHookean(E, NU)):
        assert _energy(law, g) == pytest.approx(linear, rel=1e-5)


def test_bad_material_input_is_rejected_with_the_fix():
    with pytest.raises(ValueError, match=r"nu = 0.5: must be < 0.5.*use nu <= 0.45"):
        SaintVenantKirchhoff(E, 0.5)
    with pytest.raises(ValueError, match=r"E = -1.0: must be finite and > 0"):
        NeoHookean(-1.0, 0.3)
    with pytest.raises(ValueError, match="svk"):
        material("rubber", E, NU)
    with pytest.raises(ValueError, match=r"r = 0\.0: must be finite and > 0"):
        ContactSettings(r=0.0)


def test_gaps_of_plane_and_ball_follow_their_definitions():
    domain = _square()
    plane = RigidPlane(domain, [0.0, -0.1], [0.0, 2.0])
    ball = RigidBall(domain, [0.5, -1.0], 0.5)
    cradle = RigidBall(domain, [0.5, 2.0], 3.0, inside=True)
    pts = np.array([[0.0, 0.0], [0.5, 0.0], [1.0, 1.0]])
    assert np.allclose(plane.gap_value(pts), [0.1, 0.1, 1.1])
    assert np.allclose(ball.gap_value(pts), np.linalg.norm(pts - [0.5, -1.0], axis=1) - 0.5)
    assert np.allclose(cradle.gap_value(pts), 3.0 - np.linalg.norm(pts - [0.5, 2.0], axis=1))
    plane.translate_to([0.0, 0.05])
    assert np.allclose(plane.gap_value(pts), [0.05, 0.05, 1.05])


def test_nodal_evaluation_returns_exact_vertex_values_of_the_gap():
    domain = _square()
    fdim = 1
    bottom = mesh.locate_entities_boundary(domain, fdim, lambda x: np.isclose(x[1], 0.0))
    surface = ContactSurface(domain, bottom)
    ball = RigidBall(domain, [0.5, -1.0], 0.9)
    x = ufl.SpatialCoordinate(domain)
    values = surface.nodal(surface.nodal_form(ball.gap(x)))
    coords = surface.Q.tabulate_dof_coordinates()[: values.size, :2]
    assert np.allclose(values, ball.gap_value(coords), atol=1e-13)
    assert surface.h == pytest.approx(0.25)


def test_contact_terms_are_consistent():
    """The AL density with lam = 0 is the penalty density."""
    r = 7.0
    for g in (-0.3, 0.0, 0.2):
        pen = float(ufl.algorithms.expand_derivatives(penalty_energy(ufl.as_ufl(g), r)))
        al = float(augmented_lagrangian_energy(ufl.as_ufl(g), ufl.as_ufl(0.0), r))
        assert pen == pytest.approx(al, abs=1e-15)


def test_round_off_multipliers_after_lift_off_are_not_contact():
    """Every node lifted off: multipliers of 1e-30 E are round-off, not pressure."""
    from pathlib import Path

    from fenics_contact.scene.build import build_problem
    from fenics_contact.scene.schema import load_scene

    problem = build_problem(load_scene(Path(__file__).parents[1] / "scenes" / "paper_ex2.toml"))
    contact = problem.contacts[0]
    E = contact.modulus
    contact.lam.x.array[:] = -1e-30 * E  # all that is left once the body came off
    assert contact.contact_state().active_count == 0
    assert np.all(contact.contact_state().pressure == 0.0)
    contact.lam.x.array[:] = -1e-9 * E  # small, but a pressure
    assert contact.contact_state().active_count > 0
