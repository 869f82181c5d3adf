"""After a run: boundary nodes of one body of a pair found inside the other body.

A node-to-segment pair holds its striker nodes out of the target surface,
one way only: the target's nodes, and the nodes of either body outside its
tagged surface, are not held. Where they end up inside the partner body (a
target corner pressing into the striker's facets, a striker tagged short of
where its partner reaches), the answer is wrong without a failure. A mortar
pair constrains weighted gaps: single nodes at the edge of a contact zone
may lie inside by a few per cent of h (2.3 % on the ironing scene). At the
end of a run each pair's two bodies are checked both ways: every boundary
node of one against the whole boundary of the other (a closed surface: the
pseudo-normal at the closest point tells inside from outside), and one
warning per pair names the deepest node when it lies deeper than
:data:`WARN_DEPTH` (node-to-segment) or :data:`WARN_DEPTH_MORTAR` striker
facet sizes. A self-contact pair is left to the check of a body against
itself (:mod:`.self_overlap`).
"""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING

import numpy as np
from dolfinx import fem

from mpi4py import MPI

from fenics_contact.model.automatic_pairing import body_surfaces
from fenics_contact.model.mortar import MortarContact
from fenics_contact.model.search import penetration_depth
from fenics_contact.model.segments import Polyline
from fenics_contact.model.target_surface import free_sides

if TYPE_CHECKING:
    from fenics_contact.model.problem import ContactProblem
    from fenics_contact.scene.schema import Scene

#: A boundary node deeper than this many striker facet sizes inside the partner is named.
WARN_DEPTH = 1e-2
#: The same for a mortar pair, whose weighted gaps let single nodes in a little.
WARN_DEPTH_MORTAR = 5e-2


def _inside(problem: ContactProblem, facets: np.ndarray,
            surface_facets: np.ndarray) -> tuple[float, np.ndarray]:
    """(depth, position) of the deepest owned node of ``facets`` behind ``surface_facets``."""
    V, u = problem.V, problem.u
    gdim = problem.domain.geometry.dim
    surface = Polyline(V, surface_facets, dim=gdim)
    vertices = (surface.X + surface.displacements(u))[surface.facet_vertex]
    blocks = fem.locate_dofs_topological(V, problem.domain.topology.dim - 1, facets)
    blocks = blocks[blocks < V.dofmap.index_map.size_local]
    points = V.tabulate_dof_coordinates()[blocks, :gdim] + u.x.array.reshape(-1, gdim)[blocks]
    lo, hi = vertices.reshape(-1, gdim).min(axis=0), vertices.reshape(-1, gdim).max(axis=0)
    near = np.all((points >= lo) & (points <= hi), axis=1)
    if not np.any(near):
        return 0.0, np.zeros(gdim)
    depth = penetration_depth(points[near], vertices,
                              free=free_sides(surface.blocks, MPI.COMM_SELF))
    worst = int(np.argmax(depth))
    return float(depth[worst]), points[near][worst]


def warn_body_overlap(scene: Scene, problem: ContactProblem) -> float:
    """Warn per two-body pair whose bodies overlap; return the deepest depth / h (collective)."""
    from fenics_contact.scene.checks import SceneWarning

    comm, deepest = problem.comm, 0.0
    gdim = problem.domain.geometry.dim
    for contact in problem.contacts:
        striker, target = getattr(contact, "striker_body", None), getattr(contact, "target_body",
                                                                          None)
        if striker is None or target is None or striker is target:
            continue  # self-contact: scene/self_overlap.py
        surfaces = body_surfaces(problem.domain, problem.solid.cell_tags, [target, striker])
        sides = [surfaces[b.name] for b in (target, striker)]
        found = [_inside(problem, sides[0], sides[1]), _inside(problem, sides[1], sides[0])]
        depths = [comm.allreduce(d, op=MPI.MAX) for d, _ in found]
        which = int(np.argmax(depths))
        depth, h = depths[which], contact.surface.h
        deepest = max(deepest, depth / h)
        mortar = isinstance(contact, MortarContact)
        if depth <= (WARN_DEPTH_MORTAR if mortar else WARN_DEPTH) * h:
            continue
        rank = comm.allreduce((found[which][0], comm.rank), op=MPI.MAXLOC)[1]
        point = comm.bcast(found[which][1], root=rank)
        inner, outer = ((target, striker), (striker, target))[which]
        where = ", ".join(f"{c:.4g}" for c in point[:gdim])
        what = (f"a boundary node of body {inner.name!r} lies {depth:.3g} ({depth / h:.1%} of h) "
                f"inside body {outer.name!r}")
        declared = contact.name in {p.name for p in scene.pairs}
        label = f"[[pair]] {contact.name!r}" if declared else \
            f"[pairing] automatic contact {contact.name!r}"
        if not declared:
            fix = ("The pair holds its striker nodes out of the target only: declare these two "
                   "bodies as a [[pair]] (its striker and target of your choosing, or "
                   'discretisation = "mortar"), which [pairing] then leaves to it.')
        elif mortar:
            fix = ("A mortar pair holds weighted gaps, not single nodes: refine both surfaces "
                   "where they touch, or tag the striker wherever the partner may reach.")
        else:
            fix = ("The pair holds its striker nodes out of the target only: tag the striker "
                   "wherever the partner may reach, let the finer surface strike, or use "
                   'discretisation = "mortar".')
        warnings.warn(SceneWarning(
            f"{scene.path.name}: {label}: {what}, near ({where}). {fix}"),
            stacklevel=2)
    return deepest


__all__ = ["WARN_DEPTH", "WARN_DEPTH_MORTAR", "warn_body_overlap"]
