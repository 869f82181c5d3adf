"""After a run: node-to-segment pressures that scatter from node to node.

One-pass node-to-segment transfers each striker node's force to the target
facet it lands on; on non-matching meshes the nodes sample the target's
facets unevenly and the nodal pressure of a smooth contact alternates from
node to node (a pin in a hole meshed at 0.02 against 0.03: every third node
near 0.2 of its neighbours), by an amount that refinement does not remove
on flat faces; on curved faces, where a finer striker's nodes also sample
the chords of coarser target facets, that part falls about with h (a
user's shrink fit: 31 % of the mean, 18 % on a mesh twice as fine).
Nothing fails, and a colour map of the pressure hides it. At the end of a
run each node-to-segment pair's final pressure is measured on the interior
of its contact zone (nodes whose neighbours, and their neighbours, are all in
contact, so that the zone's edge, where a smooth profile bends most, does
not count): the scatter of a node is |p_i - mean of its neighbours' p|. A
warning names the pair when the median scatter exceeds :data:`SCATTER` of
the zone's mean pressure, or a tenth of the nodes' scatter exceeds
:data:`TAIL` of it. Measured on the final states: the pin's coarse
meshes 0.21 (the finer, matched ones 0.0014, its mortar pair 0.034), the
non-matching patch test 0.16, the shipped two cylinders 0.053, Hertz on a
rigid plane 0.0035.
"""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING

import numpy as np
from dolfinx import fem

from mpi4py import MPI

from fenics_contact.model.pairs import NodeToSegmentContact

if TYPE_CHECKING:
    from fenics_contact.model.problem import ContactProblem
    from fenics_contact.scene.schema import Scene

#: Median nodal scatter, relative to the mean pressure, from which a pair is named.
SCATTER = 0.1
#: ... or the scatter of a tenth of the interior nodes (with at least TAIL_NODES of
#: them), which a small 3D zone shows where its median does not: a hemisphere on a
#: block, 17 interior nodes, median 0.056, 90th percentile 0.41, its nodal peak 23 %
#: above Hertz (mortar 6 %); the shipped node-to-segment hemispheres 0.16, the two
#: cylinders 0.074, a matching Cattaneo-Mindlin pair 0.009.
TAIL = 0.2
TAIL_NODES = 10


def nodal_scatter(contact) -> tuple[np.ndarray, float]:
    """(scatter of each owned interior node, mean pressure of the zone) of one contact.

    Pressures as reported (>= 0 here, stress); the mean over every node in
    contact, all ranks. Collective.
    """
    state = contact.contact_state()
    comm = contact.comm
    n = state.pressure.size
    pressure, active = fem.Function(contact.Q), fem.Function(contact.Q)
    pressure.x.array[:n] = -state.pressure
    active.x.array[:n] = state.active
    for f in (pressure, active):
        f.x.scatter_forward()
    closed = active.x.array > 0.5
    p = pressure.x.array
    neighbours: list[set[int]] = [set() for _ in range(p.size)]
    for cell in contact.Q.dofmap.list:
        for i in cell:
            neighbours[int(i)].update(int(j) for j in cell if j != i)
    scatter = []
    for i in np.flatnonzero(closed[:n]):
        ring = neighbours[i]
        if not ring or not all(closed[j] for j in ring):
            continue
        second = set().union(*(neighbours[j] for j in ring)) - {int(i)}
        if all(closed[j] for j in second):
            scatter.append(abs(p[i] - np.mean(p[list(ring)])))
    total = comm.allreduce(float(np.sum(-state.pressure[state.active])), op=MPI.SUM)
    count = comm.allreduce(int(np.sum(state.active)), op=MPI.SUM)
    return np.asarray(scatter), total / count if count else 0.0


def _body(problem: ContactProblem, contact) -> object | None:
    """The one body a contact's (striker) facets lie on; None when they span several."""
    try:
        return problem.solid.body_of_facets(contact.facets, "contact")
    except ValueError:
        return None


def _alike(problem: ContactProblem, pair: NodeToSegmentContact,
           ratios: dict[str, float]) -> list[str]:
    """Contacts of other discretisations on the pair's striker body that scatter too."""
    body = _body(problem, pair)
    return [f"{name!r} ({ratio:.0%})" for name, ratio in ratios.items()
            if ratio > SCATTER and body is not None
            and _body(problem, next(c for c in problem.contacts if c.name == name)) is body]


def _ratio(contact) -> tuple[float, np.ndarray, float]:
    """(median scatter / mean, every node's scatter / mean, mean pressure) (collective)."""
    scatter, mean = nodal_scatter(contact)
    every = np.concatenate(contact.comm.allgather(scatter))
    if every.size < 3 or not mean > 0.0:
        return 0.0, every, mean
    return float(np.median(every)) / mean, every / mean, mean


def warn_pressure_scatter(scene: Scene, problem: ContactProblem) -> float:
    """Warn for each node-to-segment pair whose pressure scatters; return the largest ratio.

    When a contact of another kind (a rigid obstacle, a mortar pair) on the
    same body scatters as well, the pairing cannot be the cause: the warning
    then names the bulk mesh (too few elements for the contact stress, e.g.
    through a thin wall; the crushed tube's plates and inner wall alternate
    alike at 4 layers through the wall, 18 and 20 %, and by 5 % at 8).
    """
    from fenics_contact.scene.checks import SceneWarning

    others = {c.name: _ratio(c)[0] for c in problem.contacts
              if not isinstance(c, NodeToSegmentContact)}
    worst = 0.0
    for contact in problem.contacts:
        if not isinstance(contact, NodeToSegmentContact):
            continue
        ratio, every, mean = _ratio(contact)
        worst = max(worst, ratio)
        tail = float(np.percentile(every, 90)) if every.size >= TAIL_NODES else 0.0
        if ratio <= SCATTER and tail <= TAIL:
            continue
        alike = _alike(problem, contact, others)
        if alike:
            why = (f"{' and '.join(alike)} on the same body scatter alike, although no node "
                   "there samples a partner's facets: the bulk mesh is too coarse for the "
                   "contact stress (e.g. few elements through a thin wall). Refine it there; "
                   "another discretisation of the pair would not help.")
        elif contact.self_contact and np.array_equal(contact.facets, contact.target_facets):
            why = ("one surface paired with itself holds a closed contact from both sides, "
                   "and the equations do not fix how its force splits between the facing "
                   "nodes (each facing pair sums to the profile); the resultant is right. For "
                   "a smooth pressure, tag the two parts that meet apart and pair them with "
                   'discretisation = "mortar" (docs/contacts.md).')
        else:
            why = ("one-pass node-to-segment on meshes that do not match misses the patch "
                   "test: the nodes sample the partner's facets unevenly (on curved faces "
                   "also the chords of coarser target facets), so the pressures spread and "
                   "the resultant force may be off by per cents (a uniformly pressed stack "
                   "of three blocks: -1.5 %), and refining removes it slowly if at all (on "
                   "flat faces not at all; the chords' part falls about with h). Fix: "
                   "discretisation = \"mortar\" passes the patch test, with a smooth "
                   "pressure and the exact resultant there (docs/two_bodies.md).")
        declared = contact.name in {p.name for p in scene.pairs}
        label = (f"[[pair]] {contact.name!r}" if declared else
                 f"[pairing] automatic contact {contact.name!r}")
        warnings.warn(
            f"{scene.path.name}: {label}: node-to-segment pressures scatter "
            f"from node to node by {ratio:.0%} of their mean ({mean:.4g}) inside the contact "
            f"zone (median over {every.size} nodes"
            + (f", {tail:.0%} at the 90th percentile" if tail > TAIL else "")
            + f", largest {float(every.max()):.0%}): {why}",
            SceneWarning, stacklevel=2)
    return worst


__all__ = ["SCATTER", "TAIL", "nodal_scatter", "warn_pressure_scatter"]
