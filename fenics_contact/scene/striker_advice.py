"""After a run: whether each two-body pair strikes with the surface its discretisation prefers.

The striker carries one multiplier per node. A 3D mortar pair striking with
the finer surface over-determines the coarser target and its nodal pressures
scatter about twice as much (``benchmarks/validation/striker_choice.py``).
Node-to-segment follows no rule that holds across cases (the finer surface
striking halved the interior error of two equal cylinders and doubled it on
dissimilar ones, and made a shrink fit's pressures scatter six times more):
it gets no advice here; a target node that ends inside its striker is named
by :mod:`.body_overlap`, and pressures that scatter by
:mod:`.pressure_scatter`. The facet sizes compared are those where the pair
touches at the end of the run: the striker facets with a node in contact,
and the target facets within reach of them.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from dolfinx import mesh
from scipy.spatial import cKDTree

from mpi4py import MPI

from fenics_contact.model.mortar import MortarContact
from fenics_contact.model.segments import node_blocks

if TYPE_CHECKING:
    from fenics_contact.model.problem import ContactProblem
    from fenics_contact.scene.schema import Scene

#: A size ratio beyond which the advice is given (striker / target, or its inverse).
RATIO = 0.8


@dataclass(frozen=True)
class TouchingSizes:
    """Mean facet sizes (mean edge length, length) where a pair touches."""

    striker: float
    target: float
    striker_facets: int
    target_facets: int


def _corners(problem: ContactProblem, facets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Reference and current corner positions of this rank's owned ``facets``, (n, k, d)."""
    domain = problem.domain
    gdim, fdim = domain.geometry.dim, domain.topology.dim - 1
    facets = np.asarray(facets, np.int32)
    facets = facets[facets < domain.topology.index_map(fdim).size_local]
    if facets.size == 0:
        return np.zeros((0, gdim, gdim)), np.zeros((0, gdim, gdim))
    nodes = mesh.entities_to_geometry(domain, fdim, facets)
    X = domain.geometry.x[nodes][..., :gdim]
    u = problem.u.x.array.reshape(-1, gdim)[node_blocks(problem.V)[nodes]]
    return X, X + u


def _edge_length(corners: np.ndarray) -> np.ndarray:
    """Mean edge length of each facet (2D: its length)."""
    k = corners.shape[1]
    if k == 2:
        return np.linalg.norm(corners[:, 1] - corners[:, 0], axis=1)
    edges = [np.linalg.norm(corners[:, (i + 1) % k] - corners[:, i], axis=1) for i in range(k)]
    return np.mean(edges, axis=0)


def touching_sizes(problem: ContactProblem, contact) -> TouchingSizes | None:
    """The facet sizes where ``contact`` (a two-body pair) touches; None where it does not.

    Collective.
    """
    comm = problem.comm
    gdim = problem.domain.geometry.dim
    state = contact.contact_state()
    pressed = np.concatenate(comm.allgather(contact.nodal_coordinates()[state.active][:, :gdim]))
    if pressed.shape[0] == 0:
        return None
    X, x = _corners(problem, contact.facets)
    scale = float(np.ptp(pressed, axis=0).max()) + 1.0
    if X.shape[0]:
        distance, _ = cKDTree(pressed).query(X.reshape(-1, gdim))
        touching = (distance.reshape(X.shape[:2]) <= 1e-9 * scale).any(axis=1)
    else:
        touching = np.zeros(0, bool)
    striker = np.concatenate(comm.allgather(_edge_length(x[touching])))
    centres = np.concatenate(comm.allgather(x[touching].mean(axis=1)))
    if striker.size == 0:
        return None
    _, y = _corners(problem, contact.target_facets)
    sizes = _edge_length(y)
    if y.shape[0]:
        distance, _ = cKDTree(centres).query(y.mean(axis=1))
        near = distance <= striker.max() + sizes
    else:
        near = np.zeros(0, bool)
    target = np.concatenate(comm.allgather(sizes[near]))
    if target.size == 0:
        return None
    return TouchingSizes(float(striker.mean()), float(target.mean()), striker.size, target.size)


def rim_in_contact(problem: ContactProblem, contact, size: float) -> bool:
    """Whether the striker surface's rim lies within 1.5 ``size`` of a node in contact.

    The rim: the sides of the striker's facets that no other striker facet
    shares (reference positions). Swapping such a pair would let the new
    striker overhang its target where they touch. Collective.
    """
    from fenics_contact.model.target_surface import free_sides

    domain, comm = problem.domain, problem.comm
    gdim, fdim = domain.geometry.dim, domain.topology.dim - 1
    state = contact.contact_state()
    pressed = np.concatenate(comm.allgather(contact.nodal_coordinates()[state.active][:, :gdim]))
    facets = np.asarray(contact.facets, np.int32)
    facets = facets[facets < domain.topology.index_map(fdim).size_local]
    nodes = (mesh.entities_to_geometry(domain, fdim, facets) if facets.size
             else np.zeros((0, gdim), np.int32))
    local = node_blocks(problem.V)[nodes].reshape(-1).astype(np.int32)
    blocks = problem.V.dofmap.index_map.local_to_global(local).reshape(nodes.shape)
    free = free_sides(blocks.astype(np.int64), comm)
    X = domain.geometry.x[nodes][..., :gdim]
    if gdim == 2:
        sides = X[free][:, None, :]
    else:
        sides = np.concatenate([X[free[:, k]][:, [(k + 1) % 3, (k + 2) % 3]]
                                for k in range(3)]) if X.size else np.zeros((0, 2, gdim))
    # a side on a symmetry plane is no rim: the mirrored surface goes on
    for where, axis in _plane_coordinates(problem):
        sides = sides[~np.all(np.abs(sides[:, :, axis] - where) <= 1e-9, axis=1)]
    rim = sides.reshape(-1, gdim)
    near = False
    if rim.shape[0] and pressed.shape[0]:
        distance, _ = cKDTree(pressed).query(rim)
        near = bool(np.any(distance <= 1.5 * size))
    return bool(comm.allreduce(near, op=MPI.LOR))


def _plane_coordinates(problem: ContactProblem) -> list[tuple[float, int]]:
    """(coordinate, axis) of each symmetry plane of the problem (collective)."""
    from fenics_contact.model.friction import symmetry_planes

    domain = problem.domain
    fdim = domain.topology.dim - 1
    out = []
    for facets, axis in symmetry_planes(domain, problem.solid.prescribed):
        nodes = mesh.entities_to_geometry(domain, fdim, np.asarray(facets, np.int32))
        mine = float(domain.geometry.x[nodes.reshape(-1), axis][0]) if nodes.size else np.inf
        out.append((problem.comm.allreduce(mine, op=MPI.MIN), axis))
    return out


def advise_striker(scene: Scene, problem: ContactProblem) -> list[str]:
    """Warn, per two-body pair, when the other surface should strike; return the advice given.

    Mortar in 3D: the striker's facets where it touches finer than RATIO times
    the target's (in 2D the coarser striker smooths the inside of the zone but
    resolves its edge with fewer nodes: no advice), unless the striker's rim
    is in contact: swapped, the coarser surface would overhang the finer
    one's rim, which a frictional block dragged on a larger block did not
    survive (it cycled, where the given striker converges). Node-to-segment
    pairs get none (see the module's description), nor do self-contact
    pairs, which have one surface. Collective.
    """
    from fenics_contact.scene.checks import SceneWarning

    advice = []
    for contact in problem.contacts:
        if not isinstance(contact, MortarContact) or problem.domain.geometry.dim != 3 \
                or getattr(contact, "self_contact", False):
            continue
        sizes = touching_sizes(problem, contact)
        if sizes is None:
            continue
        ratio = sizes.striker / sizes.target
        if ratio >= RATIO or rim_in_contact(problem, contact, sizes.striker):
            continue  # swapped at its rim, the striker would overhang its target's rim there
        why = ("a mortar pair's nodal pressures are smoother with the coarser surface "
               "striking (about half the scatter)")
        text = (f"{scene.path.name}: [[pair]] {contact.name!r}: where it touches, the striker's "
                f"facets are {sizes.striker:.3g} and the target's {sizes.target:.3g} "
                f"(ratio {ratio:.2f}); {why}: swap striker and target "
                "(docs/two_bodies.md, 'Which surface strikes').")
        advice.append(text)
        warnings.warn(SceneWarning(text), stacklevel=2)
    return advice


__all__ = ["RATIO", "TouchingSizes", "advise_striker", "touching_sizes"]
