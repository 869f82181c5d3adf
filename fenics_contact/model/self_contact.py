"""Self-contact: a body's surface against itself, node-to-segment with a neighbourhood rule.

The partner of each striker node is the body's own contact surface minus
the node's neighbourhood along that surface: every facet with a vertex
within ``neighbourhood`` facet sizes of the node, measured along the
surface in the reference configuration (shortest path over the facets'
edges; the facets sharing the node are always in it). Among the other
facets only those that face the node count: n_s . n_t < 0, with n_s the
node's current normal (the sum of the unit normals of its surface facets)
and n_t the facet's. The closest of them by the corner rule of
:mod:`.search` is assigned, with the same hysteresis. Without the facing
rule a node would see the facets just past its neighbourhood on its own
wall: on a convex wall it lies behind their straight extension (a false
penetration), on a concave one in front by the sagitta only (a false
contact once the wall flattens). A facet also counts only while the node
lies in front of its plane or behind it by less than ``depth`` facet sizes:
the far side of a closed convex surface faces a node too, from inside
(the facet a node had at the last search counts down to ``kept_depth``
facet sizes: a Newton iterate may push a node through the opposite wall
deeper than ``depth``, and it must stay paired to be pushed back);
and only while the node's projection falls on it or within half a facet
of it (the straight extension of a facet far from the node is no surface). A
node that no facet qualifies for keeps the non-excluded facet with the
largest signed distance (its distance is reported infinite) and its gap
is lifted by a length far beyond the surface (:attr:`SelfContactPair.lift`),
so it stays open: a closed convex surface has no partner for itself.

Everything else (the gap in UFL, the condensation w_k = S_k u) is the
two-body machinery of :mod:`.pairs` unchanged. Sign conventions as there:
g >= 0 open, lam <= 0 the pressure.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix, csr_matrix
from scipy.sparse.csgraph import dijkstra

from mpi4py import MPI

from fenics_contact.model.pairs import DeformablePair
from fenics_contact.model.search import (
    KEEP,
    TIE_TOL,
    Projection,
    facet_normals,
    penetration_depth,
    project,
)

#: Default neighbourhood radius, in facet sizes along the surface.
NEIGHBOURHOOD = 3.0
#: Search depth behind a facet's plane, in mean facet sizes.
DEPTH = 1.0
#: The same for the facet a node had at the last search (a node an iterate pushed through).
KEPT_DEPTH = 10.0
#: Largest overshoot of a projection past its facet (local coordinate) for the facet to count.
OVER = 0.5
#: Point-facet pairs the search compares at once (its memory: about 200 bytes a pair).
PAIRS = 250_000


def _surface_graph(X: np.ndarray, facet_vertex: np.ndarray) -> tuple[csr_matrix, float]:
    """Edge graph of the surface (reference lengths) and the mean facet size (length)."""
    nv = facet_vertex.shape[1]
    pairs = [(i, (i + 1) % nv) for i in range(nv if nv > 2 else 1)]
    a = np.concatenate([facet_vertex[:, i] for i, _ in pairs])
    b = np.concatenate([facet_vertex[:, j] for _, j in pairs])
    edges = np.unique(np.sort(np.stack([a, b], axis=1), axis=1), axis=0)  # each edge once
    a, b = edges[:, 0], edges[:, 1]
    length = np.linalg.norm(X[a] - X[b], axis=1)
    n = X.shape[0]
    graph = coo_matrix((np.r_[length, length], (np.r_[a, b], np.r_[b, a])), shape=(n, n))
    size = float(np.mean(length))
    return graph.tocsr(), size


def neighbourhoods(X: np.ndarray, facet_vertex: np.ndarray, sources: np.ndarray,
                   radius: float) -> csr_matrix:
    """Facets excluded for each source vertex: (len(sources), facets) boolean matrix.

    A facet is excluded when one of its vertices lies within ``radius``
    facet sizes of the source along the surface (reference configuration).
    Sources of -1 (a striker node that is not a surface vertex) exclude nothing.
    """
    graph, size = _surface_graph(X, facet_vertex)
    m = facet_vertex.shape[0]
    rows, cols = [], []
    on = np.flatnonzero(sources >= 0)
    if on.size:
        unique, inverse = np.unique(sources[on], return_inverse=True)
        dist = dijkstra(graph, indices=unique, limit=radius * size * (1 + 1e-9))
        near = np.isfinite(dist)  # (unique sources, vertices)
        hit = near[:, facet_vertex].any(axis=2)  # (unique sources, facets)
        for k, i in enumerate(on):
            f = np.flatnonzero(hit[inverse[k]])
            rows.append(np.full(f.size, i))
            cols.append(f)
    r = np.concatenate(rows) if rows else np.zeros(0, np.int64)
    c = np.concatenate(cols) if cols else np.zeros(0, np.int64)
    return csr_matrix((np.ones(r.size, bool), (r, c)), shape=(sources.size, m))


def vertex_normals(current: np.ndarray, facet_vertex: np.ndarray, n_vertices: int) -> np.ndarray:
    """Current normal at each surface vertex: the sum of its facets' unit normals (not unit)."""
    normals = facet_normals(current)
    out = np.zeros((n_vertices, current.shape[2]))
    for k in range(facet_vertex.shape[1]):
        np.add.at(out, facet_vertex[:, k], normals)
    return out


def closest_facing(
    points: np.ndarray,
    point_normals: np.ndarray,
    current: np.ndarray,
    excluded: csr_matrix,
    previous: np.ndarray | None = None,
    keep: float = KEEP,
    depth: float = DEPTH,
    kept_depth: float = KEPT_DEPTH,
) -> Projection:
    """Assign each point the closest facet that is outside its neighbourhood and faces it.

    Args:
        points: (n, gdim) current striker positions.
        point_normals: (n, gdim) their current normals (zero: no facing rule).
        current: (m, nv, gdim) current facet vertices (oriented outward).
        excluded: (n, m) boolean, True for the facets in each point's neighbourhood.
        previous: facets assigned before (-1: none), for the hysteresis.
        keep: the hysteresis tolerance (see :meth:`.search.SurfaceSearch.closest`).
        depth: how far behind a facet's plane a point may lie and still be
            assigned to it, in mean facet sizes (a facet of a closed convex
            surface faces the points on its opposite side, from inside).
        kept_depth: the same for the facet a point had at the last search (mean
            facet sizes): one Newton iterate may take a point through the
            surface by more than ``depth``, and it must stay paired to be
            pushed back.
    """
    n = points.shape[0]
    gdim = current.shape[2]
    if n == 0:
        return Projection(np.zeros(0, np.int64), np.zeros((0, gdim - 1)), np.zeros(0),
                          np.zeros(0))
    rows = max(1, PAIRS // max(current.shape[0], 1))
    if n > rows:  # every point against every facet: in blocks of points, to bound the memory
        parts = [closest_facing(points[b], point_normals[b], current, excluded[b],
                                None if previous is None or previous.size != n else previous[b],
                                keep, depth, kept_depth)
                 for b in (slice(k, k + rows) for k in range(0, n, rows))]
        return Projection(*(np.concatenate([getattr(q, f) for q in parts])
                            for f in ("facet", "xi", "distance", "overshoot")))
    normals = facet_normals(current)
    allowed = ~excluded.toarray()
    facing = np.einsum("id,jd->ij", point_normals, normals) < 0.0
    no_rule = ~np.any(point_normals != 0.0, axis=1)
    # in front of the facet's plane, or behind it by less than the search depth
    size = float(np.mean(np.linalg.norm(current[:, 1] - current[:, 0], axis=-1)))
    signed = np.einsum("ijd,jd->ij", points[:, None, :] - current[None, :, 0], normals)
    xi, dist, over = project(points, np.broadcast_to(current, (n, *current.shape)))
    valid = allowed & (facing | no_rule[:, None]) & (signed > -depth * size) & (over <= OVER)
    if not np.all(allowed.any(axis=1)):
        raise ValueError(
            "A self-contact node excludes every facet of the surface; lower the neighbourhood "
            "or refine the surface."
        )
    key = np.where(valid, dist, np.inf)
    best = key.min(axis=1, keepdims=True)
    tie = np.where(valid & (key <= best + TIE_TOL * size), over, np.inf)
    facet = np.argmin(tie, axis=1)
    # nothing faces the point: the allowed facet it is farthest in front of (stays open)
    lonely = ~valid.any(axis=1)
    if np.any(lonely):
        facet[lonely] = np.argmax(np.where(allowed[lonely], signed[lonely], -np.inf), axis=1)
    rows = np.arange(n)
    chosen = (facet, xi[rows, facet], np.where(lonely, np.inf, dist[rows, facet]),
              over[rows, facet])
    if previous is not None and previous.size == n:
        prev = np.asarray(previous, np.int64)
        ok = prev >= 0
        p = np.where(ok, prev, 0)
        length = np.linalg.norm(current[p, 1] - current[p, 0], axis=-1)
        close = dist[rows, p] <= chosen[2] + keep * length
        # a deeper search for the facet a point had: in front of it (or barely behind) at
        # the last search and deeper now, the point has passed through it in one Newton
        # iterate (a penetration to push back), not reached a far side of the surface
        kept = (allowed & (facing | no_rule[:, None]) & (over <= OVER)
                & (signed > -kept_depth * size))
        ok &= kept[rows, p] & (over[rows, p] <= keep) & close
        facet = np.where(ok, p, facet)
        lonely &= ~ok
        # a node no facet qualifies for stays without a partner (infinite distance: lifted)
        chosen = (facet, xi[rows, facet], np.where(lonely, np.inf, dist[rows, facet]),
                  over[rows, facet])
    return Projection(*chosen)


class SelfContactPair(DeformablePair):
    """A :class:`~.pairs.DeformablePair` whose target is on the striker's own body.

    The neighbourhoods and the nodes' normals are taken on the union of the
    striker and target facets (one surface when they are the same set; two
    faces of one body that meet otherwise).

    Args:
        V, u, surface, target_facets: as for the pair.
        striker_facets: local facet indices of the striker surface.
        neighbourhood: radius of each node's excluded neighbourhood, in
            facet sizes along the surface (reference configuration).
    """

    def __init__(self, V, u, surface, target_facets, striker_facets,
                 neighbourhood: float = NEIGHBOURHOOD) -> None:
        if not (np.isfinite(neighbourhood) and neighbourhood > 0):
            raise ValueError(
                f"neighbourhood must be finite and > 0 (facet sizes), got {neighbourhood}.")
        super().__init__(V, u, surface, target_facets, keep_all=True)
        # the striker's own facets, gathered like the target's (no search of its own)
        self._striker_side = DeformablePair(V, u, surface, striker_facets, keep_all=True)
        own = self._striker_side
        blocks = np.concatenate([self.target_blocks, own.target_blocks])
        #: Union surface: its vertices (global V blocks) and facets (rows: target, then striker).
        self.union_vertices, union_fv = np.unique(blocks, return_inverse=True)
        self.union_facets = union_fv.reshape(-1, self.gdim)
        self._from_target = np.searchsorted(self.union_vertices, self.vertices)
        self._from_striker = np.searchsorted(self.union_vertices, own.vertices)
        X = np.zeros((self.union_vertices.size, self.gdim))
        X[self._from_target], X[self._from_striker] = self.X_vertices, own.X_vertices
        im = V.dofmap.index_map
        local = self._striker_block.astype(np.int32)
        gblock = im.local_to_global(local) if local.size else np.zeros(0, np.int64)
        pos = np.minimum(np.searchsorted(self.union_vertices, gblock), self.union_vertices.size - 1)
        #: The union-surface vertex of each striker node (-1: not on it).
        self.striker_vertex = np.where(self.union_vertices[pos] == gblock, pos, -1)
        self.neighbourhood = float(neighbourhood)
        m = self.target_blocks.shape[0]
        self.excluded = neighbourhoods(X, self.union_facets, self.striker_vertex,
                                       self.neighbourhood)[:, :m]
        self._X_union = X
        self._lift_length = 100.0 * float(np.ptp(X, axis=0).max(initial=1.0))
        shared = np.intersect1d(np.asarray(target_facets), np.asarray(striker_facets)).size
        #: Whether striker and target are two surfaces (two bodies paired automatically, or
        #: two faces of one body): the depth inside the target is then its closest point's.
        self.two_surfaces = not V.mesh.comm.allreduce(int(shared), op=MPI.SUM)

    def _lift_past_rim(self, points, current, proj) -> None:
        """Nothing here: :meth:`_search` lifts the nodes no facet qualifies for."""

    def _search(self, current: np.ndarray) -> Projection:
        lift = self.lift.x.array.reshape(-1, self.gdim)
        previous = np.where(lift[:, 0] > 0.0, -1, self.assignment)  # lifted: no partner
        proj = closest_facing(self.striker_positions(), self._node_normals(), current,
                              self.excluded, previous=previous)
        lift[:, 0] = np.where(np.isfinite(proj.distance), 0.0, self._lift_length)
        return proj

    def penetration(self) -> np.ndarray:
        """Depth of each owned striker node inside the target (length, >= 0).

        Two surfaces (:attr:`two_surfaces`): the closest point over the whole
        target surface, as for a declared pair, so that a node held on the
        extension of a facet past a concave vertex counts as inside the next
        facet. One surface against itself: measured on the assigned (facing)
        facet, since the closest point of the whole surface to a node on it
        is the node itself; a node kept past the end of its facet at a
        concave corner of the wall (the hysteresis) can lie inside the next
        facet while in front of this plane (docs/contacts.md).
        """
        if self.two_surfaces:
            return super().penetration()
        n = self.n_owned
        current = (self.X_vertices + self.target_displacements())[self.facet_vertex]
        facet = self.assignment[:n]
        gap = np.einsum("ij,ij->i", self.striker_positions()[:n] - current[facet, 0],
                        facet_normals(current)[facet])
        return np.maximum(-(gap + self.lift.x.array.reshape(-1, self.gdim)[:n, 0]), 0.0)

    def inside_own_neighbourhood(self, depth: float) -> bool:
        """Whether a node lies deeper than ``depth`` inside a facet of its own neighbourhood.

        Two surfaces only (else False): the search never pairs a node with
        those facets, so no step size holds it out of them; a smaller
        ``neighbourhood`` does (a notch closing from its root). Collective.
        """
        found = False
        if self.two_surfaces:
            points, current, nearest = self._closest_on_surface()
            inside = penetration_depth(points, current, size=self._size, nearest=nearest,
                                       free=self.target.free) > depth
            rows = np.flatnonzero(inside)
            # (no row: scipy returns an empty sparse matrix, which numpy cannot read)
            found = bool(rows.size) and bool(
                np.asarray(self.excluded[rows, nearest.facet[rows]]).any())
        return bool(self.comm.allreduce(found, op=MPI.LOR))

    def _node_normals(self) -> np.ndarray:
        """Current normal of each striker node: the sum of its surface facets' unit normals."""
        w = np.zeros_like(self._X_union)
        w[self._from_target] = self.target_displacements()
        w[self._from_striker] = self._striker_side.target_displacements()
        union = (self._X_union + w)[self.union_facets]
        normals = vertex_normals(union, self.union_facets, self.union_vertices.size)
        on = self.striker_vertex >= 0
        out = np.zeros((self.striker_vertex.size, self.gdim))
        out[on] = normals[self.striker_vertex[on]]
        return out
