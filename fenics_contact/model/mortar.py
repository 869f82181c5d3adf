"""Mortar (segment-to-segment) frictionless contact of two bodies in 2D, in UFL.

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
meets no target facet is open (G_j = h).

The segment end points are the projections of the target facet ends onto
the striker facet (clamped to it), min/max expressions of the current
positions; every position is a UFL coefficient (the striker's own u, the
neighbours' and the slot targets' displacements w_k selected from u by
:class:`MortarTransfer`), so ``ufl.derivative`` gives the full tangent:
normals, projections and segment ends. Only the choice of the slots (which
target facets a node sees) is frozen between searches.
"""

from __future__ import annotations

import numpy as np
import ufl
from dolfinx import fem, la

from mpi4py import MPI

from fenics_contact.model.contact import ContactSettings, ContactSurface
from fenics_contact.model.contacts import Contact
from fenics_contact.model.segments import (
    Polyline,
    any_rank,
    default_slots,
    facet_sizes,
    neighbours,
    node_blocks,
    overlaps,
    pick_slots,
)

_GAUSS = ((0.5 - 0.5 / np.sqrt(3.0), 0.5), (0.5 + 0.5 / np.sqrt(3.0), 0.5))


def _perp(t: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
    return ufl.as_vector((t[1], -t[0]))


class MortarTransfer:
    """Striker neighbours and target slots of every striker node; the selection w = S u.

    Coefficients on the striker submesh (vector P1 ``W``, scalar P1 ``Q``):
    reference positions ``X_*`` and displacements ``w_*`` of the left and
    right neighbours and of each slot's target facet ends (a_k, b_k), and
    masks ``m_*`` (1 where the facet or slot exists). Unused slots point at
    the node itself with mask 0.
    """

    def __init__(self, V: fem.FunctionSpace, u: fem.Function, surface: ContactSurface,
                 target_facets: np.ndarray, slots: int | None = None) -> None:
        self.V, self.u, self.comm = V, u, V.mesh.comm
        self.striker = Polyline(V, surface.facets)
        self.target = Polyline(V, target_facets)
        self.slots = slots or default_slots(self.striker, self.target)
        self.reach = 2.0 * max(float(np.max(facet_sizes(self.striker))),
                               float(np.max(facet_sizes(self.target))))
        self.W = fem.functionspace(surface.submesh, ("Lagrange", 1, (2,)))
        Q = surface.Q
        if not np.array_equal(self.W.dofmap.list, Q.dofmap.list):
            raise RuntimeError("The vector and scalar P1 submesh spaces number nodes differently.")
        sub_geo = surface.submesh.geometry
        parent = np.asarray(surface.node_map)[sub_geo.dofmaps[0].reshape(-1)]
        n_w = self.W.dofmap.index_map.size_local + self.W.dofmap.index_map.num_ghosts
        node = np.zeros(n_w, np.int64)
        node[self.W.dofmap.list.reshape(-1)] = parent
        local = node_blocks(V)[node].astype(np.int32)
        self.block = V.dofmap.index_map.local_to_global(local).astype(np.int64)
        self.n_owned = self.W.dofmap.index_map.size_local
        self.me = self.striker.index(self.block)
        left, right = neighbours(self.striker, self.me)
        if np.any((left < 0) & (right < 0)):
            raise ValueError("A striker node of a mortar pair has no striker facet.")
        self.sides = (left, right)

        def vec(name: str) -> fem.Function:
            return fem.Function(self.W, name=name)

        def scal(name: str) -> fem.Function:
            return fem.Function(Q, name=name)

        self.X_side = [vec("mortar_X_left"), vec("mortar_X_right")]
        self.w_side = [vec("mortar_w_left"), vec("mortar_w_right")]
        self.m_side = [scal("mortar_m_left"), scal("mortar_m_right")]
        self.X_slot = [[vec(f"mortar_X{e}{k}") for e in "ab"] for k in range(self.slots)]
        self.w_slot = [[vec(f"mortar_w{e}{k}") for e in "ab"] for k in range(self.slots)]
        self.m_slot = [scal(f"mortar_m{k}") for k in range(self.slots)]
        self.assignment = np.full((n_w, self.slots), -2, np.int64)
        self._sources: list[np.ndarray] = []
        self.version = 0
        self.search_count = 0
        self._searched_u: np.ndarray | None = None
        self._fill_sides()

    def _fill_sides(self) -> None:
        """Reference positions, masks and sources of the striker neighbours (fixed)."""
        X = self.striker.X
        Xj = X[self.me]
        left, right = self.sides
        self._side_src, self._side_idx = [], []
        for s, (nb, other) in enumerate(((left, right), (right, left))):
            has = nb >= 0
            Xn = np.where(has[:, None], X[np.maximum(nb, 0)], 2.0 * Xj - X[np.maximum(other, 0)])
            self.X_side[s].x.array[:] = Xn.reshape(-1)
            self.m_side[s].x.array[:] = has.astype(float)
            idx = np.where(has, nb, self.me)
            self._side_idx.append(idx)
            self._side_src.append(self.striker.vertices[idx])

    def refresh(self) -> bool:
        """Search the slots and fill the w_*; True when some slot changed (any rank)."""
        same = self._searched_u is not None and np.array_equal(self._searched_u, self.u.x.array)
        if not any_rank(self.comm, not same):
            return False
        self._searched_u = self.u.x.array.copy()
        us = self.striker.displacements(self.u)
        ut = self.target.displacements(self.u)
        xs = self.striker.X + us
        xt = (self.target.X + ut)[self.target.facet_vertex]
        xj = xs[self.me]
        x_side = [xs[i] for i in self._side_idx]
        x_side = [np.where((self.sides[s] >= 0)[:, None], x_side[s], 2 * xj - x_side[1 - s])
                  for s in (0, 1)]
        scores = np.full((xj.shape[0], xt.shape[0]), -np.inf)
        for s, (x1, x2) in enumerate(((x_side[0], xj), (xj, x_side[1]))):
            sc = overlaps(x1, x2, xt[:, 0], xt[:, 1], self.reach)
            sc[self.sides[s] < 0] = -np.inf
            scores = np.maximum(scores, sc)
        facet, used = pick_slots(scores, self.slots)
        self.search_count += 1
        for s in (0, 1):
            self.w_side[s].x.array[:] = us[self._side_idx[s]].reshape(-1)
        fv = self.target.facet_vertex
        sources = []
        for k in range(self.slots):
            f = np.maximum(facet[:, k], 0)
            self.m_slot[k].x.array[:] = used[:, k].astype(float)
            for e in (0, 1):
                vert = fv[f, e]
                X = np.where(used[:, k, None], self.target.X[vert], self.striker.X[self.me])
                w = np.where(used[:, k, None], ut[vert], us[self.me])
                self.X_slot[k][e].x.array[:] = X.reshape(-1)
                self.w_slot[k][e].x.array[:] = w.reshape(-1)
                sources.append(np.where(used[:, k], self.target.vertices[vert], self.block))
        self._sources = [self._side_src[0], self._side_src[1], *sources]
        changed = not np.array_equal(facet[: self.n_owned], self.assignment[: self.n_owned])
        self.assignment = facet
        if any_rank(self.comm, changed):
            self.version += 1
            return True
        return False

    def extras(self) -> list[fem.Function]:
        """Displacement coefficients selected from u, in the order of :meth:`sources`."""
        return [*self.w_side, *(w for pair in self.w_slot for w in pair)]

    def sources(self) -> list[np.ndarray]:
        """Global V block each owned W block selects, one array per extra."""
        return [s[: self.n_owned] for s in self._sources]

    # -- UFL -------------------------------------------------------------------------
    def nodal_gap(self, x_j: ufl.core.expr.Expr, g_open: float) -> ufl.core.expr.Expr:
        """G_j = g~_j / A~_j at a striker node of current position ``x_j`` (length)."""
        x_side = [X + w for X, w in zip(self.X_side, self.w_side, strict=True)]
        facets = ((self.X_side[0], x_side[0], x_j, self.m_side[0], lambda xi: xi),
                  (self.X_side[1], x_j, x_side[1], self.m_side[1], lambda xi: 1.0 - xi))
        targets = [(Xa + wa, Xb + wb, m) for (Xa, Xb), (wa, wb), m
                   in zip(self.X_slot, self.w_slot, self.m_slot, strict=True)]
        weighted, area = 0, 0
        for X_nb, x1, x2, m_f, shape in facets:
            t = x2 - x1
            tt = ufl.dot(t, t)
            n_s = _perp(t) / ufl.sqrt(tt)
            dX = X_nb - self._X_node
            length = ufl.sqrt(ufl.dot(dX, dX))
            for a, b, m_k in targets:
                xa = ufl.dot(a - x1, t) / tt
                xb = ufl.dot(b - x1, t) / tt
                lo = ufl.max_value(ufl.min_value(xa, xb), 0.0)
                hi = ufl.min_value(ufl.max_value(xa, xb), 1.0)
                span = ufl.max_value(hi - lo, 0.0)
                n_t = _perp(b - a)
                denom = m_k * ufl.dot(n_s, n_t) - (1.0 - m_k)
                for q, wq in _GAUSS:
                    xi = lo + span * q
                    alpha = ufl.dot(a - (x1 + xi * t), n_t) / denom
                    weight = m_f * m_k * length * span * wq * shape(xi)
                    weighted = weighted + weight * alpha
                    area = area + weight
        full = 0.5 * sum(m * ufl.sqrt(ufl.dot(Xn - self._X_node, Xn - self._X_node))
                         for Xn, m in zip(self.X_side, self.m_side, strict=True))
        floor = 1e-8 * full
        return ufl.conditional(ufl.gt(area, floor),
                               weighted / ufl.max_value(area, floor), g_open)

    _X_node: ufl.core.expr.Expr


class MortarContact(Contact):
    """A striker surface against a target surface of another body: 2D frictionless mortar.

    Same interface as :class:`~.pairs.NodeToSegmentContact` (r relative to
    E/h with the pair modulus 2 E_s E_t / (E_s + E_t)); see the module for
    the formulation.

    Args:
        striker_facets, target_facets: local facet indices of the two surfaces.
        settings: r, its scale; the quadrature must be 'nodal' (the vertex rule
            on the nodal pairs).
        slots: target facets a striker node may see (default from the facet sizes).
        name: label in outputs.
    """

    def __init__(self, striker_facets: np.ndarray, target_facets: np.ndarray,
                 settings: ContactSettings, *, striker: str | None = None,
                 target: str | None = None, slots: int | None = None,
                 name: str = "pair") -> None:
        if settings.quadrature != "nodal":
            raise ValueError("Mortar contact holds Alart-Curnier at the nodes: use quadrature = "
                             f"'nodal', got {settings.quadrature!r}.")
        super().__init__(striker_facets, settings, name=name)
        self.target_facets = np.asarray(target_facets, dtype=np.int32)
        self._names = (striker, target)
        self._slots = slots
        self._target_force_forms: list[fem.Form] | None = None

    def _bind_partner(self, solid) -> ufl.core.expr.Expr:
        from fenics_contact.model.pairs import _named

        if solid.degree != 1 or solid.gdim != 2:
            raise ValueError("Mortar contact needs degree = 1 and a 2D mesh in this version.")
        overlap = np.intersect1d(self.facets, self.target_facets).size
        if self.comm.allreduce(overlap, op=MPI.SUM):
            raise ValueError("The striker and target facet sets share facets; a contact pair "
                             "needs two disjoint surfaces (tag them separately).")
        bodies = [
            solid.body_of_facets(facets, role) if name is None else _named(solid, name, role)
            for name, facets, role in zip(self._names, (self.facets, self.target_facets),
                                          ("striker", "target"), strict=True)
        ]
        Es, Et = (b.material.E for b in bodies)
        self.striker_body, self.target_body = bodies
        self.modulus = 2.0 * Es * Et / (Es + Et)
        self.mortar = MortarTransfer(solid.V, solid.u, self.surface, self.target_facets,
                                     self._slots)
        X = ufl.SpatialCoordinate(solid.domain)
        self.mortar._X_node = X
        self.mortar.refresh()
        return self.mortar.nodal_gap(X + solid.u, float(self.surface.h))

    def refresh(self) -> bool:
        """Search the slots and refill the coefficients when u has changed."""
        return self.mortar.refresh()

    def extras(self) -> list[fem.Function]:
        """Neighbour and slot displacements (condensed by w = S u)."""
        return self.mortar.extras()

    @property
    def transfer(self) -> MortarTransfer:
        """The slot search and selection (refresh, version, sources)."""
        return self.mortar

    def target_force(self) -> fem.Function:
        """Contact force on the target's vertices, sum over slots of S^T dL_c/dw (force)."""
        m = self.mortar
        if self._target_force_forms is None:
            q = ufl.TestFunction(m.W)
            self._target_force_forms = [
                fem.form(ufl.derivative(self.lagrangian(), w, q),
                         entity_maps=self.surface.entity_maps)
                for pair in m.w_slot for w in pair]
        m.refresh()
        from petsc4py import PETSc

        V = self.solid.V
        im = V.dofmap.index_map
        vec = PETSc.Vec().createMPI((im.size_local * 2, im.size_global * 2), bsize=2,
                                    comm=self.comm)
        vec.set(0.0)
        for form, src in zip(self._target_force_forms, m.sources()[2:], strict=True):
            local = fem.assemble_vector(form)
            local.scatter_reverse(la.InsertMode.add)
            values = local.array[: m.n_owned * 2]
            vec.setValuesBlocked(src.astype(PETSc.IntType), values, addv=PETSc.InsertMode.ADD)
        vec.assemblyBegin()
        vec.assemblyEnd()
        out = fem.Function(V, name="target_contact_force")
        out.x.array[: im.size_local * 2] = -vec.getArray(readonly=True)
        out.x.scatter_forward()
        vec.destroy()
        return out


__all__ = ["MortarContact", "MortarTransfer"]
