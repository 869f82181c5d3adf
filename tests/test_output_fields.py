"""The fields written for ParaView hold the solver's numbers, on the right nodes.

Two bodies meshed touching have a vertex of each body at every matching
interface point: the striker's nodal values must land on the striker's
vertex, never on the target's vertex at the same place.
"""

from pathlib import Path

import numpy as np
import pytest
from dolfinx import fem

from mpi4py import MPI

from fenics_contact import build_problem, load_scene, make_strategy, solve_load_path
from fenics_contact.output.io import SurfaceToBody
from fenics_contact.solvers.base import SolverSettings

SCENES = Path(__file__).parent.parent / "scenes"
MESHES = Path(__file__).parent.parent / "meshes"
#: Uniform patch-test pressure: uniaxial plane strain, E = 200, nu = 0.3, strain 0.01.
PATCH_PRESSURE = -200.0 / (1 - 0.3**2) * 0.01


def _matching_blocks(tmp_path: Path, extra: str = "") -> Path:
    """block_on_block_node_to_segment.toml, 8 divisions on both sides: coincident vertices."""
    text = (SCENES / "block_on_block_node_to_segment.toml").read_text()
    text = text.replace('"../meshes/block_on_block.geo"', f'"{MESHES / "block_on_block.geo"}"')
    text = text.replace("n_lower = 11", "n_lower = 8").replace("steps = 2", "steps = 1")
    path = tmp_path / "blocks.toml"
    path.write_text(text + extra)
    return path


def _striker_dofs(problem, W: fem.FunctionSpace) -> np.ndarray:
    """Scalar P1 dofs of the vertices of the striker's contact facets."""
    fdim = problem.domain.topology.dim - 1
    return fem.locate_dofs_topological(W, fdim, problem.surface.facets)


@pytest.mark.mpi
def test_surface_values_land_on_the_striker_vertices(tmp_path) -> None:
    problem = build_problem(load_scene(_matching_blocks(tmp_path)), MPI.COMM_WORLD)
    mapper = SurfaceToBody(problem)
    # every multiplier node maps to a vertex of a striker contact facet, one to one
    striker = _striker_dofs(problem, mapper.W)
    assert np.isin(mapper.body_dofs, striker).all()
    assert np.unique(mapper.body_dofs).size == mapper.body_dofs.size
    # the interface has coincident vertices of the other body at the same points
    coords = mapper.W.tabulate_dof_coordinates()
    on_interface = np.flatnonzero(np.isclose(coords[:, 1], 0.5))
    comm = problem.comm
    owned_dofs = mapper.W.dofmap.index_map.size_local
    n_interface = comm.allreduce(int(np.sum(on_interface < owned_dofs)), op=MPI.SUM)
    assert n_interface == 2 * problem.surface.num_dofs
    # solved: the written pressure equals the patch pressure at every striker node
    strategy = make_strategy("gnrm", problem, SolverSettings(atol=1e-10))
    record = solve_load_path(strategy, 1)
    assert record.status == "converged"
    state = problem.contact_state()
    q = fem.Function(problem.Q)
    q.x.array[: state.pressure.size] = state.pressure
    q.x.scatter_forward()
    written = mapper.field("contact_pressure", q.x.array).x.array
    owned = striker[striker < owned_dofs]
    np.testing.assert_allclose(written[owned], PATCH_PRESSURE, rtol=1e-8)
    # and the target's vertices at the same points read zero
    target = np.setdiff1d(on_interface, striker)
    assert comm.allreduce(target.size, op=MPI.SUM) > 0
    assert np.all(written[target] == 0.0)


def test_fields_at_a_node_two_contacts_share(tmp_path) -> None:
    """block_floor_wall: the corner node lies on the floor's and the wall's facets.

    Pressures add there, the gap is the smaller, active and stick/slip the
    larger: a node in contact with the wall but open to the floor was
    written open with the floor's gap (a user's 3D pair and wall: the four
    edge nodes of the peak pressure drawn open).
    """
    from fenics_contact.output.io import ContactsToBody
    from fenics_contact.output.xdmf import SHARED_NODE

    problem = build_problem(load_scene(Path(__file__).parents[1] / "scenes"
                                       / "block_floor_wall.toml"))
    mapper = ContactsToBody(problem)
    sizes = [c.lam.x.index_map.size_local for c in problem.contacts]
    assert len(sizes) == 2
    first, second = np.full(sizes[0], 1.0), np.full(sizes[1], 2.0)
    dofs = [m.body_dofs for m, _ in mapper._maps]
    shared = np.intersect1d(dofs[0], dofs[1])
    only = np.setdiff1d(dofs[0], dofs[1])
    assert MPI.COMM_WORLD.allreduce(shared.size) >= 1  # the corner
    expected = {"add": 3.0, "min": 1.0, "max": 2.0, "last": 2.0}
    for combine, value in expected.items():
        field = mapper.field("f", [first, second], combine=combine)
        assert np.all(field.x.array[shared] == value), combine
        assert np.all(field.x.array[only] == 1.0), combine
    assert SHARED_NODE == {"contact_pressure": "add", "gap": "min", "active": "max",
                           "stick_slip": "max"}
