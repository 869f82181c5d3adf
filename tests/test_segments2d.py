"""The 2D mortar segment search: which target facets a striker facet's weighted gap sees."""

from __future__ import annotations

import numpy as np

from fenics_contact.model.segments import OPPOSING, overlaps


def _inclined(depth: float, cos: float) -> tuple[np.ndarray, np.ndarray]:
    """A target facet 0.1 long centred ``depth`` below (0.5, 0), its normal at acos(cos) to y.

    For the striker facet (0, 0) -> (1, 0), whose normal in the search is
    n_s = (0, -1), the facet faces it with -n_s . n_t = cos, lies ``depth``
    from it along n_s and cos * depth along its own normal n_t.
    """
    sin = np.sqrt(1.0 - cos**2)
    centre, half = np.array([0.5, -depth]), 0.05 * np.array([cos, sin])
    return (centre + half)[None], (centre - half)[None]


def test_a_target_facet_counts_by_its_distance_along_the_striker_normal():
    """Within the reach along the striker's normal, not along the target's own.

    Inclined at cos = 0.3 (> OPPOSING) and 0.2 away along the striker's
    normal, 0.06 along its own: with the reach 0.1 it used to count, and
    the weighted gap took the far, tilted facet in. In a user's scene a
    pair 0.2 apart that never touches picked such facets up in an
    intermediate Newton iterate (weighted gap -0.46) and the whole scene
    diverged; it converges now in 41 iterations with that pair's force 0.
    """
    x1, x2 = np.array([[0.0, 0.0]]), np.array([[1.0, 0.0]])
    assert 0.3 > OPPOSING
    for depth, counted in ((0.05, True), (0.09, True), (0.2, False), (0.3, False)):
        ta, tb = _inclined(depth, 0.3)
        out, dist = overlaps(x1, x2, ta, tb, reach=0.1)
        assert abs(dist[0, 0] - 0.3 * depth) < 1e-12  # along the target's normal
        assert np.isfinite(out[0, 0]) == counted, depth
    # facing squarely (cos = 1) the reach is the normal distance, as before
    for depth, counted in ((0.09, True), (0.11, False)):
        ta, tb = _inclined(depth, 1.0)
        assert np.isfinite(overlaps(x1, x2, ta, tb, reach=0.1)[0][0, 0]) == counted, depth
