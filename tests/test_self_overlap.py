"""After a run, every body is checked against itself: boundary nodes inside the same body.

The crushed tube (``scenes/tube_crush.toml``) with its self-contact pair
mis-tagged (striker = target = "inner_top", the lower inner wall in no
pair): the run converges while the upper inner wall passes 0.019 (72 % of
a facet) into the lower one, 100 nodes deep inside, and before it said
nothing; now it names the body, the deepest node and the fix. The same in
3D (the section extruded, every node on an end face: the end faces do not
count as walls), and the tube with no self-contact pair at all. The
shipped tube, whose pair covers both walls, is clean (deepest 3.5e-11 h).
"""

from __future__ import annotations

import re
import tomllib
import warnings
from pathlib import Path

import pytest

from mpi4py import MPI

from fenics_contact import run_scene
from fenics_contact.scene.checks import SceneWarning
from fenics_contact.scene.schema import load_scene, scene_from_data
from fenics_contact.scene.self_overlap import warn_self_overlap

SCENES = Path(__file__).parents[1] / "scenes"
SCENE = SCENES / "tube_crush.toml"
#: Measured on the mis-tagged tube: nodes inside, the deepest one's depth (length).
COUNT_MISSED, DEPTH_MISSED = 100, 0.0190


def _shared_dir(factory) -> Path:
    comm = MPI.COMM_WORLD
    return Path(comm.bcast(str(factory.mktemp("self")) if comm.rank == 0 else None, root=0))


def _tube(name: str = "tube_crush.toml", **pair) -> object:
    """A shipped crushed tube, its [[pair]] changed by ``pair``."""
    data = tomllib.loads((SCENES / name).read_text())
    data["pair"][0].update(pair)
    return scene_from_data(data, SCENES / name)


def _tube_alone() -> object:
    """The crushed tube as a one-body scene: no self-contact pair."""
    data = tomllib.loads(SCENE.read_text())
    body = data.pop("body")[0]
    data.pop("pair")
    data["material"] = {k: body[k] for k in ("law", "E", "nu")}
    return scene_from_data(data, SCENE)


def _deepest(message: str) -> tuple[int, float, float]:
    """(nodes, depth, depth / h) read from a self-overlap warning."""
    found = re.search(r"(\d+) of its boundary nodes lie inside it, the deepest ([0-9.e-]+) "
                      r"\(([0-9.]+)% of h\)", message)
    assert found is not None, message
    return int(found.group(1)), float(found.group(2)), float(found.group(3)) / 100


@pytest.mark.mpi
def test_a_self_pair_that_misses_a_wall_is_named(tmp_path_factory):
    out = _shared_dir(tmp_path_factory)
    scene = _tube(target="inner_top")
    with pytest.warns(SceneWarning) as seen:
        outcome = run_scene(scene, out / "run", pictures=False)
    assert outcome.path.converged  # converged, and wrong: the walls passed each other
    named = [str(w.message) for w in seen if "overlaps itself" in str(w.message)]
    assert len(named) == 1
    count, depth, of_h = _deepest(named[0])
    assert count == COUNT_MISSED
    assert depth == pytest.approx(DEPTH_MISSED, rel=0.02)
    assert of_h == pytest.approx(0.725, abs=0.002)  # of the striker's facet size
    assert "body 'tube' overlaps itself" in named[0]
    assert "holds striker 'inner_top' out of target 'inner_top'" in named[0]
    assert "its surfaces must cover where the body touches itself" in named[0]
    assert named[0] in outcome.summary["warnings"]


def test_the_same_in_3d_where_every_node_lies_on_an_end_face(tmp_path):
    """Before the end faces were set aside every node lay on one, at depth 0: not named."""
    scene = _tube("tube_crush_3d.toml", target="inner_top")
    with pytest.warns(SceneWarning) as seen:
        outcome = run_scene(scene, tmp_path / "run", comm=MPI.COMM_SELF, pictures=False)
    assert outcome.path.converged
    named = [str(w.message) for w in seen if "overlaps itself" in str(w.message)]
    assert len(named) == 1
    count, depth, _ = _deepest(named[0])
    assert (count, depth) == (198, pytest.approx(0.0162, rel=0.02))


def test_a_body_with_no_self_pair_that_folds_through_itself_is_named(tmp_path):
    with pytest.warns(SceneWarning) as seen:
        outcome = run_scene(_tube_alone(), tmp_path / "run", comm=MPI.COMM_SELF,
                            pictures=False)
    assert outcome.path.converged
    named = [str(w.message) for w in seen if "overlaps itself" in str(w.message)]
    assert len(named) == 1
    count, depth, _ = _deepest(named[0])
    assert (count, depth) == (COUNT_MISSED, pytest.approx(DEPTH_MISSED, rel=0.02))
    assert "No self-contact pair holds the body apart from itself" in named[0]


def test_a_self_pair_that_covers_both_walls_is_clean(tmp_path):
    scene = load_scene(SCENE)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SceneWarning)  # the wall's pressure scatters (known)
        outcome = run_scene(scene, tmp_path / "run", comm=MPI.COMM_SELF, pictures=False)
    assert outcome.path.converged
    assert not [w for w in outcome.summary["warnings"] if "overlaps itself" in w]
    with warnings.catch_warnings():
        warnings.simplefilter("error", SceneWarning)
        assert warn_self_overlap(scene, outcome.problem) < 1e-9  # 3.5e-11 measured
