"""After a run: node-to-segment pressures that scatter from node to node.

One-pass node-to-segment transfers each striker node's force to the target
facet it lands on; on non-matching meshes the nodes sample the target's
facets unevenly and the nodal pressure of a smooth contact alternates from
node to node (a pin in a hole meshed at 0.02 against 0.03: every third node
near 0.2 of its neighbours), by an amount that refinement does not remove.
Nothing fails, and a colour map of the pressure hides it. At the end of a
run each node-to-segment pair's final pressure is measured on the interior
of its contact zone (nodes whose neighbours, and their neighbours, are all in
contact, so that the zone's edge, where a smooth profile bends most, does
not count): the scatter of a node is |p_i - mean of its neighbours' p|. A
warning names the pair when the median scatter exceeds :data:`SCATTER` of
the zone's mean pressure. Measured on the final states: the pin's coarse
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


def warn_pressure_scatter(scene: Scene, problem: ContactProblem) -> float:
    """Warn for each node-to-segment pair whose pressure scatters; return the largest ratio."""
    from fenics_contact.scene.checks import SceneWarning

    worst = 0.0
    for contact in problem.contacts:
        if not isinstance(contact, NodeToSegmentContact):
            continue
        scatter, mean = nodal_scatter(contact)
        every = np.concatenate(contact.comm.allgather(scatter))
        if every.size < 3 or not mean > 0.0:
            continue
        ratio = float(np.median(every)) / mean
        worst = max(worst, ratio)
        if ratio <= SCATTER:
            continue
        fix = ("Read the nodal pressures as a scattered sample (self-contact is "
               "node-to-segment only); their resultant is right." if contact.self_contact else
               "discretisation = \"mortar\" gives a smooth pressure (docs/two_bodies.md); "
               "the forces are right either way.")
        declared = contact.name in {p.name for p in scene.pairs}
        label = (f"[[pair]] {contact.name!r}" if declared else
                 f"[pairing] automatic contact {contact.name!r}")
        warnings.warn(
            f"{scene.path.name}: {label}: node-to-segment pressures scatter "
            f"from node to node by {ratio:.0%} of their mean ({mean:.4g}) inside the contact "
            f"zone (median over {every.size} nodes, largest {float(every.max()) / mean:.0%}): "
            "the nodes sample the partner's facets unevenly on meshes that do not match, and "
            f"refining does not remove it. {fix}",
            SceneWarning, stacklevel=2)
    return worst
