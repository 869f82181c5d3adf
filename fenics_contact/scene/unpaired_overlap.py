"""After a run: two bodies that no contact joins, found inside each other.

A contact holds bodies apart only where a pair or an automatic contact
joins them. Two bodies without one (a `[[pair]]` forgotten, or automatic
pairing that made none because their boxes, enlarged by the reach, did not
meet at the start) pass through each other freely and the run still
converges: the answer is wrong without a failure. At the end of a run every
such pair of bodies is checked both ways on the deformed geometry, as a
body is checked against itself (:mod:`.self_overlap`): each node of one
body's exterior facets is tested against the other body's cells
(bounding-box tree and GJK of :mod:`dolfinx.geometry`), and a node inside
has as its depth the distance to the nearest exterior facet of the other
body that faces it. One warning per pair of bodies names the deepest node
when it lies deeper than :data:`~.body_overlap.WARN_DEPTH` facet sizes (the
smaller mean exterior facet size of the two). Bodies that share vertices
(bonded) are checked too: a node on the shared face lies in cells that
contain it and does not count.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from itertools import combinations
from typing import TYPE_CHECKING

import numpy as np

from mpi4py import MPI

from fenics_contact.model.automatic_pairing import mean_facet_size
from fenics_contact.model.passage import deformed_vertices
from fenics_contact.scene.body_overlap import WARN_DEPTH
from fenics_contact.scene.self_overlap import (
    body_cells,
    depths,
    exterior_facets,
    gathered_surface,
    nodes_inside,
)

if TYPE_CHECKING:
    from fenics_contact.model.body import Body
    from fenics_contact.model.problem import ContactProblem
    from fenics_contact.scene.schema import Scene


@dataclass(frozen=True)
class BodyIntrusion:
    """The deepest boundary node of one body inside another that no contact joins to it.

    Attributes:
        inner, outer: the names of the body the node belongs to and of the body it lies in.
        count: boundary nodes of ``inner`` deeper than the tolerance inside ``outer``.
        depth: the deepest one's distance to ``outer``'s surface (length).
        h: the smaller mean exterior facet size of the two bodies (length).
        point: its current position.
    """

    inner: str
    outer: str
    count: int
    depth: float
    h: float
    point: np.ndarray


def unpaired_bodies(problem: ContactProblem) -> list[tuple[Body, Body]]:
    """The pairs of distinct bodies that no contact of ``problem`` joins."""
    joined = set()
    for contact in problem.contacts:
        striker = getattr(contact, "striker_body", None)
        target = getattr(contact, "target_body", None)
        if striker is not None and target is not None:
            joined.add(frozenset((striker.name, target.name)))
    return [(a, b) for a, b in combinations(problem.solid.bodies, 2)
            if frozenset((a.name, b.name)) not in joined]


def _boxes_meet(comm: MPI.Comm, first: np.ndarray, second: np.ndarray, pad: float) -> bool:
    """Whether the bounding boxes of two point sets (each spread over the ranks) meet."""
    def box(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        gdim = x.shape[1]
        lo = x.min(axis=0) if x.size else np.full(gdim, np.inf)
        hi = x.max(axis=0) if x.size else np.full(gdim, -np.inf)
        low, high = np.empty(gdim), np.empty(gdim)
        comm.Allreduce(np.ascontiguousarray(lo, float), low, op=MPI.MIN)
        comm.Allreduce(np.ascontiguousarray(hi, float), high, op=MPI.MAX)
        return low, high

    (lo1, hi1), (lo2, hi2) = box(first), box(second)
    return bool(np.all(lo1 <= hi2 + pad) and np.all(lo2 <= hi1 + pad))


def intrusion(problem: ContactProblem, inner: Body, outer: Body, x: np.ndarray,
              tolerance: float, h: float) -> BodyIntrusion:
    """The deepest boundary node of ``inner`` inside ``outer`` (collective).

    ``x``: :func:`~fenics_contact.model.passage.deformed_vertices`;
    ``tolerance``: the depth (length) past which a node counts; ``h``: the
    collision test's length unit.
    """
    comm = problem.comm
    inner_surface = gathered_surface(problem, body_cells(problem, inner), x, [])
    outer_cells = body_cells(problem, outer)
    outer_surface = gathered_surface(problem, outer_cells, x, [])
    nothing = BodyIntrusion(inner.name, outer.name, 0, 0.0, h, np.zeros(x.shape[1]))
    if inner_surface.ids.size == 0 or outer_surface.ids.size == 0:
        return nothing
    inside = nodes_inside(problem, outer_cells, x, inner_surface, h)
    ids, points = (a[inside] for a in inner_surface.nodes())
    if ids.size:
        depth, _ = depths(points, ids, outer_surface, inner_surface.node_normals(ids))
    else:
        depth = np.zeros(0)
    count = np.unique(np.concatenate(comm.allgather(ids[depth > tolerance]))).size
    worst = int(np.argmax(depth)) if depth.size else -1
    local = float(depth[worst]) if depth.size else 0.0
    best, rank = comm.allreduce((local, comm.rank), op=MPI.MAXLOC)
    point = comm.bcast(points[worst] if comm.rank == rank and worst >= 0 else None, root=rank)
    if point is None:
        return nothing
    return BodyIntrusion(inner.name, outer.name, count, best, h, np.asarray(point))


def unpaired_intrusions(problem: ContactProblem) -> list[BodyIntrusion]:
    """The deeper way of each unpaired pair of bodies whose boxes meet (collective)."""
    out = []
    x = deformed_vertices(problem.V, problem.u)
    domain = problem.domain
    for a, b in unpaired_bodies(problem):
        facets = [exterior_facets(domain, body_cells(problem, body)) for body in (a, b)]
        h = min(mean_facet_size(domain, f) for f in facets)
        if not np.isfinite(h):
            continue
        points = [x[np.unique(domain.geometry.dofmaps[0][body_cells(problem, body)])]
                  for body in (a, b)]
        if not _boxes_meet(problem.comm, points[0], points[1], WARN_DEPTH * h):
            continue
        tolerance = WARN_DEPTH * h
        found = [intrusion(problem, a, b, x, tolerance, h), intrusion(problem, b, a, x,
                                                                      tolerance, h)]
        out.append(max(found, key=lambda f: f.depth))
    return out


def warn_unpaired_overlap(scene: Scene, problem: ContactProblem) -> float:
    """Warn per pair of bodies that no contact joins and that lie inside each other.

    Returns the deepest depth / h (collective).
    """
    from fenics_contact.scene.checks import SceneWarning

    deepest = 0.0
    for found in unpaired_intrusions(problem):
        deepest = max(deepest, found.depth / found.h)
        if found.depth <= WARN_DEPTH * found.h:
            continue
        where = ", ".join(f"{c:.4g}" for c in found.point)
        automatic = scene.pairing is not None
        why = ("[pairing] made no contact for them: their reference boxes, enlarged by the "
               "reach (the largest prescribed displacement plus margin), did not meet. Raise "
               "[pairing] margin past the distance they travel, or declare a [[pair]] between "
               "them." if automatic else
               "Declare a [[pair]] between them (striker and target: the faces that meet), or "
               "let [pairing] automatic = true find it.")
        warnings.warn(SceneWarning(
            f"{scene.path.name}: bodies {found.inner!r} and {found.outer!r} pass through each "
            f"other, and no contact joins them: {found.count} boundary node"
            f"{'s' if found.count != 1 else ''} of {found.inner!r} lie inside "
            f"{found.outer!r}, the deepest {found.depth:.3g} ({found.depth / found.h:.1%} of "
            f"h) near ({where}). {why}"), stacklevel=2)
    return deepest


__all__ = ["BodyIntrusion", "intrusion", "unpaired_bodies", "unpaired_intrusions",
           "warn_unpaired_overlap"]
