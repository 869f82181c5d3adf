"""The 3D patch test's two blocks, each meshed as the mirror image of its own half.

The lower block [0, W]^2 x [0, H] and the upper block [0, W]^2 x [H, 2H]
(as ``meshes/block_on_block_3d.geo``: quarter model, x = 0 and y = 0 the
symmetry planes) are meshed by gmsh over x <= W/2 only, with tetrahedra of
sizes ``h_lower`` and ``h_upper``, and each half is mirrored about x = W/2.
On the contact plane z = H both faces then have a chain of edges along the
line x = W/2, with different nodes on it: the striker's and the target's
interior edges lie on one line, and striker corners on that line lie on
target edges (and target vertices on striker edges). Under a uniform
compression the line stays where it is in both bodies (to round-off).

Tags as in the .geo: cells ``striker`` 1 (upper) and ``target`` 2 (lower);
facets ``top`` 2, ``striker_face`` 3, ``target_face`` 4, ``bottom`` 5,
``symmetry_x`` 6, ``symmetry_y`` 7.
"""

from __future__ import annotations

import basix.ufl
import numpy as np
from dolfinx import mesh as dmesh

from mpi4py import MPI

from fenics_contact.scene.build import BodyMesh

W = H = 0.5
FACETS = {"top": 2, "striker_face": 3, "target_face": 4, "bottom": 5, "symmetry_x": 6,
          "symmetry_y": 7}


def _half(gmsh, z0: float, h: float) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and tetrahedra of the block [0, W/2] x [0, W] x [z0, z0 + H] at size h."""
    gmsh.model.add(f"half_{z0}")
    gmsh.model.occ.addBox(0.0, 0.0, z0, W / 2, W, H)
    gmsh.model.occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMin", h)
    gmsh.option.setNumber("Mesh.MeshSizeMax", h)
    gmsh.model.mesh.generate(3)
    tags, coords, _ = gmsh.model.mesh.getNodes()
    index = np.zeros(int(tags.max()) + 1, np.int64)
    index[tags.astype(np.int64)] = np.arange(tags.size)
    _, _, nodes = gmsh.model.mesh.getElements(3)
    tets = index[nodes[0].astype(np.int64).reshape(-1, 4)]
    gmsh.model.remove()
    return coords.reshape(-1, 3), tets


def _mirrored(x: np.ndarray, tets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The half and its mirror image about x = W/2, sharing the nodes on that plane."""
    on_plane = np.abs(x[:, 0] - W / 2) < 1e-12
    image = x[~on_plane] * [-1.0, 1.0, 1.0] + [W, 0.0, 0.0]
    node = np.where(on_plane, np.arange(len(x)), len(x) + np.cumsum(~on_plane) - 1)
    # the mirror turns the tetrahedra inside out: swap two vertices
    return np.vstack([x, image]), np.vstack([tets, node[tets][:, [0, 2, 1, 3]]])


def mirrored_blocks(h_upper: float = 0.125, h_lower: float = 0.17,
                    comm: MPI.Comm = MPI.COMM_WORLD) -> BodyMesh:
    """The two blocks, each the mirror image of its half about x = W/2 (see module)."""
    from fenics_contact.scene.meshing import gmsh_session

    x = np.zeros((0, 3))
    cells = np.zeros((0, 4), np.int64)
    body = np.zeros(0, np.int32)
    if comm.rank == 0:
        with gmsh_session() as (gmsh, _):
            gmsh.option.setNumber("General.Terminal", 0)
            upper = _mirrored(*_half(gmsh, H, h_upper))
            lower = _mirrored(*_half(gmsh, 0.0, h_lower))
        x = np.vstack([upper[0], lower[0]])
        cells = np.vstack([upper[1], lower[1] + len(upper[0])])
        body = np.repeat(np.array([1, 2], np.int32), [len(upper[1]), len(lower[1])])
    element = basix.ufl.element("Lagrange", "tetrahedron", 1, shape=(3,))
    domain = dmesh.create_mesh(comm, cells, element, x)
    n_cells = domain.topology.index_map(3).size_local
    original = np.asarray(domain.topology.original_cell_index)[:n_cells]
    body = comm.bcast(body, root=0)
    cell_tags = dmesh.meshtags(domain, 3, np.arange(n_cells, dtype=np.int32), body[original])
    domain.topology.create_connectivity(2, 3)
    facets = dmesh.exterior_facet_indices(domain.topology)
    mid = dmesh.compute_midpoints(domain, 2, facets)
    f2c = domain.topology.connectivity(2, 3)
    owner = np.array([cell_tags.values[f2c.links(f)[0]] for f in facets], np.int32)
    values = np.zeros(facets.size, np.int32)

    def near(axis: int, value: float) -> np.ndarray:
        return np.abs(mid[:, axis] - value) < 1e-9

    values[near(2, 2 * H)] = FACETS["top"]
    values[near(2, H) & (owner == 1)] = FACETS["striker_face"]
    values[near(2, H) & (owner == 2)] = FACETS["target_face"]
    values[near(2, 0.0)] = FACETS["bottom"]
    values[near(0, 0.0)] = FACETS["symmetry_x"]
    values[near(1, 0.0)] = FACETS["symmetry_y"]
    keep = values > 0
    facet_tags = dmesh.meshtags(domain, 2, facets[keep], values[keep])
    return BodyMesh(domain, facet_tags, dict(FACETS), cell_tags, {"striker": 1, "target": 2})
