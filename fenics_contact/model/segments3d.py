"""Mortar segmentation in 3D: striker triangles cut by the projected target triangles.

The 3D mortar weighted gap of a striker node j is the integral over its
striker triangles of N_j g, the gap measured along the striker triangle's
normal n_s (as in 2D, :mod:`.mortar`). The integrand is smooth only on the
*segments*: the pieces of a striker triangle S that one target triangle T
covers. This module finds them, in the current configuration:

1. T's vertices are projected along n_s onto S's plane and written in S's
   local coordinates xi = (xi_1, xi_2) (x = s_0 + xi_1 (s_1 - s_0) + xi_2
   (s_2 - s_0)); S itself is the reference triangle (0, 0), (1, 0), (0, 1);
2. the projected T is clipped against S (Sutherland-Hodgman: both convex),
   giving a convex polygon of at most six vertices;
3. the polygon is cut into triangles fanned from its first vertex.

Every polygon vertex carries its *provenance*, which says how it moves
with the bodies, so that a UFL expression can rebuild it from the vertex
positions and ``ufl.derivative`` can linearise the segmentation:

* ``STRIKER_VERTEX`` k: the corner k of S (xi fixed);
* ``TARGET_VERTEX`` k: T's vertex k projected along n_s;
* ``EDGE_CROSSING`` (i, k): S's edge i (from corner i to corner i + 1
  mod 3, see :data:`STRIKER_EDGES`) crossing T's projected edge k (from T's
  vertex k to vertex k + 1 mod 3).

:func:`corner_from_provenance` evaluates those formulas (the same algebra
a UFL form would hold); the tests check that it reproduces the clipped
coordinates and that the segments tile the covered area exactly. The
candidate pairs come from a k-d tree on the target centroids (O(n log m))
and are clipped all at once with array operations (:func:`segment_pairs`:
fixed-width vertex buffers with a count per pair, the three striker edges
in turn); :func:`clip` and :func:`segment_pair`, one pair at a time, are
the reference it is tested against (:func:`segment_pairs_loop`).

References: Puso and Laursen, CMAME 193 (2004) 601-629; Popp, Gee and
Wall, IJNME 79 (2009) 1354-1391 (segment-based integration in 3D).
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import chain

import numpy as np

#: Provenance kinds of a segment corner.
STRIKER_VERTEX, TARGET_VERTEX, EDGE_CROSSING = 0, 1, 2
#: The striker's edges in local coordinates, as (a, b, c) with a xi_1 + b xi_2 = c:
#: edge 0 from corner 0 to 1 (xi_2 = 0), edge 1 from 1 to 2 (xi_1 + xi_2 = 1),
#: edge 2 from 2 to 0 (xi_1 = 0). Inside: a xi_1 + b xi_2 on the side of corner (i + 2) % 3.
STRIKER_EDGES = np.array([[0.0, 1.0, 0.0], [1.0, 1.0, 1.0], [1.0, 0.0, 0.0]])
#: Corners of the reference striker triangle.
REFERENCE = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
#: Polygons thinner than this (in xi area) are dropped.
AREA_TOL = 1e-14
#: A target vertex at most this far outside a striker edge (in xi) counts as inside: the
#: crossing of two nearly collinear edges (the rims of two faces that end together) is
#: ill-conditioned, and its derivative, large as 1 / distance, would swamp the tangent.
#: The sliver so kept is at most this wide.
CLIP_TOL = 1e-6
#: Cosine of the largest angle between n_s and -n_t for a target triangle to count.
OPPOSING = 0.2


@dataclass(frozen=True)
class Segments:
    """The segments of a striker surface against a target surface.

    Attributes:
        striker: (k,) striker triangle of each segment.
        target: (k,) target triangle of each segment.
        xi: (k, 3, 2) the segment's corners in the striker triangle's local coordinates.
        kind: (k, 3) provenance kind of each corner (``STRIKER_VERTEX``, ...).
        index: (k, 3, 2) provenance indices: (corner, -1), (target vertex, -1)
            or (striker edge, target edge).
    """

    striker: np.ndarray
    target: np.ndarray
    xi: np.ndarray
    kind: np.ndarray
    index: np.ndarray

    def __len__(self) -> int:
        return int(self.striker.size)

    def xi_areas(self) -> np.ndarray:
        """Area of each segment in local coordinates (the striker triangle's is 1/2)."""
        e1 = self.xi[:, 1] - self.xi[:, 0]
        e2 = self.xi[:, 2] - self.xi[:, 0]
        return 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """A x b of two 3-vectors (..., 3), written out (np.cross is slow on small arrays)."""
    return np.stack([a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1],
                     a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
                     a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]], axis=-1)


def unit_normal(tri: np.ndarray) -> np.ndarray:
    """Unit normal (s_1 - s_0) x (s_2 - s_0) / |...| of triangles (..., 3, 3)."""
    n = _cross(tri[..., 1, :] - tri[..., 0, :], tri[..., 2, :] - tri[..., 0, :])
    return n / np.sqrt(np.sum(n * n, axis=-1, keepdims=True))


def local_coordinates(striker: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Local coordinates xi of points (k, 3) projected along a striker triangle's normal."""
    e1, e2 = striker[1] - striker[0], striker[2] - striker[0]
    n = _cross(e1, e2)
    nn = float(n @ n)
    # dual vectors: m_a . e_b = delta_ab and m_a . n = 0, so the normal offset drops out
    m1 = _cross(e2, n) / nn
    m2 = _cross(n, e1) / nn
    d = points - striker[0]
    return np.stack([d @ m1, d @ m2], axis=-1)


def _inside(point: np.ndarray, edge: int) -> float:
    """Signed distance-like value, >= 0 on the striker's side of its edge ``edge``."""
    a, b, c = STRIKER_EDGES[edge]
    value = a * point[0] + b * point[1] - c
    return value if edge == 0 or edge == 2 else -value


def _crossing(p: np.ndarray, q: np.ndarray, edge: int) -> np.ndarray:
    """The point of segment p-q on the line of the striker's edge ``edge``.

    The clipping asks for it only between a vertex strictly inside and one
    outside, so it lies on the segment: a vertex inside only by CLIP_TOL is
    its own exit or entry point (the line through it and its outside
    neighbour may meet the edge's line far away when both are nearly
    parallel).
    """
    a, b, c = STRIKER_EDGES[edge]
    fp, fq = a * p[0] + b * p[1] - c, a * q[0] + b * q[1] - c
    t = fp / (fp - fq)
    return p + t * (q - p)


def clip(target_xi: np.ndarray) -> list[tuple[np.ndarray, tuple[int, int, int]]]:
    """The projected target triangle (3, 2) clipped against the reference triangle.

    Returns the polygon's vertices, counter-clockwise, each with its
    provenance (kind, i, j). The target triangle may come in either orientation.
    """
    tri = np.asarray(target_xi, float)
    e1, e2 = tri[1] - tri[0], tri[2] - tri[0]
    order = [0, 1, 2] if e1[0] * e2[1] - e1[1] * e2[0] > 0 else [0, 2, 1]
    # each vertex: (xi, provenance); each edge (from vertex v to the next) carries a line:
    # ("t", k) target edge from vertex k to k + 1 mod 3 (in T's own numbering), ("s", i).
    poly = [(tri[k], (TARGET_VERTEX, k, -1)) for k in order]
    lines = []
    for a, b in zip(order, [*order[1:], order[0]], strict=True):
        lines.append(("t", a) if (a + 1) % 3 == b else ("t", b))
    for edge in range(3):
        if not poly:
            break
        out: list[tuple[np.ndarray, tuple[int, int, int]]] = []
        out_lines: list[tuple[str, int]] = []
        count = len(poly)
        for v in range(count):
            (p, prov_p), (q, _) = poly[v], poly[(v + 1) % count]
            line = lines[v]
            fp, fq = _inside(p, edge), _inside(q, edge)
            if fp >= -CLIP_TOL:
                out.append((p, prov_p))
                if fq >= -CLIP_TOL:
                    out_lines.append(line)
                    continue
                if fp >= 0.0:
                    out_lines.append(line)
                    x = _crossing(p, q, edge)
                    out.append((x, _crossing_provenance(line, edge)))
                # a vertex inside only by the tolerance is its own exit point
                out_lines.append(("s", edge))
            elif fq >= 0.0:
                x = _crossing(p, q, edge)
                out.append((x, _crossing_provenance(line, edge)))
                out_lines.append(line)
            # entering at a vertex inside only by the tolerance: that vertex is the entry
        poly, lines = out, out_lines
    return _without_repeats(poly)


def _crossing_provenance(line: tuple[str, int], edge: int) -> tuple[int, int, int]:
    """Provenance of the point where an edge on ``line`` crosses the striker's edge ``edge``."""
    kind, k = line
    if kind == "t":
        return (EDGE_CROSSING, edge, k)
    # two striker edges meet at the corner they share
    shared = {frozenset((0, 1)): 1, frozenset((1, 2)): 2, frozenset((0, 2)): 0}
    return (STRIKER_VERTEX, shared[frozenset((k, edge))], -1)


def _without_repeats(poly):
    """Drop consecutive vertices closer than round-off (a vertex exactly on an edge)."""
    kept = []
    for x, prov in poly:
        if kept and np.linalg.norm(x - kept[-1][0]) < 1e-13:
            continue
        kept.append((x, prov))
    while len(kept) > 1 and np.linalg.norm(kept[0][0] - kept[-1][0]) < 1e-13:
        kept.pop()
    return kept


def corner_from_provenance(kind: int, index: tuple[int, int], striker: np.ndarray,
                           target: np.ndarray) -> np.ndarray:
    """The xi of a segment corner rebuilt from the current vertex positions (3, 3) each.

    The formulas a UFL expression of the segment corners would hold: a fixed
    corner, a projected target vertex, or the crossing of a striker edge with
    a projected target edge.
    """
    if kind == STRIKER_VERTEX:
        return REFERENCE[index[0]].copy()
    projected = local_coordinates(striker, target)
    if kind == TARGET_VERTEX:
        return projected[index[0]]
    edge, k = index
    return _crossing(projected[k], projected[(k + 1) % 3], edge)


def segment_pair(striker: np.ndarray, target: np.ndarray) -> list[tuple[np.ndarray, tuple]]:
    """The segments of one striker triangle (3, 3) under one target triangle (3, 3).

    Each segment: (corners xi (3, 2), ((kind, i, j) for each corner)). Empty
    when the projections do not overlap or the target does not face the striker.
    """
    if float(unit_normal(striker) @ unit_normal(target)) > -OPPOSING:
        return []
    polygon = clip(local_coordinates(striker, target))
    if len(polygon) < 3:
        return []
    out = []
    x0, p0 = polygon[0]
    for k in range(1, len(polygon) - 1):
        (x1, p1), (x2, p2) = polygon[k], polygon[k + 1]
        e1, e2 = x1 - x0, x2 - x0
        if 0.5 * abs(e1[0] * e2[1] - e1[1] * e2[0]) <= AREA_TOL:
            continue
        out.append((np.array([x0, x1, x2]), (p0, p1, p2)))
    return out


def candidate_pairs(striker: np.ndarray, target: np.ndarray,
                    reach: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The (striker, target) triangle pairs worth clipping, sorted by striker then target.

    ``reach``: target triangles farther than this from a striker triangle's
    plane (normal distance between centroids) are not tried (default: twice
    the largest triangle size of either surface). Candidates come from a
    k-d tree on the target centroids and are filtered in bulk (facing,
    normal distance, lateral distance against the two triangles' radii).
    """
    from scipy.spatial import cKDTree

    striker, target = np.asarray(striker, float), np.asarray(target, float)
    empty = np.zeros(0, np.int64)
    if not (len(striker) and len(target)):
        return empty, empty
    size = max(_largest_size(striker), _largest_size(target))
    reach = 2.0 * size if reach is None else reach
    cs, ct = striker.mean(axis=1), target.mean(axis=1)
    rs = np.linalg.norm(striker - cs[:, None], axis=-1).max(axis=1)
    rt = np.linalg.norm(target - ct[:, None], axis=-1).max(axis=1)
    # a pair kept below has normal distance <= reach and lateral distance <= rs + rt
    radius = np.sqrt(reach**2 + (rs + rt.max()) ** 2) * (1.0 + 1e-12)
    near = cKDTree(ct).query_ball_point(cs, radius)
    s_idx = np.repeat(np.arange(len(cs)), [len(n) for n in near])
    t_idx = np.fromiter(chain.from_iterable(near), np.int64, count=s_idx.size)
    ns, nt = unit_normal(striker), unit_normal(target)
    ns_pair = ns[s_idx]
    facing = np.einsum("ij,ij->i", ns_pair, nt[t_idx]) <= -OPPOSING
    s_idx, t_idx, ns_pair = s_idx[facing], t_idx[facing], ns_pair[facing]
    d = ct[t_idx] - cs[s_idx]
    normal = np.einsum("ij,ij->i", d, ns_pair)
    lateral = np.linalg.norm(d - normal[:, None] * ns_pair, axis=1)
    keep = (np.abs(normal) <= reach) & (lateral <= rs[s_idx] + rt[t_idx])
    s_idx, t_idx = s_idx[keep], t_idx[keep]
    order = np.lexsort((t_idx, s_idx))
    return s_idx[order], t_idx[order]


def segment_surfaces(striker: np.ndarray, target: np.ndarray,
                     reach: float | None = None) -> Segments:
    """Every segment of a striker surface (n, 3, 3) against a target surface (m, 3, 3).

    The pairs of :func:`candidate_pairs` (``reach`` as there), clipped all at
    once by :func:`segment_pairs`; segments sorted by striker then target triangle.
    """
    striker, target = np.asarray(striker, float), np.asarray(target, float)
    return segment_pairs(striker, target, *candidate_pairs(striker, target, reach))


def segment_pairs_loop(striker: np.ndarray, target: np.ndarray, s_idx: np.ndarray,
                       t_idx: np.ndarray) -> Segments:
    """:func:`segment_pairs` pair by pair with :func:`segment_pair` (the reference)."""
    striker, target = np.asarray(striker, float), np.asarray(target, float)
    rows: list[tuple[int, int, np.ndarray, tuple]] = []
    for s, t in zip(s_idx, t_idx, strict=True):
        for xi, prov in segment_pair(striker[s], target[t]):
            rows.append((int(s), int(t), xi, prov))
    if not rows:
        return _no_segments()
    return Segments(
        striker=np.array([r[0] for r in rows], np.int64),
        target=np.array([r[1] for r in rows], np.int64),
        xi=np.array([r[2] for r in rows]),
        kind=np.array([[p[0] for p in r[3]] for r in rows], np.int64),
        index=np.array([[[p[1], p[2]] for p in r[3]] for r in rows], np.int64),
    )


def _no_segments() -> Segments:
    empty = np.zeros(0, np.int64)
    return Segments(empty, empty, np.zeros((0, 3, 2)), np.zeros((0, 3), np.int64),
                    np.zeros((0, 3, 2), np.int64))


#: The corner two striker edges share: _SHARED[i, j] for edges i != j.
_SHARED = np.array([[-1, 1, 0], [1, -1, 2], [0, 2, -1]])
#: Kinds of the line an edge of the clipped polygon lies on: a target edge or a striker edge.
_ON_TARGET, _ON_STRIKER = 0, 1


def segment_pairs(striker: np.ndarray, target: np.ndarray, s_idx: np.ndarray,
                  t_idx: np.ndarray) -> Segments:
    """The segments of the triangle pairs (striker[s_idx[p]], target[t_idx[p]]), all at once.

    The same segments, in the same order (pair by pair, then fanned from the
    polygon's first vertex), with the same provenance as :func:`segment_pair`
    applied to each pair in turn (:func:`segment_pairs_loop`), computed with
    array operations over all pairs: every polygon is a fixed-width buffer of
    vertices with a count, clipped against the three striker edges in turn.
    """
    striker, target = np.asarray(striker, float), np.asarray(target, float)
    s_idx, t_idx = np.asarray(s_idx, np.int64), np.asarray(t_idx, np.int64)
    tri_s, tri_t = striker[s_idx], target[t_idx]
    ns, nt = unit_normal(tri_s), unit_normal(tri_t)
    facing = ~(ns[:, 0] * nt[:, 0] + ns[:, 1] * nt[:, 1] + ns[:, 2] * nt[:, 2] > -OPPOSING)
    s_idx, t_idx, tri_s, tri_t = s_idx[facing], t_idx[facing], tri_s[facing], tri_t[facing]
    if not s_idx.size:
        return _no_segments()
    alive, x, prov, count = _clip_all(_local_coordinates_all(tri_s, tri_t))
    s_idx, t_idx = s_idx[alive], t_idx[alive]
    x, prov, count = _without_repeats_all(x, prov, count)
    # fan from vertex 0: triangles (0, k, k + 1), k = 1 .. count - 2
    width = x.shape[1]
    if width < 3:
        return _no_segments()
    k = np.arange(1, width - 1)
    x0 = x[:, :1]
    e1, e2 = x[:, 1:-1] - x0, x[:, 2:] - x0
    area = 0.5 * np.abs(e1[..., 0] * e2[..., 1] - e1[..., 1] * e2[..., 0])
    keep = (k[None, :] + 1 < count[:, None]) & ~(area <= AREA_TOL)
    pair, column = np.nonzero(keep)
    corners = np.stack([np.zeros_like(column), column + 1, column + 2], axis=1)
    provenance = prov[pair[:, None], corners]
    return Segments(
        striker=s_idx[pair],
        target=t_idx[pair],
        xi=x[pair[:, None], corners],
        kind=provenance[..., 0],
        index=provenance[..., 1:],
    )


def _local_coordinates_all(striker: np.ndarray, points: np.ndarray) -> np.ndarray:
    """:func:`local_coordinates` of points (p, k, 3) in striker triangles (p, 3, 3): (p, k, 2)."""
    e1 = striker[:, 1] - striker[:, 0]
    e2 = striker[:, 2] - striker[:, 0]
    n = _cross(e1, e2)
    nn = np.sum(n * n, axis=-1, keepdims=True)
    m1 = _cross(e2, n) / nn
    m2 = _cross(n, e1) / nn
    d = points - striker[:, None, 0]
    # one matrix-vector product per triangle, as in local_coordinates (the same round-off)
    return np.stack([(d @ m1[:, :, None])[..., 0], (d @ m2[:, :, None])[..., 0]], axis=-1)


def _edge_value(x: np.ndarray, edge: int) -> np.ndarray:
    """The value a xi_1 + b xi_2 - c of the striker's edge ``edge`` at points (..., 2)."""
    a, b, c = STRIKER_EDGES[edge]
    return a * x[..., 0] + b * x[..., 1] - c


def _clip_all(tri: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`clip` (before removing repeats) of projected target triangles (p, 3, 2).

    Returns the pairs whose polygon is not empty (k,), their polygons'
    vertices (k, w, 2), their provenance (k, w, 3) and the vertex counts (k,);
    slots past a polygon's count hold zeros.
    """
    n_pairs = tri.shape[0]
    rows = np.arange(n_pairs)[:, None]
    e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    positive = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0] > 0
    # counter-clockwise vertex order; each polygon edge (from a vertex to the next) lies
    # on a line: the target edge line_index (line_kind _ON_TARGET) or a striker edge
    order = np.where(positive[:, None], np.array([0, 1, 2]), np.array([0, 2, 1]))
    x = tri[rows, order]
    prov = np.stack([np.full((n_pairs, 3), TARGET_VERTEX), order,
                     np.full((n_pairs, 3), -1)], axis=-1)
    line_kind = np.full((n_pairs, 3), _ON_TARGET)
    line_index = np.where(positive[:, None], np.array([0, 1, 2]), np.array([2, 1, 0]))
    count = np.full(n_pairs, 3)
    alive = np.arange(n_pairs)
    for edge in range(3):
        n_pairs, width = x.shape[:2]
        if not n_pairs:
            break
        rows = np.arange(n_pairs)[:, None]
        slot = np.arange(width)[None, :]
        valid = slot < count[:, None]
        following = np.where(slot + 1 < count[:, None], slot + 1, 0)
        f = _edge_value(x, edge)
        signed = -f if edge == 1 else f
        inside, strict = signed >= -CLIP_TOL, signed >= 0.0
        inside_p = valid & inside
        inside_q, strict_q = inside[rows, following], strict[rows, following]
        leaving = inside_p & ~inside_q
        # a vertex inside only by the tolerance is its own exit or entry point (_crossing)
        crosses = (leaving & strict) | (valid & ~inside_p & inside_q & strict_q)
        own_exit = leaving & ~strict
        # each vertex p gives p when inside, then the crossing of its edge p-q with the
        # striker edge when exactly one of p, q is inside
        n_out = inside_p.astype(np.int64) + crosses
        end = np.cumsum(n_out, axis=1)
        start = end - n_out
        count = end[:, -1]
        new_width = int(count.max())
        new_x = np.zeros((n_pairs, new_width, 2))
        new_prov = np.zeros((n_pairs, new_width, 3), np.int64)
        new_kind = np.zeros((n_pairs, new_width), np.int64)
        new_index = np.zeros((n_pairs, new_width), np.int64)
        pair, at = np.nonzero(inside_p)
        to = start[pair, at]
        new_x[pair, to] = x[pair, at]
        new_prov[pair, to] = prov[pair, at]
        exit_here = own_exit[pair, at]
        new_kind[pair, to] = np.where(exit_here, _ON_STRIKER, line_kind[pair, at])
        new_index[pair, to] = np.where(exit_here, edge, line_index[pair, at])
        pair, at = np.nonzero(crosses)
        nxt = following[pair, at]
        p, q = x[pair, at], x[pair, nxt]
        fp, fq = f[pair, at], f[pair, nxt]
        t = fp / (fp - fq)
        on_target = line_kind[pair, at] == _ON_TARGET
        k = line_index[pair, at]
        after_p = inside_p[pair, at]
        to = start[pair, at] + after_p
        new_x[pair, to] = p + t[:, None] * (q - p)
        new_prov[pair, to] = np.stack([
            np.where(on_target, EDGE_CROSSING, STRIKER_VERTEX),
            np.where(on_target, edge, _SHARED[k, edge]),
            np.where(on_target, k, -1)], axis=-1)
        # leaving the striker, the polygon goes on along the striker's edge
        new_kind[pair, to] = np.where(after_p, _ON_STRIKER, line_kind[pair, at])
        new_index[pair, to] = np.where(after_p, edge, k)
        # drop the polygons clipped away
        kept = count > 0
        alive, count = alive[kept], count[kept]
        x, prov = new_x[kept], new_prov[kept]
        line_kind, line_index = new_kind[kept], new_index[kept]
    return alive, x, prov, count


def _without_repeats_all(x: np.ndarray, prov: np.ndarray,
                         count: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_without_repeats` of polygons (p, w, 2) with provenance (p, w, 3) and counts (p,)."""
    n_pairs, width = x.shape[:2]
    rows = np.arange(n_pairs)
    kept = np.zeros((n_pairs, width), bool)
    last = np.zeros(n_pairs, np.int64)  # the last kept vertex (when there is one)
    for slot in range(width):
        step = x[:, slot] - x[rows, last]
        close = np.sqrt(step[:, 0] * step[:, 0] + step[:, 1] * step[:, 1]) < 1e-13
        keep = (slot < count) & ~(close & kept.any(axis=1))
        kept[:, slot] = keep
        last = np.where(keep, slot, last)
    # then drop trailing vertices that repeat the first one
    n_kept = kept.sum(axis=1)
    position = np.cumsum(kept, axis=1) - 1
    pair, slot = np.nonzero(kept)
    new_x = np.zeros((n_pairs, width, 2))
    new_prov = np.zeros((n_pairs, width, 3), np.int64)
    new_x[pair, position[pair, slot]] = x[pair, slot]
    new_prov[pair, position[pair, slot]] = prov[pair, slot]
    for _ in range(width):
        tail = new_x[rows, np.maximum(n_kept - 1, 0)] - new_x[:, 0]
        close = np.sqrt(tail[:, 0] * tail[:, 0] + tail[:, 1] * tail[:, 1]) < 1e-13
        drop = (n_kept > 1) & close
        if not drop.any():
            break
        n_kept = n_kept - drop
    return new_x, new_prov, n_kept


def _largest_size(tris: np.ndarray) -> float:
    edges = np.linalg.norm(tris - np.roll(tris, 1, axis=1), axis=-1)
    return float(edges.max()) if edges.size else 0.0


#: Degree-2 rule on the reference triangle (barycentric points, weights summing to 1).
_RULE = (np.array([[2 / 3, 1 / 6, 1 / 6], [1 / 6, 2 / 3, 1 / 6], [1 / 6, 1 / 6, 2 / 3]]),
         np.full(3, 1 / 3))


def weighted_gaps(striker: np.ndarray, target: np.ndarray, connectivity: np.ndarray,
                  segments: Segments, n_nodes: int) -> tuple[np.ndarray, np.ndarray]:
    """Reference weighted gaps and covered weights of the striker nodes (numpy).

    g~_j = int N_j g dA and A~_j = int N_j dA over the segments, dA the
    striker triangle's area element in the configuration given, g the
    distance along n_s to the target plane (>= 0 open). A degree-2 rule is
    exact: on a segment N_j is linear and so is g.

    Args:
        striker: (n, 3, 3) striker triangle vertex positions.
        target: (m, 3, 3) target triangle vertex positions.
        connectivity: (n, 3) striker node of each striker triangle corner.
        segments: from :func:`segment_surfaces` on the same positions.
        n_nodes: number of striker nodes.
    """
    gap_sum = np.zeros(n_nodes)
    weight_sum = np.zeros(n_nodes)
    points, weights = _RULE
    xi_areas = segments.xi_areas()
    for k in range(len(segments)):
        s, t = segments.striker[k], segments.target[k]
        tri_s, tri_t = striker[s], target[t]
        n_s, n_t = unit_normal(tri_s), unit_normal(tri_t)
        area = 0.5 * np.linalg.norm(np.cross(tri_s[1] - tri_s[0], tri_s[2] - tri_s[0]))
        xi_corners = segments.xi[k]
        scale = 2.0 * area * xi_areas[k]
        for bary, w in zip(points, weights, strict=True):
            xi = bary @ xi_corners
            shape = np.array([1.0 - xi[0] - xi[1], xi[0], xi[1]])
            x_s = shape @ tri_s
            gap = np.dot(tri_t[0] - x_s, n_t) / np.dot(n_s, n_t)
            gap_sum[connectivity[s]] += scale * w * shape * gap
            weight_sum[connectivity[s]] += scale * w * shape
    return gap_sum, weight_sum


__all__ = [
    "EDGE_CROSSING",
    "STRIKER_VERTEX",
    "TARGET_VERTEX",
    "Segments",
    "candidate_pairs",
    "clip",
    "corner_from_provenance",
    "local_coordinates",
    "segment_pair",
    "segment_pairs",
    "segment_pairs_loop",
    "segment_surfaces",
    "unit_normal",
    "weighted_gaps",
]
