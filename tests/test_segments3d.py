"""3D mortar segmentation: clipping, provenance of the corners, exact tiling, weighted gaps."""

from __future__ import annotations

import numpy as np
import pytest

from fenics_contact.model.segments3d import (
    CLIP_TOL,
    CORNER_SNAP,
    EDGE_CROSSING,
    STRIKER_VERTEX,
    TARGET_VERTEX,
    Segments,
    _merged,
    candidate_pairs,
    clip,
    corner_from_provenance,
    segment_pair,
    segment_pairs,
    segment_pairs_loop,
    segment_surfaces,
    weighted_gaps,
)

RNG = np.random.default_rng(20261126)


def _polygon_area(xy: np.ndarray) -> float:
    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def _grid_overlap(tri: np.ndarray, n: int = 1200) -> float:
    """Area of (projected triangle) n (reference triangle) by counting grid points."""
    h = 1.0 / n
    g = (np.arange(n) + 0.5) * h
    X, Y = np.meshgrid(g, g)
    inside_ref = X + Y <= 1.0
    a, b, c = tri
    def side(p, q):
        return (q[0] - p[0]) * (Y - p[1]) - (q[1] - p[1]) * (X - p[0])
    s1, s2, s3 = side(a, b), side(b, c), side(c, a)
    inside_t = ((s1 >= 0) & (s2 >= 0) & (s3 >= 0)) | ((s1 <= 0) & (s2 <= 0) & (s3 <= 0))
    return float(np.sum(inside_ref & inside_t)) * h * h


def test_clipped_polygon_is_the_overlap_of_the_two_triangles() -> None:
    for _ in range(40):
        tri = RNG.uniform(-0.4, 1.2, size=(3, 2))
        polygon = clip(tri)
        area = _polygon_area(np.array([x for x, _ in polygon])) if len(polygon) >= 3 else 0.0
        assert area >= -1e-15  # counter-clockwise
        assert area == pytest.approx(_grid_overlap(tri), abs=3e-3)


def test_known_overlaps_are_exact() -> None:
    covering = np.array([[-1.0, -1.0], [3.0, -1.0], [-1.0, 3.0]])
    assert _polygon_area(np.array([x for x, _ in clip(covering)])) == pytest.approx(0.5, 1e-14)
    assert {p for _, p in clip(covering)} == {(STRIKER_VERTEX, k, -1) for k in range(3)}
    inside = np.array([[0.1, 0.1], [0.3, 0.1], [0.1, 0.3]])
    assert {p for _, p in clip(inside[::-1])} == {(TARGET_VERTEX, k, -1) for k in range(3)}
    shifted = np.array([[0.5, -1.0], [2.0, -1.0], [0.5, 3.0]])  # covers xi_1 >= 0.5
    polygon = clip(shifted)
    assert _polygon_area(np.array([x for x, _ in polygon])) == pytest.approx(0.125, 1e-14)
    assert sorted(p[0] for _, p in polygon) == [STRIKER_VERTEX, EDGE_CROSSING, EDGE_CROSSING]


def _random_pair() -> tuple[np.ndarray, np.ndarray]:
    """A striker triangle near z = 0 (normal up) and an overlapping target facing it."""
    striker = np.array([[0.0, 0.0, 0.0], [1.0, 0.1, 0.05], [0.2, 0.9, -0.04]])
    centre = RNG.uniform(0.1, 0.6, size=2)
    angles = np.sort(RNG.uniform(0, 2 * np.pi, 3))[::-1]  # clockwise seen from above
    radius = RNG.uniform(0.3, 0.8)
    target = np.column_stack([centre[0] + radius * np.cos(angles),
                              centre[1] + radius * np.sin(angles),
                              0.02 + 0.05 * RNG.standard_normal(3)])
    return striker, target


def test_corners_are_rebuilt_from_their_provenance_and_follow_the_bodies() -> None:
    """The formulas a UFL form would hold give the clipped corners, before and after a
    small motion of all six vertices (the same combinatorics)."""
    checked = 0
    for _ in range(30):
        striker, target = _random_pair()
        pieces = segment_pair(striker, target)
        for xi, provenance in pieces:
            for corner, (kind, i, j) in zip(xi, provenance, strict=True):
                rebuilt = corner_from_provenance(kind, (i, j), striker, target)
                np.testing.assert_allclose(rebuilt, corner, atol=1e-12)
                checked += 1
        moved_s = striker + 1e-7 * RNG.standard_normal((3, 3))
        moved_t = target + 1e-7 * RNG.standard_normal((3, 3))
        moved = segment_pair(moved_s, moved_t)
        if len(moved) != len(pieces):
            continue
        for (_, provenance), (xi_m, provenance_m) in zip(pieces, moved, strict=True):
            if provenance != provenance_m:
                continue
            for corner_m, (kind, i, j) in zip(xi_m, provenance, strict=True):
                rebuilt = corner_from_provenance(kind, (i, j), moved_s, moved_t)
                np.testing.assert_allclose(rebuilt, corner_m, atol=1e-12)
    assert checked > 100


def _grid_surface(nx: int, ny: int, z: float, flip: bool, jitter: float = 0.0,
                  tilt: tuple[float, float] = (0.0, 0.0)):
    """Triangulated unit square at height z (+ tilt), normal up (or down when flipped)."""
    x = np.linspace(0.0, 1.0, nx + 1)
    y = np.linspace(0.0, 1.0, ny + 1)
    X, Y = np.meshgrid(x, y, indexing="ij")
    if jitter:
        inner = (X > 0) & (X < 1) & (Y > 0) & (Y < 1)
        X = X + inner * jitter / nx * RNG.uniform(-1, 1, X.shape)
        Y = Y + inner * jitter / ny * RNG.uniform(-1, 1, Y.shape)
    Z = z + tilt[0] * X + tilt[1] * Y
    points = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    node = np.arange(points.shape[0]).reshape(nx + 1, ny + 1)
    cells = []
    for i in range(nx):
        for j in range(ny):
            a, b, c, d = node[i, j], node[i + 1, j], node[i + 1, j + 1], node[i, j + 1]
            cells += [(a, b, c), (a, c, d)]
    cells = np.array(cells)
    if flip:
        cells = cells[:, ::-1]
    tri = points[cells]
    normal_z = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])[:, 2]
    assert np.all(normal_z < 0 if flip else normal_z > 0)  # no triangle turned over
    return points, cells


def test_segments_tile_the_striker_surface_on_non_matching_meshes() -> None:
    """Every piece of a striker covered by the target belongs to exactly one segment."""
    ps, cs = _grid_surface(5, 4, 0.0, flip=False, jitter=0.15)
    pt, ct = _grid_surface(7, 9, 0.01, flip=True, jitter=0.15)
    striker, target = ps[cs], pt[ct]
    segments = segment_surfaces(striker, target)
    areas = 0.5 * np.linalg.norm(np.cross(striker[:, 1] - striker[:, 0],
                                          striker[:, 2] - striker[:, 0]), axis=-1)
    covered = np.zeros(len(cs))
    np.add.at(covered, segments.striker, 2.0 * areas[segments.striker] * segments.xi_areas())
    np.testing.assert_allclose(covered, areas, rtol=1e-12)
    assert covered.sum() == pytest.approx(1.0, rel=1e-12)


def test_weighted_gaps_are_exact_for_planes() -> None:
    """Non-matching flat surfaces: g~_j = d A_j at a distance d; a tilted target plane gives
    the integral of the hat function times the linear gap."""
    ps, cs = _grid_surface(5, 4, 0.0, flip=False, jitter=0.15)
    striker = ps[cs]
    n = ps.shape[0]
    areas = 0.5 * np.linalg.norm(np.cross(striker[:, 1] - striker[:, 0],
                                          striker[:, 2] - striker[:, 0]), axis=-1)
    lumped = np.zeros(n)
    np.add.at(lumped, cs, np.repeat(areas[:, None] / 3.0, 3, axis=1))
    for tilt in ((0.0, 0.0), (0.05, -0.03)):
        pt, ct = _grid_surface(7, 9, 0.02, flip=True, jitter=0.15, tilt=tilt)
        # the target reaches past the striker so that every striker point is covered
        pt[:, :2] = 1.2 * (pt[:, :2] - 0.5) + 0.5
        pt[:, 2] = 0.02 + tilt[0] * pt[:, 0] + tilt[1] * pt[:, 1]
        target = pt[ct]
        segments = segment_surfaces(striker, target)
        gaps, weights = weighted_gaps(striker, target, cs, segments, n)
        np.testing.assert_allclose(weights, lumped, rtol=1e-12)
        nodal = 0.02 + tilt[0] * ps[:, 0] + tilt[1] * ps[:, 1]
        exact = np.zeros(n)
        for cell, area in zip(cs, areas, strict=True):
            g = nodal[cell]
            exact[cell] += area * (g + g.sum()) / 12.0  # int N_j g = A (2 g_j + g_k + g_l) / 12
        np.testing.assert_allclose(gaps, exact, rtol=1e-12, atol=1e-15)


def test_target_triangles_not_facing_the_striker_give_no_segment() -> None:
    striker = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    same_way = striker + np.array([0.0, 0.0, 0.01])
    assert segment_pair(striker, same_way) == []
    assert len(segment_pair(striker, same_way[::-1])) >= 1


def _pair_surfaces(seed: int):
    rng_state = RNG.bit_generator.state
    RNG.bit_generator.state = np.random.default_rng(seed).bit_generator.state
    ps, cs = _grid_surface(3, 3, 0.0, flip=False, jitter=0.15)
    pt, ct = _grid_surface(4, 5, 0.02, flip=True, jitter=0.15)
    RNG.bit_generator.state = rng_state
    pt[:, :2] = 1.2 * (pt[:, :2] - 0.5) + 0.5
    pt[:, 2] = 0.02 + 0.05 * pt[:, 0] - 0.03 * pt[:, 1]
    return ps, cs, pt, ct


def test_ufl_segment_forms_give_the_weighted_gaps_and_their_tangent() -> None:
    """The weighted gaps assembled from the UFL forms on the segment mesh equal the numpy
    reference to round-off, and their derivative with respect to the eighteen vertex
    displacements of each segment (which also moves the clipped corners) matches central
    differences (measured 3.6e-10 relative)."""
    import ufl
    from dolfinx import fem
    from dolfinx.fem import petsc as fem_petsc

    from fenics_contact.model.segment_forms3d import SegmentForms, provenance_weights

    ps, cs, pt, ct = _pair_surfaces(3)
    striker, target = ps[cs], pt[ct]
    segments = segment_surfaces(striker, target)
    reference_g, reference_w = weighted_gaps(striker, target, cs, segments, ps.shape[0])
    forms = SegmentForms(len(segments) + 17)  # spare cells stay empty
    forms.fill(np.concatenate([striker[segments.striker], target[segments.target]], axis=1),
               provenance_weights(segments))
    gap_form, weight_form = fem.form(forms.gap_form), fem.form(forms.weight_form)
    nodes = cs[segments.striker]
    for form, reference in ((gap_form, reference_g), (weight_form, reference_w)):
        gathered = np.zeros(ps.shape[0])
        np.add.at(gathered, nodes, forms.per_segment(fem.assemble_vector(form).array))
        np.testing.assert_allclose(gathered, reference, rtol=1e-12, atol=1e-15)

    tangent = fem.form(ufl.derivative(forms.gap_form, forms.w, ufl.TrialFunction(forms.W6)))
    matrix = fem_petsc.assemble_matrix(tangent)
    matrix.assemble()
    rng = np.random.default_rng(1)
    direction = 1e-3 * rng.standard_normal(forms.w.x.array.size)  # keeps the combinatorics

    def residual(step: float) -> np.ndarray:
        forms.w.x.array[:] = step * direction
        return fem.assemble_vector(gap_form).array.copy()

    h = 1e-4
    central = (residual(h) - residual(-h)) / (2 * h)
    forms.w.x.array[:] = 0.0
    x, y = matrix.createVecs()
    x.array[:] = direction
    matrix.mult(x, y)
    error = np.max(np.abs(central - y.array)) / np.max(np.abs(y.array))
    print(f"tangent against central differences: {error:.2e}")
    assert error <= 1e-7



# -- the vectorised segmentation against the pair-by-pair reference ---------------------


def _assert_same_segments(got: Segments, expected: Segments) -> None:
    assert len(got) == len(expected)
    np.testing.assert_array_equal(got.striker, expected.striker)
    np.testing.assert_array_equal(got.target, expected.target)
    np.testing.assert_array_equal(got.kind, expected.kind)
    np.testing.assert_array_equal(got.index, expected.index)
    np.testing.assert_array_equal(got.snap, expected.snap)
    np.testing.assert_allclose(got.xi, expected.xi, rtol=0.0, atol=1e-14)
    assert got.xi.shape == (len(expected), 3, 2)
    assert got.kind.shape == (len(expected), 3) and got.index.shape == (len(expected), 3, 2)


def _surfaces_against_reference(striker: np.ndarray, target: np.ndarray,
                                reach: float | None = None) -> Segments:
    """segment_surfaces, checked against segment_pair applied to each candidate pair."""
    got = segment_surfaces(striker, target, reach)
    _assert_same_segments(got, segment_pairs_loop(striker, target,
                                                  *candidate_pairs(striker, target, reach)))
    return got


def _kinds(segments: Segments) -> set[int]:
    return set(np.unique(segments.kind).tolist())


def _on_sphere(points: np.ndarray, radius: float, below: bool) -> np.ndarray:
    """The unit square's points mapped onto a spherical cap touching z = 0 at its centre."""
    x, y = points[:, 0] - 0.5, points[:, 1] - 0.5
    z = radius - np.sqrt(radius**2 - x**2 - y**2)
    return np.column_stack([x, y, -z if below else z])


def _pair_by_pair_cases() -> dict[str, tuple[np.ndarray, np.ndarray]]:
    cases = {}
    ps, cs = _grid_surface(9, 7, 0.0, flip=False, jitter=0.3)
    pt, ct = _grid_surface(11, 13, 0.01, flip=True, jitter=0.3)
    cases["jittered grids"] = (ps[cs], pt[ct])
    ps, cs = _grid_surface(8, 8, 0.0, flip=False)
    pt, ct = _grid_surface(8, 8, 0.0, flip=True)
    cases["matching grids (coincident rims)"] = (ps[cs], pt[ct])
    pt, ct = _grid_surface(16, 4, 0.0, flip=True)
    cases["nested grids (vertices on edges)"] = (ps[cs], pt[ct])
    pt, ct = _grid_surface(8, 8, 0.0, flip=True)
    pt[:, :2] += 1e-7 * RNG.uniform(-1, 1, (pt.shape[0], 2))  # inside the tolerance
    cases["matching grids moved by 1e-7"] = (ps[cs], pt[ct])
    pt, ct = _grid_surface(10, 6, 0.03, flip=True, jitter=0.2, tilt=(0.2, -0.3))
    cases["tilted target"] = (ps[cs], pt[ct])
    ps, cs = _grid_surface(8, 9, 0.0, flip=False, jitter=0.2)
    pt, ct = _grid_surface(10, 7, 0.0, flip=True, jitter=0.2)
    cases["spherical caps"] = (_on_sphere(ps, 1.0, below=False)[cs],
                               _on_sphere(pt, 1.0, below=True)[ct] + [0.0, 0.0, -0.005])
    return cases


@pytest.mark.parametrize("case", sorted(_pair_by_pair_cases()))
def test_vectorised_segmentation_equals_the_pair_by_pair_reference(case: str) -> None:
    """The same segments, in the same order, with the same provenance and corners."""
    striker, target = _pair_by_pair_cases()[case]
    segments = _surfaces_against_reference(striker, target)
    assert np.unique(segments.striker).size >= 0.6 * len(striker)
    assert TARGET_VERTEX in _kinds(segments)


def test_vectorised_segmentation_of_every_pair_of_random_triangles() -> None:
    """All pairs of random triangles (overlapping or not, facing or not, either
    orientation), against segment_pair one pair at a time."""
    striker = RNG.uniform(0.0, 1.0, (25, 3, 3)) * [1.0, 1.0, 0.1]
    target = RNG.uniform(-0.2, 1.2, (40, 3, 3)) * [1.0, 1.0, 0.1] + [0.0, 0.0, 0.05]
    s_idx, t_idx = (a.ravel() for a in np.meshgrid(np.arange(25), np.arange(40),
                                                   indexing="ij"))
    expected = segment_pairs_loop(striker, target, s_idx, t_idx)
    _assert_same_segments(segment_pairs(striker, target, s_idx, t_idx), expected)
    assert len(expected) > 200
    assert _kinds(expected) == {STRIKER_VERTEX, TARGET_VERTEX, EDGE_CROSSING}
    # any order of the pairs, repeated pairs too
    shuffled = RNG.permutation(np.concatenate([np.arange(s_idx.size), np.arange(50)]))
    _assert_same_segments(segment_pairs(striker, target, s_idx[shuffled], t_idx[shuffled]),
                          segment_pairs_loop(striker, target, s_idx[shuffled], t_idx[shuffled]))


def test_vectorised_clipping_at_the_tolerance_and_on_the_edges() -> None:
    """Target vertices exactly on the striker's edges and corners, or just inside or
    outside them within and beyond CLIP_TOL (vertices moved onto the lines, the crossings
    of nearly collinear edges, repeated vertices, slivers dropped), against the reference
    triangle's own plane."""
    striker = np.array([[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]])
    values = np.array([-0.5, 0.0, 0.25, 0.5, 1.0, 1.5])
    offsets = np.array([0.0, 1e-15, -1e-15, 0.5, -0.5, 1.0, -1.0, 1.5, -1.5, 3.0]) * CLIP_TOL
    xi = (RNG.choice(values, (4000, 3, 2))
          + RNG.choice(offsets, (4000, 3, 2)) * (RNG.uniform(size=(4000, 3, 1)) < 0.7))
    # on the hypotenuse, with or without an offset
    on_hypotenuse = RNG.uniform(size=(4000, 3)) < 0.3
    xi[..., 1] = np.where(on_hypotenuse, 1.0 - xi[..., 0] + RNG.choice(offsets, (4000, 3)),
                          xi[..., 1])
    # facing the striker: clockwise seen from above
    e1, e2 = xi[:, 1] - xi[:, 0], xi[:, 2] - xi[:, 0]
    clockwise = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0] < 0
    xi = np.where(clockwise[:, None, None], xi, xi[:, ::-1])
    target = np.concatenate([xi, np.full((4000, 3, 1), 0.01)], axis=-1)
    s_idx, t_idx = np.zeros(4000, np.int64), np.arange(4000)
    with np.errstate(invalid="ignore"):  # a few targets are degenerate (no normal)
        expected = segment_pairs_loop(striker, target, s_idx, t_idx)
        _assert_same_segments(segment_pairs(striker, target, s_idx, t_idx), expected)
    assert len(expected) > 2000
    assert _kinds(expected) == {STRIKER_VERTEX, TARGET_VERTEX, EDGE_CROSSING}
    # vertices within the tolerance moved onto the striker's edges and corners: no corner
    # outside the striker (beyond round-off)
    assert np.any((expected.snap >= 0) & (expected.snap < CORNER_SNAP))
    assert np.any(expected.snap >= CORNER_SNAP)
    outside = np.minimum.reduce([expected.xi[..., 0], expected.xi[..., 1],
                                 1.0 - expected.xi.sum(axis=-1)])
    assert outside.min() > -1e-15


def test_coincident_corners_become_one_where_the_lines_around_them_meet() -> None:
    """Two polygon corners closer than round-off become one, where the edges before and
    after them meet; a corner between two edges on one line goes."""
    eps = 1e-16
    # a target edge across the striker's corner 1, cutting off a tip of size eps: the two
    # crossings become the corner itself (it moves with the striker, not the target edge)
    poly = [(np.array([0.0, 0.0]), (STRIKER_VERTEX, 0, -1)),
            (np.array([1.0 - eps, 0.0]), (EDGE_CROSSING, 0, 2)),
            (np.array([1.0 - eps, eps]), (EDGE_CROSSING, 1, 2)),
            (np.array([0.0, 1.0]), (STRIKER_VERTEX, 2, -1))]
    lines = [("s", 0), ("t", 2), ("s", 1), ("s", 2)]
    merged = _merged(poly, lines)
    assert [p for _, p in merged] == [(STRIKER_VERTEX, k, -1) for k in range(3)]
    np.testing.assert_array_equal(merged[1][0], [1.0, 0.0])
    # a crossing at a vertex (t = 0): one corner where target edge 0 meets striker edge 1
    poly = [(np.array([0.2, 0.2]), (TARGET_VERTEX, 0, -1)),
            (np.array([0.6, 0.4]), (TARGET_VERTEX, 1, -1)),
            (np.array([0.6, 0.4 + 1e-14]), (EDGE_CROSSING, 1, 1)),
            (np.array([0.5, 0.5]), (STRIKER_VERTEX, 2, -1))]
    lines = [("t", 0), ("t", 1), ("s", 1), ("t", 2)]
    merged = _merged(poly, lines)
    # (the polygon starts at its corner of least provenance)
    assert [p for _, p in merged] == [(STRIKER_VERTEX, 2, -1), (TARGET_VERTEX, 0, -1),
                                      (EDGE_CROSSING, 1, 0)]
    # a corner between two edges on the striker's edge 0
    poly = [(np.array([0.0, 0.0]), (STRIKER_VERTEX, 0, -1)),
            (np.array([0.5, 0.0]), (TARGET_VERTEX, 1, -1)),
            (np.array([1.0, 0.0]), (STRIKER_VERTEX, 1, -1)),
            (np.array([0.0, 1.0]), (STRIKER_VERTEX, 2, -1))]
    lines = [("s", 0), ("s", 0), ("s", 1), ("s", 2)]
    assert [p for _, p in _merged(poly, lines)] == [(STRIKER_VERTEX, k, -1) for k in range(3)]


def test_no_pairs_give_no_segments() -> None:
    striker = RNG.uniform(size=(4, 3, 3))
    for segments in (segment_surfaces(striker, np.zeros((0, 3, 3))),
                     segment_surfaces(np.zeros((0, 3, 3)), striker),
                     segment_surfaces(striker, striker + np.array([10.0, 0.0, 0.0])),
                     segment_pairs(striker, striker, np.zeros(0, int), np.zeros(0, int))):
        assert len(segments) == 0
        assert segments.xi.shape == (0, 3, 2) and segments.index.shape == (0, 3, 2)
        assert segments.kind.shape == (0, 3)


def test_segments_tile_matching_grids_moved_within_the_tolerance() -> None:
    """Target vertices moved by 1e-7 (inside CLIP_TOL): each striker triangle is tiled once.

    The vertices are moved back onto the striker's edges and corners (an early rule that
    extrapolated a crossing along the nearly parallel edge gave one segment of xi-area
    2.94, coverage 5.6 % too high; keeping vertices outside by the tolerance left the
    coverage 1e-6 off). Measured: 8e-13, the vertices' distances squared.
    """
    striker, target = _pair_by_pair_cases()["matching grids moved by 1e-7"]
    segments = segment_surfaces(striker, target)
    per_triangle = np.zeros(len(striker))
    np.add.at(per_triangle, segments.striker, segments.xi_areas())
    assert np.max(segments.xi_areas()) <= 0.5 + 1e-11
    np.testing.assert_allclose(per_triangle, 0.5, atol=1e-11)


def _mirrored_line(offset: float) -> tuple[np.ndarray, np.ndarray]:
    """A jittered grid and its mirror image about x = 1/2 (one surface), striker and target.

    Both surfaces have edges along x = 1/2 with different nodes on it (5 and 7 rows); the
    target's nodes on that line are moved by ``offset`` along x (round-off in a run).
    """
    def surface(nx: int, ny: int, z: float, flip: bool, seed: int) -> np.ndarray:
        rng = np.random.default_rng(seed)
        x = np.linspace(0.0, 0.5, nx + 1)
        y = np.linspace(0.0, 1.0, ny + 1)
        X, Y = np.meshgrid(x, y, indexing="ij")
        inner = (X > 0) & (X < 0.5) & (Y > 0) & (Y < 1)
        X = X + inner * 0.2 / nx * rng.uniform(-0.5, 0.5, X.shape)
        Y = Y + inner * 0.2 / ny * rng.uniform(-1, 1, Y.shape)
        half = np.column_stack([X.ravel(), Y.ravel(), np.full(X.size, z)])
        node = np.arange(half.shape[0]).reshape(nx + 1, ny + 1)
        cells = []
        for i in range(nx):
            for j in range(ny):
                a, b, c, d = node[i, j], node[i + 1, j], node[i + 1, j + 1], node[i, j + 1]
                cells += [(a, b, c), (a, c, d)]
        tris = half[np.array(cells)]
        image = tris[:, ::-1] * [-1.0, 1.0, 1.0] + [1.0, 0.0, 0.0]
        tris = np.concatenate([tris, image])
        return tris[:, ::-1] if flip else tris

    striker = surface(3, 5, 0.0, flip=False, seed=1)
    target = surface(4, 7, 0.0, flip=True, seed=2)
    on_line = np.abs(target[..., 0] - 0.5) < 1e-12
    target[..., 0] += offset * on_line
    return striker, target


@pytest.mark.parametrize("offset", [1e-16, -1e-16, 1e-14, -1e-14, 1e-9, -1e-9])
def test_coincident_interior_edges_give_the_same_segments_on_either_side(offset: float) -> None:
    """Striker and target edges along one line, the target's a little to either side.

    The target vertices on the line are moved onto the striker's edges along it (the same
    snap codes whichever side they were on); striker corners on a target edge give, within
    round-off, one corner however the clipping met them. So the same segments (pairs,
    provenance, snap codes) on either side within round-off, every striker triangle tiled
    exactly, and the corners rebuilt from their provenance. (Kept where they were, the
    crossings of the two nearly collinear edges, or slivers of either target triangle,
    came and went with the side.) At 1e-9 the tips the target edges cut off the striker
    corners on the line are segments of their own, as they should.
    """
    striker, target = _mirrored_line(0.0)
    reference = segment_surfaces(striker, target)
    striker, target = _mirrored_line(offset)
    segments = _surfaces_against_reference(striker, target)
    if abs(offset) < 1e-13:
        for name in ("striker", "target", "kind", "index", "snap"):
            np.testing.assert_array_equal(getattr(segments, name), getattr(reference, name))
        np.testing.assert_allclose(segments.xi, reference.xi, rtol=0.0, atol=1e-12)
    pairs = {(s, t): tuple(c) for s, t, c in zip(segments.striker, segments.target,
                                                 segments.snap, strict=True)}
    for s, t, c in zip(reference.striker, reference.target, reference.snap, strict=True):
        assert pairs[s, t] == tuple(c)
    assert np.any(segments.snap >= 0)
    per_triangle = np.zeros(len(striker))
    np.add.at(per_triangle, segments.striker, segments.xi_areas())
    np.testing.assert_allclose(per_triangle, 0.5, rtol=0.0, atol=1e-14)
    for k in range(len(segments)):
        s, t = striker[segments.striker[k]], target[segments.target[k]]
        for c in range(3):
            kind, index = segments.kind[k, c], tuple(segments.index[k, c])
            rebuilt = corner_from_provenance(kind, index, s, t, segments.snap[k])
            np.testing.assert_allclose(rebuilt, segments.xi[k, c], atol=1e-14)
