"""Mortar (segment-to-segment) contact of two bodies in 2D, in UFL.

Multiplier lam P1 on the striker's contact submesh (lam <= 0 the pressure).
Weighted gap of striker node j, projected along the striker facet's normal
n_s (outward, piecewise constant):

    g~_j = int_{Gamma_s} N_j(X) g(X) dA,   g = (x_t - x_s) . n_s   (g >= 0 open)

with x_t the point of the target facet hit by the ray x_s + alpha n_s, so
g = alpha = (x_a - x_s) . n_t / (n_s . n_t) for a target facet (a, b) of
any normal n_t. On a segment g is linear in the striker facet's local
coordinate; N_j g is quadratic and the two-point Gauss rule on each segment
is exact. dA is the reference length of the striker facet. The nodal gap is
G_j = g~_j / A~_j, A~_j = int_{segments} N_j dA (the part of the support the
target covers; A~_j = A_j = int N_j dA where the target covers the
support), and Alart-Curnier holds on the pairs (lam_j, G_j) with the vertex
rule, so the converged answer does not depend on r. A node whose support
meets no target facet is open: G_j = h + max(-lam_j / r, 0), which opens it
at once whatever pressure it carried.

The segment end points are the projections of the target facet ends onto
the striker facet (clamped to it), min/max expressions of the current
positions; every position is a UFL coefficient (the striker's own u, the
neighbours' and the slot targets' displacements w_k selected from u by
:class:`MortarTransfer`), so ``ufl.derivative`` gives the full tangent:
normals, projections and segment ends. Only the choice of the slots (which
target facets a node sees) is frozen between searches.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np
import ufl
from dolfinx import default_scalar_type, fem, la

from mpi4py import MPI

from fenics_contact.model.contact import ContactSettings, ContactSurface, assemble_local
from fenics_contact.model.contacts import Contact, SlotUse
from fenics_contact.model.form_batches import CONTACT_CFLAGS
from fenics_contact.model.friction import FrictionSettings
from fenics_contact.model.search import penetration_depth
from fenics_contact.model.segments import (
    MOST_SLOTS,
    NEAR,
    OPPOSING,
    REACH,
    Polyline,
    any_rank,
    facet_sizes,
    neighbours,
    node_blocks,
    overlaps,
    pick_slots,
    slots_needed,
)
from fenics_contact.model.variational_system import Transfers

_GAUSS = ((0.5 - 0.5 / np.sqrt(3.0), 0.5), (0.5 + 0.5 / np.sqrt(3.0), 0.5))


def _perp(t: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
    return ufl.as_vector((t[1], -t[0]))


class MortarTransfer:
    """Striker neighbours and target slots of every striker node; the selection w = S u.

    Coefficients on the striker submesh, one row per point of a node's
    stencil (row 0: the left neighbour, 1: the right one, 2 + 2k and
    3 + 2k: the ends a_k, b_k of slot k's target facet): reference positions
    ``X`` and displacements ``w`` (P1, shape (rows, 2)), and masks ``m``
    (P1, shape (2 + slots,): 1 where the neighbour or the slot exists).
    Unused slots point at the node itself with mask 0. One packed
    coefficient keeps the Jacobian at 3 x 3 blocks.
    """

    def __init__(self, V: fem.FunctionSpace, u: fem.Function, surface: ContactSurface,
                 target_facets: np.ndarray, slots: int | None = None) -> None:
        self.V, self.u, self.comm = V, u, V.mesh.comm
        self.striker = Polyline(V, surface.facets)
        self.target = Polyline(V, target_facets)
        sub = surface.submesh
        Q = surface.Q
        parent = np.asarray(surface.node_map)[sub.geometry.dofmaps[0].reshape(-1)]
        n_w = Q.dofmap.index_map.size_local + Q.dofmap.index_map.num_ghosts
        node = np.zeros(n_w, np.int64)
        node[Q.dofmap.list.reshape(-1)] = parent
        local = node_blocks(V)[node].astype(np.int32)
        self.block = V.dofmap.index_map.local_to_global(local).astype(np.int64)
        self.n_owned = Q.dofmap.index_map.size_local
        self.me = self.striker.index(self.block)
        left, right = neighbours(self.striker, self.me)
        if np.any((left < 0) & (right < 0)):
            raise ValueError("A striker node of a mortar pair has no striker facet.")
        self.sides = (left, right)
        self._idx = np.stack([np.where(nb >= 0, nb, self.me) for nb in self.sides], axis=1)
        #: Target facets a support needs where the surfaces first meet (:func:`slots_needed`).
        self.slots_wanted = int(self.comm.allreduce(slots_needed(self.striker, self.target),
                                                    op=MPI.MAX))
        self.slots = int(min(self.slots_wanted, MOST_SLOTS) if slots is None else slots)
        self.striker_size = float(np.max(facet_sizes(self.striker)))
        self.reach = REACH * max(self.striker_size, float(np.max(facet_sizes(self.target))))
        self.rows = 2 + 2 * self.slots
        self.W = fem.functionspace(sub, ("Lagrange", 1, (self.rows, 2)))
        self.M = fem.functionspace(sub, ("Lagrange", 1, (2 + self.slots,)))
        if not (np.array_equal(self.W.dofmap.list, Q.dofmap.list)
                and np.array_equal(self.M.dofmap.list, Q.dofmap.list)):
            raise RuntimeError("The blocked and scalar P1 submesh spaces number nodes differently.")
        self.X = fem.Function(self.W, name="mortar_X")
        self.w = fem.Function(self.W, name="mortar_w")
        self.m = fem.Function(self.M, name="mortar_mask")
        self._X = np.zeros((n_w, self.rows, 2))
        self._m = np.zeros((n_w, 2 + self.slots))
        self._src = np.zeros((n_w, self.rows), np.int64)
        Xs = self.striker.X
        Xj = Xs[self.me]
        for s, (nb, other) in enumerate(((left, right), (right, left))):
            has = nb >= 0
            self._X[:, s] = np.where(has[:, None], Xs[np.maximum(nb, 0)],
                                     2.0 * Xj - Xs[np.maximum(other, 0)])
            self._m[:, s] = has
            self._src[:, s] = self.striker.vertices[self._idx[:, s]]
        self._excluded = self._shared_vertex_pairs()
        self.assignment = np.full((n_w, self.slots), -2, np.int64)
        self.version = 0
        self.search_count = 0
        self.overflow = 0
        #: The most target facets one striker node near contact overlapped: at the last
        #: search, and in any converged state so far (:meth:`MortarContact.note_converged`;
        #: an iterate far from the answer may stretch a facet over many; owned, this rank).
        self.overlaps_now = 0
        self.most_overlaps = 0
        self._searched_u: np.ndarray | None = None

    def refresh(self) -> bool:
        """Search the slots and fill X, w and m; True when some slot changed (any rank)."""
        same = self._searched_u is not None and np.array_equal(self._searched_u, self.u.x.array)
        if not any_rank(self.comm, not same):
            return False
        self._searched_u = self.u.x.array.copy()
        us = self.striker.displacements(self.u)
        ut = self.target.displacements(self.u)
        scores, near = self._scores(self.striker.X + us, self.target.X + ut)
        facet, used, dropped = pick_slots(scores, self.slots)
        #: Striker nodes near contact (target within NEAR facet lengths) that overlap more
        #: target facets than there are slots (owned, this rank); 0 in every test.
        self.overflow = int(np.sum(((dropped > 0) & near)[: self.n_owned]))
        counts = np.sum(scores > 0.0, axis=1)[: self.n_owned][near[: self.n_owned]]
        self.overlaps_now = int(counts.max(initial=0))
        self.search_count += 1
        self._picked = (facet, used)
        fv = self.target.facet_vertex
        for k in range(self.slots):
            f = np.maximum(facet[:, k], 0)
            on = used[:, k]
            self._m[:, 2 + k] = on
            for e in (0, 1):
                vert = fv[f, e]
                row = 2 + 2 * k + e
                self._X[:, row] = np.where(on[:, None], self.target.X[vert],
                                           self.striker.X[self.me])
                self._src[:, row] = np.where(on, self.target.vertices[vert], self.block)
        w = self._select(us, ut)
        self.X.x.array[:] = self._X.reshape(-1)
        self.w.x.array[:] = w.reshape(-1)
        self.m.x.array[:] = self._m.reshape(-1)
        changed = not np.array_equal(facet[: self.n_owned], self.assignment[: self.n_owned])
        self.assignment = facet
        if any_rank(self.comm, changed):
            self.version += 1
            return True
        return False

    def _shared_vertex_pairs(self) -> tuple[np.ndarray, np.ndarray]:
        """(node, target facet) pairs never paired: the facet holds the node or a neighbour.

        Only two surfaces of one body share vertices (self-contact, where they
        meet at a fold or a notch's root). A node's own corner is no contact:
        paired, a node on the shared vertex pressed against a facet it belongs
        to and carried a force the displacements never feel.
        """
        shared = np.intersect1d(self.striker.vertices, self.target.vertices)
        if shared.size == 0:
            return np.zeros(0, np.int64), np.zeros(0, np.int64)
        stencil = np.column_stack([self.me, self._idx[:, 0], self._idx[:, 1]])
        stencil = self.striker.vertices[stencil]  # global blocks (n, 3)
        facets = self.target.vertices[self.target.facet_vertex]  # global blocks (m, 2)
        rows = np.flatnonzero(np.isin(stencil, shared).any(axis=1))
        cols = np.flatnonzero(np.isin(facets, shared).any(axis=1))
        hit = (stencil[rows][:, None, :, None] == facets[cols][None, :, None, :]).any(axis=(2, 3))
        r, c = np.nonzero(hit)
        return rows[r], cols[c]

    def passed_through(self) -> np.ndarray:
        """Depth of each owned striker node inside the target body, where it has passed through.

        Closest point and pseudo-normal on the target polyline (as for
        node-to-segment pairs). Only depths beyond half a striker facet count
        (else 0): the weighted gaps keep a converged node within a tiny
        fraction of h of the surface, while a node deeper than the search's
        reach has no segment and would count as open (collective).
        """
        us = self.striker.displacements(self.u)
        ut = self.target.displacements(self.u)
        points = (self.striker.X + us)[self.me[: self.n_owned]]
        current = (self.target.X + ut)[self.target.facet_vertex]
        depth = penetration_depth(points, current)
        return np.where(depth > 0.5 * self.striker_size, depth, 0.0)

    def _select(self, us: np.ndarray, ut: np.ndarray) -> np.ndarray:
        """The rows w = S u of every node from striker and target vertex displacements."""
        facet, used = self._picked
        w = np.zeros_like(self._X)
        w[:, 0], w[:, 1] = us[self._idx[:, 0]], us[self._idx[:, 1]]
        fv = self.target.facet_vertex
        for k in range(self.slots):
            f = np.maximum(facet[:, k], 0)
            on = used[:, k][:, None]
            for e in (0, 1):
                w[:, 2 + 2 * k + e] = np.where(on, ut[fv[f, e]], us[self.me])
        return w

    def _scores(self, xs: np.ndarray, xt: np.ndarray) -> np.ndarray:
        """Overlaps of the target facets with each node's two striker facets, and near contact.

        ``xs``, ``xt``: current positions of the striker and target polyline vertices.
        """
        xt = xt[self.target.facet_vertex]
        xj = xs[self.me]
        x_side = [xs[self._idx[:, s]] for s in (0, 1)]
        x_side = [np.where((self.sides[s] >= 0)[:, None], x_side[s], 2 * xj - x_side[1 - s])
                  for s in (0, 1)]
        scores = np.full((xj.shape[0], xt.shape[0]), -np.inf)
        near = np.zeros(xj.shape[0], bool)
        for s, (x1, x2) in enumerate(((x_side[0], xj), (xj, x_side[1]))):
            sc, dist = overlaps(x1, x2, xt[:, 0], xt[:, 1], self.reach)
            sc[self.sides[s] < 0] = -np.inf
            near |= np.any((sc > 0.0) & (dist < NEAR), axis=1)
            scores = np.maximum(scores, sc)
        scores[self._excluded] = -np.inf
        return scores, near

    def sources(self) -> list[np.ndarray]:
        """Global V block of each row of each owned node, shape (n_owned, rows)."""
        return [self._src[: self.n_owned].copy()]

    # -- UFL -------------------------------------------------------------------------
    def _point(self, f: fem.Function, i: int) -> ufl.core.expr.Expr:
        return ufl.as_vector((f[i, 0], f[i, 1]))

    def segments(self, X_j: ufl.core.expr.Expr, x_j: ufl.core.expr.Expr):
        """The Gauss points of node j's segments and the full support area.

        Returns (points, full): ``points`` a list of (weight, facet, slot, xi,
        alpha) per Gauss point of every (striker facet, slot) segment, weight
        = m_f m_k |facet| span w_q N_j(xi) (zero on an empty segment), facet
        = (x1, x2, s) with s the neighbour row, slot k, xi the striker facet's
        local coordinate and alpha the gap along n_s; ``full`` = A_j.
        """
        X_nb = [self._point(self.X, s) for s in (0, 1)]
        x_nb = [X_nb[s] + self._point(self.w, s) for s in (0, 1)]
        facets = ((X_nb[0], x_nb[0], x_j, 0, lambda xi: xi),
                  (X_nb[1], x_j, x_nb[1], 1, lambda xi: 1.0 - xi))
        targets = [(self._point(self.X, 2 + 2 * k) + self._point(self.w, 2 + 2 * k),
                    self._point(self.X, 3 + 2 * k) + self._point(self.w, 3 + 2 * k),
                    self.m[2 + k]) for k in range(self.slots)]
        points, full = [], 0
        for Xn, x1, x2, s, shape in facets:
            m_f = self.m[s]
            t = x2 - x1
            tt = ufl.dot(t, t)
            n_s = _perp(t) / ufl.sqrt(tt)
            length = ufl.sqrt(ufl.dot(Xn - X_j, Xn - X_j))
            full = full + 0.5 * m_f * length
            for k, (a, b, m_k) in enumerate(targets):
                xa = ufl.dot(a - x1, t) / tt
                xb = ufl.dot(b - x1, t) / tt
                lo = ufl.max_value(ufl.min_value(xa, xb), 0.0)
                hi = ufl.min_value(ufl.max_value(xa, xb), 1.0)
                span = ufl.max_value(hi - lo, 0.0)
                n_t = _perp(b - a)
                # a slot serves both facets of the node; the one it does not face (a
                # striker turning a corner) gets nothing from it, as in the search
                facing = ufl.conditional(
                    ufl.lt(ufl.dot(n_s, n_t), -OPPOSING * ufl.sqrt(ufl.dot(n_t, n_t))), 1.0, 0.0)
                denom = m_k * facing * ufl.dot(n_s, n_t) - (1.0 - m_k * facing)
                for q, wq in _GAUSS:
                    xi = lo + span * q
                    alpha = ufl.dot(a - (x1 + xi * t), n_t) / denom
                    weight = m_f * m_k * facing * length * span * wq * shape(xi)
                    points.append((weight, (x1, x2, s, n_s), (k, a, b), xi, alpha))
        return points, full

    def nodal_gap(self, X_j: ufl.core.expr.Expr, x_j: ufl.core.expr.Expr,
                  g_open: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
        """G_j = g~_j / A~_j at a striker node (reference ``X_j``, current ``x_j``; length)."""
        points, full = self.segments(X_j, x_j)
        weighted = sum(p[0] * p[4] for p in points)
        area = sum(p[0] for p in points)
        floor = 1e-8 * full
        return ufl.conditional(ufl.gt(area, floor),
                               weighted / ufl.max_value(area, floor), g_open)


class MortarContact(Contact):
    """A striker surface against a target surface of another body: 2D or 3D mortar.

    In 2D the nodal gap is a UFL expression of the node's stencil (this
    module); in 3D it is an extra unknown-like coefficient G whose value,
    derivative and curvature come from the segment forms (:mod:`.mortar3d`).

    Same interface as :class:`~.pairs.NodeToSegmentContact` (r relative to
    E/h with the pair modulus 2 E_s E_t / (E_s + E_t)); see the module for
    the formulation.

    Args:
        striker_facets, target_facets: local facet indices of the two surfaces.
        settings: r, its scale; the quadrature must be 'nodal' (the vertex rule
            on the nodal pairs).
        slots: target facets a striker node may see (default from the facet sizes).
        friction: Coulomb friction (None: frictionless); the slip is measured at each
            striker node's projection on the target (:meth:`slip_increment`).
        name: label in outputs.
    """

    #: The kernels are large (MBs of C): cheap C optimisation compiles them in a
    #: fraction of the time at a small cost in assembly (docs/two_bodies.md).
    jit_options: ClassVar[dict] = {"cffi_extra_compile_args": CONTACT_CFLAGS}

    def __init__(self, striker_facets: np.ndarray, target_facets: np.ndarray,
                 settings: ContactSettings, *, striker: str | None = None,
                 target: str | None = None, slots: int | None = None,
                 friction: FrictionSettings | None = None, name: str = "pair") -> None:
        if settings.quadrature != "nodal":
            raise ValueError("Mortar contact holds Alart-Curnier at the nodes: use quadrature = "
                             f"'nodal', got {settings.quadrature!r}.")
        super().__init__(striker_facets, settings, friction=friction, name=name)
        self.target_facets = np.asarray(target_facets, dtype=np.int32)
        self._names = (striker, target)
        self._slots = slots
        self._target_force_forms: list[fem.Form] | None = None

    def facet_arguments(self) -> dict[str, np.ndarray]:
        """The striker and target facet index arrays, by argument name."""
        return {"striker_facets": self.facets, "target_facets": self.target_facets}

    def _bind_partner(self, solid) -> ufl.core.expr.Expr:
        from fenics_contact.model.pairs import bind_pair_bodies

        if solid.degree != 1:
            raise ValueError("Mortar contact needs degree = 1 (linear elements) in this version.")
        overlap = np.intersect1d(self.facets, self.target_facets).size
        if self.comm.allreduce(overlap, op=MPI.SUM):
            raise ValueError("The striker and target facet sets share facets; a contact pair "
                             "needs two disjoint surfaces (tag them separately).")
        bind_pair_bodies(self, solid)
        if solid.gdim == 3:
            from fenics_contact.model.mortar3d import MortarTransfer3D

            self.mortar = MortarTransfer3D(solid.V, solid.u, self.surface, self.target_facets,
                                           self.surface.h, self.lam)
        else:
            self.mortar = MortarTransfer(solid.V, solid.u, self.surface, self.target_facets,
                                         self._slots)
        self.mortar.refresh()
        if self.friction_settings is not None:
            # the slip of each striker node at its projection on the target (slip_increment)
            from fenics_contact.model.pairs import DeformablePair

            self.slip_pair = DeformablePair(solid.V, solid.u, self.surface, self.target_facets)
            self.slip_pair.refresh()
            self._transfer = Transfers([self.mortar, self.slip_pair])
        if solid.gdim == 3:
            return self.mortar.G
        X = ufl.SpatialCoordinate(solid.domain)
        #: The gap of a node whose support meets no target facet (length; a Constant so
        #: that the compiled forms do not depend on the mesh).
        self.open_gap = fem.Constant(solid.domain, default_scalar_type(self.surface.h))
        # a node that loses its last segment while it still carries pressure (a stiff
        # target's corner passing over it) must open at once: with a gap of h alone,
        # lam + r h < 0 kept it active with a gap of no derivative, a zero Jacobian row
        uncovered = self.open_gap + ufl.max_value(-self.lam / self.r, 0.0)
        return self.mortar.nodal_gap(X, X + solid.u, uncovered)

    def may_close(self, gaps: np.ndarray) -> np.ndarray:
        """3D: only engaged nodes (G <= 1e-3 h) carry dG/du while open; 2D: every node."""
        if self.gdim != 3:
            return super().may_close(gaps)
        from fenics_contact.model.mortar3d import ENGAGED

        return gaps <= ENGAGED * self.mortar.open_gap

    def note_converged(self) -> None:
        """2D: the overlaps of the state just converged count towards :meth:`slot_use`."""
        if self.gdim == 2:
            self.mortar.most_overlaps = max(self.mortar.most_overlaps, self.mortar.overlaps_now)

    def slot_use(self) -> SlotUse | None:
        """2D: the slots and the most target facets a striker node overlapped (collective)."""
        if self.gdim == 3:
            return None
        m = self.mortar
        wanted, now, most = (int(self.comm.allreduce(v, op=MPI.MAX))
                             for v in (m.slots_wanted, m.overlaps_now, m.most_overlaps))
        return SlotUse(self.name, m.slots, wanted, now, most)

    def reported(self, values: np.ndarray) -> np.ndarray:
        """2D: the nodal force per tributary length of the multiplier field (stress).

        With the standard basis the multiplier field is lam_h = sum_j lam_j N_j
        and striker node k receives the force int N_k lam_h dA: its nodal
        pressure is that force over int N_k dA, the lumped L2 projection of
        lam_h (what node-to-segment's multiplier and the 3D dual basis are at
        the nodes). The multipliers themselves swing at the edge of a
        contact zone (the last active node overshoots while its neighbour,
        whose weighted gap averages over a support reaching past the edge,
        opens). The active set stays the multipliers'. 3D: the dual basis
        already gives the nodal force per area; the values are returned.
        """
        if self.gdim == 3:
            return values
        # explicit width: a rank without striker nodes has 0 rows and must still take
        # part in every (collective) column
        columns = values.reshape(values.shape[0], int(np.prod(values.shape[1:])))
        out = np.column_stack([self._nodal_force_per_length(c) for c in columns.T])
        return out.reshape(values.shape)

    def _nodal_force_per_length(self, values: np.ndarray) -> np.ndarray:
        """The nodal means int N_k v_h dA / int N_k dA at the owned striker nodes (v_h: P1)."""
        if getattr(self, "_report_form", None) is None:
            self._report_field = fem.Function(self.Q)
            exact = self.surface.ds_nodal.reconstruct(metadata={"quadrature_degree": 2})
            self._report_form = fem.form(
                self._report_field * ufl.TestFunction(self.Q) * exact,
                entity_maps=self.surface.entity_maps)
        field = self._report_field
        field.x.array[:] = 0.0
        field.x.array[: values.size] = values
        field.x.scatter_forward()
        return assemble_local(self._report_form) / self.surface.lumped_area

    def slip_increment(self, u_prev: fem.Function) -> tuple[ufl.core.expr.Expr, ufl.core.expr.Expr]:
        """(T_j, s_j) of the Coulomb terms: the slip of each striker node at its projection.

        As for node-to-segment pairs (:func:`~.pairs.slip_at_projection`): the
        increment of the striker node against the target point it projects on,
        in the target facet's tangents. The normal part stays mortar's
        (weighted gaps). Measured against the slip weighted over the segments
        (docs/two_bodies.md, "Friction on mortar pairs"): the stick zone of
        Cattaneo-Mindlin keeps its edge (the weighted slip smears it inwards by
        about a node spacing) and the forms compile in a fraction of the time.
        """
        from fenics_contact.model.pairs import slip_at_projection

        return slip_at_projection(self.slip_pair, self.solid.u, u_prev, self.gdim,
                                  self.solid.symmetry_plane_axes())

    def commit_frame(self) -> None:
        """The previous frame <- the new u_prev (the projections' target vertices)."""
        if self.friction is None:
            return
        self.slip_pair.set_previous()

    def extras(self) -> list[fem.Function]:
        """The extras the kernel condenses.

        2D: the packed neighbour and slot displacements (w = S u); 3D: the nodal
        gaps G; with friction, then the projections' target vertex displacements.
        """
        slip = list(self.slip_pair.w) if self.friction_settings is not None else []
        return [self.mortar.G if self.gdim == 3 else self.mortar.w, *slip]

    @property
    def transfer(self):
        """The search and condensation (refresh, version, sources or condensation)."""
        return getattr(self, "_transfer", self.mortar)

    def refresh(self) -> bool:
        """Search and refill the coefficients when u has changed."""
        return self.transfer.refresh()

    def penetration(self) -> float | None:
        """-min(G) of the weighted gaps, or the depth of a striker node that passed through.

        A node pushed deeper than the segment search reaches has no segment
        and counts as open; measured by closest point it is inside the
        target body, and the solvers' acceptance test refuses the iterate
        (``surface_tol``). 2D and 3D alike.
        """
        passed = float(np.max(self.mortar.passed_through(), initial=0.0))
        weighted = float(np.max(-self.surface.nodal(self._gap_form), initial=0.0))
        return self.comm.allreduce(max(passed, weighted), op=MPI.MAX)

    def target_force(self) -> fem.Function:
        """Contact force on the target's vertices, S^T dL_c/dw over the slot rows (force)."""
        if self.gdim == 3:
            return self._target_force_3d()
        m = self.mortar
        if self._target_force_forms is None:
            q = ufl.TestFunction(m.W)
            form = ufl.derivative(self.lagrangian(), m.w, q)
            self._target_force_forms = [fem.form(form, entity_maps=self.surface.entity_maps,
                                                 jit_options=self.jit_options)]
        self.refresh()
        from petsc4py import PETSc

        V = self.solid.V
        im = V.dofmap.index_map
        vec = PETSc.Vec().createMPI((im.size_local * 2, im.size_global * 2), bsize=2,
                                    comm=self.comm)
        vec.set(0.0)
        local = fem.assemble_vector(self._target_force_forms[0])
        local.scatter_reverse(la.InsertMode.add)
        values = local.array[: m.n_owned * m.rows * 2].reshape(m.n_owned, m.rows, 2)[:, 2:]
        src = m.sources()[0][:, 2:]
        vec.setValuesBlocked(src.reshape(-1).astype(PETSc.IntType), values.reshape(-1),
                             addv=PETSc.InsertMode.ADD)
        vec.assemblyBegin()
        vec.assemblyEnd()
        out = fem.Function(V, name="target_contact_force")
        out.x.array[: im.size_local * 2] = -vec.getArray(readonly=True)
        if self.friction is not None:
            out.x.array[: im.size_local * 2] += self._friction_target_force()
        out.x.scatter_forward()
        vec.destroy()
        return out


    def _target_force_3d(self) -> fem.Function:
        """-(dG/du)^T dL_c/dG on the target's vertices (force)."""
        m = self.mortar
        if self._target_force_forms is None:
            form = ufl.derivative(self.lagrangian(), m.G, ufl.TestFunction(self.Q))
            self._target_force_forms = [fem.form(form, entity_maps=self.surface.entity_maps)]
        self.refresh()
        local = fem.assemble_vector(self._target_force_forms[0])
        local.scatter_reverse(la.InsertMode.add)
        force = m.target_force(local.array[: m.n_owned])
        V = self.solid.V
        lo, hi = V.dofmap.index_map.local_range
        out = fem.Function(V, name="target_contact_force")
        out.x.array[: (hi - lo) * 3] = force[3 * lo : 3 * hi]
        if self.friction is not None:
            out.x.array[: (hi - lo) * 3] += self._friction_target_force()
        out.x.scatter_forward()
        return out

    def _friction_target_force(self) -> np.ndarray:
        """-S^T dW_t/dw of the projections' target vertices, owned V dofs (friction)."""
        from petsc4py import PETSc

        pair = self.slip_pair
        if getattr(self, "_friction_forms", None) is None:
            q = ufl.TestFunction(pair.W)
            self._friction_forms = [
                fem.form(self.friction.work(self.friction.traction_t, wk, q),
                         entity_maps=self.surface.entity_maps) for wk in pair.w]
        V = self.solid.V
        im = V.dofmap.index_map
        d = self.gdim
        vec = PETSc.Vec().createMPI((im.size_local * d, im.size_global * d), bsize=d,
                                    comm=self.comm)
        vec.set(0.0)
        for form, src in zip(self._friction_forms, pair.sources(), strict=True):
            local = fem.assemble_vector(form)
            local.scatter_reverse(la.InsertMode.add)
            vec.setValuesBlocked(src.astype(PETSc.IntType), local.array[: pair.n_owned * d],
                                 addv=PETSc.InsertMode.ADD)
        vec.assemblyBegin()
        vec.assemblyEnd()
        values = -vec.getArray(readonly=True).copy()
        vec.destroy()
        return values


__all__ = ["MortarContact", "MortarTransfer"]
