"""Contact terms integrated only where they can act, exactly.

- ``restrict`` rebuilds a compiled form over fewer facets of some tag values
  and leaves every other integral as it was (against forms written over the
  kept facets directly; on 1 and 2 ranks).
- A role's own tag values leave out the facets it shares with another role.
- (The two-body kernel's use of it: tests/test_condensed_pattern.py.)
"""

from __future__ import annotations

import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh

from mpi4py import MPI

import fenics_contact  # noqa: F401  (before dolfinx)
from fenics_contact.model.tags import facet_roles, own_tag_values
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
