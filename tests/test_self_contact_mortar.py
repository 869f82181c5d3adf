"""Self-contact of two surfaces of one body on a mortar pair: the crushed tube.

``scenes/tube_crush.toml`` with its self-contact pair (upper inner quarter
striking the lower one) on ``discretisation = "mortar"``: the weighted gaps
of the striker nodes against the other quarter, no neighbourhood rule (a
mortar pair pairs only facets that face each other). The closed state is
the node-to-segment one: on 100 load steps the plates read 8.744807 against
8.7462268 and the inner wall 7.484019 against 7.485404 (50 steps, the
``crushed`` run of test_self_contact.py), 49 nodes closed in both; in 3D
(the section extruded) 0.874263 against 0.874291 per plate and 0.749319
against 0.749351 on the wall (one run each, docs/contacts.md).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mpi4py import MPI

from fenics_contact.model.mortar import MortarContact
from fenics_contact.runner import run_scene
from fenics_contact.scene.schema import SceneError, load_scene

SCENES = Path(__file__).parent.parent / "scenes"
WALL = 0.1


def _scene(tmp_path: Path, name: str = "tube_crush.toml", *, steps: int | None = None,
           edit: tuple[str, str] = ("neighbourhood = 3.0", 'discretisation = "mortar"')) -> Path:
    text = (SCENES / name).read_text().replace('"../meshes/', f'"{SCENES.parent / "meshes"}/')
    if name == "tube_crush_3d.toml":
        text = text.replace("self_contact = true\n", 'self_contact = true\ndiscretisation = '
                            '"mortar"\n').replace("neighbourhood = 3.0\n", "")
    else:
        text = text.replace(*edit)
    if steps is not None:
        text = text.replace("steps = 50", f"steps = {steps}")
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.fixture(scope="module")
def crushed_mortar(tmp_path_factory):
    """The 2D tube on a mortar self-contact pair, 100 load steps (50 take another path)."""
    folder = tmp_path_factory.mktemp("tube_mortar")
    return run_scene(load_scene(_scene(folder, steps=100)), folder / "out", comm=MPI.COMM_SELF,
                     pictures=False)


def test_the_inner_wall_closes_as_on_node_to_segment(crushed_mortar):
    assert crushed_mortar.path.converged
    assert isinstance(next(c for c in crushed_mortar.problem.contacts if c.name == "inner"),
                      MortarContact)
    states = crushed_mortar.problem.contact_states()
    # node-to-segment's closed state: 8.7462268 (100 steps) and 7.485404 (50 steps)
    assert states["top"].contact_force == pytest.approx(8.7462268, rel=1e-3)
    assert states["inner"].contact_force == pytest.approx(7.485404, rel=1e-3)
    assert abs(states["inner"].active_count - 49) <= 2
    assert states["inner"].max_penetration <= 1e-10 * WALL
    # no node of either quarter inside the other beyond the mortar allowance: no warning
    assert crushed_mortar.summary["warnings"] == []


def test_the_pair_and_the_plates_balance(crushed_mortar):
    problem = crushed_mortar.problem
    states = problem.contact_states()
    top, bottom = states["top"].contact_force, states["bottom"].contact_force
    assert abs(top - bottom) <= 1e-10 * top
    contact = next(c for c in problem.contacts if c.name == "inner")
    n = problem.V.dofmap.index_map.size_local
    on_target = contact.target_force().x.array[: 2 * n].reshape(-1, 2).sum(axis=0)
    # the lower quarter is pushed down, by the wall's contact force to the normals' tilt
    assert -on_target[1] == pytest.approx(states["inner"].contact_force, rel=1e-2)
    # frictionless plates push in y only: the cut's support balances the x forces, and the
    # pair's two sides cancel (else the support would take their difference)
    reactions = crushed_mortar.summary["steps"][-1]["reaction_total"]
    assert np.allclose(reactions, 0.0, atol=1e-10 * top)


def test_the_tube_in_3d_closes_as_on_node_to_segment(tmp_path):
    """Tetrahedra, the 3D mortar segments; node-to-segment's 3D closed state to 1e-3."""
    outcome = run_scene(load_scene(_scene(tmp_path, "tube_crush_3d.toml")), tmp_path / "out",
                        comm=MPI.COMM_SELF, pictures=False)
    assert outcome.path.converged
    states = outcome.problem.contact_states()
    assert states["top"].contact_force == pytest.approx(0.874291, rel=1e-3)
    assert states["inner"].contact_force == pytest.approx(0.749351, rel=1e-3)
    assert states["inner"].max_penetration <= 1e-10 * WALL


def test_mortar_self_contact_mistakes_are_named(tmp_path):
    # one surface against itself: a mortar pair needs two
    one = _scene(tmp_path, edit=('target = "inner_bottom"\nself_contact = true\n'
                                 'neighbourhood = 3.0',
                                 'self_contact = true\ndiscretisation = "mortar"'))
    with pytest.raises(SceneError, match=r"a mortar pair joins two surfaces.*give a target"):
        load_scene(one)
    both = _scene(tmp_path, edit=("neighbourhood = 3.0",
                                  'neighbourhood = 3.0\ndiscretisation = "mortar"'))
    with pytest.raises(SceneError, match=r"neighbourhood.*belongs to node-to-segment"):
        load_scene(both)
