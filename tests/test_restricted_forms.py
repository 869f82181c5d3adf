"""Contact terms integrated only where they can act, exactly.

- ``restrict`` rebuilds a compiled form over fewer facets of some tag values
  and leaves every other integral as it was (against forms written over the
  kept facets directly; on 1 and 2 ranks).
- A role's own tag values leave out the facets it shares with another role.
- On two cylinders pressed together the two-body kernel integrates the pair
  over a fraction of the striker facets, every facet of a node in contact
  among them, and its condensed residual and matrix are those of the whole
  surface.
"""

from __future__ import annotations

import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh

from mpi4py import MPI

import fenics_contact  # noqa: F401  (before dolfinx)
from benchmarks import cases
from fenics_contact.model.pairs import DeformablePair
from fenics_contact.model.tags import facet_roles, own_tag_values
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings
from fenics_contact.solvers.restricted_forms import FacetLimit, restrict


@pytest.mark.mpi
def test_restrict_keeps_the_chosen_facets_and_every_other_integral() -> None:
    from dolfinx import la

    domain = mesh.create_unit_cube(MPI.COMM_WORLD, 3, 3, 3)
    fdim = domain.topology.dim - 1
    domain.topology.create_connectivity(fdim, fdim + 1)
    boundary = mesh.exterior_facet_indices(domain.topology)
    midpoints = mesh.compute_midpoints(domain, fdim, boundary)
    values = np.where(midpoints[:, 2] < 1e-12, 3, 5).astype(np.int32)  # bottom: 3
    tags = mesh.meshtags(domain, fdim, boundary, values)
    V = fem.functionspace(domain, ("Lagrange", 1))
    v = ufl.TestFunction(V)
    x = ufl.SpatialCoordinate(domain)
    ds = ufl.Measure("ds", domain=domain, subdomain_data=tags)
    form = fem.form((1 + x[0]) * v * ds(3) + 2 * v * ds((3, 5)) + v * ufl.dx)
    bottom = tags.find(3)
    kept = bottom[midpoints[values == 3][:, 0] < 0.5]  # half the bottom
    limited = restrict(form, [FacetLimit((3,), kept)], [])

    half = mesh.meshtags(domain, fdim, np.sort(kept), np.full(kept.size, 3, np.int32))
    ds_half = ufl.Measure("ds", domain=domain, subdomain_data=half)
    expected = [fem.form((3 + x[0]) * v * ds_half(3)), fem.form(2 * v * ds(5) + v * ufl.dx)]

    def owned(f: fem.Form) -> np.ndarray:
        vector = fem.assemble_vector(f)
        vector.scatter_reverse(la.InsertMode.add)
        return vector.array[: vector.index_map.size_local]

    got, want, whole = owned(limited), owned(expected[0]) + owned(expected[1]), owned(form)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-14)
    comm = domain.comm
    assert comm.allreduce(float(np.abs(whole - got).max(initial=0.0)), op=MPI.MAX) > 1e-3
    n_kept = comm.allreduce(kept.size, op=MPI.SUM)
    assert 0 < n_kept < comm.allreduce(bottom.size, op=MPI.SUM)


def test_own_tag_values_leave_out_shared_facets() -> None:
    domain = mesh.create_unit_square(MPI.COMM_SELF, 4, 4)
    fdim = 1
    domain.topology.create_connectivity(fdim, 2)
    boundary = mesh.exterior_facet_indices(domain.topology)
    mid = mesh.compute_midpoints(domain, fdim, boundary)
    bottom = boundary[mid[:, 1] < 1e-12]
    left_half = bottom[mid[mid[:, 1] < 1e-12][:, 0] < 0.5]  # a traction on part of it
    top = boundary[mid[:, 1] > 1 - 1e-12]
    _, ids = facet_roles(domain, [bottom, top, left_half])
    own = own_tag_values(ids)
    assert len(ids[0]) == 2 and len(own[0]) == 1  # the shared value is not the contact's own
    assert own[1] == ids[1]
    assert own[2] == ()
    shared = set(ids[0]) & set(ids[2])
    assert shared and not shared & set(own[0])


@pytest.fixture(scope="module")
def pressed_cylinders():
    problem = cases.build(cases.two_cylinders(0.02, push=0.02), 1.0)
    strategy = make_strategy("gnrm", problem, SolverSettings())
    for i in (1, 2, 3):
        problem.set_load(i / 3)
        assert strategy.solve().converged
    (pair,) = [c.pair for c in problem.contacts if isinstance(getattr(c, "pair", None),
                                                             DeformablePair)]
    return problem, strategy.kernel, pair


def _condensed(kernel) -> tuple[np.ndarray, np.ndarray]:
    kernel._pull()
    kernel._assemble_b()
    kernel._assemble_A()
    indptr, indices, values = kernel.A.getValuesCSR()
    n = kernel.A.getSize()[0]
    dense = np.zeros((n, n))
    dense[np.repeat(np.arange(n), np.diff(indptr)), indices] = values
    return kernel.b.getArray().copy(), dense


def test_pair_integrated_only_where_it_can_act(pressed_cylinders) -> None:
    problem, kernel, pair = pressed_cylinders
    (limit,) = kernel._limits
    striker = pair.surface.facets
    assert 0 < limit.facets.size < striker.size  # 28 of 38
    contact = next(c for c in problem.contacts if getattr(c, "pair", None) is pair)
    pressed = pair.multiplier() < 0.0  # serial: every node is owned
    assert pressed.sum() >= 3
    cells = pair.W.dofmap.list
    touching = pair._cell_facet[: cells.shape[0]][pressed[cells].any(axis=1)]
    assert np.isin(touching, limit.facets).all()
    assert set(limit.ids) == set(contact.own_ids)

    # the extended matrix holds every facet's entries (P^T A P reuses its symbolic
    # product: entries a later, wider assembly added would be left out of it)
    used = kernel.A_ext.getInfo()["nz_used"]
    kernel._assemble_ext_jacobian(kernel._J_all)  # every facet: no entry may be new
    assert kernel.A_ext.getInfo()["nz_used"] == used

    b_limited, A_limited = _condensed(kernel)
    limited = kernel.F_ext, kernel.J_ext
    try:
        kernel.F_ext, kernel.J_ext = kernel._F_all, kernel._J_all  # every striker facet
        b_all, A_all = _condensed(kernel)
    finally:
        kernel.F_ext, kernel.J_ext = limited
    assert kernel.F_ext is limited[0]  # the limits held: the whole forms were used above
    np.testing.assert_allclose(b_limited, b_all, rtol=0, atol=1e-13 * np.abs(b_all).max())
    np.testing.assert_allclose(A_limited, A_all, rtol=0, atol=1e-13 * np.abs(A_all).max())


def test_a_step_sets_in_contact_only_nodes_the_pair_couples(pressed_cylinders) -> None:
    """The exact contact set may close only nodes whose terms the kernel integrates."""
    problem, _, pair = pressed_cylinders
    contact = next(c for c in problem.contacts if getattr(c, "pair", None) is pair)
    gaps = contact.surface.nodal(contact._gap_form)
    allowed = contact.may_close(gaps)
    assert allowed.shape == gaps.shape
    assert 0 < allowed.sum() < allowed.size
    lam_of_w = contact._lam_of_w[: pair.n_owned]
    np.testing.assert_array_equal(allowed[lam_of_w], pair._coupled)
    # the open nodes left out are more than a facet size away; those near all count
    assert np.all(allowed[gaps < 0.5 * pair._size])
