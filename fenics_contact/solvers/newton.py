"""The Newton kernel that every strategy shares.

A :class:`NewtonKernel` compiles one :class:`VariationalSystem` (residual
blocks and their ``ufl.derivative`` Jacobian), assembles them into blocked
PETSc objects and takes Newton steps with a configurable linear solver
(:mod:`fenics_contact.solvers.linear`: MUMPS by default, or GMRES with a
Schur field split and algebraic multigrid). It knows nothing of contact;
strategies decide when to update, stop or cut back. Its
:class:`~fenics_contact.solvers.timing.KernelTimings` split the time spent
into compilation, assembly and linear solves.
"""

from __future__ import annotations

import itertools
import weakref

import numpy as np
from dolfinx import fem, la
from dolfinx.fem import petsc as fem_petsc

from petsc4py import PETSc

from fenics_contact.model.form_batches import form_together
from fenics_contact.model.problem import VariationalSystem
from fenics_contact.solvers.linear import (
    EisenstatWalker,
    LinearSolverSettings,
    PreconditionerLag,
    configure_ksp,
)
from fenics_contact.solvers.timing import KernelTimings, stopwatch

_prefix_counter = itertools.count()


def _forget_options(names: list[str]) -> None:
    """Remove options from PETSc's database (those a kernel put there for its solver)."""
    db = PETSc.Options()
    for name in names:
        if db.hasName(name):
            db.delValue(name)
    names.clear()


class NewtonKernel:
    """Assemble-and-solve machinery for one system F(x) = 0.

    Counts linear solves; the residual norm is the Euclidean norm of the
    assembled residual (Dirichlet rows hold x - x_D), i.e. the discrete L2
    norm of the static out-of-balance force.

    Args:
        system: residual blocks, unknowns and boundary conditions.
        linear: linear solver settings; direct LU (MUMPS) when None.
    """

    #: Hand A to the linear solver again before each solve.
    _operator_each_step = False

    def __init__(
        self, system: VariationalSystem, linear: LinearSolverSettings | None = None
    ) -> None:
        self._start(system)
        with stopwatch(self.timings, "compile_s"):
            jacobian = fem.forms.derivative_block(system.residuals, system.unknowns)
            self.F, self.J = form_together(
                [list(system.residuals), jacobian], entity_maps=system.entity_maps,
                jit_options=system.jit_options)
            self.A = fem_petsc.create_matrix(self.J, kind="mpi")
            self._work_vectors()
        self._prefix = f"fc_{system.name}_{next(_prefix_counter)}_"
        self.A.setOptionsPrefix(f"{self._prefix}A_")
        self.set_linear_solver(linear or LinearSolverSettings())

    def _start(self, system: VariationalSystem) -> None:
        """The state every kernel starts from: the system, empty timings and counters."""
        self.timings = KernelTimings()
        self.system = system
        self.unknowns = system.unknowns
        self.bcs = system.bcs
        self.ksp: PETSc.KSP | None = None
        self._keep: tuple = ()
        self.linear_solves = 0
        self.residual_norm = np.inf
        #: Norm of the Dirichlet rows (x - x_D, length) of the last assembled residual.
        self.dirichlet_norm = 0.0
        self.forcing: EisenstatWalker | None = None
        self.lag: PreconditionerLag | None = None
        #: The linear model's exact contact set at each step
        #: (:class:`~fenics_contact.solvers.complementarity.ExactContactSet`); None: the sign rule.
        self.complementarity = None
        self._built = False
        #: Krylov tolerance of each linear solve (iterative solver).
        self.krylov_rtols: list[float] = []
        #: Options this kernel put into PETSc's database; removed with the kernel
        #: (destroyed or collected), so none outlives its solver.
        self._options: list[str] = []
        self._forget = weakref.finalize(self, _forget_options, self._options)

    def _work_vectors(self) -> None:
        """Vectors b (residual), x (unknowns) and dx (Newton update) on the unknowns' spaces."""
        self.spaces = [u.function_space for u in self.unknowns]
        self.b = fem_petsc.create_vector(self.spaces, kind="mpi")
        self.x = fem_petsc.create_vector(self.spaces, kind="mpi")
        self.dx = fem_petsc.create_vector(self.spaces, kind="mpi")
        self._blocks = self.b.getAttr("_blocks")

    # -- linear solver -------------------------------------------------------
    def set_linear_solver(self, settings: LinearSolverSettings) -> None:
        """(Re)create the linear solver; the matrix and vectors are kept."""
        if self.ksp is not None:
            self.ksp.destroy()
        _forget_options(self._options)  # the previous solver's defaults must not win
        self.linear = settings
        self.ksp = PETSc.KSP().create(self.A.comm)
        self.ksp.setOptionsPrefix(self._prefix)
        self.ksp.setOperators(self.A)
        before = set(PETSc.Options().getAll())
        self._keep = configure_ksp(self.ksp, self.A, self.spaces, settings)
        self._options.extend(
            name for name in PETSc.Options().getAll()
            if name.startswith(self._prefix) and name not in before
        )
        self.forcing = (
            EisenstatWalker(settings.eta_max, settings.rtol) if settings.inexact else None
        )
        self.lag = PreconditionerLag(settings.lag_factor) if settings.lagged else None

    def begin_solve(self) -> None:
        """A new nonlinear solve starts: the forcing term starts afresh.

        So does the preconditioner, unless it is kept along the path.
        """
        if self.forcing is not None:
            self.forcing.reset()
        if self.complementarity is not None:
            self.complementarity.begin()
        if self.lag is not None and self.linear.reuse_preconditioner == "step":
            self.lag.reset()

    def _reuse_preconditioner(self, flag: bool) -> None:
        """Keep (or rebuild at the next set-up) the displacement block's multigrid."""
        pc = self.ksp.getPC()
        if pc.getType() == PETSc.PC.Type.FIELDSPLIT:
            try:
                sub = pc.getFieldSplitSubKSP()
            except PETSc.Error:  # not set up yet: nothing to keep
                return
            sub[0].getPC().setReusePreconditioner(flag)
        else:
            pc.setReusePreconditioner(flag)

    # -- state transfer --------------------------------------------------------
    def _pull(self) -> None:
        """Copy the unknown Functions into the work vector x."""
        fem_petsc.assign(self.unknowns, self.x)

    def _push(self) -> None:
        """Copy x back into the unknown Functions (ghosts updated)."""
        fem_petsc.assign(self.x, self.unknowns)
        for u in self.unknowns:
            u.x.scatter_forward()

    # -- Newton ------------------------------------------------------------------
    def assemble_residual(self) -> float:
        """Assemble F at the current unknowns; return and store its norm."""
        self.residual_norm = self._assemble_b()
        self.timings.residuals += 1
        held = self.b.getArray(readonly=True)[self._support_dofs()]
        comm = self.b.comm.tompi4py()
        self.dirichlet_norm = float(np.sqrt(comm.allreduce(float(held @ held))))
        return self.residual_norm

    def force_norm(self, norm: float, stiffness: float) -> float:
        """``norm`` with the last residual's Dirichlet rows weighted by ``stiffness`` (force).

        ``norm`` is a residual norm that holds the rows of the last
        :meth:`assemble_residual` (x - x_D, length) among force rows; they are
        replaced by ``stiffness`` (x - x_D), so every row is a force and the
        result scales with E for the same problem in any units.
        """
        d = self.dirichlet_norm
        return float(np.sqrt(max(norm * norm - d * d, 0.0) + (stiffness * d) ** 2))

    def _assemble_b(self) -> float:
        """Hook: the residual F into b (Dirichlet rows x - x_D); return its norm."""
        with stopwatch(self.timings, "residual_s"):
            self._pull()
            fem_petsc.assemble_residual(
                None, self.x, self.b, self.unknowns, self.F, self.J, self.bcs, self._blocks
            )
            if self.system.supports is not None:  # asked for only when a report needs it
                self.system.supports(self._support_dofs(), self._support_residual)
            return float(self.b.norm())

    def _support_dofs(self) -> np.ndarray:
        """The owned displacement dofs of the Dirichlet rows (local, unrolled)."""
        if getattr(self, "_held", None) is None:
            V = self.unknowns[0].function_space
            n_u = V.dofmap.index_map.size_local * V.dofmap.index_map_bs
            held = [bc.dof_indices()[0][: bc.dof_indices()[1]] for bc in self.bcs]
            held = np.unique(np.concatenate(held)) if held else np.zeros(0, np.int32)
            self._held = held[held < n_u]
        return self._held

    def _support_residual(self) -> np.ndarray:
        """The displacement residual on the Dirichlet rows before they are set (force).

        At a solution the rows hold x = x_D, so the lifting adds nothing there:
        these are the supports' forces on the bodies, contact at a held node
        included. One assembly of the displacement block (called on demand).
        """
        form = self.F[0] if isinstance(self.F, list | tuple) else self.F
        vec = fem.assemble_vector(form)
        vec.scatter_reverse(la.InsertMode.add)
        return vec.array[self._support_dofs()].copy()

    def _assemble_A(self) -> None:
        """Hook: the Jacobian at the current unknowns into A, Dirichlet rows set."""
        with stopwatch(self.timings, "jacobian_s"):
            fem_petsc.assemble_jacobian(
                None, self.x, self.A, None, self.unknowns, self.J, None, self.bcs
            )
        self.timings.jacobians += 1

    def block_norms(self) -> list[float]:
        """Norm of each residual block (after :meth:`assemble_residual`)."""
        local = self.b.getArray(readonly=True)
        out = []
        start = 0
        for u in self.unknowns:
            im = u.function_space.dofmap.index_map
            n = im.size_local * u.function_space.dofmap.index_map_bs
            out.append(float(np.sum(local[start : start + n] ** 2)))
            start += n
        comm = self.A.comm.tompi4py()
        return [float(np.sqrt(comm.allreduce(v))) for v in out]

    def newton_step(self, damping: float = 1.0, tolerance: float = 0.0) -> bool:
        """Solve J dx = F at the current unknowns and set x <- x - damping dx.

        Requires a preceding :meth:`assemble_residual`. Returns False when the
        linear solve fails or produces non-finite values (unknowns untouched).
        Subclasses change what J and F are through :meth:`_assemble_A` and
        :meth:`_assemble_b`. ``tolerance`` is the Newton tolerance of the
        solve (residual norm), which bounds the Eisenstat-Walker forcing term
        from below (an inexact solve need not go below it); 0 when unknown.
        """
        if self.complementarity is not None and self.complementarity.prepare():
            self._pull()  # the candidates set in contact: x takes their multipliers
        self._assemble_A()
        if self.complementarity is not None:
            self.complementarity.settle()  # their rows of b, without assembling it again
        iterative = self.linear.kind != "direct"
        if self.forcing is not None:
            self.ksp.setTolerances(rtol=self.forcing(self.residual_norm, tolerance))
        if iterative:
            self.krylov_rtols.append(self.ksp.getTolerances()[0])
        if not self._linear_solve():
            return False
        if self.ksp.getConvergedReason() < 0 and self.lag is not None and not self._built:
            # a kept hierarchy that no longer converges: rebuild it and solve again
            self.lag.reset()
            if not self._linear_solve():
                return False
        if self.ksp.getConvergedReason() < 0:
            return False
        if not np.all(np.isfinite(self.dx.getArray(readonly=True))):
            return False
        if self.complementarity is not None:
            with stopwatch(self.timings, "solve_s"):
                self.complementarity.correct()
        self.x.axpy(-damping, self.dx)
        self._push()
        return True

    def take_back(self, fraction: float) -> None:
        """Take back that fraction of the last Newton step: x <- x + fraction dx."""
        self.x.axpy(fraction, self.dx)
        self._push()

    def _linear_solve(self) -> bool:
        """Set up the solver (keeping the hierarchy if the lag allows) and solve into dx.

        Returns False when PETSc stopped with an error; the caller reads the
        converged reason otherwise.
        """
        t = self.timings
        self._built = build = self.lag is not None and self.lag.rebuild
        try:
            with stopwatch(t, "setup_s"):
                if self._operator_each_step:
                    self.ksp.setOperators(self.A)
                if self.lag is not None:
                    self._reuse_preconditioner(not build)
                self.ksp.setUp()
                self.ksp.getPC().setUp()
            with stopwatch(t, "solve_s"):
                self.ksp.solve(self.b, self.dx)
        except PETSc.Error:
            # A solve that stops with an error (e.g. a singular factorisation) leaves
            # b locked read-only: the next assembly into it would fail ("error code 73").
            self.b = self.b.duplicate()
            self._solver_afresh()
            return False
        if self.ksp.getPC().getFailedReason() != 0:  # e.g. a zero pivot
            self._solver_afresh()
            return False
        self.linear_solves += 1
        t.linear_solves += 1
        if self.linear.kind != "direct":
            t.krylov_iterations += self.ksp.getIterationNumber()
        if self.lag is not None:
            rhs = self.b.norm()  # the Krylov start residual (zero initial guess)
            reduction = self.ksp.getResidualNorm() / rhs if rhs > 0 else 0.0
            self.lag.record(self.ksp.getIterationNumber(), reduction, build)
        return True

    def _solver_afresh(self) -> None:
        """A new linear solver after a failed one (same settings, no kept state).

        A factorisation that failed leaves its solver unusable: MUMPS skips
        every later numeric factorisation after one that failed, and the next
        solve stops with INFOG(1) = -3, so every cut-back attempt of the load
        step would fail at its first iteration.
        """
        self.set_linear_solver(self.linear)

    def destroy(self) -> None:
        """Free the PETSc objects and remove the solver's options from the database."""
        self._forget()
        for obj in (self.ksp, self.A, self.b, self.x, self.dx):
            obj.destroy()
