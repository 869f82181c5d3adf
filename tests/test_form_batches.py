"""The blocks of a block form compiled together: one module, the same matrices.

Measured (2026-11-27, empty form cache, time to the first Newton iteration):
the frictional node-to-segment hemispheres 30.6 -> 27.6 s, the frictionless
ones 9.4 -> 7.1 s, the Hertz cylinder 2.3 -> 1.8 s (docs/benchmarks.md).
"""

from __future__ import annotations

import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh
from dolfinx.fem import petsc as fem_petsc

from mpi4py import MPI

import fenics_contact  # noqa: F401  (before petsc4py)
from fenics_contact.model.form_batches import form_together


def _blocks():
    domain = mesh.create_unit_square(MPI.COMM_WORLD, 6, 5)
    V = fem.functionspace(domain, ("Lagrange", 1, (2,)))
    Q = fem.functionspace(domain, ("Lagrange", 1))
    u, p = fem.Function(V), fem.Function(Q)
    u.interpolate(lambda x: np.vstack([0.1 * x[0] * x[1], 0.05 * x[0] ** 2]))
    p.interpolate(lambda x: 1.0 + x[0])
    v, q = ufl.TestFunction(V), ufl.TestFunction(Q)
    F = ufl.Identity(2) + ufl.grad(u)
    residuals = [ufl.inner(p * F, ufl.grad(v)) * ufl.dx + ufl.det(F) * v[0] * ufl.ds,
                 (ufl.det(F) - p ** 2) * q * ufl.dx]
    return residuals, fem.forms.derivative_block(residuals, [u, p])


@pytest.mark.mpi
def test_blocks_compiled_together_assemble_the_same_matrix_from_one_module():
    residuals, jacobian = _blocks()
    F_sep, J_sep = fem.form(residuals), fem.form(jacobian)
    F_one, J_one = form_together([residuals, jacobian])
    modules = {id(f.module) for f in [*F_one, *(b for row in J_one for b in row)]}
    assert len(modules) == 1
    A_sep = fem_petsc.assemble_matrix(J_sep, kind="mpi")
    A_one = fem_petsc.assemble_matrix(J_one, kind="mpi")
    A_sep.assemble()
    A_one.assemble()
    A_one.axpy(-1.0, A_sep)
    assert A_one.norm() <= 1e-14 * A_sep.norm()
    b_sep = fem_petsc.assemble_vector(F_sep, kind="mpi")
    b_one = fem_petsc.assemble_vector(F_one, kind="mpi")
    b_one.axpy(-1.0, b_sep)
    assert b_one.norm() <= 1e-14 * b_sep.norm()


def test_a_single_form_is_compiled_as_usual():
    residuals, _ = _blocks()
    compiled = form_together(residuals[0])
    assert isinstance(compiled, fem.Form)
