"""Automatic pairing: every body's exterior surface against every other body's.

For each unordered pair of bodies of a :class:`~.body.Solid`:

1. **Surfaces.** Each body's candidate facets are its exterior facets
   (boundary facets of the mesh whose cell is the body's), whatever
   conditions they carry: a face held by a Dirichlet condition can still be
   struck. The faces of a symmetry cut are not (:func:`symmetry_cut_facets`):
   they stay on their plane and the model lies on one side of it, so nothing
   can reach them, and a node on the cut would take part of a cut facet's
   area into its lumped area (its pressure halved at a right-angled corner).
2. **Bounding boxes.** The two bodies' reference bounding boxes, each
   enlarged by ``reach`` (the largest displacement the load path
   prescribes plus a margin, chosen by the caller), must overlap, or the
   two bodies cannot meet within the load path and no contact is made.
   Otherwise each side keeps only the facets whose own box meets the other
   body's box enlarged by twice the reach: the part of its surface that can
   come near.
3. **Striker and target.** The body with the finer surface (the smaller
   mean exterior facet size, global) is the striker; on a tie (relative
   1e-6) the body given later strikes.
4. **Search.** One node-to-segment contact per pair, whose search is the
   self-contact search of :mod:`.self_contact`: each striker node is
   assigned, at every iteration, the closest target facet that faces it
   (the facet's normal opposes the node's), in front of it or less than a
   facet size behind it; a node no facet faces keeps a lifted gap (open).
   The facing rule settles the corners, where a striker node sits on a
   target vertex shared by a facet it presses and a side facet it must not
   be held by. Two bodies that share vertices (bonded) are pairs too: the
   neighbourhood rule keeps each node off the facets around it.

A node on the surfaces of two contacts (a block resting on two others, at
their junction) carries one multiplier per contact: each contact holds it
against its own target, and the forces add.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from dolfinx import mesh

from mpi4py import MPI

from fenics_contact.model.body import Body
from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.friction import FrictionSettings, symmetry_planes
from fenics_contact.model.pairs import NodeToSegmentContact

#: Relative difference of mean facet sizes under which two surfaces count as equally fine.
SIZE_TIE = 1e-6


def body_surfaces(domain: mesh.Mesh, cell_tags: mesh.MeshTags, bodies: Sequence[Body]
                  ) -> dict[str, np.ndarray]:
    """Local exterior facets of each body's cells, by body name."""
    tdim = domain.topology.dim
    domain.topology.create_connectivity(tdim - 1, tdim)
    exterior = mesh.exterior_facet_indices(domain.topology)
    f2c = domain.topology.connectivity(tdim - 1, tdim)
    cell = np.array([f2c.links(int(f))[0] for f in exterior], dtype=np.int32)
    im = domain.topology.index_map(tdim)
    out = {}
    for b in bodies:
        marker = np.zeros(im.size_local + im.num_ghosts, dtype=bool)
        marker[cell_tags.find(b.tag)] = True
        out[b.name] = exterior[marker[cell]] if exterior.size else exterior
    return out


def _facet_points(domain: mesh.Mesh, facets: np.ndarray) -> np.ndarray:
    """(n, nv, gdim) reference vertex positions of local facets."""
    gdim = domain.geometry.dim
    fdim = domain.topology.dim - 1
    if facets.size == 0:
        return np.zeros((0, gdim, gdim))
    nodes = mesh.entities_to_geometry(domain, fdim, facets)
    return domain.geometry.x[nodes][:, :, :gdim]


def surface_box(domain: mesh.Mesh, facets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Global reference bounding box (lo, hi) of a facet set."""
    gdim = domain.geometry.dim
    x = _facet_points(domain, facets).reshape(-1, gdim)
    lo = x.min(axis=0) if x.size else np.full(gdim, np.inf)
    hi = x.max(axis=0) if x.size else np.full(gdim, -np.inf)
    comm = domain.comm
    return np.min(comm.allgather(lo), axis=0), np.max(comm.allgather(hi), axis=0)


def mean_facet_size(domain: mesh.Mesh, facets: np.ndarray) -> float:
    """Global mean of the facets' largest edge (length); owned facets only."""
    owned = facets[facets < domain.topology.index_map(domain.topology.dim - 1).size_local]
    x = _facet_points(domain, owned)
    nv = x.shape[1]
    edges = [np.linalg.norm(x[:, (i + 1) % nv] - x[:, i], axis=-1) for i in range(nv)]
    size = np.max(edges, axis=0) if owned.size else np.zeros(0)
    comm = domain.comm
    total, count = comm.allreduce(float(size.sum()), op=MPI.SUM), comm.allreduce(
        int(size.size), op=MPI.SUM)
    return total / count if count else np.inf


def facets_near_box(domain: mesh.Mesh, facets: np.ndarray, lo: np.ndarray, hi: np.ndarray
                    ) -> np.ndarray:
    """The facets whose own bounding box meets the box [lo, hi]."""
    x = _facet_points(domain, facets)
    if facets.size == 0:
        return facets
    meets = np.all((x.max(axis=1) >= lo) & (x.min(axis=1) <= hi), axis=1)
    return facets[meets]


def _plane_bounds_mesh(domain: mesh.Mesh, facets: np.ndarray, axis: int) -> bool:
    """Whether the whole mesh lies on one side of the plane of ``facets`` (collective).

    The plane is x_axis = c, c read from the facets' nodes; one side within
    1e-12 of the mesh's extent.
    """
    comm, x = domain.comm, domain.geometry.x[:, axis]
    nodes = mesh.entities_to_geometry(domain, domain.topology.dim - 1, facets).ravel() \
        if facets.size else np.zeros(0, np.int32)
    c = comm.allreduce(float(np.min(x[nodes], initial=np.inf)), op=MPI.MIN)
    lo = comm.allreduce(float(np.min(x, initial=np.inf)), op=MPI.MIN)
    hi = comm.allreduce(float(np.max(x, initial=-np.inf)), op=MPI.MAX)
    tol = 1e-12 * max(hi - lo, 1.0)
    return bool(lo >= c - tol or hi <= c + tol)


def symmetry_cut_facets(domain: mesh.Mesh, conditions: Sequence[object]) -> np.ndarray:
    """Local facets of the symmetry cuts among Dirichlet ``conditions`` (collective).

    A cut: a symmetry plane (:func:`~.friction.symmetry_planes`: one
    displacement component held at 0 on facets in one plane normal to it)
    with the whole mesh on one side. Its facets stay in the plane and nothing
    lies beyond it: they can never be contact surfaces. Other held faces (a
    clamped face, a prescribed push, a roller with bodies beyond its plane)
    can be struck and are kept.
    """
    cuts = [facets for facets, axis in symmetry_planes(domain, conditions)
            if _plane_bounds_mesh(domain, facets, axis)]
    return np.unique(np.concatenate(cuts)).astype(np.int32) if cuts else np.zeros(0, np.int32)


def automatic_contacts(
    domain: mesh.Mesh,
    cell_tags: mesh.MeshTags,
    bodies: Sequence[Body],
    settings: ContactSettings,
    reach: float,
    *,
    skip: set[frozenset[str]] = frozenset(),
    friction: FrictionSettings | None = None,
    cuts: np.ndarray | None = None,
) -> tuple[list[NodeToSegmentContact], list[tuple[str, str]]]:
    """One node-to-segment contact per pair of bodies whose enlarged boxes overlap.

    Args:
        domain: the mesh of every body.
        cell_tags: the bodies' cell tags.
        bodies: the bodies, in the order that breaks striker ties (later strikes).
        settings: r and its scale for every contact.
        reach: how far any point may travel in the load path (length): each
            body's box is enlarged by it.
        skip: body pairs (frozensets of two names) already paired by hand.
        friction: Coulomb friction of every contact (None: frictionless).
        cuts: local facets that are no contact surface (the symmetry cuts,
            :func:`symmetry_cut_facets`); the boxes and facet sizes still
            count them.

    Returns the contacts (named "<striker>-on-<target>") and the body pairs
    pruned by their boxes.
    """
    surfaces = body_surfaces(domain, cell_tags, bodies)
    boxes = {b.name: surface_box(domain, surfaces[b.name]) for b in bodies}
    sizes = {b.name: mean_facet_size(domain, surfaces[b.name]) for b in bodies}
    if cuts is not None and cuts.size:
        surfaces = {name: np.setdiff1d(f, cuts).astype(np.int32) for name, f in surfaces.items()}
    contacts, pruned = [], []
    for i, a in enumerate(bodies):
        for b in bodies[i + 1:]:
            if frozenset((a.name, b.name)) in skip:
                continue
            (alo, ahi), (blo, bhi) = boxes[a.name], boxes[b.name]
            if np.any(alo - reach > bhi + reach) or np.any(blo - reach > ahi + reach):
                pruned.append((a.name, b.name))
                continue
            near_a = facets_near_box(domain, surfaces[a.name], blo - 2 * reach, bhi + 2 * reach)
            near_b = facets_near_box(domain, surfaces[b.name], alo - 2 * reach, ahi + 2 * reach)
            counts = [domain.comm.allreduce(int(f.size), op=MPI.SUM) for f in (near_a, near_b)]
            if min(counts) == 0:
                pruned.append((a.name, b.name))
                continue
            finer_a = sizes[a.name] < sizes[b.name] * (1 - SIZE_TIE)
            striker, target = (a, b) if finer_a else (b, a)
            facets = {a.name: near_a, b.name: near_b}
            contacts.append(NodeToSegmentContact(
                facets[striker.name], facets[target.name], settings,
                striker=striker.name, target=target.name, friction=friction,
                name=f"{striker.name}-on-{target.name}", self_contact=True,
                neighbourhood=1.0))
    return contacts, pruned


__all__ = ["automatic_contacts", "body_surfaces", "facets_near_box", "mean_facet_size",
           "surface_box", "symmetry_cut_facets"]
