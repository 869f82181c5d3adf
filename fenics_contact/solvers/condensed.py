"""The Newton kernel for two-body systems: extended UFL blocks condensed by selection.

A two-body :class:`~fenics_contact.model.problem.VariationalSystem` has the
usual unknowns (u[, lam]) plus ``extras`` w_k, the displacements of each
striker node's assigned target vertices, with w_k = S_k u (S_k a 0/1
selection). The kernel assembles the extended residual R_ext and Jacobian
J_ext (every block a ``ufl.derivative``, empty blocks skipped) and condenses
them with P = [[I, 0], [0, I], [S_1, 0], ...]:

    R = P^T R_ext,    J = P^T J_ext P     (PETSc MatPtAP)

P holds explicit zeros for the couplings a node may reach next (the
transfer's ``reachable_blocks``: the vertices of the facets around its
own) and keeps the pattern of every assignment it has held, so that most
changes of assignment change values only: the symbolic product, the matrix
and the linear solver (a direct solver's analysis, a multigrid hierarchy's
aggregates and prolongators) are kept. The symbolic product is redone only
when an assignment reaches a column the pattern lacks, or when the kept
zeros outgrow the fresh pattern (:data:`KEPT_ZEROS`).
Dirichlet rows and columns are set after the product
(S couples target vertices that may carry prescribed values): rows hold
x - x_D and the columns are eliminated with PETSc's ``zeroRowsColumns``,
which also lifts the right-hand side. The residual norm is that of the
condensed residual with those rows, the measure of :class:`NewtonKernel`.

A frictionless node-to-segment pair acts only near its coupled nodes; the
kernel integrates the pair's terms there (:mod:`.restricted_forms`, the
transfer's ``acting_facets``), except the multipliers' own blocks, which
hold lam / r = 0 at every open node. J_ext is assembled over every facet
once first, so that its PETSc pattern, and with it the symbolic product,
never changes.
"""

from __future__ import annotations

import itertools

import numpy as np
import scipy.sparse as sp
import ufl.algorithms
from dolfinx import cpp as _cpp
from dolfinx import fem
from dolfinx.fem import petsc as fem_petsc

from mpi4py import MPI
from petsc4py import PETSc

from fenics_contact.model.form_batches import form_together
from fenics_contact.model.problem import VariationalSystem
from fenics_contact.solvers.linear import LinearSolverSettings
from fenics_contact.solvers.newton import NewtonKernel
from fenics_contact.solvers.restricted_forms import FacetLimit, restrict
from fenics_contact.solvers.timing import stopwatch

_prefix_counter = itertools.count()

#: The pattern of P starts afresh when the zeros kept from earlier patterns would
#: outnumber the fresh pattern's entries on the extras by more than this factor.
KEPT_ZEROS = 2.0


def _nonempty_blocks(residuals: list[ufl.Form], unknowns: list) -> list[list[ufl.Form | None]]:
    """The derivative blocks d F_i / d w_j, ``None`` where F_i does not hold w_j.

    Each residual is expanded once and the block is kept where its expanded
    integrand holds the coefficient: n expansions of first derivatives,
    rather than an expansion of each of the n x m second-derivative blocks
    (seconds on a warm start for the large contact forms). Every residual of
    the package depends on what it holds through values, not only through
    conditions, so a held coefficient gives a non-empty block.
    """
    out = []
    for residual in residuals:
        if residual is None:
            out.append([None] * len(unknowns))
            continue
        row = fem.forms.derivative_block([residual], unknowns)[0]
        held = set(ufl.algorithms.expand_derivatives(residual).coefficients())
        out.append([f if f is not None and w in held else None
                    for w, f in zip(unknowns, row, strict=True)])
    return out


def _part(form: ufl.Form, bodies: ufl.Mesh, *, volume: bool) -> ufl.Form | None:
    """The bodies' cell integrals of ``form`` (volume) or the others; None when none.

    A cell integral over another mesh (a contact submesh) is a surface term.
    """
    kept = [i for i in form.integrals()
            if (i.integral_type() == "cell" and i.ufl_domain() == bodies) == volume]
    return ufl.Form(kept) if kept else None


def _every_row_and_column(blocks: list[list[ufl.Form | None]]) -> bool:
    """Whether every row and every column of a block structure holds a block."""
    rows = all(any(f is not None for f in row) for row in blocks)
    columns = all(any(row[j] is not None for row in blocks) for j in range(len(blocks[0])))
    return rows and columns


def _owned(space: fem.FunctionSpace) -> int:
    return space.dofmap.index_map.size_local * space.dofmap.index_map_bs


class CondensedKernel(NewtonKernel):
    """Newton on (u[, lam]) of a system extended by selected target displacements.

    The Newton step is :meth:`NewtonKernel.newton_step`; the hooks
    :meth:`_assemble_b` and :meth:`_assemble_A` condense F and J with P.
    """

    #: A may be a new matrix after a search changed P.
    _operator_each_step = True

    def __init__(
        self, system: VariationalSystem, linear: LinearSolverSettings | None = None
    ) -> None:
        self._start(system)
        self.extras = system.extras
        self.transfer = system.transfer
        ext = [*self.unknowns, *self.extras]
        comm = self.unknowns[0].function_space.mesh.comm
        self._comm = comm
        with stopwatch(self.timings, "compile_s"):
            # the bodies' volume terms and the surface terms in forms of their own: in one
            # form with the pairs' coefficients the volume kernels assembled 3x slower
            residuals = list(system.residuals)
            bodies = self.unknowns[0].function_space.mesh.ufl_domain()
            volume = [_part(F, bodies, volume=True) for F in residuals]
            surface = [_part(F, bodies, volume=False) for F in residuals]
            surface_blocks = _nonempty_blocks(surface, ext)
            if not _every_row_and_column(surface_blocks):  # DOLFINx's block assembly needs it
                volume, surface = [None] * len(residuals), residuals
                surface_blocks = _nonempty_blocks(surface, ext)
            volume_blocks = _nonempty_blocks(volume, ext)
            self.F_ext, self.J_ext, self.F_vol, self.J_vol = form_together(
                [surface, surface_blocks, volume, volume_blocks],
                entity_maps=system.entity_maps, jit_options=system.jit_options)
            # the pattern: a surface block's couplings lie within its cells' (a facet's
            # dofs are its cell's), so each block takes the volume form where it has one
            self.A_ext = fem_petsc.create_matrix(
                [[v if v is not None else f for f, v in zip(row, vrow, strict=True)]
                 for row, vrow in zip(self.J_ext, self.J_vol, strict=True)], kind="mpi")
            # every facet's entries, before any limited assembly: PETSc's pattern is the
            # entries an assembly set, and P^T A P reuses its product only on a fixed one
            self.A_ext.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, True)
            self._block_index_sets = _cpp.la.petsc.create_index_sets(
                [(f.function_space.dofmap.index_map, f.function_space.dofmap.index_map_bs)
                 for f in ext])
            self._assemble_ext_jacobian(self.J_ext)
            self.A_ext.setOption(PETSc.Mat.Option.NEW_NONZERO_LOCATION_ERR, True)
            self._F_all, self._J_all = self.F_ext, self.J_ext
            self._limits: list[FacetLimit] = []
            self.ext_spaces = [f.function_space for f in ext]
            self.b_ext = fem_petsc.create_vector(self.ext_spaces, kind="mpi")
            self._work_vectors()
            self.z = fem_petsc.create_vector(self.spaces, kind="mpi")
        self._prefix = f"fc_{system.name}2_{next(_prefix_counter)}_"
        # Layouts: each rank owns its rows block after block (see linear.block_index_sets).
        n_red = sum(_owned(V) for V in self.spaces)
        n_ext = sum(_owned(V) for V in self.ext_spaces)
        self._n_red, self._n_ext = n_red, n_ext
        self._red0 = np.asarray(comm.allgather(comm.exscan(n_red) or 0), np.int64)
        self._ext0 = int(comm.exscan(n_ext) or 0)
        self._N_red, self._N_ext = comm.allreduce(n_red), comm.allreduce(n_ext)
        im = self.spaces[0].dofmap.index_map
        self._bs = self.spaces[0].dofmap.index_map_bs
        self._vranges = np.asarray(comm.allgather(im.local_range[0]), np.int64)
        n_u = _owned(self.spaces[0])
        bc_dofs = [bc.dof_indices()[0][: bc.dof_indices()[1]] for bc in self.bcs]
        self._bc_local = (
            np.unique(np.concatenate(bc_dofs)).astype(np.int32) if bc_dofs
            else np.zeros(0, np.int32)
        )
        self._bc_local = self._bc_local[self._bc_local < n_u]
        self._bc_rows = (self._red0[comm.rank] + self._bc_local).astype(PETSc.IntType)
        self._g = np.zeros(self.unknowns[0].x.array.size)
        self.P: PETSc.Mat | None = None
        self._P_keys: np.ndarray | None = None
        self.A: PETSc.Mat | None = None
        self._P_version = None
        self.linear = linear or LinearSolverSettings()
        self._refresh()
        self._assemble_condensed_jacobian()
        self.set_linear_solver(self.linear)
        self.rebuilds = 0

    # -- selection -------------------------------------------------------------
    def _reduced_rows(self, blocks: np.ndarray) -> np.ndarray:
        """Global reduced rows of component 0 of global V blocks."""
        owner = np.searchsorted(self._vranges, blocks, side="right") - 1
        return self._red0[owner] + (blocks - self._vranges[owner]) * self._bs

    def _build_P(self) -> bool:
        """P: extended rows to reduced columns; identity on unknowns, dw/du on extras.

        Returns True when P is a new matrix (a new pattern), False when only its
        values changed (the selection fits the kept pattern).
        """
        keys, values, selections = self._selection()
        self._P_version = self.transfer.version
        kept = self._P_keys
        seen = kept is not None and np.isin(keys, kept, assume_unique=True).all()
        if kept is not None and self._comm.allreduce(bool(seen), op=MPI.LAND):
            self.P.setValuesIJV(*self._csr(kept), _spread(kept, keys, values),
                                rowmap=np.arange(*self.P.getOwnershipRange(),
                                                 dtype=PETSc.IntType))
            self.P.assemble()
            return False
        pattern = keys
        if hasattr(self.transfer, "reachable_blocks"):
            reach = self.transfer.reachable_blocks()
            extra = [self._reachable_keys(reach[i], *selections[i]) for i in selections
                     if reach[i] is not None]
            if extra:
                pattern = np.union1d(keys, np.concatenate(extra))
        if kept is not None:
            union = np.union1d(kept, pattern)
            grown = union.size - pattern.size > KEPT_ZEROS * max(pattern.size - self._n_red, 1)
            if not self._comm.allreduce(bool(grown), op=MPI.LOR):
                pattern = union
        self._P_keys = pattern
        if self.P is not None:
            self.P.destroy()
        self.P = PETSc.Mat().createAIJ(
            size=((self._n_ext, self._N_ext), (self._n_red, self._N_red)),
            csr=(*self._csr(pattern), _spread(pattern, keys, values)), comm=self._comm,
        )
        self.P.assemble()
        return True

    def _selection(self) -> tuple[np.ndarray, np.ndarray, dict[int, tuple[int, int]]]:
        """This rank's entries of P as sorted keys (ext row * N + column) and values.

        An extra is either a 0/1 selection of V blocks (``sources()``) or, when
        the transfer has ``condensation()``, any sparse derivative of the extra
        with respect to u (rows: its owned dofs; columns: global V dofs). Also
        returns, per extra, its first extended row and its number of rows.
        """
        rank = self._comm.rank
        counts = [np.ones(self._n_red, np.int64)]
        cols = [self._red0[rank] + np.arange(self._n_red, dtype=np.int64)]
        vals = [np.ones(self._n_red)]
        selections = {}
        offset = self._n_red
        for i, item in enumerate(_condensation(self.transfer)):
            if isinstance(item, np.ndarray):
                base = self._reduced_rows(np.asarray(item, np.int64).reshape(-1))
                # a 2D source (node, row) selects for a packed coefficient of shape (rows, bs)
                col = (base[:, None] + np.arange(self._bs)[None, :]).reshape(-1)
                counts.append(np.ones(col.size, np.int64))
                cols.append(col)
                vals.append(np.ones(col.size))
            else:
                rows = item.tocsr()
                rows.sort_indices()
                counts.append(np.diff(rows.indptr).astype(np.int64))
                cols.append(self._reduced_dofs(rows.indices.astype(np.int64)))
                vals.append(rows.data)
            selections[i] = (offset, counts[-1].size)
            offset += counts[-1].size
        count = np.concatenate(counts)
        assert count.size == self._n_ext
        rows = np.repeat(np.arange(self._n_ext, dtype=np.int64), count)
        keys = rows * self._N_red + np.concatenate(cols)
        order = np.argsort(keys, kind="stable")
        return keys[order], np.concatenate(vals)[order], selections

    def _csr(self, keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Row pointers and columns of this rank's rows of P from sorted keys."""
        rows, cols = np.divmod(keys, self._N_red)
        indptr = np.searchsorted(rows, np.arange(self._n_ext + 1))
        return indptr.astype(PETSc.IntType), cols.astype(PETSc.IntType)

    def _reachable_keys(self, near: tuple[np.ndarray, np.ndarray], offset: int,
                        size: int) -> np.ndarray:
        """Keys (ext row * N + column) of the blocks each node's rows may come to select.

        ``size`` rows from ``offset``: per node, ``rows`` blocks of bs components.
        """
        indptr, blocks = near
        rows = size // ((indptr.size - 1) * self._bs) if indptr.size > 1 else 0
        node = np.repeat(np.arange(indptr.size - 1, dtype=np.int64), np.diff(indptr))
        base = self._reduced_rows(np.asarray(blocks, np.int64))
        keys = [(offset + (node * rows + r) * self._bs + c) * self._N_red + base + c
                for r in range(rows) for c in range(self._bs)]
        return np.concatenate(keys) if keys else np.zeros(0, np.int64)

    def _reduced_dofs(self, dofs: np.ndarray) -> np.ndarray:
        """Global reduced rows of global V dofs (block * bs + component)."""
        return self._reduced_rows(dofs // self._bs) + dofs % self._bs

    def _extra_residual(self, f: object) -> np.ndarray:
        """The owned entries of the extended residual of the unknown or extra ``f``."""
        start = 0
        for g in (*self.unknowns, *self.extras):
            n = _owned(g.function_space)
            if g is f:
                return self.b_ext.getArray(readonly=True)[start : start + n].copy()
            start += n
        raise KeyError("not a block of this system")

    def _add_curvature(self) -> None:
        """A += sum_j (dL/dw_j) d^2 w_j / du^2 of extras that are not linear in u."""
        curvature = getattr(self.transfer, "curvature", None)
        if curvature is None:
            return
        with stopwatch(self.timings, "transfer_s"):
            rows, cols, vals = curvature(self._extra_residual)
            if rows.size:
                m = sp.csr_matrix((vals, (self._reduced_dofs(rows), self._reduced_dofs(cols))),
                                  shape=(self._N_red, self._N_red))
                m.sum_duplicates()
                start = np.flatnonzero(np.diff(m.indptr))
                for i in start:
                    lo, hi = m.indptr[i], m.indptr[i + 1]
                    self.A.setValues(int(i), m.indices[lo:hi].astype(PETSc.IntType),
                                     m.data[lo:hi], addv=PETSc.InsertMode.ADD_VALUES)
            self.A.assemble()

    def _refresh(self) -> None:
        """Search and refill the target coefficients; new P when an assignment changed."""
        with stopwatch(self.timings, "search_s"):
            self.transfer.refresh()
        with stopwatch(self.timings, "transfer_s"):
            self._limit_forms()
        if self._P_version != self.transfer.version:
            with stopwatch(self.timings, "transfer_s"):
                if self._build_P() and self.A is not None:
                    self.A.destroy()
                    self.A = None
                    self.rebuilds = getattr(self, "rebuilds", 0) + 1

    def _limit_forms(self) -> None:
        """Integrate the pairs' terms only where they can act (``acting_facets``).

        Every block keeps its compiled kernels; the blocks of u and of the
        extras, residual and tangent, are rebuilt over the acting facets when
        they change (collective). A multiplier's own blocks keep every facet:
        lam / r = 0 is the equation of an open node.
        """
        acting = (self.transfer.acting_facets() if hasattr(self.transfer, "acting_facets")
                  else [])
        limits = [FacetLimit(ids, facets) for ids, facets in acting]
        same = len(limits) == len(self._limits) and all(
            a.same_as(b) for a, b in zip(limits, self._limits, strict=True))
        if self._comm.allreduce(same, op=MPI.LAND):
            return
        self._limits = limits
        maps = self.system.entity_maps
        n = len(self.unknowns)

        def own(i: int) -> bool:  # a multiplier of the unknowns
            return 1 <= i < n

        def limited(form: fem.Form | None, whole: bool) -> fem.Form | None:
            return form if form is None or whole or not limits else restrict(form, limits, maps)

        self.F_ext = [limited(f, own(i)) for i, f in enumerate(self._F_all)]
        self.J_ext = [[limited(f, own(i) and own(j)) for j, f in enumerate(row)]
                      for i, row in enumerate(self._J_all)]

    # -- assembly ------------------------------------------------------------------
    def _assemble_ext_jacobian(self, surface: list) -> None:
        """J_ext: the volume blocks, then the given surface blocks."""
        self.A_ext.zeroEntries()
        index_sets = self._block_index_sets
        for i, row in enumerate(self.J_vol):  # DOLFINx's block assembly, block by block
            for j, form in enumerate(row):
                if form is not None:
                    sub = self.A_ext.getLocalSubMatrix(index_sets[i], index_sets[j])
                    _cpp.fem.petsc.assemble_matrix(
                        sub, form._cpp_object, fem.assemble.pack_constants(form),
                        fem.assemble.pack_coefficients(form), [], True)
                    self.A_ext.restoreLocalSubMatrix(index_sets[i], index_sets[j], sub)
        fem_petsc.assemble_matrix(self.A_ext, surface, bcs=[], diag=1.0)
        self.A_ext.assemble()

    def _assemble_condensed_jacobian(self) -> None:
        with stopwatch(self.timings, "jacobian_s"):
            self._assemble_ext_jacobian(self.J_ext)
        self.timings.jacobians += 1
        with stopwatch(self.timings, "transfer_s"):
            if self.A is None:
                self.A = self.A_ext.PtAP(self.P)
                self.A.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
                if self.ksp is not None:
                    self.set_linear_solver(self.linear)
            else:
                self.A_ext.PtAP(self.P, result=self.A)

    def _boundary_values(self) -> None:
        """Z = x - x_D on the Dirichlet rows, 0 elsewhere."""
        self._g[:] = 0.0
        for bc in self.bcs:
            bc.set(self._g)
        u = self.unknowns[0].x.array
        self.z.zeroEntries()
        z = self.z.getArray()
        z[self._bc_local] = u[self._bc_local] - self._g[self._bc_local]

    def _assemble_b(self) -> float:
        """Search, assemble R_ext, condense b = P^T R_ext, set Dirichlet rows; return the norm."""
        self._refresh()
        with stopwatch(self.timings, "residual_s"):
            self._pull()
            b = self.b_ext
            with b.localForm() as local:
                local.set(0.0)
            fem_petsc.assemble_vector(b, self.F_ext)
            self._add_volume_residual(b)
            b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        with stopwatch(self.timings, "transfer_s"):
            self.P.multTranspose(b, self.b)
            self._boundary_values()
            arr = self.b.getArray()
            if self.system.supports is not None:  # the supports' forces, contact included
                self.system.supports(self._bc_local, arr[self._bc_local].copy())
            arr[self._bc_local] = self.z.getArray(readonly=True)[self._bc_local]
            return float(self.b.norm())

    def _add_volume_residual(self, b: PETSc.Vec) -> None:
        """Add the volume residual blocks into the (local form of the) extended b."""
        offsets, ghost_offsets = b.getAttr("_blocks")
        with b.localForm() as local:
            array = local.array_w
            for i, form in enumerate(self.F_vol):
                if form is None:
                    continue
                part = fem.assemble_vector(form).array  # owned, then ghosts
                size = offsets[i + 1] - offsets[i]
                array[offsets[i]:offsets[i + 1]] += part[:size]
                array[ghost_offsets[i]:ghost_offsets[i + 1]] += part[size:]

    def _assemble_A(self) -> None:
        """Condensed Jacobian A = P^T J_ext P, Dirichlet elimination lifting b."""
        self._assemble_condensed_jacobian()
        self._add_curvature()
        with stopwatch(self.timings, "transfer_s"):
            self.A.zeroRowsColumns(self._bc_rows, 1.0, self.z, self.b)

    def destroy(self) -> None:
        """Free the PETSc objects and remove the solver's options from the database."""
        self._forget()
        for obj in (self.ksp, self.A, self.A_ext, self.P, self.b, self.b_ext, self.x,
                    self.dx, self.z):
            if obj is not None:
                obj.destroy()


def _spread(pattern: np.ndarray, keys: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Values on ``pattern`` (sorted keys): ``values`` at ``keys``, explicit zeros elsewhere."""
    out = np.zeros(pattern.size)
    out[np.searchsorted(pattern, keys)] = values
    return out


def _condensation(transfer) -> list:
    """Each extra's condensation: a V-block selection, or a sparse derivative."""
    if hasattr(transfer, "condensation"):
        return list(transfer.condensation())
    return list(transfer.sources())


def kernel_for(
    system: VariationalSystem, linear: LinearSolverSettings | None = None
) -> NewtonKernel:
    """The Newton kernel a system needs: condensing when it has extras."""
    if system.extras:
        return CondensedKernel(system, linear)
    return NewtonKernel(system, linear)


__all__ = ["CondensedKernel", "kernel_for"]
