"""The 3D mortar weighted gaps as UFL forms on a mesh of segments.

One DOLFINx cell per segment (:mod:`.segments3d`): disconnected reference
triangles, all at the same place, so that the spatial coordinate of a cell
*is* the reference coordinate eta of the segment. The mesh is made once
with a fixed capacity; a search only refills its DG0 coefficients:

* ``X``: reference positions of the segment's striker triangle (rows 0-2)
  and target triangle (rows 3-5), shape (6, 3);
* ``w``: their displacements, the *extended unknowns* (6, 3), selected from
  the bodies' displacement by the search (condensed as in 2D);
* ``provenance``: one-hot weights of each corner's kind and indices, and
  of each target vertex's snap code (3, 22).

The corners (:func:`~.segments3d.corner_from_provenance`, written in UFL),
the striker point, the gap along the striker normal and the hat functions
N_j are UFL expressions of those, so ``ufl.derivative`` with respect to
``w`` linearises the whole segmentation (normals, projections, edge
crossings). Unused cells hold a dummy pair of triangles and zero weights:
they contribute nothing. Assembling :attr:`SegmentForms.gap_form` gives,
per cell, the three contributions int_seg N_j g dA of the segment to its
striker corners (length^3); :attr:`weight_form` the int_seg N_j dA
(length^2).

For the chain rule of the nodal gaps (:mod:`.mortar3d`) the module also
holds the derivatives of both with respect to ``w`` (per cell 3 x 18) and
the second derivative (per cell 18 x 18) of the weighted sum
sum_corners (a_c N_c g + b_c N_c) jac over the segment, with ``a`` and ``b``
DG0 data (3,) per cell.
"""

from __future__ import annotations

import basix.ufl
import numpy as np
import scipy.sparse as sp
import ufl
from dolfinx import fem
from dolfinx import mesh as dmesh
from dolfinx.fem import petsc as fem_petsc

from mpi4py import MPI

from fenics_contact.model.form_batches import (
    CONTACT_CFLAGS,
    WAIT_S,
    compile_in_background,
    form_together,
)
from fenics_contact.model.segments3d import REFERENCE, STRIKER_EDGES, Segments

#: Columns of a corner's provenance row: kind (3), striker corner (3), target
#: vertex (3), striker edge (3), target edge (3); then, in row r, the snap code of the
#: target vertex r (7: not moved, onto edge line 0, 1, 2, onto corner 0, 1, 2).
KIND, CORNER, VERTEX, EDGE, TARGET_EDGE, SNAP = 0, 3, 6, 9, 12, 15
#: Width of a provenance row.
WIDTH = 22
#: C optimisation of the second-derivative kernel: gcc takes about 8 s at -O0 and
#: 170 s at -O1 on it (2-core machine); -O1 assembles it 2.3 times faster, but it
#: is assembled only on the segments of engaged nodes (docs/two_bodies.md).
HESSIAN_OPT = "-O0"
#: Rows of the segment's (6, 3) vertex data: the striker triangle's and the target's.
HALVES = {"s": (0, 1, 2), "t": (3, 4, 5)}
#: A pair of triangles that keeps every formula finite in unused cells.
_DUMMY = np.vstack([np.column_stack([REFERENCE, np.zeros(3)]),
                    np.column_stack([REFERENCE[::-1], np.ones(3)])])


def _rows(direction: ufl.core.expr.Expr, rows: tuple[int, ...]) -> ufl.core.expr.Expr:
    """``direction`` (6, 3) with every row outside ``rows`` zero (a derivative's direction)."""
    return ufl.as_matrix([[direction[r, i] if r in rows else 0.0 for i in range(3)]
                          for r in range(6)])


def provenance_weights(segments: Segments) -> np.ndarray:
    """One-hot provenance rows of every segment corner and snap code, shape (k, 3, WIDTH)."""
    k = len(segments)
    out = np.zeros((k, 3, WIDTH))
    rows = np.arange(k)
    for r in range(3):
        out[rows, r, SNAP + 1 + segments.snap[:, r]] = 1.0
    for c in range(3):
        kind, i, j = segments.kind[:, c], segments.index[:, c, 0], segments.index[:, c, 1]
        out[rows, c, KIND + kind] = 1.0
        for code, column in ((0, CORNER), (1, VERTEX), (2, EDGE)):
            sel = kind == code
            out[rows[sel], c, column + i[sel]] = 1.0
        sel = kind == 2
        out[rows[sel], c, TARGET_EDGE + j[sel]] = 1.0
    return out


class SegmentForms:
    """A segment mesh of ``capacity`` cells with the weighted-gap forms on it (one process).

    Args:
        capacity: the most segments it can hold.
        comm: the mesh's communicator (each process segments its own striker triangles).
        dual: weight the gap with the dual basis Phi_j = 4 N_j - 1 of the striker
            triangle (int Phi_j N_k = delta_jk int N_k) instead of N_j on the cells
            whose ``theta`` is 1 (striker triangles the target covers whole); the
            covered area keeps N_j. See :mod:`.mortar3d`.
    """

    def __init__(self, capacity: int, comm: MPI.Comm = MPI.COMM_SELF, *,
                 dual: bool = False) -> None:
        self.capacity = int(capacity)
        self.dual = bool(dual)
        x = np.tile(REFERENCE, (self.capacity, 1))
        cells = np.arange(3 * self.capacity, dtype=np.int64).reshape(-1, 3)
        element = basix.ufl.element("Lagrange", "triangle", 1, shape=(2,))
        self.mesh = dmesh.create_mesh(comm, cells, element, x)
        #: Input row of each local cell (the mesh may reorder the cells).
        self.cell_rows = np.asarray(self.mesh.topology.original_cell_index, dtype=np.int64)
        self.W6 = fem.functionspace(self.mesh, ("DG", 0, (6, 3)))
        self.X = fem.Function(self.W6, name="segment_vertices")
        self.w = fem.Function(self.W6, name="segment_displacements")
        self.provenance = fem.Function(fem.functionspace(self.mesh, ("DG", 0, (3, WIDTH))))
        self.V3 = fem.functionspace(self.mesh, ("DG", 0, (3,)))
        self.count = 0
        gap, jac, shape = self._integrand()
        #: 1 on the segments of a wholly covered striker triangle (dual basis), else 0.
        self.theta = fem.Function(fem.functionspace(self.mesh, ("DG", 0)), name="dual")
        weight = shape
        if self.dual:
            weight = shape + self.theta * (3.0 * shape - ufl.as_vector([1.0, 1.0, 1.0]))
        v = ufl.TestFunction(self.V3)
        dx = ufl.dx(metadata={"quadrature_degree": 2})  # N_j g is quadratic on a segment
        self.gap_form = ufl.dot(weight * gap * jac, v) * dx
        self.weight_form = ufl.dot(shape * jac, v) * dx
        #: Corner weights of the weighted gaps (a) and covered areas (b) in :attr:`hessian_parts`.
        self.a = fem.Function(self.V3, name="gap_weights")
        self.b = fem.Function(self.V3, name="area_weights")
        dw, dW = ufl.TestFunction(self.W6), ufl.TrialFunction(self.W6)
        weighted = (ufl.dot(self.a, weight) * gap + ufl.dot(self.b, shape)) * jac * dx
        self.gap_tangent_form = ufl.derivative(self.gap_form, self.w, dW)
        self.weight_tangent_form = ufl.derivative(self.weight_form, self.w, dW)
        #: The Hessian in blocks of the striker (s) and target (t) vertex rows:
        #: ss, st and tt; H = ss + st + st^T + tt (the mixed derivatives commute).
        #: Three smaller kernels instead of one, compiled at the same time.
        self.hessian_parts = {
            f"hessian_{a}{b}": ufl.derivative(
                ufl.derivative(weighted, self.w, _rows(dw, HALVES[a])), self.w,
                _rows(dW, HALVES[b]))
            for a, b in ("ss", "st", "tt")}
        self._compiled: dict[str, fem.Form] = {}
        self._matrices: dict = {}
        self._start_compiling()
        self.fill(np.zeros((0, 6, 3)), np.zeros((0, 3, WIDTH)))

    #: The forms each compiled as its own module; the Hessian's parts (the largest) are
    #: needed last.
    NAMES = ("gap", "weight", "gap_tangent", "weight_tangent")
    HESSIAN = ("hessian_ss", "hessian_st", "hessian_tt")
    #: Set by the process's first segment mesh, which starts the background compilation.
    _compiling_started = False

    @staticmethod
    def jit_options(name: str) -> dict:
        """C flags of a form's module: the large Hessian kernel at HESSIAN_OPT."""
        flags = [HESSIAN_OPT, "-g0"] if name.startswith("hessian") else CONTACT_CFLAGS
        # another segment mesh's background process may be compiling it: wait for it
        return {"cffi_extra_compile_args": flags, "timeout": WAIT_S}

    def _ufl_form(self, name: str) -> ufl.Form:
        return self.hessian_parts[name] if name in self.hessian_parts else getattr(
            self, f"{name}_form")

    def _start_compiling(self) -> None:
        """Compile the forms in background processes (one machine, empty cache).

        Only the process's first segment mesh does: a form's module does not
        depend on the mesh, and a later mesh waits for the same modules.

        The Hessian's three parts, the longest to compile and the last needed,
        are compiled by child processes while this one compiles the other
        forms and goes on building the problem; :meth:`assemble_matrix` waits
        for them when the Hessian is first assembled.
        """
        self._pending = None
        if SegmentForms._compiling_started:  # the same modules as the first segment mesh's
            return
        SegmentForms._compiling_started = True
        self._pending = compile_in_background(
            [([self.hessian_parts[name]], self.jit_options(name)) for name in self.HESSIAN],
            self.mesh.comm)

    def _form(self, name: str) -> fem.Form:
        if self._pending is not None and name in self.HESSIAN:
            self._pending.wait()
            self._pending = None
        if name not in self._compiled:
            self._compiled[name] = form_together(self._ufl_form(name),
                                                 jit_options=self.jit_options(name))
        return self._compiled[name]

    def compiled(self) -> dict[str, fem.Form]:
        """The four forms other than the Hessian, compiled (once)."""
        return {name: self._form(name) for name in self.NAMES}

    def assemble_matrix(self, name: str) -> sp.csr_matrix:
        """A compiled bilinear form (``gap_tangent``, ``weight_tangent``, ``hessian``) as CSR.

        The PETSc matrix of each form is made once (its pattern is block
        diagonal, one block per cell) and refilled. ``hessian`` sums its parts.
        """
        if name == "hessian":
            ss, st, tt = (self.assemble_matrix(part) for part in self.HESSIAN)
            return (ss + st + st.T + tt).tocsr()
        form = self._form(name)
        matrix = self._matrices.get(name)
        if matrix is None:
            matrix = self._matrices[name] = fem_petsc.create_matrix(form)
        matrix.zeroEntries()
        fem_petsc.assemble_matrix(matrix, form)
        matrix.assemble()
        indptr, indices, data = matrix.getValuesCSR()
        return sp.csr_matrix((data, indices, indptr), shape=matrix.getSize())

    def cell_dofs(self) -> tuple[np.ndarray, np.ndarray]:
        """Input row (segment) of every dof of the (3,) and the (6, 3) DG0 spaces.

        Returns (rows3, rows18): for each local dof its segment row, and the
        position inside the segment's block (corner c, or vertex row r * 3 + i).
        """
        out = []
        for space in (self.V3, self.W6):
            bs = space.dofmap.index_map_bs
            block = space.dofmap.list.reshape(-1)  # one block per cell
            row = np.empty(block.size * bs, np.int64)
            pos = np.empty(block.size * bs, np.int64)
            dofs = (block[:, None] * bs + np.arange(bs)[None, :])
            row[dofs.reshape(-1)] = np.repeat(self.cell_rows, bs)
            pos[dofs.reshape(-1)] = np.tile(np.arange(bs), block.size)
            out.append((row, pos))
        return out[0], out[1]

    def _integrand(self):
        X, w, p = self.X, self.w, self.provenance

        def point(r: int):
            return ufl.as_vector([X[r, i] + w[r, i] for i in range(3)])

        s = [point(r) for r in range(3)]
        t = [point(r) for r in range(3, 6)]
        e1, e2 = s[1] - s[0], s[2] - s[0]
        n = ufl.cross(e1, e2)
        det = ufl.dot(n, n)
        m1, m2 = ufl.cross(e2, n) / det, ufl.cross(n, e1) / det
        reference = [ufl.as_vector([float(a), float(b)]) for a, b in REFERENCE]

        def moved(k: int):
            """Target vertex k projected, then moved as its snap code says (segments3d.snapped)."""
            q = ufl.as_vector([ufl.dot(t[k] - s[0], m1), ufl.dot(t[k] - s[0], m2)])
            half = 0.5 * (q[0] + q[1] - 1.0)
            onto = [ufl.as_vector([q[0], 0.0]), q - ufl.as_vector([half, half]),
                    ufl.as_vector([0.0, q[1]])]
            return (p[k, SNAP] * q + sum(p[k, SNAP + 1 + i] * onto[i] for i in range(3))
                    + sum(p[k, SNAP + 4 + c] * reference[c] for c in range(3)))

        projected = [moved(k) for k in range(3)]

        def crossing(a, b, edge: int):
            ca, cb, cc = (float(v) for v in STRIKER_EDGES[edge])
            fa = ca * a[0] + cb * a[1] - cc
            fb = ca * b[0] + cb * b[1] - cc
            safe = fa - fb + ufl.conditional(ufl.eq(fa, fb), 1.0, 0.0)
            return a + fa / safe * (b - a)

        corners = []
        for c in range(3):
            fixed = sum(p[c, CORNER + k] * reference[k] for k in range(3))
            vertex = sum(p[c, VERTEX + k] * projected[k] for k in range(3))
            crossed = sum(p[c, EDGE + e] * p[c, TARGET_EDGE + k]
                          * crossing(projected[k], projected[(k + 1) % 3], e)
                          for e in range(3) for k in range(3))
            corners.append(p[c, KIND] * fixed + p[c, KIND + 1] * vertex
                           + p[c, KIND + 2] * crossed)
        eta = ufl.SpatialCoordinate(self.mesh)
        d1, d2 = corners[1] - corners[0], corners[2] - corners[0]
        xi = corners[0] + d1 * eta[0] + d2 * eta[1]
        shape = ufl.as_vector([1 - xi[0] - xi[1], xi[0], xi[1]])
        x_s = shape[0] * s[0] + shape[1] * s[1] + shape[2] * s[2]
        n_s = n / ufl.sqrt(det)
        n_t = ufl.cross(t[1] - t[0], t[2] - t[0])
        gap = ufl.dot(t[0] - x_s, n_t) / ufl.dot(n_s, n_t)
        # int_seg f dA = |e1 x e2| |det(d1, d2)| int_cell f d(eta) (the cell's area is 1/2)
        jac = abs(d1[0] * d2[1] - d1[1] * d2[0]) * ufl.sqrt(det)
        return gap, jac, shape

    def fill(self, vertices: np.ndarray, provenance: np.ndarray) -> None:
        """Load k <= capacity segments: (k, 6, 3) reference vertices, (k, 3, WIDTH) provenance.

        The displacements ``w`` are set to zero; the remaining cells are emptied.
        """
        k = vertices.shape[0]
        if k > self.capacity:
            raise ValueError(f"{k} segments exceed the segment mesh's capacity "
                             f"{self.capacity}; make it larger.")
        allv = np.broadcast_to(_DUMMY, (self.capacity, 6, 3)).copy()
        allp = np.zeros((self.capacity, 3, WIDTH))
        allv[:k], allp[:k] = vertices, provenance
        self.X.x.array[:] = allv[self.cell_rows].reshape(-1)
        self.provenance.x.array[:] = allp[self.cell_rows].reshape(-1)
        self.w.x.array[:] = 0.0
        self.count = k

    def set_dual(self, theta: np.ndarray) -> None:
        """Load the (count,) dual flags of the segments (0 in unused cells)."""
        full = np.zeros(self.capacity)
        full[: self.count] = theta
        self.theta.x.array[:] = full[self.cell_rows]

    def set_corner_weights(self, a: np.ndarray, b: np.ndarray) -> None:
        """Load the (count, 3) corner weights of :attr:`hessian_parts` (zero in unused cells)."""
        for f, values in ((self.a, a), (self.b, b)):
            full = np.zeros((self.capacity, 3))
            full[: self.count] = values
            f.x.array[:] = full[self.cell_rows].reshape(-1)

    def per_segment(self, assembled: np.ndarray) -> np.ndarray:
        """Cell values of an assembled DG0 (3,) vector in segment order, shape (count, 3)."""
        out = np.empty((self.capacity, 3))
        out[self.cell_rows] = assembled.reshape(-1, 3)
        return out[: self.count]


__all__ = ["SegmentForms", "provenance_weights"]
