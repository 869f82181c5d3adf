"""Mortar contact of two bodies in 3D: nodal gaps from segments, condensed by the chain rule.

The weighted gap and covered area of a striker node j (as in 2D, :mod:`.mortar`),

    g~_j = int_{Gamma_s} N_j g dA,    A~_j = int_{segments} N_j dA,    G_j = g~_j / A~_j,

are integrals over the segments of the striker triangles against the target
triangles (:mod:`.segments3d`), assembled from the UFL forms on the segment
mesh (:mod:`.segment_forms3d`) in the current configuration. The contact
terms see only the nodal gaps: ``G`` is a P1 function on the striker's
contact submesh, an *extra* of the variational system whose value and
derivative this transfer supplies. With R the residual of the extended
system (u, lam, G) the Newton system on (u, lam) is, by the chain rule,

    R_red = P^T R,    J_red = P^T J P + sum_j (dL/dG_j) d^2 G_j / du^2,

with P = [[I, 0], [0, I], [dG/du, 0]] (:meth:`condensation`) and the second
term :meth:`curvature`:

    d^2 G_j = (d^2 g~_j - G_j d^2 A~_j - dG_j (x) dA~_j - dA~_j (x) dG_j) / A~_j,

whose first two terms are the second derivative of the segment functional
sum_j a_j g~_j + b_j A~_j (a_j = c_j / A~_j, b_j = -c_j G_j / A~_j,
c_j = dL/dG_j), assembled by ``ufl.derivative`` on the segment mesh. Every
derivative comes from UFL; the segmentation (which target triangle covers
which part of a striker triangle, and the provenance of each corner) is
frozen between searches, and a search runs whenever u changes.

A node whose support no target covers (A~_j <= 1e-8 of its support) is
open: G_j = h, dG_j = 0. Both surfaces are gathered on every rank; each
rank segments the striker triangles it owns and the nodal sums are reduced
over the ranks.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from dolfinx import fem

from fenics_contact.model.contact import ContactSurface
from fenics_contact.model.search import penetration_depth
from fenics_contact.model.segment_forms3d import SegmentForms, provenance_weights
from fenics_contact.model.segments import Polyline, any_rank, node_blocks
from fenics_contact.model.segments3d import candidate_pairs, segment_pairs

#: Segments per striker triangle the segment mesh is first made for (it grows when needed).
SEGMENTS_PER_TRIANGLE = 8
#: A striker triangle whose covered fraction is at least 1 - WHOLE weights its gaps with
#: the dual basis; the others (at the target's borders) keep the standard one.
WHOLE = 1e-2
#: A node with G below this fraction of the open gap h is engaged (its derivatives kept).
ENGAGED = 1e-3
#: A node counts as covered when its covered area exceeds this fraction of its support.
COVERED = 1e-8


def _triangle_areas(tris: np.ndarray) -> np.ndarray:
    return 0.5 * np.linalg.norm(np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]),
                                axis=-1)


class MortarTransfer3D:
    """The nodal gaps G of a 3D mortar pair, their derivatives and curvature (see module).

    Args:
        V: the displacement space (vector P1, 3D).
        u: the displacement.
        surface: the striker's contact surface (its submesh carries lam and G).
        target_facets: local facet indices of the target surface (triangles).
        open_gap: G of an uncovered node (length).
        lam: the pair's multiplier (nodes where it is nonzero are always engaged).
    """

    def __init__(self, V: fem.FunctionSpace, u: fem.Function, surface: ContactSurface,
                 target_facets: np.ndarray, open_gap: float,
                 lam: fem.Function | None = None) -> None:
        self.V, self.u, self.comm = V, u, V.mesh.comm
        self.striker = Polyline(V, surface.facets, dim=3)
        self.target = Polyline(V, target_facets, dim=3)
        Q = surface.Q
        sub = surface.submesh
        parent = np.asarray(surface.node_map)[sub.geometry.dofmaps[0].reshape(-1)]
        im = Q.dofmap.index_map
        node = np.zeros(im.size_local + im.num_ghosts, np.int64)
        node[Q.dofmap.list.reshape(-1)] = parent
        local = node_blocks(V)[node].astype(np.int32)
        blocks = V.dofmap.index_map.local_to_global(local).astype(np.int64)
        #: Striker vertex (index in ``striker.vertices``) of every local dof of G.
        self.q_vertex = self.striker.index(blocks)
        self.n_owned = im.size_local
        self.G = fem.Function(Q, name="mortar_gap")
        self.open_gap = float(open_gap)
        n = self.striker.vertices.size
        self.support = np.zeros(n)
        tris = self.striker.X[self.striker.facet_vertex]
        np.add.at(self.support, self.striker.facet_vertex,
                  np.repeat(_triangle_areas(tris)[:, None] / 3.0, 3, axis=1))
        edges = [np.linalg.norm(np.roll(t, 1, axis=1) - t, axis=-1).max()
                 for t in (tris, self.target.X[self.target.facet_vertex])]
        #: The longest striker triangle edge (reference, length).
        self.striker_size = float(edges[0])
        self.reach = 2.0 * max(edges)
        self.n_dofs = V.dofmap.index_map.size_global * 3
        lo, hi = self.striker.owned
        self._capacity = max(SEGMENTS_PER_TRIANGLE * (hi - lo), 16)
        self._segment_forms: dict[str, SegmentForms] = {}
        self.lam = lam
        shared = np.intersect1d(self.striker.vertices, self.target.vertices)
        #: Striker triangles with a vertex on the target surface (None: the surfaces meet
        #: nowhere, as on two bodies).
        self._meeting = (np.isin(self.striker.vertices[self.striker.facet_vertex], shared)
                         .any(axis=1) if shared.size else None)
        self.engaged_count = 0
        self.version = 0
        self.search_count = 0
        self.segment_count = 0
        self._searched_u: np.ndarray | None = None

    @property
    def forms(self) -> SegmentForms:
        """The segment mesh holding every segment of the last search."""
        return self._segment_forms["all"]

    # -- search and nodal gaps -------------------------------------------------------
    def _forms(self, which: str, k: int) -> SegmentForms:
        """The segment mesh ``which`` ('all', 'near', 'loaded'), large enough for k segments."""
        forms = self._segment_forms.get(which)
        if which == "all":
            if forms is None or k > forms.capacity:
                capacity = max(self._capacity, 2 * k)
                forms = self._segment_forms[which] = SegmentForms(capacity, dual=True)
            return forms
        # the derivative meshes are assembled whole, unused cells included: keep them
        # within 25 % of the segments they hold (a new mesh reuses the compiled forms)
        if forms is None or k > forms.capacity or forms.capacity > 2 * max(k, 16):
            capacity = max(16, int(1.25 * k) + 1)
            forms = self._segment_forms[which] = SegmentForms(capacity, dual=True)
        return forms

    def refresh(self) -> bool:
        """Segment, assemble G and dG/du at the current u; True when they changed (any rank).

        The derivatives are assembled only on the segments of *engaged* nodes
        (G_j <= 1e-3 h or lam_j != 0): every other node is inactive (lam + r G > 0,
        or G > 0 for the penalty), its residual and tangent vanish, and its row of
        dG/du is zero without loss.
        """
        same = self._searched_u is not None and np.array_equal(self._searched_u, self.u.x.array)
        if not any_rank(self.comm, not same):
            return False
        self._searched_u = self.u.x.array.copy()
        self.search_count += 1
        s, t = self.striker, self.target
        xs = (s.X + s.displacements(self.u))[s.facet_vertex]
        xt = (t.X + t.displacements(self.u))[t.facet_vertex]
        lo, hi = s.owned
        seg = self._segments(xs[lo:hi], xt)
        k = len(seg)
        self.segment_count = int(self.comm.allreduce(k))
        vertices = np.concatenate([xs[lo:hi][seg.striker], xt[seg.target]], axis=1)
        provenance = provenance_weights(seg)
        covered = np.zeros(hi - lo)
        np.add.at(covered, seg.striker, seg.xi_areas())
        theta = (covered >= 0.5 * (1.0 - WHOLE))[seg.striker].astype(float)
        corner_vertex = s.facet_vertex[seg.striker + lo]
        blocks = np.concatenate([s.vertices[corner_vertex],
                                 t.vertices[t.facet_vertex[seg.target]]], axis=1)
        segment_dofs = (3 * blocks[:, :, None] + np.arange(3)).reshape(k, 18)
        forms = self._forms("all", k)
        forms.fill(vertices, provenance)
        forms.set_dual(theta)
        compiled = forms.compiled()
        n = s.vertices.size
        g = np.zeros(n)
        area = np.zeros(n)
        np.add.at(g, corner_vertex, forms.per_segment(fem.assemble_vector(compiled["gap"]).array))
        np.add.at(area, corner_vertex,
                  forms.per_segment(fem.assemble_vector(compiled["weight"]).array))
        g = self.comm.allreduce(g)
        area = self.comm.allreduce(area)
        covered = area > COVERED * self.support
        inv = np.where(covered, 1.0 / np.where(covered, area, 1.0), 0.0)
        G = np.where(covered, g * inv, self.open_gap)
        engaged = covered & (G <= ENGAGED * self.open_gap)
        if self.lam is not None:
            lam = np.zeros(n)
            lam[self.q_vertex[: self.n_owned]] = self.lam.x.array[: self.n_owned]
            engaged |= covered & (self.comm.allreduce(lam) != 0.0)
        near = np.flatnonzero(np.any(engaged[corner_vertex], axis=1))
        self.engaged_count = int(np.count_nonzero(engaged))
        near_forms = self._forms("near", near.size)
        near_forms.fill(vertices[near], provenance[near])
        near_forms.set_dual(theta[near])
        self._corner_vertex, self._segment_dofs = corner_vertex[near], segment_dofs[near]
        self._near_data = (vertices[near], provenance[near], theta[near])
        dg = self._gathered_rows("gap_tangent")
        dA = self._gathered_rows("weight_tangent")
        scale = np.where(engaged, inv, 0.0)
        self.dG = (sp.diags(scale) @ (dg - sp.diags(np.where(engaged, G, 0.0)) @ dA)).tocsr()
        self.dA = dA
        self.values, self.area, self.covered, self._inv = G, area, covered, scale
        self.G.x.array[:] = G[self.q_vertex]
        self.version += 1
        return True

    def _segments(self, xs: np.ndarray, xt: np.ndarray):
        """Segments of this rank's striker triangles ``xs`` against the target ``xt``.

        Pairs of triangles that share a vertex are not clipped: only two
        surfaces of one body share vertices (self-contact, where they meet), and
        a corner's own triangles are no contact (a node on it would press
        against a triangle it belongs to).
        """
        s_idx, t_idx = candidate_pairs(xs, xt, self.reach)
        if self._meeting is not None and s_idx.size:
            lo = self.striker.owned[0]
            mine = self.striker.vertices[self.striker.facet_vertex[s_idx + lo]]
            theirs = self.target.vertices[self.target.facet_vertex[t_idx]]
            near = self._meeting[s_idx + lo]
            touch = (mine[near][:, :, None] == theirs[near][:, None, :]).any(axis=(1, 2))
            keep = np.ones(s_idx.size, bool)
            keep[np.flatnonzero(near)[touch]] = False
            s_idx, t_idx = s_idx[keep], t_idx[keep]
        return segment_pairs(xs, xt, s_idx, t_idx)

    def passed_through(self) -> np.ndarray:
        """Depth of each owned striker node inside the target body, where it has passed through.

        As in 2D (:meth:`.mortar.MortarTransfer.passed_through`): closest point
        and pseudo-normal on the target triangles; only depths beyond half the
        longest striker edge count (else 0). A node deeper than the search's
        ``reach`` has no segment and its gap reads open (length).
        """
        s, t = self.striker, self.target
        points = (s.X + s.displacements(self.u))[self.q_vertex[: self.n_owned]]
        current = (t.X + t.displacements(self.u))[t.facet_vertex]
        depth = penetration_depth(points, current)
        return np.where(depth > 0.5 * self.striker_size, depth, 0.0)

    def _gathered_rows(self, name: str) -> sp.csr_matrix:
        """A per-segment (3 x 18) derivative summed into striker-node rows and V-dof columns."""
        forms = self._segment_forms["near"]
        matrix = forms.assemble_matrix(name).tocoo()
        (rows3, corner), (rows18, pos) = forms.cell_dofs()
        keep = rows3[matrix.row] < forms.count
        r, c, v = matrix.row[keep], matrix.col[keep], matrix.data[keep]
        node = self._corner_vertex[rows3[r], corner[r]]
        dof = self._segment_dofs[rows18[c], pos[c]]
        parts = self.comm.allgather((node, dof, v))
        node, dof, v = (np.concatenate(p) for p in zip(*parts, strict=True))
        return sp.csr_matrix((v, (node, dof)), shape=(self.striker.vertices.size, self.n_dofs))

    # -- what the condensing kernel asks ---------------------------------------------
    def condensation(self) -> list[sp.csr_matrix]:
        """dG/du of the owned dofs of G (rows) in global V dofs (block * 3 + component)."""
        return [self.dG[self.q_vertex[: self.n_owned]]]

    def curvature(self, residual_of) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """sum_j c_j d^2 G_j / du^2 as (rows, cols, values) in global V dofs (this rank's part).

        ``residual_of(G)``: the owned entries c_j = dL/dG_j of the extended residual.
        """
        c = np.zeros(self.striker.vertices.size)
        c[self.q_vertex[: self.n_owned]] = residual_of(self.G)
        c = self.comm.allreduce(c)
        a = c * self._inv
        b = -a * np.where(self.covered, self.values, 0.0)
        # only segments with a loaded corner (c_j != 0: the active nodes) contribute
        vertices, provenance, theta = self._near_data
        loaded = np.flatnonzero(np.any(a[self._corner_vertex] != 0.0, axis=1))
        forms = self._forms("loaded", loaded.size)
        forms.fill(vertices[loaded], provenance[loaded])
        forms.set_dual(theta[loaded])
        corners = self._corner_vertex[loaded]
        forms.set_corner_weights(a[corners], b[corners])
        H = forms.assemble_matrix("hessian").tocoo()
        _, (rows18, pos) = forms.cell_dofs()
        keep = rows18[H.row] < forms.count
        r, cc, v = H.row[keep], H.col[keep], H.data[keep]
        dofs = self._segment_dofs[loaded]
        rows = [dofs[rows18[r], pos[r]]]
        cols = [dofs[rows18[cc], pos[cc]]]
        vals = [v]
        # the rank-one terms of the nodes this rank owns
        own = self.q_vertex[: self.n_owned]
        T = (self.dG[own].T @ sp.diags(a[own]) @ self.dA[own]).tocoo()
        for m in (T, T.T.tocoo()):
            rows.append(m.row)
            cols.append(m.col)
            vals.append(-m.data)
        return (np.concatenate(rows).astype(np.int64), np.concatenate(cols).astype(np.int64),
                np.concatenate(vals))

    def sources(self) -> list[np.ndarray]:
        """No 0/1 selection: the kernel uses :meth:`condensation`."""
        return []

    # -- outputs -------------------------------------------------------------------
    def target_force(self, c_owned: np.ndarray) -> np.ndarray:
        """Force on the target vertices, -(dG/du)^T c restricted to them, global V dofs (dense)."""
        c = np.zeros(self.striker.vertices.size)
        c[self.q_vertex[: self.n_owned]] = c_owned
        c = self.comm.allreduce(c)
        force = -(self.dG.T @ c)
        mask = np.zeros(self.n_dofs, bool)
        mask[(3 * self.target.vertices[:, None] + np.arange(3)).reshape(-1)] = True
        return np.where(mask, force, 0.0)


__all__ = ["MortarTransfer3D"]
