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
wall and, on a curved wall, lie behind their straight extension: a false
penetration. A node that no facet faces (nothing across from it) keeps the
non-excluded facet with the largest signed distance, so it stays open.

Everything else (the gap in UFL, the condensation w_k = S_k u) is the
two-body machinery of :mod:`.pairs` unchanged. Sign conventions as there:
g >= 0 open, lam <= 0 the pressure.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix, csr_matrix
from scipy.sparse.csgraph import dijkstra

from fenics_contact.model.pairs import DeformablePair
from fenics_contact.model.search import KEEP, TIE_TOL, Projection, facet_normals, project

#: Default neighbourhood radius, in facet sizes along the surface.
NEIGHBOURHOOD = 3.0


def _surface_graph(X: np.ndarray, facet_vertex: np.ndarray) -> tuple[csr_matrix, float]:
    """Edge graph of the surface (reference lengths) and the mean facet size (length)."""
    nv = facet_vertex.shape[1]
    pairs = [(i, (i + 1) % nv) for i in range(nv if nv > 2 else 1)]
    a = np.concatenate([facet_vertex[:, i] for i, _ in pairs])
    b = np.concatenate([facet_vertex[:, j] for _, j in pairs])
    length = np.linalg.norm(X[a] - X[b], axis=1)
    n = X.shape[0]
    graph = coo_matrix((np.r_[length, length], (np.r_[a, b], np.r_[b, a])), shape=(n, n))
    size = float(np.mean([np.max(np.linalg.norm(X[facet_vertex[:, i]] - X[facet_vertex[:, j]],
                                                  axis=1)) for i, j in pairs]))
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
) -> Projection:
    """Assign each point the closest facet that is outside its neighbourhood and faces it.

    Args:
        points: (n, gdim) current striker positions.
        point_normals: (n, gdim) their current normals (zero: no facing rule).
        current: (m, nv, gdim) current facet vertices (oriented outward).
        excluded: (n, m) boolean, True for the facets in each point's neighbourhood.
        previous: facets assigned before (-1: none), for the hysteresis.
        keep: the hysteresis tolerance (see :meth:`.search.SurfaceSearch.closest`).
    """
    n = points.shape[0]
    gdim = current.shape[2]
    if n == 0:
        return Projection(np.zeros(0, np.int64), np.zeros((0, gdim - 1)), np.zeros(0),
                          np.zeros(0))
    normals = facet_normals(current)
    allowed = ~excluded.toarray()
    facing = np.einsum("id,jd->ij", point_normals, normals) < 0.0
    no_rule = ~np.any(point_normals != 0.0, axis=1)
    valid = allowed & (facing | no_rule[:, None])
    if not np.all(allowed.any(axis=1)):
        raise ValueError(
            "A self-contact node excludes every facet of the surface; lower the neighbourhood "
            "or refine the surface."
        )
    xi, dist, over = project(points, np.broadcast_to(current, (n, *current.shape)))
    size = float(np.max(np.linalg.norm(current[:, 1] - current[:, 0], axis=-1)))
    key = np.where(valid, dist, np.inf)
    best = key.min(axis=1, keepdims=True)
    tie = np.where(valid & (key <= best + TIE_TOL * size), over, np.inf)
    facet = np.argmin(tie, axis=1)
    # nothing faces the point: the allowed facet it is farthest in front of (stays open)
    lonely = ~valid.any(axis=1)
    if np.any(lonely):
        signed = np.einsum("ijd,jd->ij", points[lonely][:, None, :] - current[None, :, 0],
                           normals)
        facet[lonely] = np.argmax(np.where(allowed[lonely], signed, -np.inf), axis=1)
    rows = np.arange(n)
    chosen = (facet, xi[rows, facet], dist[rows, facet], over[rows, facet])
    if previous is not None and previous.size == n:
        prev = np.asarray(previous, np.int64)
        ok = prev >= 0
        p = np.where(ok, prev, 0)
        length = np.linalg.norm(current[p, 1] - current[p, 0], axis=-1)
        close = dist[rows, p] <= chosen[2] + keep * length
        ok &= valid[rows, p] & (over[rows, p] <= keep) & close
        facet = np.where(ok, p, facet)
        chosen = (facet, xi[rows, facet], dist[rows, facet], over[rows, facet])
    return Projection(*chosen)


class SelfContactPair(DeformablePair):
    """A :class:`~.pairs.DeformablePair` whose target is the striker's own body surface.

    Args:
        V, u, surface, target_facets: as for the pair (the target facets may
            be the striker's own).
        neighbourhood: radius of each node's excluded neighbourhood, in
            facet sizes along the surface (reference configuration).
    """

    def __init__(self, V, u, surface, target_facets, neighbourhood: float = NEIGHBOURHOOD) -> None:
        if not (np.isfinite(neighbourhood) and neighbourhood > 0):
            raise ValueError(
                f"neighbourhood must be finite and > 0 (facet sizes), got {neighbourhood}.")
        super().__init__(V, u, surface, target_facets)
        im = V.dofmap.index_map
        local = self._striker_block.astype(np.int32)
        gblock = im.local_to_global(local) if local.size else np.zeros(0, np.int64)
        pos = np.searchsorted(self.vertices, gblock)
        pos = np.minimum(pos, max(self.vertices.size - 1, 0))
        #: The surface vertex of each striker node (-1: not on the target surface).
        self.striker_vertex = np.where(self.vertices[pos] == gblock, pos, -1)
        self.neighbourhood = float(neighbourhood)
        self.excluded = neighbourhoods(self.X_vertices, self.facet_vertex, self.striker_vertex,
                                       self.neighbourhood)

    def _search(self, current: np.ndarray) -> Projection:
        normals = vertex_normals(current, self.facet_vertex, self.vertices.size)
        on = self.striker_vertex >= 0
        point_normals = np.zeros((self.striker_vertex.size, self.gdim))
        point_normals[on] = normals[self.striker_vertex[on]]
        return closest_facing(self.striker_positions(), point_normals, current, self.excluded,
                              previous=self.assignment)

    def penetration(self) -> np.ndarray:
        """Depth of each owned striker node behind its assigned facet's plane (length, >= 0).

        Measured on the assigned (facing) facet: the closest point of the whole
        surface to a node is the node itself.
        """
        n = self.n_owned
        current = (self.X_vertices + self.target_displacements())[self.facet_vertex]
        facet = self.assignment[:n]
        gap = np.einsum("ij,ij->i", self.striker_positions()[:n] - current[facet, 0],
                        facet_normals(current)[facet])
        return np.maximum(-gap, 0.0)
