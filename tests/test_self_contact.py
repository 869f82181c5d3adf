"""Self-contact: the search that skips a node's neighbourhood, and the crushed tube scene.

``scenes/tube_crush.toml`` (half model, neo-Hookean, R_out = 1, wall 0.1,
4 x 54 x 2 triangles through and along the wall) is flattened between two
rigid plates until the upper inner quarter closes on the lower one (a
self-contact [[pair]] of the tube with itself).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
import ufl
from dolfinx import fem, la

from mpi4py import MPI

from fenics_contact.model.search import facet_normals
from fenics_contact.model.self_contact import closest_facing, neighbourhoods, vertex_normals
from fenics_contact.runner import run_scene
from fenics_contact.scene.schema import SceneError, load_scene

SCENE = Path(__file__).parent.parent / "scenes" / "tube_crush.toml"
WALL = 0.1


def circle(n: int, radius: float = 1.0, inward: bool = True):
    """Vertices and facets of a closed polygon; normals point to the centre when inward."""
    angle = 2 * np.pi * np.arange(n) / n
    X = radius * np.stack([np.cos(angle), np.sin(angle)], axis=1)
    facets = np.stack([np.arange(n), (np.arange(n) + 1) % n], axis=1)
    # perp(b - a) = (t_y, -t_x) points out of a counter-clockwise loop
    return X, facets if not inward else facets[:, ::-1]


def test_the_neighbourhood_is_measured_along_the_surface():
    X, facets = circle(40)
    excluded = neighbourhoods(X, facets, np.array([0, 10, -1]), 3.0).toarray()
    # a vertex touches two facets; 3 facet sizes each way add three more on each side
    assert excluded[0].sum() == 8 and excluded[1].sum() == 8 and excluded[2].sum() == 0
    near = {f for f in range(40) if 0 in facets[f] or 1 in facets[f] or 39 in facets[f]}
    assert near <= set(np.flatnonzero(excluded[0]))
    # a slit: two faces 1e-3 apart in space but far along the surface exclude nothing of each other
    Y = np.array([[0, 0], [1, 0], [2, 0], [2, 1e-3], [1, 1e-3], [0, 1e-3]], float)
    slit = np.array([[0, 1], [1, 2], [2, 3], [3, 4], [4, 5]])
    far = neighbourhoods(Y, slit, np.array([1]), 1.0).toarray()[0]
    assert far.tolist() == [True, True, False, False, False]


def test_a_node_on_a_curved_wall_sees_only_facets_that_face_it():
    """Past its neighbourhood a node's own wall reads it inside (convex) or touching (concave)."""
    Y, outward = circle(40, inward=False)
    convex = Y[outward]
    # convex wall: the first facet past the neighbourhood of vertex 0 reads it inside
    assert np.dot(Y[0] - convex[4, 0], facet_normals(convex)[4]) < 0
    X, facets = circle(40)
    current = X[facets]
    points = X[[0, 5]]
    normal = facet_normals(current)
    # concave wall: it reads it open by the sagitta only, closed once the wall flattens
    assert 0 < np.dot(points[0] - current[4, 0], normal[4]) < 0.25
    excluded = neighbourhoods(X, facets, np.array([0, 5]), 3.0)
    proj = closest_facing(points, -points, current, excluded)
    assert not np.any(excluded.toarray()[[0, 1], proj.facet])
    assert np.all(np.einsum("ij,ij->i", normal[proj.facet], -points) < 0)  # facing
    gap = np.einsum("ij,ij->i", points - current[proj.facet, 0], normal[proj.facet])
    assert np.all(gap > 0.9)  # open: the facing facets lie half a circle away
    # a closed circle seen from outside (normals outward): nothing faces a node, it stays open
    lonely = closest_facing(Y[[0]], Y[[0]], convex, neighbourhoods(Y, outward, np.array([0]), 3.0))
    assert lonely.distance[0] == np.inf  # no partner: the pair lifts its gap (stays open)
    # ... also when it had a partner at the last search (the hysteresis keeps no facet for it)
    again = closest_facing(Y[[0]], Y[[0]], convex, neighbourhoods(Y, outward, np.array([0]), 3.0),
                           previous=np.array([20]))
    assert again.distance[0] == np.inf


def test_a_node_that_loses_every_facet_is_not_held_by_its_previous_one():
    """The fold of a flattened wall: the old facet lies far along its extension.

    A node whose projection falls 14 facet lengths off the only facet that
    faces it has no partner; the hysteresis must not give it back the facet
    it had (its gap to that facet's straight extension would be a false
    penetration).
    """
    facet = np.array([[[0.0, 0.0], [-0.1, 0.0]]])  # normal +y (outward of the lower wall)
    point = np.array([[1.5, -0.002]])  # 0.002 below the extension, 14 lengths past the end
    excluded = neighbourhoods(np.array([[0.0, 0.0], [-0.1, 0.0]]), np.array([[0, 1]]),
                              np.array([-1]), 3.0)
    proj = closest_facing(point, np.array([[0.0, -1.0]]), facet, excluded, previous=np.array([0]))
    assert proj.overshoot[0] > 10
    assert proj.distance[0] == np.inf


def test_a_node_an_iterate_pushed_through_its_facet_stays_paired():
    """Behind its facet by more than the search depth: kept when it had that facet.

    One Newton iterate of a closing wall (24 layers, facets of 0.0045) took
    nodes through the opposite wall by several facet sizes; without a
    partner they were lifted and open, and the walls passed through each
    other (280 of 325 nodes lost their partner in the tube's closing step).
    A node keeps the facet it had down to ``KEPT_DEPTH`` facet sizes; a new
    facet still needs ``DEPTH``, and nothing is kept deeper than that (the
    far side of a closed surface).
    """
    from fenics_contact.model.self_contact import DEPTH, KEPT_DEPTH

    X = np.stack([np.linspace(1.0, -1.0, 21), np.zeros(21)], axis=1)  # normal +y
    facets = np.stack([np.arange(20), np.arange(1, 21)], axis=1)
    current = X[facets]
    size = 0.1
    excluded = neighbourhoods(X, facets, np.array([-1, -1, -1]), 3.0)
    depths = np.array([0.5 * (DEPTH + KEPT_DEPTH), 0.5 * DEPTH, 1.2 * KEPT_DEPTH]) * size
    points = np.stack([np.full(3, 0.05), -depths], axis=1)
    normals = np.tile([0.0, -1.0], (3, 1))
    below = facets.shape[0] // 2 - 1  # the facet over x = 0.05 (x runs from 1 to -1)
    assert current[below, 1, 0] < 0.05 < current[below, 0, 0]
    fresh = closest_facing(points, normals, current, excluded)
    assert fresh.distance[0] == np.inf and fresh.distance[2] == np.inf
    assert fresh.facet[1] == below and fresh.distance[1] == pytest.approx(depths[1])
    kept = closest_facing(points, normals, current, excluded, previous=np.full(3, below))
    assert kept.facet[0] == below and kept.distance[0] == pytest.approx(depths[0])
    assert kept.distance[2] == np.inf


def test_the_search_in_blocks_of_points_is_the_search_at_once(monkeypatch):
    """Memory is bounded by comparing blocks of points with every facet: same answer."""
    import fenics_contact.model.self_contact as self_contact

    X, facets = circle(40)
    wavy = X * (1.0 + 0.2 * np.sin(3 * np.arctan2(X[:, 1], X[:, 0])))[:, None]
    current = wavy[facets]
    sources = np.arange(0, 40, 3)
    points = wavy[sources] + 0.05 * np.cos(np.arange(sources.size))[:, None]
    normals = vertex_normals(current, facets, 40)[sources]
    excluded = neighbourhoods(wavy, facets, sources, 2.0)
    previous = (np.arange(sources.size) * 7) % 40
    whole = closest_facing(points, normals, current, excluded, previous=previous)
    monkeypatch.setattr(self_contact, "PAIRS", 90)  # blocks of 2 points
    blocks = closest_facing(points, normals, current, excluded, previous=previous)
    for name in ("facet", "xi", "distance", "overshoot"):
        np.testing.assert_array_equal(getattr(blocks, name), getattr(whole, name))


@pytest.fixture(scope="module")
def crushed(tmp_path_factory):
    out = tmp_path_factory.mktemp("tube") / "out"
    return run_scene(load_scene(SCENE), out, comm=MPI.COMM_SELF, pictures=False)


def test_the_inner_wall_closes_without_penetration(crushed):
    assert crushed.path.converged
    steps = crushed.summary["steps"]
    inner = [s["contacts"]["inner"] for s in steps]
    assert max(s["max_penetration"] for s in inner) <= 1e-8 * WALL
    first = next(i for i, s in enumerate(inner) if s["active_count"] > 0)
    assert first > 40 and inner[-1]["active_count"] >= 30  # closes late, then spreads
    # the plates take the crushing force; the wall contact carries most of it at the end
    last = steps[-1]["contacts"]
    assert 0.7 * last["top"]["normal_force"] < last["inner"]["normal_force"]
    state = crushed.problem.contact_states()["inner"]
    assert state.max_penetration <= 1e-8 * WALL


def test_every_force_balances(crushed):
    """Plates (vertical) and the self-contact's two sides (they cancel) to 1e-10."""
    problem = crushed.problem
    states = problem.contact_states()
    top, bottom = states["top"].contact_force, states["bottom"].contact_force
    assert abs(top - bottom) <= 1e-10 * top
    contact = next(c for c in problem.contacts if c.name == "inner")
    v = ufl.TestFunction(problem.V)
    form = fem.form(ufl.derivative(contact.lagrangian(), problem.u, v),
                    entity_maps=contact.surface.entity_maps)
    vec = fem.assemble_vector(form)
    vec.scatter_reverse(la.InsertMode.add)
    n = problem.V.dofmap.index_map.size_local
    on_striker = -vec.array[: 2 * n].reshape(-1, 2).sum(axis=0)
    on_target = contact.target_force().x.array[: 2 * n].reshape(-1, 2).sum(axis=0)
    # the upper quarter is pushed up by the lower one
    assert on_striker[1] > 0.9 * states["inner"].contact_force
    assert np.allclose(on_striker + on_target, 0.0, rtol=0, atol=1e-10 * top)


def test_no_node_is_assigned_a_facet_of_its_own_neighbourhood(crushed):
    pair = next(c for c in crushed.problem.contacts if c.name == "inner").pair
    rows = np.arange(pair.n_owned)
    assert not np.any(pair.excluded.toarray()[rows, pair.assignment[rows]])
    # the fold: the quarters meet there, so those nodes exclude facets of the target
    assert pair.excluded.sum(axis=1).max() >= 3


def test_self_contact_mistakes_are_named(tmp_path):
    text = SCENE.read_text().replace('"../meshes/', f'"{SCENE.parent.parent / "meshes"}/')
    path = tmp_path / "tube.toml"
    path.write_text(text.replace("self_contact = true\n", ""))
    with pytest.raises(SceneError, match=r"neighbourhood.*self_contact = true"):
        load_scene(path)
    path.write_text(text.replace("self_contact = true\nneighbourhood = 3.0\n", ""))
    with pytest.raises(SceneError, match=r"1 \[\[body\]\] block\(s\); \[\[pair\]\] 'inner' is "
                       r"a contact pair between two bodies, and a contact pair needs two bodies: "
                       r"add a \[\[body\]\] per body.*or self_contact = true in \[\[pair\]\] "
                       r"'inner'"):
        load_scene(path)
    path.write_text(text.replace("neighbourhood = 3.0", "neighbourhood = -1.0"))
    with pytest.raises(SceneError, match="neighbourhood"):
        load_scene(path)
    path.write_text(text.replace("[[pair]]\nname", "[pairing]\nautomatic = true\n\n[[pair]]\nname"))
    with pytest.raises(SceneError, match=r"\[pairing\] automatic = true pairs every body with "
                       r"every other, and a contact pair needs two bodies.*or remove \[pairing\]"):
        load_scene(path)
    bare = re.sub(r"^\[\[pair\]\]\n.*?\n\n", "", text, flags=re.S | re.M)
    path.write_text(re.sub(r"^\[\[obstacle\]\]\n.*?\n\n", "", bare, flags=re.S | re.M))
    with pytest.raises(SceneError, match=r"no contact: add a \[\[pair\]\] with striker and "
                       r"target facet tags, \[pairing\] automatic = true, or an \[\[obstacle\]\]"):
        load_scene(path)


def _coarse_tube_alone(tmp_path: Path, form: str) -> Path:
    """The crushed tube on a coarse mesh, pressed a little, without its self-contact pair.

    ``form`` "body": one [[body]] block; "material": a [material] table.
    """
    text = SCENE.read_text().replace('"../meshes/', f'"{SCENE.parent.parent / "meshes"}/')
    text = re.sub(r"^\[\[pair\]\]\n.*?\n\n", "", text, flags=re.S | re.M)
    text = (text.replace("n_t = 4, n_q = 54", "n_t = 2, n_q = 12")
            .replace("steps = 50", "steps = 3").replace("-1.81", "-0.3"))
    if form == "material":
        text = text.replace('[[body]]\nname = "tube"\ntag = "tube"\n', "[material]\n")
    path = tmp_path / f"tube_{form}.toml"
    path.write_text(text)
    return path


def test_one_body_with_obstacles_only_runs_as_the_material_form(tmp_path):
    """A [[body]] scene with no [[pair]] (obstacles only) was refused: 'a contact pair needs
    two bodies'. It is the [material] scene with its body named: the same steps and forces."""
    body = load_scene(_coarse_tube_alone(tmp_path, "body"))
    plain = load_scene(_coarse_tube_alone(tmp_path, "material"))
    assert body.pairs == () and [b.name for b in body.bodies] == ["tube"]
    assert (body.obstacle, body.contact) == (plain.obstacle, plain.contact)
    runs = [run_scene(s, tmp_path / s.path.stem, comm=MPI.COMM_SELF, pictures=False)
            for s in (body, plain)]
    assert all(r.path.converged for r in runs)
    forces = [[s["contact_force"] for s in r.summary["steps"]] for r in runs]
    assert len(forces[0]) == 3 and forces[0][-1] > 0
    assert forces[0] == pytest.approx(forces[1], rel=1e-10)
    assert [r.summary["iterations"] for r in runs] == [runs[1].summary["iterations"]] * 2
    assert runs[0].summary["bodies"][0]["name"] == "tube"
    assert [o["name"] for o in runs[0].summary["obstacles"]] == ["bottom", "top"]


@pytest.mark.mpi
def test_the_crushed_tube_is_the_same_on_every_process_count(tmp_path):
    """Serial: plate force 8.746237917567147 and 49 inner nodes in contact (2 ranks: the same).

    The exact contact set of each Newton step (the scenes' default): the state a
    100-step path reaches too (8.7462268). The sign rule's 50-step path ends at
    8.610074878945737 (and 8.613757270912824 from the extrapolated start):
    docs/contacts.md.
    """
    out = Path(MPI.COMM_WORLD.bcast(str(tmp_path), root=0)) / "out"
    outcome = run_scene(load_scene(SCENE), out, pictures=False)
    assert outcome.path.converged
    states = outcome.problem.contact_states()
    assert states["top"].contact_force == pytest.approx(8.746237917567147, rel=1e-8)
    assert states["inner"].active_count == 49
    assert states["inner"].max_penetration <= 1e-8 * WALL


def test_a_self_contact_pair_on_two_bodies_is_refused(tmp_path):
    from fenics_contact.scene.build import build_problem

    shipped = SCENE.parent / "cylinder_between_plates.toml"
    text = shipped.read_text().replace('"../meshes/', f'"{SCENE.parent.parent / "meshes"}/')
    path = tmp_path / "cbp.toml"
    path.write_text(text.replace('target = "right_side"\n',
                                 'target = "right_side"\nself_contact = true\n'))
    with pytest.raises(SceneError, match=r"\[\[pair\]\] 'side' has self_contact = true, but "
                       r"striker = 'left_side' and target = 'right_side' lie on bodies"):
        build_problem(load_scene(path), MPI.COMM_SELF)


def test_the_tube_in_3d_follows_the_plane_strain_section(crushed, tmp_path):
    """Self-contact in 3D: the section extruded (tetrahedra, u_z = 0 on both faces).

    The plates' force per unit depth follows the 2D scene's through the
    crush (measured: 0.2-1.3 %, 2.5 % the step before the inner wall
    touches) and in the closed state (measured 0.04 %); the inner wall
    closes on about the same nodes (2 rows through the depth), without
    penetration, and the plates balance.
    """
    scene3d = SCENE.with_name("tube_crush_3d.toml")
    outcome = run_scene(load_scene(scene3d), tmp_path / "out", comm=MPI.COMM_SELF,
                        pictures=False)
    assert outcome.path.converged
    depth = 0.1
    plane = np.array([s.contacts["top"]["normal_force"] for s in crushed.path.steps])
    solid = np.array([s.contacts["top"]["normal_force"] for s in outcome.path.steps]) / depth
    assert plane.size == solid.size == 50
    assert np.all(np.abs(solid[:-1] - plane[:-1]) <= 0.03 * plane[:-1])
    # closed: 3D ends where no node is held past a concave corner, 2D where one is (1.5 %)
    assert solid[-1] == pytest.approx(plane[-1], rel=0.02)
    states = outcome.problem.contact_states()
    rows = crushed.problem.contact_states()["inner"].active_count
    assert abs(states["inner"].active_count - 2 * rows) <= 2  # measured 99 against 2 x 49
    inner = states["inner"]
    assert inner.constraint_penetration <= 1e-8 * WALL
    # by closest point over the lower wall: nodes held on their facets past its bent edges,
    # 5.7e-7 (5.5e-6 h) at most (measured)
    h = next(c for c in outcome.problem.contacts if c.name == "inner").surface.h
    assert inner.max_penetration <= 1e-5 * h
    top, bottom = states["top"].contact_force, states["bottom"].contact_force
    assert abs(top - bottom) <= 1e-10 * top


def test_the_wall_pressure_scatter_is_blamed_on_the_bulk_mesh(crushed):
    """Inner wall 20 %, plates 17 % alike (4 layers through the wall): not the pairing."""
    said = [w for w in crushed.summary["warnings"] if "scatter from node to node" in w]
    assert len(said) == 1
    assert re.search(r"'bottom' \(1[5-9]%\) and 'top' \(1[5-9]%\)", said[0])
    assert "bulk mesh" in said[0]
    assert "mortar\"" not in said[0]
