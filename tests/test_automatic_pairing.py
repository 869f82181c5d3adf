"""[pairing] automatic = true gives the answer of the hand-declared [[pair]] blocks.

On the stack of three blocks the bottom and top blocks are pruned by their
bounding boxes, the two interfaces are found with the hand-declared striker
(equal facet sizes: the body given later strikes), and every contact's
force and every nodal pressure equal the hand-declared run's. The same on
the cylinder between two plates (the left cylinder's surface is finer).
The faces of a symmetry cut are no contact surface: before, the stack's
node on the cut x = 0 took half a cut facet into its lumped area and its
pressure read -1.0989 against the declared pair's -2.1978.
"""

from __future__ import annotations

import dataclasses
import tomllib
from pathlib import Path

import numpy as np
import pytest

from mpi4py import MPI

from fenics_contact.runner import run_scene
from fenics_contact.scene.build import build_problem
from fenics_contact.scene.schema import SceneError, load_scene, scene_from_data

SCENES = Path(__file__).parent.parent / "scenes"


def automatic(name: str, **pairing) -> tuple:
    """The shipped scene and its variant with [pairing] automatic = true instead of [[pair]].

    The declared pairs are made node-to-segment, as the automatic ones are.
    """
    path = SCENES / name
    data = tomllib.loads(path.read_text())
    data.pop("pair")
    data["pairing"] = {"automatic": True, **pairing}
    hand = load_scene(path)
    hand = dataclasses.replace(hand, pairs=tuple(
        dataclasses.replace(p, discretisation="node-to-segment") for p in hand.pairs))
    return hand, scene_from_data(data, path)


def pressures(problem, name: str, force: bool = False) -> dict[tuple, float]:
    """Nodal pressure (or force: pressure times lumped area) of the active nodes, by place."""
    contact = next(c for c in problem.contacts if c.name == name)
    state = problem.contact_states()[name]
    x = contact.nodal_coordinates()
    value = state.pressure * (contact.surface.lumped_area if force else 1.0)
    return {tuple(np.round(p[:2], 9)): v for p, v in zip(x, value, strict=True) if v < 0}


def compare(hand, auto, tmp_path: Path) -> tuple:
    runs = [run_scene(s, tmp_path / n, comm=MPI.COMM_SELF, pictures=False)
            for s, n in ((hand, "hand"), (auto, "auto"))]
    assert all(r.path.converged for r in runs)
    return tuple(r.problem for r in runs)


def test_stack_automatic_pairs_match_the_declared_ones(tmp_path):
    hand, auto = automatic("stack_3_blocks.toml")
    problem_h, problem_a = compare(hand, auto, tmp_path)
    states_h, states_a = problem_h.contact_states(), problem_a.contact_states()
    # bottom and top are 0.4 apart (more than the reach 0.012 + 0.108): pruned
    assert sorted(states_a) == sorted(states_h) == ["floor", "middle-on-bottom", "top-on-middle"]
    for name, state in states_h.items():
        assert states_a[name].contact_force == pytest.approx(state.contact_force, rel=1e-8)
        assert states_a[name].active_count == state.active_count == 11
        ph, pa = pressures(problem_h, name), pressures(problem_a, name)
        assert sorted(ph) == sorted(pa)
        # the same pressure at every node but the striker's free corner x = 1, whose lumped
        # area takes in half a side facet too: there the nodal force is the same. The
        # node on the symmetry cut x = 0 reads the declared pressure (the cut is no surface)
        corners = [k for k in ph if k[0] == 1.0]
        assert len(corners) == (1 if name != "floor" else 0) or name == "floor"
        inner = [k for k in ph if k not in corners or name == "floor"]
        assert any(k[0] == 0.0 for k in inner)
        assert np.allclose([pa[k] for k in inner], [ph[k] for k in inner], rtol=1e-8, atol=0)
        fh, fa = pressures(problem_h, name, True), pressures(problem_a, name, True)
        assert np.allclose([fa[k] for k in fh], list(fh.values()), rtol=1e-8, atol=0)
    # the automatic contacts carry multipliers on the free sides too (open there), none on
    # the cut: 14 striker nodes against the declared 11 (17 when the cut was a surface)
    for name in ("middle-on-bottom", "top-on-middle"):
        auto_c = next(c for c in problem_a.contacts if c.name == name)
        hand_c = next(c for c in problem_h.contacts if c.name == name)
        assert auto_c.Q.dofmap.index_map.size_global == 14
        assert hand_c.Q.dofmap.index_map.size_global == 11


def test_only_symmetry_cuts_that_bound_the_mesh_are_set_aside():
    """u_x = 0 on x = 0 with the mesh on one side is a cut; on a plane through the mesh
    (a roller with material beyond it), or with u_x = 0.1, or holding both components, not."""
    from dolfinx import mesh

    from fenics_contact.model.automatic_pairing import symmetry_cut_facets
    from fenics_contact.model.body import PrescribedDisplacement

    domain = mesh.create_rectangle(MPI.COMM_SELF, [[0.0, 0.0], [2.0, 1.0]], [4, 2])
    domain.topology.create_connectivity(1, 2)

    def on(x0: float) -> np.ndarray:
        return mesh.locate_entities(domain, 1, lambda x: np.isclose(x[0], x0))

    def cut(facets: np.ndarray, value: tuple) -> int:
        return symmetry_cut_facets(domain, [PrescribedDisplacement(facets, value)]).size

    assert cut(on(0.0), (0.0, None)) == on(0.0).size == 2
    assert cut(on(2.0), (0.0, None)) == 2  # the far side bounds the mesh too
    assert cut(on(1.0), (0.0, None)) == 0  # the mesh lies on both sides
    assert cut(on(0.0), (0.1, None)) == 0  # a moving roller: no symmetry
    assert cut(on(0.0), (0.0, 0.0)) == 0  # clamped: may be struck


def test_cylinder_automatic_pair_matches_the_declared_one(tmp_path):
    hand, auto = automatic("cylinder_between_plates.toml")
    problem_h, problem_a = compare(hand, auto, tmp_path)
    states_h, states_a = problem_h.contact_states(), problem_a.contact_states()
    assert sorted(states_a) == ["floor", "left-on-right", "press"]
    for name_h, name_a in (("side", "left-on-right"), ("floor", "floor"), ("press", "press")):
        assert states_a[name_a].contact_force == pytest.approx(
            states_h[name_h].contact_force, rel=1e-8), name_h
        assert states_a[name_a].active_count == states_h[name_h].active_count
    ph, pa = pressures(problem_h, "side"), pressures(problem_a, "left-on-right")
    assert sorted(ph) == sorted(pa) and len(ph) == states_h["side"].active_count
    assert np.allclose([pa[k] for k in ph], list(ph.values()), rtol=1e-8, atol=0)


def test_pairing_mistakes_are_named(tmp_path):
    path = SCENES / "stack_3_blocks.toml"
    data = tomllib.loads(path.read_text())
    data.pop("pair")
    data["pairing"] = {"automatic": False}
    with pytest.raises(SceneError, match=r"\[pairing\] automatic = False: set automatic = true"):
        scene_from_data(data, path)
    data["pairing"] = {"automatic": True, "margins": 0.1}
    with pytest.raises(SceneError, match=r"unknown key 'margins' at \[pairing\].*'margin'"):
        scene_from_data(data, path)
    data["pairing"] = {"automatic": True, "margin": -1.0}
    with pytest.raises(SceneError, match=r"\[pairing\] margin = -1.0: must be > 0"):
        scene_from_data(data, path)
    # the boxes, each enlarged by the reach (0.012 + margin), decide which bodies pair:
    # bottom and top are 0.4 apart
    names = {}
    for margin in (0.18, 0.2):
        data["pairing"] = {"automatic": True, "margin": margin}
        problem = build_problem(scene_from_data(data, path), MPI.COMM_SELF)
        names[margin] = sorted(c.name for c in problem.contacts)
    assert names[0.18] == ["floor", "middle-on-bottom", "top-on-middle"]
    assert names[0.2] == ["floor", "middle-on-bottom", "top-on-bottom", "top-on-middle"]
    # a body pair joined by a [[pair]] is left to it: automatic pairing adds the others
    data = tomllib.loads(path.read_text())
    data["pair"] = [{**data["pair"][0], "name": "declared"}]
    data["pairing"] = {"automatic": True}
    problem = build_problem(scene_from_data(data, path), MPI.COMM_SELF)
    assert [c.name for c in problem.contacts] == ["declared", "middle-on-bottom", "floor"]


def test_a_node_touching_two_bodies_has_a_multiplier_in_each_contact(tmp_path):
    """The top block's underside node at the joint of the two blocks it rests on."""
    outcome = run_scene(load_scene(SCENES / "junction_blocks.toml"), tmp_path / "out",
                        comm=MPI.COMM_SELF, pictures=False)
    assert outcome.path.converged
    problem = outcome.problem
    states = problem.contact_states()
    assert sorted(states) == ["left-floor", "right-floor", "right-on-left", "top-on-left",
                              "top-on-right"]
    junction = (1.0, 0.4)
    on_left, on_right = pressures(problem, "top-on-left"), pressures(problem, "top-on-right")
    assert junction in on_left and junction in on_right  # pressed in both contacts
    assert max(on_left) == junction and min(on_right) == junction  # and the last of each
    press = -problem.reaction(problem.solid.prescribed[2].facets)[1]
    floors = states["left-floor"].contact_force + states["right-floor"].contact_force
    assert floors == pytest.approx(press, rel=1e-10)
    handed = 0.0
    for name in ("top-on-left", "top-on-right"):
        contact = next(c for c in problem.contacts if c.name == name)
        handed -= contact.target_force().x.array.reshape(-1, 2)[:, 1].sum()
    assert handed == pytest.approx(press, rel=1e-8)  # measured 4e-10 (the Newton tolerance)
    # the mirror image but for the one-pass joint of the bottom blocks (measured 0.9 %)
    left, right = states["top-on-left"].contact_force, states["top-on-right"].contact_force
    assert left == pytest.approx(right, rel=0.02)


@pytest.mark.mpi
def test_automatic_pairs_on_every_process_give_the_serial_forces(tmp_path):
    """The junction on 1 or 2 processes: every contact's serial force to 1e-8."""
    out = Path(MPI.COMM_WORLD.bcast(str(tmp_path), root=0))
    serial = {"right-on-left": 0.21603746971001433, "top-on-left": 1.275947239650492,
              "top-on-right": 1.2872507754986384, "left-floor": 1.2758692401341534,
              "right-floor": 1.2872708529163035}
    outcome = run_scene(load_scene(SCENES / "junction_blocks.toml"), out, pictures=False)
    assert outcome.path.converged
    for name, state in outcome.problem.contact_states().items():
        assert state.contact_force == pytest.approx(serial[name], rel=1e-8), name
