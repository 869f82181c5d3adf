"""After each load step: boundary nodes of one body of a pair found inside the other body.

A node-to-segment pair holds its striker nodes out of the target surface,
one way only: the target's nodes, and the nodes of either body outside its
tagged surface, are not held. Where they end up inside the partner body (a
target corner pressing into the striker's facets, a striker tagged short of
where its partner reaches), the answer is wrong without a failure. A mortar
pair constrains weighted gaps: single nodes at the edge of a contact zone
may lie inside by a few per cent of h (2.3 % on the ironing scene). After
every load step each pair's two bodies are checked both ways: every boundary
node of one against the whole boundary of the other (a closed surface: the
pseudo-normal at the closest point tells inside from outside), and one
warning per pair names the deepest node when it lies deeper than
:data:`WARN_DEPTH` (node-to-segment) or :data:`WARN_DEPTH_MORTAR` striker
facet sizes, at the end of the run; a pair whose bodies overlapped at an
earlier step only is named with the step where it went deepest (blocks slid
off each other: the lower corner 4.2 % of h inside the upper block at step
26 of 40, parted at the end). A self-contact pair is left to the check of a
body against itself (:mod:`.self_overlap`).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
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


@dataclass
class PairOverlap:
    """The deepest boundary node of one two-body pair's bodies inside the other body.

    Attributes:
        contact: the pair's name.
        depth: the node's depth (length); h: the pair's striker facet size.
        mortar: whether the pair is a mortar pair (its allowance is larger).
        inner, outer: the body the node belongs to and the body it lies in.
        point: the node's current position.
    """

    contact: str
    depth: float
    h: float
    mortar: bool
    inner: str
    outer: str
    point: np.ndarray

    @property
    def warned(self) -> bool:
        """Whether the depth exceeds the pair's allowance."""
        return self.depth > (WARN_DEPTH_MORTAR if self.mortar else WARN_DEPTH) * self.h


def _nearest_pair(problem: ContactProblem, contacts: list, point: np.ndarray):
    """Of the pairs joining two bodies, the one whose striker nodes lie nearest ``point``."""
    if len(contacts) == 1:
        return contacts[0]
    gdim = problem.domain.geometry.dim
    distance = []
    for contact in contacts:
        x = contact.nodal_coordinates()[:, :gdim]
        near = float(np.min(np.linalg.norm(x - point[:gdim], axis=1), initial=np.inf))
        distance.append(problem.comm.allreduce(near, op=MPI.MIN))
    return contacts[int(np.argmin(distance))]


def pair_overlaps(problem: ContactProblem) -> list[PairOverlap]:
    """The deepest overlap of each pair of bodies that pairs join, both ways (collective).

    Two bodies joined by several pairs (an indenter on a block's top, and a
    second pair on its side) are measured once, and the overlap is laid to
    the pair whose striker nodes lie nearest it: its allowance and its
    advice apply.
    """
    comm, out = problem.comm, []
    groups: dict[frozenset, list] = {}
    for contact in problem.contacts:
        striker, target = getattr(contact, "striker_body", None), getattr(contact, "target_body",
                                                                          None)
        if striker is None or target is None or striker is target:
            continue  # self-contact: scene/self_overlap.py
        groups.setdefault(frozenset((striker.name, target.name)), []).append(contact)
    for contacts in groups.values():
        if any(c.ramping for c in contacts):
            continue  # an interference fit not yet resolved: the bodies overlap by design
        striker, target = contacts[0].striker_body, contacts[0].target_body
        surfaces = body_surfaces(problem.domain, problem.solid.cell_tags, [target, striker])
        sides = [surfaces[b.name] for b in (target, striker)]
        found = [_inside(problem, sides[0], sides[1]), _inside(problem, sides[1], sides[0])]
        depths = [comm.allreduce(d, op=MPI.MAX) for d, _ in found]
        which = int(np.argmax(depths))
        rank = comm.allreduce((found[which][0], comm.rank), op=MPI.MAXLOC)[1]
        point = np.asarray(comm.bcast(found[which][1], root=rank))
        inner, outer = ((target, striker), (striker, target))[which]
        contact = _nearest_pair(problem, contacts, point)
        out.append(PairOverlap(contact.name, depths[which], float(contact.surface.h),
                               isinstance(contact, MortarContact), inner.name, outer.name,
                               point))
    return out


class OverlapWatch:
    """The deepest overlap of each pair over the load steps (:meth:`step` after each one)."""

    def __init__(self, problem: ContactProblem) -> None:
        self.problem = problem
        #: pair name -> (load step, load factor, its overlap) of the step it went deepest.
        self.worst: dict[str, tuple[int, float, PairOverlap]] = {}

    def step(self, step: int, load_factor: float) -> None:
        """Measure the pairs in the state just converged (collective)."""
        for found in pair_overlaps(self.problem):
            kept = self.worst.get(found.contact)
            if found.warned and (kept is None or found.depth > kept[2].depth):
                self.worst[found.contact] = (step, load_factor, found)


def warn_body_overlap(scene: Scene, problem: ContactProblem,
                      watch: OverlapWatch | None = None) -> float:
    """Warn per two-body pair whose bodies overlap; return the deepest depth / h (collective).

    ``watch``: the run's record of every load step; a pair whose bodies
    overlapped at an earlier step but not at the last one is named with that
    step (a corner that slid past its partner's edge and came out again).
    """
    from fenics_contact.scene.checks import SceneWarning

    deepest = 0.0
    gdim = problem.domain.geometry.dim
    for found in pair_overlaps(problem):
        deepest = max(deepest, found.depth / found.h)
        when = ""
        if not found.warned:
            earlier = watch.worst.get(found.contact) if watch is not None else None
            if earlier is None:
                continue
            step, load_factor, found = earlier
            when = (f"at load step {step} (load factor {load_factor:.4g}; the last step is "
                    "clear of it) ")
        depth, h = found.depth, found.h
        where = ", ".join(f"{c:.4g}" for c in found.point[:gdim])
        what = (f"{when}a boundary node of body {found.inner!r} lies {depth:.3g} "
                f"({depth / h:.1%} of h) inside body {found.outer!r}")
        declared = found.contact in {p.name for p in scene.pairs}
        label = f"[[pair]] {found.contact!r}" if declared else \
            f"[pairing] automatic contact {found.contact!r}"
        if declared and scene.solver.method == "penalty":
            fix = ("The penalty method lets a pair's surfaces overlap by about the pressure "
                   "over r: raise the pair's r, or use gnrm or auto, which hold the gap "
                   "exactly.")
        elif not declared:
            fix = ("The pair holds its striker nodes out of the target only: declare these two "
                   "bodies as a [[pair]] (its striker and target of your choosing, or "
                   'discretisation = "mortar"), which [pairing] then leaves to it.')
        elif found.mortar:
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


__all__ = ["WARN_DEPTH", "WARN_DEPTH_MORTAR", "OverlapWatch", "PairOverlap", "pair_overlaps",
           "warn_body_overlap"]
