"""Closest-point search of striker nodes on a target surface (node-to-segment).

The target surface is a set of straight facets: segments in 2D, triangles in
3D, each given by its vertex positions in the current configuration and
oriented so that the vertex order gives the outward normal
(2D: ``n = perp(b - a)`` with ``perp(t) = (t_y, -t_x)``; 3D:
``n = (b - a) x (c - a)``).

Search: a k-d tree (``scipy.spatial.cKDTree``) on the facet centroids. The
best of the k nearest facets (by centroid) bounds the distance d of a point
to the surface; a facet can hold a point within d (plus the tie tolerance)
only if its centroid lies within d + rho_f of the point, with rho_f that
facet's centroid-to-vertex radius. The points whose k-th centroid lies
nearer than that get every such facet from one ball query, and all
(point, facet) candidates are projected at once in flat arrays
(vectorised; no per-point loop and no repeated queries), so every facet
that can hold the closest point is examined; O(n log m) for n striker nodes
and m facets.

Corner rule (documented in docs/two_bodies.md): each candidate facet's
*clamped* closest point (the projection limited to the facet) gives a
distance; the facet with the smallest distance is assigned. Where the
projection leaves every facet (a convex corner or edge) several facets
share the nearest vertex at the same distance; the tie is broken by the
smallest overshoot of the *unclamped* projection outside the facet, and the
gap is measured from that facet's plane (its straight extension). On a flat
or gently curved target the gap is then continuous when a node slides from
facet to facet; at a sharp convex corner it jumps to the next facet once
that facet's projection overshoots less.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Relative tolerance (of the facet size) under which two clamped distances tie.
TIE_TOL = 1e-10
#: Hysteresis of the assignment (local coordinates; see SurfaceSearch.closest).
KEEP = 0.05


@dataclass(frozen=True)
class Projection:
    """Result of a search for n points.

    Attributes:
        facet: index of the assigned facet per point.
        xi: unclamped local coordinates of the projection on the assigned
            facet, shape (n, gdim - 1) (2D: 0 at a, 1 at b; 3D: barycentric
            weights of b and c).
        distance: distance to the clamped closest point (length units).
        overshoot: how far the unclamped projection lies outside the facet
            in local coordinates (0 inside).
    """

    facet: np.ndarray
    xi: np.ndarray
    distance: np.ndarray
    overshoot: np.ndarray


def _segment_projection(p: np.ndarray, a: np.ndarray, b: np.ndarray):
    """Unclamped xi, clamped distance and overshoot of points p on segments (a, b)."""
    t = b - a
    tt = np.einsum("...i,...i->...", t, t)
    xi = np.einsum("...i,...i->...", p - a, t) / tt
    xc = np.clip(xi, 0.0, 1.0)
    closest = a + xc[..., None] * t
    dist = np.linalg.norm(p - closest, axis=-1)
    over = np.abs(xi - xc)
    return xi[..., None], dist, over


def _triangle_projection(p: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray):
    """Unclamped barycentric (xi_b, xi_c), clamped distance and overshoot on triangles."""
    e1, e2 = b - a, c - a
    d = p - a
    g11 = np.einsum("...i,...i->...", e1, e1)
    g12 = np.einsum("...i,...i->...", e1, e2)
    g22 = np.einsum("...i,...i->...", e2, e2)
    r1 = np.einsum("...i,...i->...", d, e1)
    r2 = np.einsum("...i,...i->...", d, e2)
    det = g11 * g22 - g12**2
    s = (g22 * r1 - g12 * r2) / det
    t = (g11 * r2 - g12 * r1) / det
    bary = np.stack([1.0 - s - t, s, t], axis=-1)
    over = np.sum(np.maximum(-bary, 0.0), axis=-1)
    inside = over == 0.0
    normal_dist = np.linalg.norm(d - s[..., None] * e1 - t[..., None] * e2, axis=-1)
    edge = np.full(s.shape, np.inf)
    for q0, q1 in ((a, b), (b, c), (c, a)):
        _, de, _ = _segment_projection(p, q0, q1)
        edge = np.minimum(edge, de)
    dist = np.where(inside, normal_dist, edge)
    return np.stack([s, t], axis=-1), dist, over


def project(points: np.ndarray, facets: np.ndarray) -> Projection:
    """Closest facet for each point by brute force over the given candidates.

    Args:
        points: (n, gdim) current positions.
        facets: (n, k, nv, gdim) candidate facet vertices per point.
    """
    p = points[:, None, :]
    if facets.shape[2] == 2:
        xi, dist, over = _segment_projection(p, facets[:, :, 0], facets[:, :, 1])
    else:
        xi, dist, over = _triangle_projection(p, facets[:, :, 0], facets[:, :, 1], facets[:, :, 2])
    return xi, dist, over


class SurfaceSearch:
    """Closest facet of a target surface for every striker node.

    Args:
        vertices: (m, nv, gdim) current vertex positions of the target facets.
        candidates: neighbours asked of the k-d tree first (the result does
            not depend on it; only the speed does).
    """

    def __init__(self, vertices: np.ndarray, candidates: int = 8,
                 size: float | None = None) -> None:
        self.vertices = np.asarray(vertices, float)
        m = self.vertices.shape[0]
        if m == 0:
            raise ValueError("The target surface has no facets.")
        self.centroids = self.vertices.mean(axis=1)
        #: Centroid-to-vertex radius of each facet (length).
        self.radius = np.max(np.linalg.norm(self.vertices - self.centroids[:, None, :], axis=-1),
                             axis=1)
        self.rho = float(np.max(self.radius))
        #: Length scale of the tie tolerance: the largest first edge of the facets, or
        #: ``size`` (that of the whole surface when these facets are part of it).
        self.size = float(np.max(np.linalg.norm(
            self.vertices[:, 1] - self.vertices[:, 0], axis=-1))) if size is None else size
        try:
            from scipy.spatial import cKDTree
        except ImportError as err:  # pragma: no cover - depends on the install
            raise ImportError(
                "Two-body contact searches with scipy.spatial.cKDTree; install it with "
                "`pip install fenics-contact[bodies]` (or `pip install scipy`)."
            ) from err
        self.tree = cKDTree(self.centroids)
        self.k = int(min(candidates, m))

    def closest(
        self, points: np.ndarray, previous: np.ndarray | None = None, keep: float = KEEP
    ) -> Projection:
        """Assign a facet to every point with the corner rule of the module.

        ``previous``: the facets assigned before (-1: none). A point keeps its
        previous facet while that facet's unclamped projection leaves it by at
        most ``keep`` (in local coordinates) and its clamped distance exceeds
        the best by at most ``keep`` times the facet size: the hysteresis
        that stops a node in contact at a convex vertex from flipping between
        the two facets from one Newton iteration to the next.
        """
        points = np.asarray(points, float)
        n = points.shape[0]
        if n == 0:
            gd = self.vertices.shape[2]
            return Projection(np.zeros(0, np.int64), np.zeros((0, gd - 1)), np.zeros(0),
                              np.zeros(0))
        m = self.vertices.shape[0]
        dist_c, idx = self.tree.query(points, k=self.k)
        dist_c, idx = dist_c.reshape(n, -1), idx.reshape(n, -1)
        facet, xi, dist, over = self._pick(points, idx)
        # The closest point of a facet lies within rho_f of its centroid: once the
        # k-th nearest centroid is farther than (best distance + tol + rho), no
        # other facet can be closer or tie; the others get every such facet.
        tol = TIE_TOL * self.size
        if self.k < m:
            todo = np.flatnonzero(dist_c[:, -1] <= dist + tol + self.rho)
            if todo.size:
                f, x, d, o = self._pick_within(points[todo], dist[todo] + tol)
                facet[todo], xi[todo], dist[todo], over[todo] = f, x, d, o
        if previous is not None and previous.size == n:
            prev = np.asarray(previous, np.int64)
            has = prev >= 0
            if np.any(has):
                rows = np.flatnonzero(has)
                xp, dp, op = project(points[rows], self.vertices[prev[rows]][:, None])
                length = np.linalg.norm(
                    self.vertices[prev[rows], 1] - self.vertices[prev[rows], 0], axis=-1)
                ok = (op[:, 0] <= keep) & (dp[:, 0] <= dist[rows] + keep * length)
                sel = rows[ok]
                facet[sel] = prev[sel]
                xi[sel], dist[sel], over[sel] = xp[ok, 0], dp[ok, 0], op[ok, 0]
        return Projection(facet, xi, dist, over)

    def _pick_within(self, points: np.ndarray, bound: np.ndarray):
        """The corner rule over every facet that can lie within ``bound`` of each point.

        One ball query gives the facets whose centroid lies within bound +
        rho; those within bound + rho_f are projected in one flat batch, and
        the candidates of each point are ranked by centroid distance first
        (the k-d tree's order, which breaks exact ties as :meth:`_pick` does).
        """
        n = points.shape[0]
        found = self.tree.query_ball_point(points, r=bound + self.rho, return_sorted=False)
        counts = np.fromiter((len(f) for f in found), np.int64, n)
        cand = np.concatenate([np.asarray(f, np.int64) for f in found]) if n else \
            np.zeros(0, np.int64)
        owner = np.repeat(np.arange(n), counts)
        centre = np.linalg.norm(points[owner] - self.centroids[cand], axis=-1)
        near = centre <= bound[owner] + self.radius[cand] * (1.0 + 1e-12)
        owner, cand, centre = owner[near], cand[near], centre[near]
        xi, dist, over = project(points[owner], self.vertices[cand][:, None])
        xi, dist, over = xi[:, 0], dist[:, 0], over[:, 0]
        order = np.lexsort((centre, owner))
        owner, cand, xi, dist, over = owner[order], cand[order], xi[order], dist[order], \
            over[order]
        start = np.flatnonzero(np.r_[True, owner[1:] != owner[:-1]])
        best = np.minimum.reduceat(dist, start)
        lengths = np.diff(np.r_[start, owner.size])
        key = np.where(dist <= np.repeat(best, lengths) + TIE_TOL * self.size, over, np.inf)
        # first (nearest centroid) of the least overshoot among the ties, per point
        rank = np.lexsort((np.arange(owner.size), key, owner))
        first = rank[start]
        return cand[first], xi[first], dist[first], over[first]

    def _pick(self, points: np.ndarray, idx: np.ndarray):
        xi, dist, over = project(points, self.vertices[idx])
        tol = TIE_TOL * self.size
        best = dist.min(axis=1, keepdims=True)
        # Among facets within the tie tolerance, the least overshoot wins.
        key = np.where(dist <= best + tol, over, np.inf)
        j = np.argmin(key, axis=1)
        rows = np.arange(points.shape[0])
        return idx[rows, j], xi[rows, j], dist[rows, j], over[rows, j]


def facet_normals(vertices: np.ndarray) -> np.ndarray:
    """Unit normals of oriented facets (m, nv, gdim): segments (t_y, -t_x), triangles e1 x e2."""
    if vertices.shape[2] == 2:
        t = vertices[:, 1] - vertices[:, 0]
        n = np.stack([t[:, 1], -t[:, 0]], axis=-1)
    else:
        n = np.cross(vertices[:, 1] - vertices[:, 0], vertices[:, 2] - vertices[:, 0])
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


def _closest_points(points: np.ndarray, facets: np.ndarray) -> np.ndarray:
    """Closest point of each facet (n, nv, gdim) to each point (n, gdim), clamped to the facet."""
    a = facets[:, 0]
    if facets.shape[1] == 2:
        t = facets[:, 1] - a
        xi = np.clip(np.einsum("ij,ij->i", points - a, t) / np.einsum("ij,ij->i", t, t), 0, 1)
        return a + xi[:, None] * t
    xi, dist, over = project(points, facets[:, None])
    st, dist, over = xi[:, 0], dist[:, 0], over[:, 0]
    inside = a + st[:, :1] * (facets[:, 1] - a) + st[:, 1:] * (facets[:, 2] - a)
    best, best_d = inside.copy(), np.where(over == 0.0, dist, np.inf)
    for q0, q1 in ((0, 1), (1, 2), (2, 0)):
        c = _closest_points(points, facets[:, [q0, q1]])
        d = np.linalg.norm(points - c, axis=-1)
        closer = d < best_d
        best[closer], best_d[closer] = c[closer], d[closer]
    return best


def penetration_depth(points: np.ndarray, vertices: np.ndarray, candidates: int = 8,
                      size: float | None = None, nearest: Projection | None = None,
                      free: np.ndarray | None = None) -> np.ndarray:
    """How deep each point lies inside an oriented surface, by closest point (length; 0 outside).

    The actual surface, not the plane of an assigned facet: the closest point
    over all facets, and the side from the pseudo-normal (the sum of the
    normals of every facet that shares that closest point), which is right at
    edges and vertices where one facet's plane is not. Points past the rim of
    the surface (:func:`past_free_edge` with no reach) count as outside; without
    ``free``, those whose closest point lies on one facet only, at its border.

    Args:
        points: (n, gdim) positions.
        vertices: (m, nv, gdim) facet vertices, ordered so the normals point outward.
        candidates: nearest facets (by centroid) examined per point.
        size: the tie tolerance's length scale (:class:`SurfaceSearch`).
        nearest: ``SurfaceSearch(vertices, candidates, size).closest(points)``
            when the caller has it already.
        free: (m, nv) bool, the free sides of each facet (see :func:`past_free_edge`).
    """
    points = np.asarray(points, float)
    if points.shape[0] == 0:
        return np.zeros(0)
    nearest, idx, ties, on_surface = _closest_ties(points, vertices, candidates, size, nearest)
    if free is not None:
        on_rim, held = _rim(points, vertices, free, nearest, idx, ties)
        on_surface = ~on_rim | held
    pseudo = np.einsum("ij,ijk->ik", ties.astype(float), facet_normals(vertices)[idx])
    closest = _closest_points(points, vertices[nearest.facet])
    behind = np.einsum("ij,ij->i", points - closest, pseudo) < 0.0
    return np.where(behind & on_surface, nearest.distance, 0.0)


def past_free_edge(points: np.ndarray, vertices: np.ndarray, free: np.ndarray,
                   candidates: int = 8, size: float | None = None,
                   nearest: Projection | None = None,
                   reach: np.ndarray | float = 0.0) -> np.ndarray:
    """Whether each point lies past the rim of the surface (bool).

    The rim is made of the free sides of the facets (2D: the end vertices of
    the polyline; 3D: the edges of the patch that one facet alone holds). A
    point is past it when its closest point of the surface lies on the rim,
    no facet that touches that closest point holds the point's projection on
    its plane, and the point is farther than ``reach`` from it. Such a point
    faces no part of the surface; the body's other faces are there, not this
    surface.

    Args:
        points: (n, gdim) positions.
        vertices: (m, nv, gdim) facet vertices, ordered so the normals point outward.
        free: (m, nv) bool, the free sides of each facet (side k: 2D the end
            vertex k, 3D the edge opposite vertex k).
        candidates: nearest facets (by centroid) examined per point.
        size: the tie tolerance's length scale (:class:`SurfaceSearch`).
        nearest: ``SurfaceSearch(vertices, candidates, size).closest(points)``
            when the caller has it already.
        reach: per point or for all, the distance from the rim within which a
            point past it still counts as facing the surface (length).
    """
    points = np.asarray(points, float)
    n = points.shape[0]
    if n == 0:
        return np.zeros(0, bool)
    nearest, idx, ties, _ = _closest_ties(points, vertices, candidates, size, nearest)
    on_rim, held = _rim(points, vertices, free, nearest, idx, ties)
    return on_rim & ~held & (nearest.distance > reach)


def _rim(points: np.ndarray, vertices: np.ndarray, free: np.ndarray, nearest: Projection,
         idx: np.ndarray, ties: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(closest point on the rim, projection held by a facet touching it), per point."""
    closest = _closest_points(points, vertices[nearest.facet])
    facets = vertices[idx]  # (n, k, nv, gdim)
    xi_c, _, _ = project(closest, facets)
    nv = vertices.shape[1]
    bary = np.concatenate([1.0 - xi_c.sum(axis=-1, keepdims=True), xi_c], axis=-1)
    on_rim = np.zeros(idx.shape, bool)
    for k in range(nv):
        others = [j for j in range(nv) if j not in _side(nv, k)]
        on_side = np.all(np.abs(bary[..., others]) <= 1e-9, axis=-1)
        on_rim |= on_side & free[idx][..., k]
    _, _, over = project(points, facets)
    held = np.any(ties & (over <= 1e-9), axis=1)
    return np.any(ties & on_rim, axis=1), held


def _side(nv: int, k: int) -> tuple[int, ...]:
    """The facet vertices of side k: 2D the end vertex k, 3D the edge opposite vertex k."""
    return (k,) if nv == 2 else ((k + 1) % 3, (k + 2) % 3)


def _closest_ties(points: np.ndarray, vertices: np.ndarray, candidates: int,
                  size: float | None, nearest: Projection | None):
    """(closest projection, candidate facets, ties to the closest distance, on the surface).

    On the surface: the closest point inside its facet, or shared by several
    facets. Past a free edge of the surface (the closest point on one facet
    only, at its boundary) no side is defined: the body's other faces are
    there, not this surface.
    """
    search = SurfaceSearch(vertices, candidates, size=size)
    if nearest is None:
        nearest = search.closest(points)
    k = min(max(candidates, 2 * points.shape[1]), vertices.shape[0])
    _, idx = search.tree.query(points, k=k)
    idx = np.asarray(idx).reshape(points.shape[0], -1)
    idx[:, 0] = nearest.facet  # the closest facet is always among the candidates
    _, dist, _ = project(points, vertices[idx])
    ties = dist <= nearest.distance[:, None] + TIE_TOL * search.size
    on_surface = (nearest.overshoot == 0.0) | (ties.sum(axis=1) > 1)
    return nearest, idx, ties, on_surface
