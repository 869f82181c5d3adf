"""The Newton kernel that every strategy shares.

A :class:`NewtonKernel` compiles one :class:`VariationalSystem` (residual
blocks and their ``ufl.derivative`` Jacobian), assembles them into blocked
PETSc objects and takes Newton steps with a direct solver (MUMPS). It knows
nothing of contact; strategies decide when to update, stop or cut back.
"""

from __future__ import annotations

import itertools

import numpy as np
from dolfinx import fem
from dolfinx.fem import petsc as fem_petsc

from petsc4py import PETSc

from fenics_contact.problem import VariationalSystem

_prefix_counter = itertools.count()


class NewtonKernel:
    """Assemble-and-solve machinery for one system F(x) = 0.

    Counts linear solves; the residual norm is the Euclidean norm of the
    assembled residual (Dirichlet rows hold x - x_D), i.e. the discrete L2
    norm of the static out-of-balance force.
    """

    def __init__(self, system: VariationalSystem, linear_solver: str = "mumps") -> None:
        self.system = system
        self.unknowns = system.unknowns
        self.bcs = system.bcs
        self.F = fem.form(system.residuals, entity_maps=system.entity_maps)
        jacobian = fem.forms.derivative_block(system.residuals, system.unknowns)
        self.J = fem.form(jacobian, entity_maps=system.entity_maps)
        self.A = fem_petsc.create_matrix(self.J, kind="mpi")
        spaces = [u.function_space for u in self.unknowns]
        self.b = fem_petsc.create_vector(spaces, kind="mpi")
        self.x = fem_petsc.create_vector(spaces, kind="mpi")
        self.dx = fem_petsc.create_vector(spaces, kind="mpi")
        self._blocks = self.b.getAttr("_blocks")
        prefix = f"fc_{system.name}_{next(_prefix_counter)}_"
        self.ksp = PETSc.KSP().create(self.A.comm)
        self.ksp.setOptionsPrefix(prefix)
        self.ksp.setOperators(self.A)
        self.ksp.setType("preonly")
        pc = self.ksp.getPC()
        pc.setType("lu")
        pc.setFactorSolverType(linear_solver)
        self.A.setOptionsPrefix(f"{prefix}A_")
        self.ksp.setFromOptions()
        self.linear_solves = 0
        self.residual_norm = np.inf

    def _pull(self) -> None:
        """Copy the unknown Functions into the work vector x."""
        fem_petsc.assign(self.unknowns, self.x)

    def _push(self) -> None:
        """Copy x back into the unknown Functions (ghosts updated)."""
        fem_petsc.assign(self.x, self.unknowns)
        for u in self.unknowns:
            u.x.scatter_forward()

    def assemble_residual(self) -> float:
        """Assemble F at the current unknowns; return and store its norm."""
        self._pull()
        fem_petsc.assemble_residual(
            None, self.x, self.b, self.unknowns, self.F, self.J, self.bcs, self._blocks
        )
        self.residual_norm = float(self.b.norm())
        return self.residual_norm

    def block_norms(self) -> list[float]:
        """Norm of each residual block (after :meth:`assemble_residual`)."""
        offsets = []
        local = self.b.getArray(readonly=True)
        out = []
        start = 0
        for u in self.unknowns:
            im = u.function_space.dofmap.index_map
            n = im.size_local * u.function_space.dofmap.index_map_bs
            offsets.append((start, start + n))
            out.append(float(np.sum(local[start : start + n] ** 2)))
            start += n
        comm = self.A.comm.tompi4py()
        return [float(np.sqrt(comm.allreduce(v))) for v in out]

    def newton_step(self, damping: float = 1.0) -> bool:
        """Solve J dx = F at the current unknowns and set x <- x - damping dx.

        Requires a preceding :meth:`assemble_residual`. Returns False when the
        linear solve fails or produces non-finite values (unknowns untouched).
        """
        fem_petsc.assemble_jacobian(None, self.x, self.A, None, self.unknowns, self.J, None,
                                    self.bcs)
        try:
            self.ksp.solve(self.b, self.dx)
        except PETSc.Error:
            return False
        self.linear_solves += 1
        if self.ksp.getConvergedReason() < 0:
            return False
        if not np.all(np.isfinite(self.dx.getArray(readonly=True))):
            return False
        self.x.axpy(-damping, self.dx)
        self._push()
        return True

    def destroy(self) -> None:
        """Free the PETSc objects."""
        for obj in (self.ksp, self.A, self.b, self.x, self.dx):
            obj.destroy()
