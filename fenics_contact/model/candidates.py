"""Candidate contact facets: the boundary facets an obstacle can reach on its path.

Only these facets carry multiplier degrees of freedom (the contact submesh),
so a scene models only the part of the boundary that can touch. A facet is a
candidate when one of its vertices comes within ``margin`` of the obstacle
at one of ``samples`` positions along the obstacle's straight path
(``offset = t * motion``, t = 0 ... 1). The margin is widened by

- ``displacement_bound``: the largest displacement the body's own surface
  can undergo (for a body pushed onto a fixed obstacle, the push), and
- half the distance the obstacle moves between two samples, so that the
  sampling cannot step over a facet.

Gaps are measured in the reference configuration with
:meth:`RigidObstacle.gap_value` (length units, positive when clear).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Literal

import numpy as np
from dolfinx import mesh

from fenics_contact.model.obstacles import RigidObstacle


def boundary_facets(domain: mesh.Mesh) -> np.ndarray:
    """All exterior facets of the local mesh part (local indices)."""
    fdim = domain.topology.dim - 1
    domain.topology.create_connectivity(fdim, domain.topology.dim)
    return np.asarray(mesh.exterior_facet_indices(domain.topology), dtype=np.int32)


def detect_candidate_facets(
    domain: mesh.Mesh,
    obstacle: RigidObstacle,
    motion: Sequence[float] | None = None,
    margin: float = 0.0,
    *,
    displacement_bound: float = 0.0,
    samples: int = 5,
) -> np.ndarray:
    """Exterior facets whose vertices come within the margin of the obstacle on its path.

    Args:
        domain: the body mesh.
        obstacle: the rigid obstacle, at its load-factor-0 placement.
        motion: obstacle displacement at load factor 1 (length); None: fixed.
        margin: detection distance (length), >= 0.
        displacement_bound: largest displacement of the body surface (length).
        samples: positions sampled along the path (>= 2 when it moves).

    Returns:
        Local indices of the candidate facets (sorted; may be empty on a rank).
    """
    if not (margin >= 0 and displacement_bound >= 0):
        raise ValueError(
            f"margin and displacement_bound must be >= 0, got {margin} and {displacement_bound}."
        )
    gdim = domain.geometry.dim
    path = np.zeros(gdim) if motion is None else np.asarray(motion, dtype=float)
    if path.shape != (gdim,):
        raise ValueError(f"Obstacle motion {list(path)} needs {gdim} components.")
    moves = bool(np.linalg.norm(path) > 0)
    n_samples = max(int(samples), 2) if moves else 1
    reach = margin + displacement_bound
    if moves:
        reach += 0.5 * float(np.linalg.norm(path)) / (n_samples - 1)

    facets = boundary_facets(domain)
    fdim = domain.topology.dim - 1
    nodes = mesh.entities_to_geometry(domain, fdim, facets)
    points = domain.geometry.x[nodes.ravel(), :gdim]
    home = np.array(obstacle.point.value, dtype=float, copy=True)
    closest = np.full(points.shape[0], np.inf)
    try:
        for t in np.linspace(0.0, 1.0, n_samples):
            obstacle.point.value[:] = home + t * path
            closest = np.minimum(closest, obstacle.gap_value(points))
    finally:
        obstacle.point.value[:] = home
    near = (closest < reach).reshape(nodes.shape).any(axis=1)
    return np.sort(facets[near])


#: How a problem picks its candidate facets: its own tag, detection along the
#: obstacle's path, or every exterior facet.
CandidateMode = Literal["tag", "detected", "boundary"]


def choose_candidates(
    domain: mesh.Mesh,
    obstacle: RigidObstacle,
    tagged: np.ndarray,
    mode: CandidateMode,
    reach: float,
) -> np.ndarray:
    """Candidate facets by ``mode``; ``reach`` bounds the body's own displacement (length).

    'tag' returns ``tagged`` (the problem's own choice), 'detected' the
    facets :func:`detect_candidate_facets` finds for a fixed obstacle with
    margin ``reach``, 'boundary' every exterior facet.
    """
    if mode == "tag":
        return tagged
    if mode == "boundary":
        return boundary_facets(domain)
    if mode == "detected":
        return detect_candidate_facets(domain, obstacle, None, 0.0, displacement_bound=reach)
    raise ValueError(f"Unknown candidate mode {mode!r}; use 'tag', 'detected' or 'boundary'.")
