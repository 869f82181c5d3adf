"""After a run: boundary nodes of a body found inside the same body (self-overlap).

A self-contact pair holds its striker nodes out of its target surface only.
Where a body touches itself at a place its pairs' surfaces do not cover (a
pair whose target is its own striker surface, a wall in no pair, a body
with no self-contact pair that folds), the walls pass through each other
and the run still converges: the answer is wrong without a failure. A
two-surface pair holds the striker's nodes, not the target's: a target
node may end up behind the striker surface.

At the end of a run every body is checked on its deformed geometry: each
node of its exterior facets is tested against the body's own cells that do
not contain it (bounding-box tree and GJK of :mod:`dolfinx.geometry`, on
each rank's owned cells; the body's surface is gathered on every rank).
A node inside one of them lies inside the body; its depth is its distance
to the nearest wall: the exterior facets of the body that do not contain it
and face it (:func:`depths`). One warning per body names the deepest node
when it lies deeper than
:data:`~.body_overlap.WARN_DEPTH` facet sizes
(:data:`~.body_overlap.WARN_DEPTH_MORTAR` where the body has a mortar
self-contact pair), h being its self-contact pair's striker facet size or,
without such a pair, the mean size of the body's exterior facets.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from dolfinx import geometry, mesh

from mpi4py import MPI

from fenics_contact.model.automatic_pairing import mean_facet_size
from fenics_contact.model.mortar import MortarContact
from fenics_contact.model.passage import deformed_vertices, placed
from fenics_contact.model.search import project
from fenics_contact.scene.body_overlap import WARN_DEPTH, WARN_DEPTH_MORTAR

if TYPE_CHECKING:
    from fenics_contact.model.body import Body
    from fenics_contact.model.problem import ContactProblem
    from fenics_contact.scene.schema import Scene

#: Nearest facets (by centroid) examined first for a node's depth.
CANDIDATES = 32


@dataclass(frozen=True)
class Surface:
    """A body's exterior facets, gathered on every rank (deformed configuration).

    Attributes:
        ids: (m, nv) global geometry node numbers of each facet.
        points: (m, nv, gdim) current positions of their vertices (length).
        normals: (m, gdim) their current unit outward normals.
        roles: (m,) bit mask: bit 2k the facet is on the striker surface of
            the body's k-th self-contact pair, bit 2k+1 on its target.
        triangles: (t, 2 or 3, gdim) the facets as segments (2D) or
            triangles (3D; a quadrilateral is two).
        parent: (t,) the facet of each triangle.
    """

    ids: np.ndarray
    points: np.ndarray
    normals: np.ndarray
    roles: np.ndarray
    triangles: np.ndarray
    parent: np.ndarray

    def nodes(self) -> tuple[np.ndarray, np.ndarray]:
        """(global numbers, current positions) of the surface's nodes, sorted by number."""
        ids, first = np.unique(self.ids.ravel(), return_index=True)
        return ids, self.points.reshape(-1, self.points.shape[-1])[first]

    def node_normals(self, ids: np.ndarray) -> np.ndarray:
        """(n, gdim) unit sums of the outward normals of the facets around each node."""
        nodes = np.unique(self.ids)
        total = np.zeros((nodes.size, self.normals.shape[1]))
        nv = self.ids.shape[1]
        np.add.at(total, np.searchsorted(nodes, self.ids.ravel()), np.repeat(self.normals, nv, 0))
        out = total[np.searchsorted(nodes, ids)]
        return out / np.maximum(np.linalg.norm(out, axis=1, keepdims=True), 1e-300)


@dataclass(frozen=True)
class Overlap:
    """The deepest boundary node of a body inside the same body (global, on every rank).

    Attributes:
        count: the nodes deeper than the tolerance.
        depth: the deepest node's distance to the nearest wall (:func:`depths`;
            length; 0: none inside).
        point: its current position.
        node_roles: bit mask (:class:`Surface`) of the facets around it.
        wall_roles: that of the nearest wall's facet (the wall it entered).
    """

    count: int
    depth: float
    point: np.ndarray
    node_roles: int
    wall_roles: int


def body_cells(problem: ContactProblem, body: Body) -> np.ndarray:
    """The body's owned cells (every owned cell for a one-body mesh)."""
    tdim = problem.domain.topology.dim
    owned = problem.domain.topology.index_map(tdim).size_local
    tags = problem.solid.cell_tags
    if body.tag is None or tags is None:
        return np.arange(owned, dtype=np.int32)
    cells = tags.find(body.tag)
    return cells[cells < owned].astype(np.int32)


def exterior_facets(domain: mesh.Mesh, cells: np.ndarray) -> np.ndarray:
    """Owned exterior facets of the mesh whose cell is one of ``cells``."""
    tdim = domain.topology.dim
    domain.topology.create_connectivity(tdim - 1, tdim)
    f2c = domain.topology.connectivity(tdim - 1, tdim)
    exterior = mesh.exterior_facet_indices(domain.topology)
    im = domain.topology.index_map(tdim)
    marker = np.zeros(im.size_local + im.num_ghosts, dtype=bool)
    marker[cells] = True
    cell = np.array([f2c.links(int(f))[0] for f in exterior], dtype=np.int32)
    return exterior[marker[cell]] if exterior.size else exterior


def _outward_normals(domain: mesh.Mesh, facets: np.ndarray, corners: np.ndarray,
                     x: np.ndarray) -> np.ndarray:
    """(m, gdim) unit normals of exterior facets with corners ``corners``, away from their cell."""
    tdim = domain.topology.dim
    f2c = domain.topology.connectivity(tdim - 1, tdim)
    if facets.size == 0:
        return np.zeros((0, x.shape[1]))
    if x.shape[1] == 2:
        t = corners[:, 1] - corners[:, 0]
        n = np.stack([t[:, 1], -t[:, 0]], axis=-1)
    else:
        n = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    cells = np.array([f2c.links(int(f))[0] for f in facets], np.int64)
    centre = x[domain.geometry.dofmaps[0][cells]].mean(axis=1)
    n *= np.where(np.einsum("ij,ij->i", n, corners.mean(axis=1) - centre) < 0, -1.0, 1.0)[:, None]
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def _triangulated(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(segments or triangles, parent facet) of facets (m, nv, gdim); a quadrilateral is two."""
    m = points.shape[0]
    if points.shape[1] != 4:
        return points, np.arange(m)
    # dolfinx orders a quadrilateral's vertices 0 1 / 2 3 (tensor product): the cycle is 0 1 3 2
    return (np.concatenate([points[:, [0, 1, 3]], points[:, [0, 3, 2]]]),
            np.concatenate([np.arange(m), np.arange(m)]))


def gathered_surface(problem: ContactProblem, cells: np.ndarray, x: np.ndarray,
                     pairs: list) -> Surface:
    """The exterior surface of the body made of ``cells``, on every rank (collective).

    ``x``: :func:`~fenics_contact.model.passage.deformed_vertices`; ``pairs``: the
    body's self-contact pairs.
    """
    domain, comm = problem.domain, problem.comm
    fdim, gdim = domain.topology.dim - 1, domain.geometry.dim
    facets = exterior_facets(domain, cells)
    nodes = mesh.entities_to_geometry(domain, fdim, facets)
    nv = nodes.shape[1] if facets.size else {2: 2, 3: 3}[gdim]
    nodes = nodes.reshape(-1, nv)
    glob = domain.geometry.index_map().local_to_global(np.arange(x.shape[0], dtype=np.int32))
    roles = np.zeros(facets.size, np.int64)
    for k, contact in enumerate(pairs):
        roles |= np.isin(facets, contact.facets) << (2 * k)
        roles |= np.isin(facets, contact.target_facets) << (2 * k + 1)
    normals = _outward_normals(domain, facets, x[nodes], x)
    ids = np.concatenate(comm.allgather(glob[nodes])).reshape(-1, nv)
    points = np.concatenate(comm.allgather(x[nodes])).reshape(-1, nv, gdim)
    normals = np.concatenate(comm.allgather(normals)).reshape(-1, gdim)
    triangles, parent = _triangulated(points)
    return Surface(ids, points, normals, np.concatenate(comm.allgather(roles)), triangles,
                   parent)


def nodes_inside(problem: ContactProblem, cells: np.ndarray, x: np.ndarray,
                 surface: Surface, scale: float) -> np.ndarray:
    """Surface nodes (indices into ``surface.nodes()``) inside an owned cell not containing them.

    The test runs on the geometry divided by ``scale`` (length), so that the
    collision tolerance of :mod:`dolfinx.geometry` (about 1e-6, absolute) is
    1e-6 of it.
    """
    domain = problem.domain
    gdim, tdim = domain.geometry.dim, domain.topology.dim
    nodes, positions = surface.nodes()
    points = np.zeros((nodes.size, 3))
    points[:, :gdim] = positions / scale
    with placed(domain, x / scale):
        tree = geometry.bb_tree(domain, tdim, entities=cells)
        found = geometry.compute_colliding_cells(
            domain, geometry.compute_collisions_points(tree, points), points)
    owner = np.repeat(np.arange(nodes.size), np.diff(found.offsets))
    if owner.size == 0:
        return owner
    glob = domain.geometry.index_map().local_to_global(np.arange(x.shape[0], dtype=np.int32))
    corners = glob[domain.geometry.dofmaps[0][found.array]]
    foreign = ~np.any(corners == nodes[owner][:, None], axis=1)
    return np.unique(owner[foreign])


def depths(points: np.ndarray, node_ids: np.ndarray, surface: Surface,
           normals: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(depth, facet) of each node inside a body: its distance to the nearest wall (length).

    The wall: the exterior facets of ``surface`` that do not contain the node
    and face it (their outward normal against the node's: ``normals``, by
    default :meth:`Surface.node_normals`, the node being on ``surface``).
    A facet facing the node's way is not a wall it entered: in a slab held
    in plane strain every node lies in the plane of an end face, and on a
    symmetry cut in that of the cut, at distance 0. 0 where no facet faces it.
    """
    from scipy.spatial import cKDTree

    tri = surface.triangles
    centres = tri.mean(axis=1)
    radius = float(np.max(np.linalg.norm(tri - centres[:, None], axis=-1)))
    tree = cKDTree(centres)
    k = min(CANDIDATES, tri.shape[0])
    reach, idx = tree.query(points, k=k)
    reach, idx = reach.reshape(len(points), -1), idx.reshape(len(points), -1)
    normals = surface.node_normals(node_ids) if normals is None else normals
    dist, wall = _nearest_wall(points, node_ids, normals, surface, idx)
    redo = np.flatnonzero(reach[:, -1] <= dist + radius) if k < tri.shape[0] else []
    for i in redo:  # a nearer facet may lie past the k nearest centroids
        near = np.asarray(tree.query_ball_point(points[i], dist[i] + radius)
                          if np.isfinite(dist[i]) else np.arange(tri.shape[0]), np.int64)
        d, w = _nearest_wall(points[i:i + 1], node_ids[i:i + 1], normals[i:i + 1], surface,
                             near[None])
        dist[i], wall[i] = d[0], w[0]
    return np.where(np.isfinite(dist), dist, 0.0), wall


def _nearest_wall(points: np.ndarray, node_ids: np.ndarray, normals: np.ndarray,
                  surface: Surface, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Nearest of the candidate triangles ``idx`` (n, k) that is a wall to its node (length)."""
    _, dist, _ = project(points, surface.triangles[idx])
    facet = surface.parent[idx]
    own = np.any(surface.ids[facet] == node_ids[:, None, None], axis=-1)
    away = np.einsum("ikd,id->ik", surface.normals[facet], normals) > 0.0
    dist = np.where(own | away, np.inf, dist)
    best = np.argmin(dist, axis=1)
    rows = np.arange(points.shape[0])
    return dist[rows, best], surface.parent[idx[rows, best]]


def self_overlap(problem: ContactProblem, body: Body, pairs: list, tolerance: float,
                 scale: float) -> Overlap:
    """The deepest boundary node of ``body`` inside the body itself (collective).

    ``pairs``: the body's self-contact pairs; ``tolerance``: the depth
    (length) past which a node counts; ``scale``: a length of the body's
    facets (the collision test's unit).
    """
    comm = problem.comm
    x = deformed_vertices(problem.V, problem.u)
    cells = body_cells(problem, body)
    surface = gathered_surface(problem, cells, x, pairs)
    if surface.ids.size == 0:
        return Overlap(0, 0.0, np.zeros(x.shape[1]), 0, 0)
    inside = nodes_inside(problem, cells, x, surface, scale)
    ids, points = (a[inside] for a in surface.nodes())
    depth, wall = depths(points, ids, surface) if ids.size else (np.zeros(0), np.zeros(0, int))
    deep = ids[depth > tolerance]
    count = np.unique(np.concatenate(comm.allgather(deep))).size
    worst = int(np.argmax(depth)) if depth.size else -1
    local = float(depth[worst]) if depth.size else 0.0
    best, rank = comm.allreduce((local, comm.rank), op=MPI.MAXLOC)
    found = None
    if comm.rank == rank and worst >= 0:
        around = np.bitwise_or.reduce(surface.roles[np.any(surface.ids == ids[worst], axis=1)])
        found = (points[worst], int(around), int(surface.roles[wall[worst]]))
    point, node_roles, wall_roles = comm.bcast(found, root=rank) or (np.zeros(x.shape[1]), 0, 0)
    return Overlap(count, best, point, node_roles, wall_roles)


def _behind_striker(pairs: list, found: Overlap) -> object | None:
    """The two-surface pair whose target node lies behind its own striker surface, if any."""
    for k, contact in enumerate(pairs):
        striker, target = 1 << (2 * k), 1 << (2 * k + 1)
        if found.node_roles & target and not found.node_roles & striker \
                and found.wall_roles & striker:
            return contact
    return None


def _which_node(pairs: list, found: Overlap) -> str:
    """Where the deepest node and the wall it entered lie on the pairs' surfaces."""
    for k, contact in enumerate(pairs):
        if found.node_roles & (1 << (2 * k)):
            return (f"the node strikes in [[pair]] {contact.name!r}, but the wall it entered is "
                    "not that pair's target")
    if found.node_roles:
        return "the node is on a target surface only, which holds no node of its own"
    return "the node is on no surface of a self-contact pair"


def _advice(scene: Scene, body: Body, pairs: list, found: Overlap, h: float) -> str:
    """The warning's text: what lies where, and the fix."""
    where = ", ".join(f"{c:.4g}" for c in found.point)
    depth = f"{found.depth:.3g} ({found.depth / h:.1%} of h)"
    contact = _behind_striker(pairs, found)
    if contact is not None:
        fix = ("A mortar pair holds weighted gaps, not single nodes: refine both surfaces "
               "where they touch." if isinstance(contact, MortarContact) else
               "The pair holds its striker nodes out of the target only: let the finer "
               "surface strike, or tag both surfaces as one and pair it with itself "
               "(striker = target: every node is held, though walls that meet node on node "
               "may then cycle; docs/contacts.md).")
        return (f"[[pair]] {contact.name!r}: a node of the target surface lies {depth} "
                f"behind the striker surface, near ({where}). {fix}")
    head = (f"body {body.name!r} overlaps itself: {found.count} of its boundary nodes lie "
            f"inside it, the deepest {depth} inside the opposite wall, near ({where})")
    if not pairs:
        return (f"{head}. No self-contact pair holds the body apart from itself: declare a "
                "[[pair]] with self_contact = true (a [[body]] scene) whose surfaces cover "
                "where it touches itself.")
    specs = {p.name: p for p in scene.pairs}
    named = "; ".join(
        f"[[pair]] {c.name!r} holds striker {specs[c.name].striker!r} out of target "
        f"{specs[c.name].target!r}" if c.name in specs else f"[[pair]] {c.name!r}"
        for c in pairs)
    return (f"{head}; {_which_node(pairs, found)}. A self-contact pair holds only its striker "
            f"nodes out of its target ({named}): its surfaces must cover where the body "
            "touches itself. Tag the two walls that meet as striker and target, or both as "
            "one surface paired with itself.")


def _self_pairs(problem: ContactProblem, body: Body) -> list:
    """The contacts of ``problem`` that pair ``body`` with itself."""
    return [c for c in problem.contacts
            if getattr(c, "striker_body", None) is body and getattr(c, "target_body", None)
            is body]


def warn_self_overlap(scene: Scene, problem: ContactProblem) -> float:
    """Warn per body whose boundary nodes lie inside the body itself; return the deepest / h.

    Collective. Depth over h, h the body's self-contact striker facet size
    (or its mean exterior facet size without a self-contact pair).
    """
    from fenics_contact.scene.checks import SceneWarning

    deepest = 0.0
    for body in problem.solid.bodies:
        pairs = _self_pairs(problem, body)
        cells = body_cells(problem, body)
        size = mean_facet_size(problem.domain, exterior_facets(problem.domain, cells))
        if not np.isfinite(size):
            continue
        h = min((c.surface.h for c in pairs), default=size)
        mortar = any(isinstance(c, MortarContact) for c in pairs)
        tolerance = (WARN_DEPTH_MORTAR if mortar else WARN_DEPTH) * h
        found = self_overlap(problem, body, pairs, tolerance, size)
        deepest = max(deepest, found.depth / h)
        if found.depth <= tolerance:
            continue
        warnings.warn(SceneWarning(
            f"{scene.path.name}: {_advice(scene, body, pairs, found, h)}"), stacklevel=2)
    return deepest


__all__ = ["Overlap", "Surface", "self_overlap", "warn_self_overlap"]
