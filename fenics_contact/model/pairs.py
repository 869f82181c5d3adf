"""Two deformable bodies in one mesh: node-to-segment Alart-Curnier contact in UFL.

The bodies share one mesh, one displacement space and one set of boundary
conditions; cell tags tell them apart and each has its own material. A
contact pair is a striker facet set against a target facet set.

The gap of a striker node s on its assigned target facet (vertices a, b in
2D; a, b, c in 3D), in the current configuration ``x = X + u``:

    t = x_b - x_a,  n = perp(t) / |t|            (3D: (x_b - x_a) x (x_c - x_a) normalised)
    g = (x_s - x_a) . n                          (g >= 0 open)

The target vertex positions are held as vector P1 coefficients on the
striker's contact submesh: reference positions ``X_k`` and displacements
``w_k`` (k = a, b[, c]), filled by the search (:mod:`.search`) every
iteration. With ``x_k = X_k + w_k`` the gap is a UFL expression, so
``ufl.derivative`` with respect to u, lam and every w_k gives the residual
and the whole node-to-segment tangent, including the rotation of the target
facet. The solver condenses the w_k onto u with the selection w_k = S_k u
(:meth:`DeformablePair.sources`). Sign conventions as in
:mod:`fenics_contact.model.contact`: lam <= 0 is the striker's pressure.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np
import scipy.sparse as sp
import ufl
from dolfinx import fem, la, mesh

from mpi4py import MPI

from fenics_contact.model.body import Body
from fenics_contact.model.contact import ContactSettings, ContactSurface
from fenics_contact.model.contacts import Contact
from fenics_contact.model.form_batches import CONTACT_CFLAGS
from fenics_contact.model.friction import FrictionSettings, symmetric_frame
from fenics_contact.model.search import (
    TIE_TOL,
    Projection,
    SurfaceSearch,
    past_free_edge,
    penetration_depth,
)
from fenics_contact.model.segments import node_blocks
from fenics_contact.model.state import ContactState
from fenics_contact.model.target_surface import REACH_FACETS, TargetSurface

#: A node farther than this many facet sizes in front of its facet, with lam >= 0,
#: is open at any r: the solver's condensation leaves it out (DeformablePair.coupled).
COUPLING_GAP = 1.0
#: A frictionless pair searches again only nodes that may have come within this many
#: facet sizes of the target (DeformablePair._search).
SKIN = 4.0
#: How far past the rim of the target a striker node may lie and still be held, in its
#: own facet size (DeformablePair.refresh): a quarter facet, where half the tributary
#: length of a striker's end node has left the target.
BEYOND_RIM = 0.25


class DeformablePair:
    """A striker surface against a deformable target surface of the same mesh.

    Each rank keeps only the target facets that can hold the closest point
    of its striker nodes (:class:`~.target_surface.TargetSurface`): the
    target surface is not gathered, and the kept vertices' displacements are
    scattered from their owners. ``target_blocks``, ``vertices``,
    ``facet_vertex`` and ``X_vertices`` describe the kept facets; the
    assignment indexes them.

    Args:
        V: the displacement space (vector P1).
        u: the displacement.
        surface: the striker's contact surface (its submesh carries lam and W).
        target_facets: local facet indices of the target surface.
        keep_all: keep the whole target surface on every rank.
    """

    def __init__(
        self,
        V: fem.FunctionSpace,
        u: fem.Function,
        surface: ContactSurface,
        target_facets: np.ndarray,
        keep_all: bool = False,
    ) -> None:
        domain = V.mesh
        comm = domain.comm
        gdim = domain.geometry.dim
        tdim = domain.topology.dim
        fdim = tdim - 1
        self.comm = comm
        self.gdim = gdim
        self.V = V
        self.u = u
        self.surface = surface
        nv = gdim  # vertices per facet: segments in 2D, triangles in 3D
        topology = domain.topology
        for d0, d1 in ((fdim, tdim), (0, tdim), (tdim, 0), (fdim, 0)):
            topology.create_connectivity(d0, d1)
        facet_im = topology.index_map(fdim)
        facets = np.unique(np.asarray(target_facets, np.int32))
        facets = facets[facets < facet_im.size_local]
        nodes = mesh.entities_to_geometry(domain, fdim, facets).reshape(-1, nv) \
            if facets.size else np.zeros((0, nv), np.int32)
        if facets.size and mesh.entities_to_geometry(domain, fdim, facets).shape[1] != nv:
            raise ValueError(
                "Target facets must be segments (2D) or triangles (3D); split "
                "quadrilateral faces into triangles."
            )
        x = domain.geometry.x[:, :gdim]
        # Orient each facet: the vertex order gives the outward normal.
        f2c = topology.connectivity(fdim, tdim)
        cells = np.array([f2c.links(f)[0] for f in facets], np.int64)
        cell_centre = (
            x[domain.geometry.dofmaps[0][cells]].mean(axis=1)
            if facets.size else np.zeros((0, gdim))
        )
        X = x[nodes]
        normal = self._normals(X)
        flip = np.einsum("ij,ij->i", normal, X.mean(axis=1) - cell_centre) < 0
        if nv == 2:
            nodes[flip] = nodes[flip][:, ::-1]
        else:
            nodes[flip] = nodes[flip][:, [0, 2, 1]]
        node_block = node_blocks(V)
        #: The target facets this rank keeps (owned ones are exchanged, never gathered).
        self.target = TargetSurface(V, node_block[nodes].reshape(-1, nv),
                                    x[nodes].reshape(-1, nv, gdim), keep_all=keep_all)
        if self.target.num_global == 0:
            raise ValueError("The target facet set is empty on every rank.")
        # Striker nodes: W blocks on the submesh and their parent V blocks.
        self.W = fem.functionspace(surface.submesh, ("Lagrange", 1, (gdim,)))
        sub_geo = surface.submesh.geometry
        parent_node = np.asarray(surface.node_map)[sub_geo.dofmaps[0].reshape(-1)]
        n_w = self.W.dofmap.index_map.size_local + self.W.dofmap.index_map.num_ghosts
        self._striker_node = np.zeros(n_w, np.int64)
        self._striker_node[self.W.dofmap.list.reshape(-1)] = parent_node
        self._striker_block = node_block[self._striker_node]
        self.n_owned = self.W.dofmap.index_map.size_local
        self.X = [fem.Function(self.W, name=f"target_X{k}") for k in range(nv)]
        self.w = [fem.Function(self.W, name=f"target_w{k}") for k in range(nv)]
        #: Added to the gap of the nodes with no partner (component 0; length): a node
        #: past the target's rim (:meth:`refresh`) is lifted to its distance from the
        #: target, so it stays open and its written gap is that distance.
        self.lift = fem.Function(self.W, name="gap_lift")
        self._node_size = _node_sizes(surface.submesh, self.W)
        self.assignment = np.full(n_w, -1, np.int64)
        self.projection = None
        #: lam at each W block (owned first), set by a frictionless contact; None: every
        #: node is condensed (see :meth:`coupled`).
        self.multiplier = None
        self._coupled = np.ones(self.W.dofmap.index_map.size_local, bool)
        #: The tag values that only the striker's contact integrals read (set by the
        #: contact): :meth:`acting_facets` limits them; none, no limit.
        self.limit_ids: tuple[int, ...] = ()
        self._acting = la.vector(self.W.dofmap.index_map, 1)
        sub_fdim = surface.submesh.topology.dim
        sub_cells = surface.submesh.topology.index_map(sub_fdim)
        #: The mesh facet of each submesh cell (owned and ghost).
        self._cell_facet = np.asarray(surface.entity_map.sub_topology_to_topology(
            np.arange(sub_cells.size_local + sub_cells.num_ghosts, dtype=np.int32), False))
        # the skin of the search (see _search): per node, how far it may still move
        self._slack = np.zeros(n_w)
        self._skin_points: np.ndarray | None = None
        self._skin_current: np.ndarray | None = None
        #: Nodes the last search searched (owned and ghost).
        self.searched = 0
        #: Which nodes the last search searched (the others kept their facet and lift).
        self._fresh = np.ones(n_w, bool)
        #: Whether some kept node's lift dates from an earlier search (:meth:`settle_lifts`).
        self._stale_lifts = False
        self.w_prev: list[fem.Function] | None = None
        #: Incremented whenever some striker node changes facet (on any rank).
        self.version = 0
        self.search_count = 0
        self._searched_u: np.ndarray | None = None
        self._size = self.target.facet_size(u)
        self.target.gather(self.striker_positions(), REACH_FACETS * self._size, u)

    # -- the kept target facets ----------------------------------------------------
    @property
    def target_blocks(self) -> np.ndarray:
        """(m, nv) global V blocks of the kept facets' vertices."""
        return self.target.blocks

    @property
    def vertices(self) -> np.ndarray:
        """The kept facets' distinct global V blocks."""
        return self.target.vertices

    @property
    def facet_vertex(self) -> np.ndarray:
        """(m, nv) index in :attr:`vertices` of each kept facet's vertices."""
        return self.target.facet_vertex

    @property
    def X_vertices(self) -> np.ndarray:
        """Reference positions of :attr:`vertices` (length)."""
        return self.target.X_vertices

    def _normals(self, X: np.ndarray) -> np.ndarray:
        if self.gdim == 2:
            t = X[:, 1] - X[:, 0]
            return np.stack([t[:, 1], -t[:, 0]], axis=-1)
        return np.cross(X[:, 1] - X[:, 0], X[:, 2] - X[:, 0])

    # -- UFL -------------------------------------------------------------------
    def positions(self) -> list[ufl.core.expr.Expr]:
        """Current positions x_k = X_k + w_k of the assigned facet's vertices."""
        return [Xk + wk for Xk, wk in zip(self.X, self.w, strict=True)]

    def normal(self) -> ufl.core.expr.Expr:
        """Unit outward normal of the assigned target facet (current configuration)."""
        xk = self.positions()
        if self.gdim == 2:
            t = xk[1] - xk[0]
            return ufl.as_vector((t[1], -t[0])) / ufl.sqrt(ufl.dot(t, t))
        c = ufl.cross(xk[1] - xk[0], xk[2] - xk[0])
        return c / ufl.sqrt(ufl.dot(c, c))

    def gap(self, x_s: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
        """Signed normal gap of ``x_s`` to its facet's plane, plus the node's lift (length).

        The lift is data (0 for a node that faces the target), so the tangent
        is that of the plane gap.
        """
        return ufl.dot(x_s - self.positions()[0], self.normal()) + self.lift[0]

    def shape_weights(self, x_s: ufl.core.expr.Expr) -> list[ufl.core.expr.Expr]:
        """Weights N_k of the facet vertices at the projection of ``x_s`` (sum 1).

        2D: xi = (x_s - x_a) . t / |t|^2, N = (1 - xi, xi). 3D: the
        barycentric coordinates (1 - s - t, s, t) of the projection on the
        triangle's plane. Unclamped, like the gap.
        """
        xk = self.positions()
        d = x_s - xk[0]
        if self.gdim == 2:
            t = xk[1] - xk[0]
            xi = ufl.dot(d, t) / ufl.dot(t, t)
            return [1.0 - xi, xi]
        e1, e2 = xk[1] - xk[0], xk[2] - xk[0]
        g11, g12, g22 = ufl.dot(e1, e1), ufl.dot(e1, e2), ufl.dot(e2, e2)
        r1, r2 = ufl.dot(d, e1), ufl.dot(d, e2)
        det = g11 * g22 - g12**2
        s = (g22 * r1 - g12 * r2) / det
        t = (g11 * r2 - g12 * r1) / det
        return [1.0 - s - t, s, t]

    def track_previous(self, u_prev: fem.Function) -> list[fem.Function]:
        """Hold the assigned vertices' displacements in ``u_prev`` as data on W.

        Returns the coefficients w_prev_k (filled at every search and by
        :meth:`set_previous`); they are data, not unknowns.
        """
        self._u_prev = u_prev
        self.w_prev = [fem.Function(self.W, name=f"target_w{k}_prev") for k in range(self.gdim)]
        self.set_previous()
        return self.w_prev

    def set_previous(self) -> None:
        """Gather the target's displacements in u_prev and refill w_prev_k (collective)."""
        self._prev_t = self.target_displacements(self._u_prev)
        self._fill_previous()

    def _fill_previous(self) -> None:
        if self.w_prev is None or self.assignment.size == 0 or np.any(self.assignment < 0):
            return
        verts = self.facet_vertex[self.assignment]
        for k, wk in enumerate(self.w_prev):
            wk.x.array[:] = self._prev_t[verts[:, k]].reshape(-1)

    # -- search ------------------------------------------------------------------
    def target_displacements(self, u: fem.Function | None = None) -> np.ndarray:
        """Displacement (default: the current u) of every kept target vertex (collective)."""
        return self.target.displacements(self.u if u is None else u)

    def striker_positions(self) -> np.ndarray:
        """Current positions of the striker nodes (owned and ghost W blocks)."""
        x0 = self.V.mesh.geometry.x[self._striker_node, : self.gdim]
        return x0 + self.u.x.array.reshape(-1, self.gdim)[self._striker_block]

    def refresh(self) -> bool:
        """Search, then fill X_k and w_k; True when the assignment changed on any rank.

        Skipped (False) when u has not changed since the last search on any rank.
        """
        same = self._searched_u is not None and np.array_equal(self._searched_u, self.u.x.array)
        if self.comm.allreduce(same, op=MPI.LAND):
            return False
        self._searched_u = self.u.x.array.copy()
        points = self.striker_positions()
        gathers = self.target.gathers
        w_t, proj = self._settled_search(points, lambda current: self._search(current))
        self._lift_past_rim(points, (self.X_vertices + w_t)[self.facet_vertex], proj)
        if self.target.gathers != gathers and self.w_prev is not None:
            self._prev_t = self.target_displacements(self._u_prev)  # new vertex numbering
        self.search_count += 1
        self.projection = proj
        facet = proj.facet
        changed = not np.array_equal(facet[: self.n_owned], self.assignment[: self.n_owned])
        changed = self.comm.allreduce(changed, op=MPI.LOR)
        self.assignment = facet
        verts = self.facet_vertex[facet]
        for k in range(self.gdim):
            self.X[k].x.array[:] = self.X_vertices[verts[:, k]].reshape(-1)
            self.w[k].x.array[:] = w_t[verts[:, k]].reshape(-1)
        self._fill_previous()
        coupled = self.coupled(w_t)
        moved = self.comm.allreduce(not np.array_equal(coupled, self._coupled), op=MPI.LOR)
        self._coupled = coupled
        if changed or moved:
            self.version += 1
        return changed

    # -- the search's memory (a resumed run) -------------------------------------------
    def search_state(self) -> dict[str, np.ndarray]:
        """What the next search carries over from the last ones (local arrays, this rank).

        The facet each node holds (the hysteresis keeps it while it stays
        about as close as the closest one), the lifts (a self-contact node
        lifted at the last search has no facet to keep), the last projection
        and the skin of the search (which nodes the next one skips), the kept
        target facets, the coefficients filled from them, and whether the
        current u is the one last searched (the next refresh is then skipped).
        A fresh pair restored with :meth:`restore_search_state` searches on as
        this one does: without it the first search after a resume starts
        from no facet and may pick the other of two facets that tie (a node
        at their common vertex).
        """
        proj = self.projection
        n = self.assignment.size
        skin = self._skin_points is not None
        state = {f"kept_{k}": v for k, v in self.target.kept_state().items()}
        state |= {
            "assignment": self.assignment.copy(),
            "lift": self.lift.x.array.copy(),
            "projection": np.array(proj is not None),
            "xi": proj.xi.copy() if proj is not None else np.zeros((n, self.gdim - 1)),
            "distance": proj.distance.copy() if proj is not None else np.zeros(n),
            "overshoot": proj.overshoot.copy() if proj is not None else np.zeros(n),
            "slack": self._slack.copy(),
            "skin": np.array(skin),
            "skin_points": self._skin_points.copy() if skin else np.zeros((0, self.gdim)),
            "skin_current": (self._skin_current.copy() if skin
                             else np.zeros((0, self.gdim, self.gdim))),
            "coupled": self._coupled.copy(),
            "size": np.array(self._size),
            "searched_here": np.array(self._searched_u is not None
                                      and np.array_equal(self._searched_u, self.u.x.array)),
        }
        for k in range(self.gdim):
            state[f"X{k}"] = self.X[k].x.array.copy()
            state[f"w{k}"] = self.w[k].x.array.copy()
        return state

    def restore_search_state(self, state: dict[str, np.ndarray]) -> None:
        """Put back a :meth:`search_state` at the u it was taken at (collective).

        Raises:
            ValueError: the state was taken on another surface (its arrays do
                not fit this pair's nodes).
        """
        n = self.assignment.size
        if (state["assignment"].shape != (n,) or state["lift"].shape != self.lift.x.array.shape
                or state["coupled"].shape != self._coupled.shape):
            raise ValueError("The saved search state does not fit this pair's striker nodes.")
        self.target.restore_kept({k[len("kept_"):]: v for k, v in state.items()
                                  if k.startswith("kept_")}, self.u)
        self.assignment = np.asarray(state["assignment"], np.int64).copy()
        self.lift.x.array[:] = state["lift"]
        self._stale_lifts = True  # the search that set them is not known here
        self.projection = (Projection(self.assignment.copy(), np.array(state["xi"]),
                                      np.array(state["distance"]), np.array(state["overshoot"]))
                           if bool(state["projection"]) else None)
        self._slack = np.array(state["slack"])
        skin = bool(state["skin"])
        self._skin_points = np.array(state["skin_points"]) if skin else None
        self._skin_current = np.array(state["skin_current"]) if skin else None
        self._coupled = np.array(state["coupled"], bool)
        self._size = float(state["size"])
        self._searched_u = self.u.x.array.copy() if bool(state["searched_here"]) else None
        for k in range(self.gdim):
            self.X[k].x.array[:] = state[f"X{k}"]
            self.w[k].x.array[:] = state[f"w{k}"]
        if self.w_prev is not None:
            self._prev_t = self.target_displacements(self._u_prev)
            self._fill_previous()
        self.version += 1

    def _lift_past_rim(self, points: np.ndarray, current: np.ndarray, proj: Projection) -> None:
        """Lift the gap of the nodes past the target's rim to their distance from it.

        Past a free side of the target (its end in 2D, the rim of the patch in
        3D) the plane of the last facet extends over nothing: a striker running
        on beyond the target would be held level with it and its force counted
        (a bridge across two supports: +19 %). A node whose projection falls on
        no facet at its closest point, farther than :data:`BEYOND_RIM` of its own
        facet size from it, gets the lift d - g: its gap becomes d, its distance
        from the target (> 0).
        """
        fresh = self._fresh if self._fresh.shape[0] == points.shape[0] else np.ones(
            points.shape[0], bool)
        lift = self.lift.x.array.reshape(-1, self.gdim)[:, 0].copy()
        lift[fresh] = 0.0  # a node the skin kept keeps its lift: it is open, far in front
        self._stale_lifts = not fresh.all()
        maybe = np.flatnonzero((proj.overshoot > 0.0) & fresh)
        if maybe.size and current.shape[0]:
            near = _closest(current, points[maybe], self._size)
            past = past_free_edge(points[maybe], current, self.target.free, size=self._size,
                                  nearest=near, reach=BEYOND_RIM * self._node_size[maybe])
            rows = maybe[past]
            plane = self._plane_gaps(points[rows], current[proj.facet[rows]])
            lift[rows] = near.distance[past] - plane
        self.lift.x.array.reshape(-1, self.gdim)[:, 0] = lift

    def settle_lifts(self) -> None:
        """Lift every node past the rim to its present distance (for written gaps; collective).

        A search lifts only the nodes it searched; the nodes its skin kept,
        open and several facet sizes in front, keep the lift of their last
        search, which moves their gap but not the answer. The gaps that are
        written and measured are taken after this.
        """
        if not self.comm.allreduce(self._stale_lifts, op=MPI.LOR) or self.projection is None:
            return
        self._fresh = np.ones(self._fresh.shape[0], bool)
        w_t = self.target_displacements()
        self._lift_past_rim(self.striker_positions(), (self.X_vertices + w_t)[self.facet_vertex],
                            self.projection)

    def _settled_search(self, points: np.ndarray, search) -> tuple[np.ndarray, Projection]:
        """Run ``search(current facets)`` until the kept facets settle ``points`` (collective).

        Between runs the kept box grows and the facets are exchanged again;
        the assignment is carried over by global facet index. Returns the
        kept vertices' displacements and the projection.
        """
        target = self.target
        while True:
            self._size = target.facet_size(self.u)
            motion = 0.0 if target.keep_all else target.motion(self.u)
            w_t = self.target_displacements()
            proj = search((self.X_vertices + w_t)[self.facet_vertex])
            tol = TIE_TOL * self._size
            if target.covers(points, proj.distance, tol, motion):
                return w_t, proj
            held = self.assignment >= 0
            gid = np.full(self.assignment.shape, -1, np.int64)
            gid[held] = target.gid[self.assignment[held]]
            reach = target.reach_for(points, proj.distance, tol, REACH_FACETS * self._size)
            target.gather(points, reach, self.u)
            self.assignment = np.where(held, np.searchsorted(target.gid, gid), -1)

    def _search(self, current: np.ndarray) -> Projection:
        """Closest target facet of the striker nodes (current facet vertices given).

        A frictionless pair searches again only the nodes that may have come
        near: a node found farther than :data:`SKIN` facet sizes keeps its
        facet while its own motion plus the largest motion of the target
        since its search leaves it at least that far, its multiplier is not
        compressive and it stays that far in front of its facet's plane (so
        it is open, whatever its facet). The others, and every node after the
        kept facets changed, are searched.
        """
        points = self.striker_positions()
        todo = self._to_search(points, current)
        if not todo.all():  # a kept facet's plane may have turned towards its node
            kept = np.flatnonzero(~todo)
            gap = self._plane_gaps(points[kept], current[self.assignment[kept]])
            todo[kept[gap <= SKIN * self._size]] = True
        if todo.all():
            proj = _closest(current, points, self._size, self.assignment)
        else:
            found = _closest(current, points[todo], self._size, self.assignment[todo])
            old = self.projection
            proj = Projection(self.assignment.copy(), old.xi.copy(), old.distance.copy(),
                              old.overshoot.copy())
            proj.facet[todo], proj.xi[todo] = found.facet, found.xi
            proj.distance[todo], proj.overshoot[todo] = found.distance, found.overshoot
        self.searched = int(todo.sum())
        self._fresh = todo
        slack = np.where(todo, proj.distance - SKIN * self._size, self._slack)
        self._slack, self._skin_points, self._skin_current = slack, points, current
        return proj

    def _to_search(self, points: np.ndarray, current: np.ndarray) -> np.ndarray:
        """Which nodes :meth:`_search` must search (bool over owned and ghost W blocks)."""
        everyone = np.ones(points.shape[0], bool)
        previous = self._skin_current
        same = (self.multiplier is not None and previous is not None
                and previous.shape == current.shape and self.projection is not None
                and self._skin_points.shape == points.shape)
        if not self.comm.allreduce(same, op=MPI.LAND):
            return everyone
        moved = np.abs(current - previous).max(initial=0.0)
        moved = self.comm.allreduce(float(np.sqrt(self.gdim) * moved), op=MPI.MAX)
        self._slack = self._slack - np.linalg.norm(points - self._skin_points, axis=1) - moved
        self._skin_points = points
        lam = self.multiplier()
        return (self._slack <= 0.0) | (lam < 0.0)

    def penetration(self) -> np.ndarray:
        """Depth of each owned striker node inside the current target surface (length, >= 0).

        Measured to the closest point of the whole target surface (collective:
        the kept facets hold it, :meth:`_settled_search`), not to the plane of
        the assigned facet: a node left on the extension of a facet it has
        passed can lie inside the real surface while its gap to that plane is
        positive.
        """
        points, current, nearest = self._closest_on_surface()
        return penetration_depth(points, current, size=self._size, nearest=nearest,
                                 free=self.target.free)

    def _closest_on_surface(self) -> tuple[np.ndarray, np.ndarray, Projection]:
        """(owned striker positions, current target facet vertices, closest projections).

        The closest point over the whole target surface, the kept facets settled
        for it (collective; :meth:`_settled_search`).
        """
        points = self.striker_positions()[: self.n_owned]
        gathers = self.target.gathers
        w_t, nearest = self._settled_search(points,
                                            lambda current: _closest(current, points, self._size))
        if self.target.gathers != gathers and self.w_prev is not None:
            self._prev_t = self.target_displacements(self._u_prev)
        return points, (self.X_vertices + w_t)[self.facet_vertex], nearest

    def sources(self) -> list[np.ndarray]:
        """Global V block index that each owned W block selects, one array per vertex k.

        w_k = S_k u with S_k[i*bs + c, sources[k][i]*bs + c] = 1.
        """
        facet = self.assignment[: self.n_owned]
        return [self.target_blocks[facet, k] for k in range(self.gdim)]

    # -- condensation ----------------------------------------------------------------
    def gap_offset(self) -> np.ndarray:
        """What the pair adds to the gap to the assigned facet's plane: the lift (length)."""
        return self.lift.x.array.reshape(-1, self.gdim)[:, 0]

    def coupled(self, w_t: np.ndarray) -> np.ndarray:
        """Owned nodes whose contact can act at the current state (bool).

        ``w_t``: the kept target vertices' displacements.

        A node with lam >= 0 and a gap above :data:`COUPLING_GAP` facet sizes
        is open whatever r (lam + r g > 0): its residual and tangent do not
        depend on the target, so the solver leaves its selection out. Every
        node counts when the contact gave no :attr:`multiplier`.
        """
        n = self.n_owned
        if self.multiplier is None or self.projection is None:
            return np.ones(n, bool)
        x = (self.X_vertices + w_t)[self.facet_vertex[self.assignment[:n]]]
        offset = np.asarray(self.gap_offset())
        gap = self._plane_gaps(self.striker_positions()[:n], x) + (
            offset[:n] if offset.ndim else offset)
        lam = self.multiplier()[:n]
        return (gap < COUPLING_GAP * self._size) | (lam < 0.0)

    def acting_facets(self) -> list[tuple[tuple[int, ...], np.ndarray]]:
        """Where the contact's terms can be nonzero: [(tag values, local mesh facets)].

        The striker facets with a vertex that :meth:`coupled` keeps (collective:
        ghost nodes take their owner's flag). On the others every node is open
        at any r, and the contact's residual, its tangent and its coupling to
        the target vanish there; the multiplier's own equation, lam / r = 0, is
        the one term left (a solver keeps it everywhere). Empty (no limit) with
        friction, where every node counts, or when no tag value is the
        striker's alone (:attr:`limit_ids`).
        """
        if self.multiplier is None or not self.limit_ids:
            return []
        flags = self._acting
        flags.array[: self.n_owned] = self._coupled
        flags.scatter_forward()
        cells = self.W.dofmap.list
        acting = (flags.array[cells] > 0.5).any(axis=1)
        return [(self.limit_ids, self._cell_facet[: cells.shape[0]][acting])]

    def _plane_gaps(self, points: np.ndarray, facets: np.ndarray) -> np.ndarray:
        """Signed distance of each point to the plane of its facet (facets: (n, nv, gdim))."""
        normal = self._normals(facets)
        normal /= np.linalg.norm(normal, axis=1)[:, None]
        return np.einsum("ij,ij->i", points - facets[:, 0], normal)

    def condensation(self) -> list[sp.csr_matrix]:
        """w_k = S_k u as sparse rows (owned W dofs by global V dofs), open nodes left out."""
        n, bs = self.n_owned, self.gdim
        keep = np.repeat(self._coupled, bs)
        rows = np.flatnonzero(keep)
        out = []
        for block in self.sources():
            cols = (block[:, None] * bs + np.arange(bs)[None, :]).reshape(-1)[keep]
            out.append(sp.csr_matrix((np.ones(rows.size), (rows, cols)),
                                     shape=(n * bs, self.V.dofmap.index_map.size_global * bs)))
        return out

    def reachable_blocks(self) -> list[tuple[np.ndarray, np.ndarray]]:
        """The V blocks each owned node may select once its facet moves to a neighbour.

        For every selection of :meth:`sources`: (indptr, blocks), CSR rows of
        owned nodes listing the vertices of the kept facets that share a
        vertex with the node's assigned facet (none for a node without one).
        The solver keeps these couplings in its pattern, so that moving to
        such a facet changes values only.
        """
        fv = self.facet_vertex
        m, nv = fv.shape
        incidence = sp.csr_matrix(
            (np.ones(fv.size), (np.repeat(np.arange(m), nv), fv.reshape(-1))),
            shape=(m, self.vertices.size))
        star = ((incidence @ incidence.T) @ incidence).tocsr()
        facet = self.assignment[: self.n_owned]
        rows = star[np.where(facet >= 0, facet, 0)]
        rows = sp.diags(((facet >= 0) & self._coupled).astype(float)) @ rows
        rows.eliminate_zeros()
        rows.sort_indices()
        near = (rows.indptr.astype(np.int64), self.vertices[rows.indices].astype(np.int64))
        return [near] * self.gdim


class NodeToSegmentContact(Contact):
    """A striker surface of the solid against a target surface of another of its bodies.

    One-pass node-to-segment: each striker node is projected on its closest
    target facet (:class:`DeformablePair`). ``r`` relative to E/h uses the
    pair modulus E = 2 E_s E_t / (E_s + E_t) of the striker's and target's
    bodies and h of the striker facets.

    Args:
        striker_facets: local facet indices of the striker surface (they carry lam).
        target_facets: local facet indices of the target surface.
        settings: r, its scale; the quadrature must be 'nodal'.
        striker: the striker's body (default: the body whose cells carry its facets).
        target: the target's body (likewise).
        friction: Coulomb friction (None: frictionless); see :meth:`slip_increment`.
        name: label in outputs.
        self_contact: the target is the striker's own body (the facet sets may be
            one): each node's neighbourhood along the surface is excluded from its
            search and only facets facing it count (:mod:`.self_contact`).
        neighbourhood: radius of that neighbourhood in facet sizes.
    """

    #: The pair's tangent kernels are large (MBs of C with friction in 3D): -O1
    #: compiles the kernel's blocks in 5.9 s against 9.4 s at -O2 (frictional
    #: hemispheres) and assembles as fast; it costs the bodies' own (small)
    #: kernels about a tenth of their assembly speed (docs/benchmarks.md).
    jit_options: ClassVar[dict] = {"cffi_extra_compile_args": CONTACT_CFLAGS}

    def __init__(
        self,
        striker_facets: np.ndarray,
        target_facets: np.ndarray,
        settings: ContactSettings,
        *,
        striker: str | None = None,
        target: str | None = None,
        friction: FrictionSettings | None = None,
        name: str = "pair",
        self_contact: bool = False,
        neighbourhood: float = 3.0,
    ) -> None:
        if settings.quadrature != "nodal":
            raise ValueError(
                "Two-body contact is node-to-segment: use quadrature = 'nodal', "
                f"got {settings.quadrature!r}."
            )
        super().__init__(striker_facets, settings, friction=friction, name=name)
        self.target_facets = np.asarray(target_facets, dtype=np.int32)
        self._names = (striker, target)
        self.self_contact = self_contact
        self.neighbourhood = neighbourhood
        self._target_force_forms: list[fem.Form] | None = None
        self._lam_of_w: np.ndarray | None = None

    def facet_arguments(self) -> dict[str, np.ndarray]:
        """The striker and target facet index arrays, by argument name."""
        return {"striker_facets": self.facets, "target_facets": self.target_facets}

    def _bind_partner(self, solid) -> ufl.core.expr.Expr:
        if solid.degree != 1:
            raise ValueError(
                f"Two-body contact needs degree = 1 (vertex node-to-segment), got {solid.degree}."
            )
        overlap = np.intersect1d(self.facets, self.target_facets).size
        if not self.self_contact and self.comm.allreduce(overlap, op=MPI.SUM):
            raise ValueError(
                "The striker and target facet sets share facets; a contact pair needs two "
                "disjoint surfaces (tag them separately)."
            )
        bind_pair_bodies(self, solid)
        if self.self_contact:
            from fenics_contact.model.self_contact import SelfContactPair

            self.pair = SelfContactPair(solid.V, solid.u, self.surface, self.target_facets,
                                        self.facets, self.neighbourhood)
        else:
            self.pair = DeformablePair(solid.V, solid.u, self.surface, self.target_facets)
        self.pair.limit_ids = self.own_ids
        if not self.frictional:
            self.pair.multiplier = self._multiplier_at_nodes
        self.pair.refresh()
        return self.pair.gap(ufl.SpatialCoordinate(solid.domain) + solid.u)

    def _multiplier_at_nodes(self) -> np.ndarray:
        """The multiplier at each W block of the pair (both live on the striker submesh)."""
        if self._lam_of_w is None:
            W, Q = self.pair.W, self.lam.function_space
            index = np.zeros(W.dofmap.index_map.size_local + W.dofmap.index_map.num_ghosts,
                             np.int64)
            index[W.dofmap.list.reshape(-1)] = Q.dofmap.list.reshape(-1)
            self._lam_of_w = index
        return self.lam.x.array[self._lam_of_w]

    def may_close(self, gaps: np.ndarray) -> np.ndarray:
        """The nodes the pair couples (:meth:`DeformablePair.coupled`), owned, in lam's order.

        Elsewhere the solver holds neither the node's coupling to the target
        nor its terms (they are zero while it is open), so a Newton step must
        not set it in contact.
        """
        self._multiplier_at_nodes()  # the W -> lam map
        flags = np.zeros(self.lam.x.array.size, bool)
        flags[self._lam_of_w[: self.pair.n_owned]] = self.pair._coupled
        return flags[: gaps.size]

    # -- search ---------------------------------------------------------------------
    def refresh(self) -> bool:
        """Search and refill the target coefficients when u has changed."""
        return self.pair.refresh()

    def contact_state(self) -> ContactState:
        """The state (:meth:`Contact.contact_state`) with every lift of the present search."""
        self.refresh()
        self.pair.settle_lifts()
        return super().contact_state()

    def search_state(self) -> dict[str, np.ndarray]:
        """The pair's search memory (:meth:`DeformablePair.search_state`)."""
        return self.pair.search_state()

    def restore_search_state(self, state: dict[str, np.ndarray]) -> None:
        """Put back a :meth:`search_state` (a resumed run; collective)."""
        self.pair.restore_search_state(state)

    def extras(self) -> list[fem.Function]:
        """The target vertex displacements w_k (condensed by w_k = S_k u)."""
        return list(self.pair.w)

    @property
    def transfer(self) -> DeformablePair:
        """The pair: its search, version and selection (see :meth:`DeformablePair.sources`)."""
        return self.pair

    def penetration(self) -> float:
        """Global depth inside the actual target surface (:meth:`DeformablePair.penetration`)."""
        depth = self.pair.penetration()
        return self.comm.allreduce(float(np.max(depth, initial=0.0)), op=MPI.MAX)

    # -- friction -----------------------------------------------------------------------
    def slip_increment(self, u_prev: fem.Function) -> tuple[ufl.core.expr.Expr, ufl.core.expr.Expr]:
        """T of the target facet and the relative slip (:func:`slip_at_projection`)."""
        return slip_at_projection(self.pair, self.solid.u, u_prev, self.gdim,
                                  self.solid.symmetry_plane_axes())

    def commit_frame(self) -> None:
        """w_k_prev <- the assigned vertices' displacements in the new u_prev."""
        if self.friction is not None:
            self.pair.set_previous()

    # -- the force on the target ------------------------------------------------------------
    def target_force(self) -> fem.Function:
        """Contact force the striker puts on the target's vertices (force per node).

        f_target = sum_k S_k^T dL_c/dw_k with L_c the contact term (normal and
        tangential): the node-to-segment transfer, (1 - xi) and xi of each
        striker node's force on its facet's vertices in 2D. Zero off the
        target surface.
        """
        if self._target_force_forms is None:
            q = ufl.TestFunction(self.pair.W)
            forms = []
            for wk in self.pair.w:
                form = ufl.derivative(self.lagrangian(), wk, q)
                if self.friction is not None:
                    form += self.friction.work(self.friction.traction_t, wk, q)
                forms.append(fem.form(form, entity_maps=self.surface.entity_maps))
            self._target_force_forms = forms
        self.pair.refresh()
        from petsc4py import PETSc

        V = self.solid.V
        gdim = self.gdim
        im = V.dofmap.index_map
        vec = PETSc.Vec().createMPI((im.size_local * gdim, im.size_global * gdim),
                                    bsize=gdim, comm=self.comm)
        vec.set(0.0)
        for form, src in zip(self._target_force_forms, self.pair.sources(), strict=True):
            local = fem.assemble_vector(form)
            local.scatter_reverse(la.InsertMode.add)
            values = local.array[: self.pair.n_owned * gdim]
            vec.setValuesBlocked(src.astype(PETSc.IntType), values, addv=PETSc.InsertMode.ADD)
        vec.assemblyBegin()
        vec.assemblyEnd()
        out = fem.Function(V, name="target_contact_force")
        out.x.array[: im.size_local * gdim] = -vec.getArray(readonly=True)
        out.x.scatter_forward()
        vec.destroy()
        return out


def _node_sizes(submesh: mesh.Mesh, W: fem.FunctionSpace) -> np.ndarray:
    """Mean diameter of the striker facets at each W block (owned and ghost; length)."""
    x = submesh.geometry.x
    cells = x[submesh.geometry.dofmaps[0]]  # (cells, nv, 3)
    nv = cells.shape[1]
    diameter = np.max([np.linalg.norm(cells[:, i] - cells[:, j], axis=-1)
                       for i in range(nv) for j in range(i + 1, nv)], axis=0)
    blocks = W.dofmap.list
    n = W.dofmap.index_map.size_local + W.dofmap.index_map.num_ghosts
    total, count = np.zeros(n), np.zeros(n)
    np.add.at(total, blocks.reshape(-1), np.repeat(diameter, blocks.shape[1]))
    np.add.at(count, blocks.reshape(-1), 1.0)
    return total / np.maximum(count, 1.0)


def _closest(current: np.ndarray, points: np.ndarray, size: float,
             previous: np.ndarray | None = None) -> Projection:
    """:meth:`SurfaceSearch.closest` of ``points`` on the facets ``current``.

    With no facets (a rank that keeps none yet) every distance is inf, which
    no kept box settles: the caller exchanges more facets.
    """
    n, gdim = points.shape
    if current.shape[0] == 0:
        return Projection(np.full(n, -1, np.int64), np.zeros((n, gdim - 1)),
                          np.full(n, np.inf), np.zeros(n))
    return SurfaceSearch(current, size=size).closest(points, previous=previous)


def slip_at_projection(pair: DeformablePair, u: fem.Function, u_prev: fem.Function,
                       gdim: int, planes: tuple[fem.Function, fem.Function] | None = None,
                       ) -> tuple[ufl.core.expr.Expr, ufl.core.expr.Expr]:
    """T of the target facet and the relative slip of a striker node and its projection.

    dg_t = T^T [(x_s - x_s_prev) - (x_p - x_p_prev)] with x_p = sum_k N_k x_k
    at the current projection (same xi then and now), so the reference
    positions cancel: dg_t = T^T [(u - u_prev) - sum_k N_k (w_k - w_k_prev)].
    w_k_prev, the previous displacements of the assigned vertices, are data
    filled by the search from u_prev. Under a common rigid translation
    dg_t = 0 and its derivative vanishes, so the friction forces on the
    striker and on the target balance exactly. ``planes``: the symmetry
    planes' nodal data (:func:`~.friction.plane_axes`), for a frame that
    holds the plane's normal at the nodes on it (:func:`~.friction.symmetric_frame`).
    """
    w_prev = pair.track_previous(u_prev)
    x_s = ufl.SpatialCoordinate(u.function_space.mesh) + u
    tangents = symmetric_frame(pair.normal(), gdim, planes)
    target = sum(
        (N * (wk - wk_prev)
         for N, wk, wk_prev in zip(pair.shape_weights(x_s), pair.w, w_prev, strict=True)),
        ufl.zero(gdim),
    )
    return tangents, tangents.T * ((u - u_prev) - target)


def check_pair_cells(domain: mesh.Mesh, name: str) -> None:
    """Refuse a pair on cells whose facets its search cannot handle (ValueError).

    In 3D the node-to-segment and mortar pairs work on triangle facets
    (tetrahedra); hexahedra give quadrilateral facets. In 2D every facet is
    a segment (triangles and quadrilaterals alike).
    """
    cell = domain.topology.cell_type
    if domain.topology.dim == 3 and cell != mesh.CellType.tetrahedron:
        raise ValueError(
            f"Contact pair {name!r}: the mesh's cells are {cell.name} (facets: "
            f"{'quadrilaterals' if cell == mesh.CellType.hexahedron else 'not triangles'}); "
            "node-to-segment and mortar pairs in 3D need triangle facets. Mesh the bodies "
            "with tetrahedra (gmsh: leave out Recombine and Transfinite Volume); rigid "
            "obstacles work on hexahedra."
        )


def bind_pair_bodies(contact: Contact, solid) -> None:
    """Set a pair's ``striker_body`` and ``target_body`` and its r scale's modulus.

    The bodies are named by the contact (``_names``) or found from its facets;
    the modulus is the harmonic mean 2 E_s E_t / (E_s + E_t) (stress). Pairs
    on cells they cannot handle are refused first (:func:`check_pair_cells`).
    """
    check_pair_cells(solid.domain, contact.name)
    bodies = [
        solid.body_of_facets(facets, role) if name is None else _named(solid, name, role)
        for name, facets, role in zip(contact._names, (contact.facets, contact.target_facets),
                                      ("striker", "target"), strict=True)
    ]
    Es, Et = (b.material.E for b in bodies)
    contact.striker_body, contact.target_body = bodies
    contact.modulus = 2.0 * Es * Et / (Es + Et)


def _named(solid, name: str, role: str) -> Body:
    """The body named ``name`` (ValueError naming the choices)."""
    found = [b for b in solid.bodies if b.name == name]
    if not found:
        raise ValueError(
            f"The {role} body {name!r} is not among the bodies "
            f"{[b.name for b in solid.bodies]}; use one of those names."
        )
    return found[0]
