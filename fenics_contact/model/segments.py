"""Mortar segmentation data in 2D: gathered polylines, striker neighbours, target slots.

The mortar weighted gap of a striker node j (:mod:`.mortar`) is an integral
over the node's two striker facets. Each facet is cut at the projections
(along the striker facet's normal) of the end points of the target facets
that overlap it, so that every segment lies on one striker facet and one
target facet. The cutting is written in UFL; this module supplies, for
every striker node, the data the UFL expression needs:

* the two striker neighbours L and R of the node along its surface (the
  facets (L, j) and (j, R), oriented so that ``perp(x2 - x1)`` with
  ``perp(t) = (t_y, -t_x)`` points out of the striker), and
* up to ``slots`` target facets (a_k, b_k) whose projection overlaps one of
  the two striker facets (opposing normals, within reach).

Both surfaces are gathered on every rank (O(surface) memory and traffic,
like the node-to-segment search); the slot search compares every striker
node with every target facet (O(n m) per search), which is what limits it
to surfaces of a few thousand facets.
"""

from __future__ import annotations

import numpy as np
from dolfinx import fem, mesh

from mpi4py import MPI

#: Target facets farther than this many of the largest facet lengths are not candidates.
REACH = 2.0
#: A node whose target lies within this many facet lengths counts as near contact.
NEAR = 0.25
#: Slots per striker node at least (more where the target is finer than the striker).
SLOTS = 4
#: Slots per striker node at most when chosen from the facet sizes (compile time grows
#: with them); a pair may ask for more (``[[pair]] slots``).
MOST_SLOTS = 12
#: Stretch allowed for when counting the target facets a striker support may overlap.
STRETCH = 1.25
#: Lowest cosine of the angle between the striker normal and minus the target normal.
OPPOSING = 0.2
#: A target facet whose projection misses a striker facet by up to this (local coordinate)
#: is kept in a slot: it costs nothing (zero-length segment) and spares a rebuild.
MARGIN = 0.02


def node_blocks(V: fem.FunctionSpace) -> np.ndarray:
    """Local block (vertex dof) of V at each local geometry node (P1 on a P1 mesh)."""
    geo = V.mesh.geometry
    out = np.full(geo.x.shape[0], -1, dtype=np.int64)
    out[geo.dofmaps[0].reshape(-1)] = V.dofmap.list.reshape(-1)
    return out


class Polyline:
    """A facet set gathered on every rank, oriented outward (2D segments or 3D triangles).

    Attributes:
        blocks: (m, d) global V blocks of each facet's vertices, ordered so
            that the facet's normal points out of the body: perp(x_1 - x_0)
            with perp(t) = (t_y, -t_x) in 2D, (x_1 - x_0) x (x_2 - x_0) in 3D.
        vertices: the distinct global blocks; ``facet_vertex`` indexes them.
        X: (len(vertices), d) reference positions of the vertices (length).
        owned: (start, stop) of this rank's facets in ``blocks``.
    """

    def __init__(self, V: fem.FunctionSpace, facets: np.ndarray, *, dim: int = 2) -> None:
        domain = V.mesh
        comm = domain.comm
        tdim = domain.topology.dim
        fdim = tdim - 1
        gdim = domain.geometry.dim
        if gdim != dim:
            raise ValueError(f"This mortar surface is {dim}D; the mesh is {gdim}D.")
        for d0, d1 in ((fdim, tdim), (0, tdim), (tdim, 0), (fdim, 0)):
            domain.topology.create_connectivity(d0, d1)
        facets = np.unique(np.asarray(facets, np.int32))
        facets = facets[facets < domain.topology.index_map(fdim).size_local]
        x = domain.geometry.x[:, :gdim]
        if facets.size:
            nodes = mesh.entities_to_geometry(domain, fdim, facets)
            if nodes.shape[1] != gdim:
                raise ValueError("Mortar facets must be segments (2D) or triangles (3D); "
                                 "split quadrilateral faces into triangles.")
            f2c = domain.topology.connectivity(fdim, tdim)
            cells = np.array([f2c.links(f)[0] for f in facets], np.int64)
            centre = x[domain.geometry.dofmaps[0][cells]].mean(axis=1)
            n = _facet_normals(x[nodes])
            flip = np.einsum("ij,ij->i", n, x[nodes].mean(axis=1) - centre) < 0
            nodes[flip] = nodes[flip][:, ::-1] if gdim == 2 else nodes[flip][:, [0, 2, 1]]
            local = node_blocks(V)[nodes].reshape(-1).astype(np.int32)
            blocks = V.dofmap.index_map.local_to_global(local).reshape(-1, gdim)
            coords = x[nodes]
        else:
            blocks, coords = np.zeros((0, gdim), np.int64), np.zeros((0, gdim, gdim))
        counts = comm.allgather(int(blocks.shape[0]))
        start = int(sum(counts[: comm.rank]))
        self.owned = (start, start + counts[comm.rank])
        self.blocks = np.concatenate(comm.allgather(blocks.astype(np.int64)))
        all_x = np.concatenate(comm.allgather(coords.reshape(-1, gdim, gdim)))
        if self.blocks.shape[0] == 0:
            raise ValueError("A mortar surface has no facets on any rank.")
        self.dim = gdim
        self.vertices, inverse = np.unique(self.blocks, return_inverse=True)
        self.facet_vertex = inverse.reshape(-1, gdim)
        self.X = np.zeros((self.vertices.size, gdim))
        self.X[self.facet_vertex.reshape(-1)] = all_x.reshape(-1, gdim)
        lo, hi = V.dofmap.index_map.local_range
        mine = (self.vertices >= lo) & (self.vertices < hi)
        self._own_local = (self.vertices[mine] - lo).astype(np.int64)
        self._own_pos = np.concatenate(comm.allgather(np.flatnonzero(mine)))
        self.comm = comm

    def displacements(self, u: fem.Function) -> np.ndarray:
        """Displacement of every vertex, on every rank (collective)."""
        d = self.dim
        values = u.x.array.reshape(-1, d)[self._own_local]
        out = np.empty((self.vertices.size, d))
        out[self._own_pos] = np.concatenate(self.comm.allgather(values.reshape(-1, d)))
        return out

    def index(self, blocks: np.ndarray) -> np.ndarray:
        """Position in ``vertices`` of global blocks (ValueError when absent)."""
        pos = np.searchsorted(self.vertices, blocks)
        pos = np.minimum(pos, self.vertices.size - 1)
        if not np.all(self.vertices[pos] == blocks):
            raise ValueError("A striker node is not a vertex of the striker surface.")
        return pos


def _facet_normals(X: np.ndarray) -> np.ndarray:
    """Unnormalised normals of facets (m, d, d) in their vertex order."""
    if X.shape[-1] == 2:
        t = X[:, 1] - X[:, 0]
        return np.stack([t[:, 1], -t[:, 0]], axis=-1)
    return np.cross(X[:, 1] - X[:, 0], X[:, 2] - X[:, 0])


def neighbours(line: Polyline, nodes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Left and right neighbours (indices in ``line.vertices``, -1: none) of given vertices.

    Left: the first vertex of the facet whose second vertex is the node;
    right: the second vertex of the facet whose first vertex it is.
    """
    n = line.vertices.size
    left = np.full(n, -1, np.int64)
    right = np.full(n, -1, np.int64)
    fv = line.facet_vertex
    if np.unique(fv[:, 0]).size != fv.shape[0] or np.unique(fv[:, 1]).size != fv.shape[0]:
        raise ValueError("The striker facets of a mortar pair must form simple polylines.")
    left[fv[:, 1]] = fv[:, 0]
    right[fv[:, 0]] = fv[:, 1]
    return left[nodes], right[nodes]


def overlaps(x1: np.ndarray, x2: np.ndarray, ta: np.ndarray, tb: np.ndarray,
             reach: float) -> tuple[np.ndarray, np.ndarray]:
    """Overlap (local coordinate of the striker facet) of every target facet with each facet.

    Args:
        x1: (n, 2) current first end points of n striker facets.
        x2: (n, 2) their second end points.
        ta: (m, 2) current first end points of m target facets.
        tb: (m, 2) their second end points.
        reach: largest distance of a target facet along the striker facet's
            normal that counts (length): its normal distance over the cosine
            between the facets (a facet tilted away, near in its own normal
            but far along the striker's, does not count).

    Returns (n, m) arrays: the length in [0, 1] local coordinates of the
    projection overlap (-inf where the facets do not face each other or lie
    farther than ``reach`` along the striker's normal; slightly
    negative values, down to -MARGIN, for near misses), and the normal
    distance relative to the striker facet's length.
    """
    t = x2 - x1
    tt = np.einsum("ij,ij->i", t, t)
    xa = np.einsum("nmi,ni->nm", ta[None] - x1[:, None], t) / tt[:, None]
    xb = np.einsum("nmi,ni->nm", tb[None] - x1[:, None], t) / tt[:, None]
    lo = np.maximum(np.minimum(xa, xb), 0.0)
    hi = np.minimum(np.maximum(xa, xb), 1.0)
    ns = np.stack([t[:, 1], -t[:, 0]], axis=-1) / np.sqrt(tt)[:, None]
    tt_t = tb - ta
    nt = np.stack([tt_t[:, 1], -tt_t[:, 0]], axis=-1)
    nt /= np.linalg.norm(nt, axis=-1, keepdims=True)
    cos = -ns @ nt.T
    mid = x1[:, None] + (0.5 * (lo + hi))[..., None] * t[:, None]
    dist = np.abs(np.einsum("nmi,mi->nm", ta[None] - mid, nt))
    out = hi - lo
    out[(cos < OPPOSING) | (dist > reach * np.maximum(cos, 0.0)) | (out < -MARGIN)] = -np.inf
    return out, dist / np.sqrt(tt)[:, None]


def pick_slots(scores: np.ndarray, slots: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The ``slots`` largest overlaps per row of ``scores`` (-1 where none).

    Returns the facets, whether each slot is used, and per row the number
    of target facets with a positive overlap that found no slot: such a
    node's gap is averaged over the part of its support its slots cover.
    """
    n = scores.shape[0]
    if n == 0 or scores.shape[1] == 0:
        return (np.full((n, slots), -1, np.int64), np.zeros((n, slots), bool),
                np.zeros(n, np.int64))
    dropped = np.maximum(np.sum(scores > 0.0, axis=1) - slots, 0)
    k = min(slots, scores.shape[1])
    order = np.argsort(-scores, axis=1, kind="stable")[:, :k]
    best = np.take_along_axis(scores, order, axis=1)
    facet = np.full((n, slots), -1, np.int64)
    used = np.zeros((n, slots), bool)
    ok = np.isfinite(best)
    facet[:, :k] = np.where(ok, order, -1)
    used[:, :k] = ok
    return facet, used, dropped


def facet_sizes(line: Polyline) -> np.ndarray:
    """Reference length of each facet of a polyline."""
    X = line.X[line.facet_vertex]
    return np.linalg.norm(X[:, 1] - X[:, 0], axis=-1)


def slots_needed(striker: Polyline, target: Polyline, stretch: float = STRETCH) -> int:
    """Target facets the support of a striker node may overlap where the surfaces meet.

    For every striker node whose distance to the target exceeds the
    surfaces' closest approach by at most its support length (the nodes
    where the surfaces first meet), the target facets within half its
    support length (times ``stretch``) of a target vertex near its closest
    point are counted; the largest count is returned (at least
    :data:`SLOTS`). Where the meshes change along the surfaces beyond that
    zone, :attr:`MortarTransfer.most_overlaps` tells afterwards. A coarse striker facet over
    a fine target needs more than the default slots: with too few, the
    weighted gap would leave part of the support out and jump as the facets
    it keeps change. Reference configuration; the same on every rank (both
    polylines are gathered).
    """
    from scipy.spatial import cKDTree

    if not (striker.facet_vertex.size and target.facet_vertex.size):
        return SLOTS
    xs, xt = striker.X, target.X
    ends = xt[target.facet_vertex]
    ls = facet_sizes(striker)
    support = np.zeros(len(xs))
    np.add.at(support, striker.facet_vertex[:, 0], ls)
    np.add.at(support, striker.facet_vertex[:, 1], ls)
    # closest point of each striker node on the target polyline
    a, b = ends[:, 0], ends[:, 1]
    ab = b - a
    tree = cKDTree(0.5 * (a + b))
    extent = float(np.linalg.norm(np.ptp(np.vstack([xs, xt]), axis=0)))
    longest = float(np.max(np.linalg.norm(ab, axis=1)))
    _, nearest = tree.query(xs, k=min(8, len(ab)))
    nearest = np.atleast_2d(nearest.T).T
    d = xs[:, None] - a[nearest]
    s = np.clip(np.einsum("nki,nki->nk", d, ab[nearest])
                / np.einsum("nki,nki->nk", ab[nearest], ab[nearest]), 0.0, 1.0)
    foot = a[nearest] + s[..., None] * ab[nearest]
    dist = np.linalg.norm(xs[:, None] - foot, axis=-1)
    best = np.argmin(dist, axis=1)
    closest = foot[np.arange(len(xs)), best]
    gap = dist[np.arange(len(xs)), best]
    vertices = cKDTree(xt)
    most = SLOTS
    for j in np.flatnonzero(gap <= gap.min() + support):
        radius = 0.5 * stretch * support[j]
        centres = xt[vertices.query_ball_point(closest[j], radius + 1e-12 * extent)]
        if not len(centres):
            continue
        near = tree.query_ball_point(closest[j], 2.0 * radius + longest)
        pa, pab = a[near], ab[near]
        t = np.clip(np.einsum("cki,ki->ck", centres[:, None] - pa, pab)
                    / np.einsum("ki,ki->k", pab, pab), 0.0, 1.0)
        reach = np.linalg.norm(centres[:, None] - (pa + t[..., None] * pab), axis=-1)
        most = max(most, int(np.max(np.sum(reach < radius, axis=1))))
    return most


def any_rank(comm: MPI.Comm, flag: bool) -> bool:
    """Whether ``flag`` holds on some rank (collective)."""
    return bool(comm.allreduce(bool(flag), op=MPI.LOR))
