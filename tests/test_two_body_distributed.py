"""Node-to-segment pairs without a gathered target surface (issue 21, item 4).

Each rank keeps only the target facets that can hold the closest point of
its striker nodes (``fenics_contact/model/target_surface.py``). The answers
are those of the whole surface: the same Newton counts and forces as the
serial run (``make test`` runs the ``mpi`` tests again on 2 processes).
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from mpi4py import MPI

from benchmarks import cases
from fenics_contact import load_scene
from fenics_contact.model.search import SurfaceSearch
from fenics_contact.model.target_surface import _outside_distance
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings

ROOT = Path(__file__).resolve().parents[1]
#: Serial run of the coarse hemispheres (h_contact 0.04, h_far 0.12, 2 steps):
#: Newton iterations per step and the contact force, measured with the whole
#: target surface on the rank (before the target was distributed).
SERIAL_ITERATIONS = [4, 3]
SERIAL_FORCE = 0.08028729628296515


def _hemispheres():
    scene = load_scene(ROOT / "scenes" / "two_hemispheres_3d_node_to_segment.toml")
    mesh = dataclasses.replace(scene.mesh, parameters={
        **scene.mesh.parameters, "h_contact": 0.04, "h_far": 0.12})
    return cases.build(dataclasses.replace(scene, mesh=mesh), 1.0, comm=MPI.COMM_WORLD)


@pytest.fixture(scope="module")
def hemispheres() -> dict:
    problem = _hemispheres()
    strategy = make_strategy("gnrm", problem, SolverSettings())
    its = []
    for i in (1, 2):
        problem.set_load(i / 2)
        result = strategy.solve()
        assert result.converged
        its.append(result.iterations)
    return {"problem": problem, "iterations": its}


@pytest.mark.mpi
def test_two_body_3d_gives_the_serial_counts_and_force(hemispheres: dict) -> None:
    assert hemispheres["iterations"] == SERIAL_ITERATIONS
    force = hemispheres["problem"].contact_state().contact_force
    assert force == pytest.approx(SERIAL_FORCE, rel=1e-10)


@pytest.mark.mpi
def test_hemispheres_keep_part_of_the_target(hemispheres: dict) -> None:
    """The far striker nodes need only the target's upper band: part of its facets."""
    pair = hemispheres["problem"].pair
    comm = hemispheres["problem"].comm
    kept = pair.target_blocks.shape[0]
    assert comm.allreduce(int(kept < pair.target.num_global), op=MPI.SUM) >= 1
    _check_kept(hemispheres["problem"])


def _check_kept(problem) -> None:
    """Every assigned facet is kept; the kept vertices' displacements are the owners' values."""
    pair = problem.pair
    kept = pair.target_blocks.shape[0]
    assert np.all((pair.assignment >= 0) & (pair.assignment < kept))
    w = pair.target_displacements()
    lo, hi = problem.V.dofmap.index_map.local_range
    mine = (pair.vertices >= lo) & (pair.vertices < hi)
    u = problem.u.x.array.reshape(-1, 3)
    np.testing.assert_array_equal(w[mine], u[pair.vertices[mine] - lo])


#: Wide flat blocks (block_on_block_3d.geo, 1 x 1 x 0.2 each, node-to-segment),
#: so that a 2-process partition cuts both bodies: Newton iterations per step and
#: force measured serially with the whole target on the rank.
BLOCKS_ITERATIONS = [4, 2]
BLOCKS_FORCE = 4.996737475946084


@pytest.mark.mpi
def test_striker_on_both_ranks_keeps_part_of_the_target(tmp_path) -> None:
    text = (ROOT / "scenes" / "block_on_block_3d.toml").read_text()
    for old, new in (('discretisation = "mortar"', 'discretisation = "node-to-segment"'),
                     ("h_upper = 0.125, h_lower = 0.17",
                      "width = 1.0, height = 0.2, h_upper = 0.08, h_lower = 0.11"),
                     ('"../meshes/', f'"{ROOT / "meshes"}/')):
        assert old in text
        text = text.replace(old, new)
    comm = MPI.COMM_WORLD
    folder = Path(comm.bcast(str(tmp_path) if comm.rank == 0 else None))
    path = folder / f"blocks_{comm.rank}.toml"
    path.write_text(text)
    problem = cases.build(load_scene(path), 1.0, comm=comm)
    strategy = make_strategy("gnrm", problem, SolverSettings())
    its = []
    for i in (1, 2):
        problem.set_load(i / 2)
        its.append(strategy.solve().iterations)
    assert its == BLOCKS_ITERATIONS
    assert problem.contact_state().contact_force == pytest.approx(BLOCKS_FORCE, rel=1e-10)
    _check_kept(problem)
    pair = problem.pair
    if comm.size > 1:
        # the striker spans every rank, and some rank holds only part of the target
        assert comm.allreduce(int(pair.n_owned > 0), op=MPI.SUM) == comm.size
        partial = int(pair.target_blocks.shape[0] < pair.target.num_global)
        assert comm.allreduce(partial, op=MPI.SUM) >= 1


def test_search_matches_brute_force_on_a_closed_surface() -> None:
    """The ball-query search assigns what the corner rule over every facet assigns."""
    from scipy.spatial import ConvexHull

    rng = np.random.default_rng(1)
    p = rng.normal(size=(400, 3))
    p /= np.linalg.norm(p, axis=1)[:, None]
    tris = p[ConvexHull(p).simplices]
    points = rng.normal(size=(300, 3))
    points *= (rng.uniform(0.3, 3.0, 300) / np.linalg.norm(points, axis=1))[:, None]
    search = SurfaceSearch(tris)
    got = search.closest(points)
    every = np.broadcast_to(np.arange(tris.shape[0]), (points.shape[0], tris.shape[0]))
    facet, _, dist, _ = search._pick(points, every)
    np.testing.assert_array_equal(got.facet, facet)
    np.testing.assert_array_equal(got.distance, dist)


def test_outside_distance_of_boxes() -> None:
    """Distance to the part of the target's box outside the kept box (length)."""
    target = np.array([[0.0, 0.0, -1.0], [1.0, 1.0, 0.0]])
    box = np.array([[-0.5, -0.5, -0.3], [1.5, 1.5, 1.5]])
    points = np.array([[0.5, 0.5, 1.0], [0.5, 0.5, 0.0], [2.0, 0.5, -0.5]])
    np.testing.assert_allclose(_outside_distance(points, target, box), [1.3, 0.3, 1.0])
    everything = np.array([[-2.0, -2.0, -2.0], [2.0, 2.0, 2.0]])
    assert np.all(np.isinf(_outside_distance(points, target, everything)))
