"""Mortar segmentation in 3D: striker triangles cut by the projected target triangles.

The 3D mortar weighted gap of a striker node j is the integral over its
striker triangles of N_j g, the gap measured along the striker triangle's
normal n_s (as in 2D, :mod:`.mortar`). The integrand is smooth only on the
*segments*: the pieces of a striker triangle S that one target triangle T
covers. This module finds them, in the current configuration:

1. T's vertices are projected along n_s onto S's plane and written in S's
   local coordinates xi = (xi_1, xi_2) (x = s_0 + xi_1 (s_1 - s_0) + xi_2
   (s_2 - s_0)); S itself is the reference triangle (0, 0), (1, 0), (0, 1);
2. a projected vertex less than CLIP_TOL from the line of one of S's edges
   is moved onto that line (orthogonally in xi), one near two of the lines
   onto the corner they share (:func:`snap_codes`, :func:`snapped`); a
   target edge whose two ends were moved onto one line *is* that striker
   edge for the clipping;
3. the projected T is clipped against S (Sutherland-Hodgman: both convex),
   giving a convex polygon of at most six vertices;
4. the polygon is cut into triangles fanned from its first vertex.

Step 2 is for surfaces whose edges lie on one line: the rims of two faces
that end together, and interior edges that coincide (two meshes that are
mirror images, or structured alike). There the crossing of a striker edge
with a target edge along it is ill-conditioned (its derivative is as large
as 1 / distance) and, with the two edges apart by round-off, which of the
two target triangles along the edge covers the sliver between them flips
from one search to the next. Moved onto the line, the vertex is on it for
every target triangle it belongs to (the move depends on the vertex and S
only): the moved target triangles still tile the plane, the triangle on the
far side of the edge covers nothing and the near one covers up to the edge
exactly, and the moved position is a linear function of the projected one,
so the segment corners stay smooth functions of the vertex positions while
the vertex stays within the tolerance.

Every polygon vertex carries its *provenance*, which says how it moves
with the bodies, so that a UFL expression can rebuild it from the vertex
positions and ``ufl.derivative`` can linearise the segmentation:

* ``STRIKER_VERTEX`` k: the corner k of S (xi fixed);
* ``TARGET_VERTEX`` k: T's vertex k projected along n_s (and moved by step 2);
* ``EDGE_CROSSING`` (i, k): S's edge i (from corner i to corner i + 1
  mod 3, see :data:`STRIKER_EDGES`) crossing T's projected edge k (from T's
  vertex k to vertex k + 1 mod 3, its ends moved by step 2).

The moves of step 2 are the pair's *snap codes*, one per target vertex
(:data:`NOT_SNAPPED`, onto edge line i, or onto corner c as ``CORNER_SNAP + c``),
kept with every segment and frozen with the provenance between searches.

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
#: A projected target vertex less than this (in xi) from the line of a striker edge is
#: moved onto the line (:func:`snapped`): the crossing of two nearly collinear edges is
#: ill-conditioned, and its derivative, large as 1 / distance, would swamp the tangent.
#: Nothing else is kept outside a striker edge (an earlier rule counted a target vertex up
#: to this far outside as inside: crossings near a striker corner were kept outside too,
#: and their corner slid along the striker edge as the target moved).
CLIP_TOL = 1e-6
#: Snap code of a target vertex left where it is; 0, 1, 2: moved onto that striker edge's
#: line; CORNER_SNAP + c: moved onto the striker's corner c.
NOT_SNAPPED, CORNER_SNAP = -1, 3
#: The striker edges a snap code puts a vertex on, as a bit mask (bit i: edge i), indexed
#: by code + 1: none, edge 0, 1, 2, corner 0 (edges 0 and 2), 1 (0, 1), 2 (1, 2).
_ON_LINES = np.array([0, 1, 2, 4, 5, 3, 6])
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
        snap: (k, 3) snap code of each of the target triangle's vertices
            (:func:`snap_codes`), which the target vertices and edges in the
            provenance refer to.
    """

    striker: np.ndarray
    target: np.ndarray
    xi: np.ndarray
    kind: np.ndarray
    index: np.ndarray
    snap: np.ndarray

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


#: Snap code of a vertex near the striker edges of a bit mask (bit i: edge i), indexed by
#: the mask: none, edge 0, edge 1, corner 1, edge 2, corner 0, corner 2 (all three: none).
_CODE_OF_MASK = np.array([NOT_SNAPPED, 0, 1, CORNER_SNAP + 1, 2, CORNER_SNAP,
                          CORNER_SNAP + 2, NOT_SNAPPED])
#: The lowest set bit of a mask of striker edges (the edge two snapped vertices share).
_LOWEST_BIT = np.array([-1, 0, 1, 0, 2, 0, 1, 0])


def snap_codes(target_xi: np.ndarray) -> np.ndarray:
    """Snap codes (..., 3) of projected target vertices (..., 3, 2): see :data:`CLIP_TOL`.

    A vertex less than CLIP_TOL (the value a xi_1 + b xi_2 - c of
    :data:`STRIKER_EDGES`) from one striker edge's line gets that edge's
    number, from two lines ``CORNER_SNAP`` + the corner they share, else
    ``NOT_SNAPPED``. The lines are whole lines: a vertex beyond the end of a
    striker edge but on its line is moved too (the target edge through it
    lies along the striker edge).
    """
    x = np.asarray(target_xi, float)
    mask = sum((np.abs(_edge_value(x, edge)) <= CLIP_TOL).astype(np.int64) << edge
               for edge in range(3))
    return _CODE_OF_MASK[mask]


def snapped(target_xi: np.ndarray, codes: np.ndarray) -> np.ndarray:
    """Projected target vertices (..., 3, 2) moved as their snap codes (..., 3) say.

    Onto the line of edge 0 (xi_2 = 0) or 2 (xi_1 = 0) by dropping that
    coordinate, onto that of edge 1 (xi_1 + xi_2 = 1) along (1, 1), onto a
    corner: the corner. The same algebra as the UFL forms.
    """
    x = np.asarray(target_xi, float)
    codes = np.asarray(codes)
    half = 0.5 * (x[..., 0] + x[..., 1] - 1.0)
    xi1 = np.where(codes == 2, 0.0, np.where(codes == 1, x[..., 0] - half, x[..., 0]))
    xi2 = np.where(codes == 0, 0.0, np.where(codes == 1, x[..., 1] - half, x[..., 1]))
    out = np.stack([xi1, xi2], axis=-1)
    corner = codes >= CORNER_SNAP
    return np.where(corner[..., None], REFERENCE[np.where(corner, codes - CORNER_SNAP, 0)],
                    out)


def _crossing(p: np.ndarray, q: np.ndarray, edge: int) -> np.ndarray:
    """The point of segment p-q on the line of the striker's edge ``edge``.

    The clipping asks for it only between a vertex strictly inside and one
    outside, so it lies on the segment (a vertex on the edge's line is its
    own exit or entry point).
    """
    a, b, c = STRIKER_EDGES[edge]
    fp, fq = a * p[0] + b * p[1] - c, a * q[0] + b * q[1] - c
    t = fp / (fp - fq)
    return p + t * (q - p)


def clip(target_xi: np.ndarray) -> list[tuple[np.ndarray, tuple[int, int, int]]]:
    """The projected target triangle (3, 2) clipped against the reference triangle.

    Returns the polygon's vertices, counter-clockwise, each with its
    provenance (kind, i, j). The target triangle may come in either
    orientation. Its vertices are first moved as their snap codes say
    (:func:`snap_codes`, :func:`snapped`); a target edge whose two ends are
    on one striker edge's line is that edge, and a vertex on a striker
    edge's line is on it exactly (its own entry or exit point, never
    crossed).
    """
    tri = np.asarray(target_xi, float)
    codes = snap_codes(tri)
    moved = snapped(tri, codes)
    on_lines = _ON_LINES[codes + 1]
    e1, e2 = tri[1] - tri[0], tri[2] - tri[0]
    order = [0, 1, 2] if e1[0] * e2[1] - e1[1] * e2[0] > 0 else [0, 2, 1]
    # each vertex: (xi, provenance, the striker edges it lies on as a bit mask); each edge
    # (from vertex v to the next) carries a line: ("t", k) target edge from vertex k to
    # k + 1 mod 3 (in T's own numbering), ("s", i) the line of striker edge i.
    poly = [(moved[k], (TARGET_VERTEX, k, -1), int(on_lines[k])) for k in order]
    lines = []
    for a, b in zip(order, [*order[1:], order[0]], strict=True):
        shared = int(on_lines[a] & on_lines[b])
        if shared:
            lines.append(("s", int(_LOWEST_BIT[shared])))
        else:
            lines.append(("t", a) if (a + 1) % 3 == b else ("t", b))
    for edge in range(3):
        if not poly:
            break
        out: list[tuple[np.ndarray, tuple[int, int, int], int]] = []
        out_lines: list[tuple[str, int]] = []
        count = len(poly)
        a, b, c = STRIKER_EDGES[edge]
        sign = -1.0 if edge == 1 else 1.0
        for v in range(count):
            (p, _, on_p), (q, _, on_q) = poly[v], poly[(v + 1) % count]
            line = lines[v]
            fp = 0.0 if on_p >> edge & 1 else sign * (a * p[0] + b * p[1] - c)
            fq = 0.0 if on_q >> edge & 1 else sign * (a * q[0] + b * q[1] - c)
            strict_p = fp >= 0.0 and not on_p >> edge & 1
            strict_q = fq >= 0.0 and not on_q >> edge & 1
            if fp >= 0.0:
                out.append(poly[v])
                if fq >= 0.0:
                    out_lines.append(line)
                    continue
                if strict_p:
                    out_lines.append(line)
                    out.append(_crossing_vertex(p, q, line, edge))
                # a vertex on the edge is its own exit point
                out_lines.append(("s", edge))
            elif strict_q:
                out.append(_crossing_vertex(p, q, line, edge))
                out_lines.append(line)
            # entering at a vertex on the edge: that vertex
        poly, lines = out, out_lines
    return _merged([(x, prov) for x, prov, _ in poly], lines)


def _crossing_vertex(p: np.ndarray, q: np.ndarray, line: tuple[str, int],
                     edge: int) -> tuple[np.ndarray, tuple[int, int, int], int]:
    """The polygon vertex where its edge p-q on ``line`` crosses the striker's edge ``edge``."""
    prov = _crossing_provenance(line, edge)
    if prov[0] == STRIKER_VERTEX:
        return REFERENCE[prov[1]].copy(), prov, (1 << edge) | (1 << line[1])
    return _crossing(p, q, edge), prov, 1 << edge


def _crossing_provenance(line: tuple[str, int], edge: int) -> tuple[int, int, int]:
    """Provenance of the point where an edge on ``line`` crosses the striker's edge ``edge``."""
    kind, k = line
    if kind == "t":
        return (EDGE_CROSSING, edge, k)
    # two striker edges meet at the corner they share
    shared = {frozenset((0, 1)): 1, frozenset((1, 2)): 2, frozenset((0, 2)): 0}
    return (STRIKER_VERTEX, shared[frozenset((k, edge))], -1)


#: Consecutive polygon vertices closer than this (in xi) are one corner.
REPEAT_TOL = 1e-13


def _meeting(first: tuple[str, int], second: tuple[str, int]) -> tuple[int, int, int] | None:
    """Provenance of the point where two lines of a polygon's edges meet (None: one line)."""
    if first == second:
        return None
    if first[0] == "s" and second[0] == "s":
        return (STRIKER_VERTEX, int(_SHARED[first[1], second[1]]), -1)
    if first[0] != second[0]:
        edge, k = (first[1], second[1]) if first[0] == "s" else (second[1], first[1])
        return (EDGE_CROSSING, edge, k)
    # two target edges meet at the target vertex they share
    (vertex,) = {first[1], (first[1] + 1) % 3} & {second[1], (second[1] + 1) % 3}
    return (TARGET_VERTEX, vertex, -1)


def _merged(poly: list, lines: list) -> list:
    """The clipped polygon with its zero-length edges and flat vertices removed.

    ``poly``: the vertices (xi, provenance); ``lines``: the line of each edge
    (from a vertex to the next, see :func:`clip`). Two consecutive vertices
    closer than REPEAT_TOL (a target edge through a striker corner, a vertex
    on an edge) become one, where the lines of the edges before and after
    them meet, so that the corner moves as those lines do (keeping either of
    the two would move the corner along the vanished edge's line, a wrong
    derivative although the right value); when both are one line the two
    vertices go. A vertex whose two edges lie on one line goes too.
    """
    poly, lines = list(poly), list(lines)
    changed = True
    while changed and len(poly) >= 3:
        changed = False
        n = len(poly)
        for m in range(n):
            after = (m + 1) % n
            if lines[m - 1] == lines[m]:  # a flat vertex
                del poly[m], lines[m]
                changed = True
                break
            step = poly[after][0] - poly[m][0]
            if np.sqrt(step[0] * step[0] + step[1] * step[1]) >= REPEAT_TOL:
                continue
            meeting = _meeting(lines[m - 1], lines[after])
            if meeting is None:  # both vertices lie on the line before and after them
                for index in sorted((m, after), reverse=True):
                    del poly[index], lines[index]
            else:
                x = REFERENCE[meeting[1]].copy() if meeting[0] == STRIKER_VERTEX else poly[m][0]
                poly[m] = (x, meeting)
                lines[m] = lines[after]
                del poly[after], lines[after]
            changed = True
            break
    if not poly:
        return poly
    # the fan starts at the corner of least provenance: the same segments for the same polygon
    first = min(range(len(poly)), key=lambda v: poly[v][1])
    return poly[first:] + poly[:first]


def corner_from_provenance(kind: int, index: tuple[int, int], striker: np.ndarray,
                           target: np.ndarray, snap: np.ndarray | None = None) -> np.ndarray:
    """The xi of a segment corner rebuilt from the current vertex positions (3, 3) each.

    The formulas a UFL expression of the segment corners would hold: a fixed
    corner, a projected target vertex, or the crossing of a striker edge with
    a projected target edge, the target vertices moved as the snap codes
    ``snap`` (3,) say (by default those of the positions given).
    """
    if kind == STRIKER_VERTEX:
        return REFERENCE[index[0]].copy()
    projected = local_coordinates(striker, target)
    projected = snapped(projected, snap_codes(projected) if snap is None else snap)
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
    rows: list[tuple[int, int, np.ndarray, tuple, np.ndarray]] = []
    for s, t in zip(s_idx, t_idx, strict=True):
        codes = snap_codes(local_coordinates(striker[s], target[t]))
        for xi, prov in segment_pair(striker[s], target[t]):
            rows.append((int(s), int(t), xi, prov, codes))
    if not rows:
        return _no_segments()
    return Segments(
        striker=np.array([r[0] for r in rows], np.int64),
        target=np.array([r[1] for r in rows], np.int64),
        xi=np.array([r[2] for r in rows]),
        kind=np.array([[p[0] for p in r[3]] for r in rows], np.int64),
        index=np.array([[[p[1], p[2]] for p in r[3]] for r in rows], np.int64),
        snap=np.array([r[4] for r in rows], np.int64),
    )


def _no_segments() -> Segments:
    empty = np.zeros(0, np.int64)
    return Segments(empty, empty, np.zeros((0, 3, 2)), np.zeros((0, 3), np.int64),
                    np.zeros((0, 3, 2), np.int64), np.zeros((0, 3), np.int64))


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
    projected = _local_coordinates_all(tri_s, tri_t)
    codes = snap_codes(projected)
    alive, x, prov, count, line_kind, line_index = _clip_all(projected, codes)
    s_idx, t_idx, codes = s_idx[alive], t_idx[alive], codes[alive]
    x, prov, count = _merged_all(x, prov, count, line_kind, line_index)
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
        snap=codes[pair],
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


def _clip_all(tri: np.ndarray, codes: np.ndarray) -> tuple[np.ndarray, ...]:
    """:func:`clip` (before :func:`_merged`) of projected target triangles (p, 3, 2).

    ``codes`` (p, 3): their vertices' snap codes (:func:`snap_codes`). Returns
    the pairs whose polygon is not empty (k,), their polygons' vertices (k, w, 2),
    their provenance (k, w, 3), the vertex counts (k,) and the line of each
    edge (from a vertex to the next): its kind (_ON_TARGET, _ON_STRIKER) and
    index (k, w) each; slots past a polygon's count hold zeros.
    """
    n_pairs = tri.shape[0]
    rows = np.arange(n_pairs)[:, None]
    e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    positive = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0] > 0
    # counter-clockwise vertex order; each polygon edge (from a vertex to the next) lies
    # on a line: the target edge line_index (line_kind _ON_TARGET) or a striker edge;
    # each vertex on the striker edges of the bit mask ``on``
    order = np.where(positive[:, None], np.array([0, 1, 2]), np.array([0, 2, 1]))
    x = snapped(tri, codes)[rows, order]
    on = _ON_LINES[codes + 1][rows, order]
    prov = np.stack([np.full((n_pairs, 3), TARGET_VERTEX), order,
                     np.full((n_pairs, 3), -1)], axis=-1)
    # a target edge whose two ends are on one striker edge's line is that edge
    shared = on & np.roll(on, -1, axis=1)
    line_kind = np.where(shared > 0, _ON_STRIKER, _ON_TARGET)
    line_index = np.where(shared > 0, _LOWEST_BIT[shared],
                          np.where(positive[:, None], np.array([0, 1, 2]), np.array([2, 1, 0])))
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
        on_line = (on >> edge & 1).astype(bool)
        f = np.where(on_line, 0.0, _edge_value(x, edge))
        signed = -f if edge == 1 else f
        inside, strict = signed >= 0.0, (signed >= 0.0) & ~on_line
        inside_p = valid & inside
        inside_q, strict_q = inside[rows, following], strict[rows, following]
        leaving = inside_p & ~inside_q
        # a vertex on the edge is its own exit or entry point (_crossing)
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
        new_on = np.zeros((n_pairs, new_width), np.int64)
        pair, at = np.nonzero(inside_p)
        to = start[pair, at]
        new_x[pair, to] = x[pair, at]
        new_prov[pair, to] = prov[pair, at]
        new_on[pair, to] = on[pair, at]
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
        corner = _SHARED[k, edge]
        # two striker edges cross at the corner they share, exactly
        new_x[pair, to] = np.where(on_target[:, None], p + t[:, None] * (q - p),
                                   REFERENCE[np.where(on_target, 0, corner)])
        new_prov[pair, to] = np.stack([
            np.where(on_target, EDGE_CROSSING, STRIKER_VERTEX),
            np.where(on_target, edge, corner),
            np.where(on_target, k, -1)], axis=-1)
        new_on[pair, to] = np.where(on_target, 1 << edge, (1 << edge) | (1 << k))
        # leaving the striker, the polygon goes on along the striker's edge
        new_kind[pair, to] = np.where(after_p, _ON_STRIKER, line_kind[pair, at])
        new_index[pair, to] = np.where(after_p, edge, k)
        # drop the polygons clipped away
        kept = count > 0
        alive, count = alive[kept], count[kept]
        x, prov, on = new_x[kept], new_prov[kept], new_on[kept]
        line_kind, line_index = new_kind[kept], new_index[kept]
    return alive, x, prov, count, line_kind, line_index


def _merged_all(x: np.ndarray, prov: np.ndarray, count: np.ndarray, line_kind: np.ndarray,
                line_index: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_merged` of polygons (p, w, 2), provenance (p, w, 3), counts (p,), edge lines.

    Only the polygons with a short edge or two consecutive edges on one line
    (degenerate contact: a few) go through :func:`_merged`, one at a time.
    """
    n_pairs, width = x.shape[:2]
    if not n_pairs:
        return x, prov, count
    slot = np.arange(width)[None, :]
    valid = slot < count[:, None]
    following = np.where(slot + 1 < count[:, None], slot + 1, 0)
    rows = np.arange(n_pairs)[:, None]
    step = x[rows, following] - x
    short = np.sqrt(step[..., 0] * step[..., 0] + step[..., 1] * step[..., 1]) < REPEAT_TOL
    same = ((line_kind[rows, following] == line_kind)
            & (line_index[rows, following] == line_index))
    flagged = np.flatnonzero(np.any(valid & (short | same), axis=1) & (count >= 3))
    x, prov, count = x.copy(), prov.copy(), count.copy()
    for pair in flagged:
        n = int(count[pair])
        poly = [(x[pair, v].copy(), tuple(int(i) for i in prov[pair, v])) for v in range(n)]
        lines = [("s" if line_kind[pair, v] == _ON_STRIKER else "t", int(line_index[pair, v]))
                 for v in range(n)]
        kept = _merged(poly, lines)
        count[pair] = len(kept)
        for v, (xv, pv) in enumerate(kept):
            x[pair, v], prov[pair, v] = xv, pv
    # the fan starts at the corner of least provenance (as _merged)
    key = (prov[..., 0] * 16 + prov[..., 1]) * 16 + prov[..., 2] + 1
    slot = np.arange(width)[None, :]
    first = np.argmin(np.where(slot < count[:, None], key, np.iinfo(np.int64).max), axis=1)
    order = np.where(slot < count[:, None],
                     (slot + first[:, None]) % np.maximum(count, 1)[:, None], slot)
    return x[rows, order], prov[rows, order], count


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
    "snap_codes",
    "snapped",
    "unit_normal",
    "weighted_gaps",
]
