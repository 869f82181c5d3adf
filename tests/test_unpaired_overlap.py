"""After a run, two bodies that no contact joins are checked for nodes inside each other.

The bridge (``scenes/bridge.toml``) with its right pair left out: the
bridge, pressed in the middle and resting on the left support, sinks
through the right support (10 of its nodes, the deepest 0.0291 = 58 % of
h), the run converges, and before it said nothing. Now it names the two
bodies and the fix. The shipped bridge, whose supports are far apart and
joined to the bridge by pairs, has no pair of bodies to check.
"""

from __future__ import annotations

import re
import tomllib
import warnings
from pathlib import Path

import pytest

from mpi4py import MPI

from fenics_contact import load_scene, run_scene
from fenics_contact.scene.checks import SceneWarning
from fenics_contact.scene.schema import scene_from_data
from fenics_contact.scene.unpaired_overlap import unpaired_bodies, warn_unpaired_overlap

SCENE = Path(__file__).parents[1] / "scenes" / "bridge.toml"


def _shared_dir(factory) -> Path:
    comm = MPI.COMM_WORLD
    return Path(comm.bcast(str(factory.mktemp("unpaired")) if comm.rank == 0 else None, root=0))


@pytest.mark.mpi
def test_bodies_that_no_contact_joins_and_pass_through_each_other_are_named(
        tmp_path_factory):
    data = tomllib.loads(SCENE.read_text())
    data["pair"] = [p for p in data["pair"] if p["name"] != "on-right"]
    scene = scene_from_data(data, SCENE)
    with pytest.warns(SceneWarning) as seen:
        outcome = run_scene(scene, _shared_dir(tmp_path_factory) / "run", pictures=False)
    assert outcome.path.converged  # converged, and wrong: the bridge sank into its support
    named = [str(w.message) for w in seen if "no contact joins them" in str(w.message)]
    assert len(named) == 1
    found = re.search(r"bodies '(\w+)' and '(\w+)' pass through each other, and no contact "
                      r"joins them: (\d+) boundary nodes of '\w+' lie inside '\w+', the deepest "
                      r"([0-9.e-]+) \(([0-9.]+)% of h\)", named[0])
    assert found is not None, named[0]
    assert found.group(1, 2) == ("bridge", "right")
    assert int(found.group(3)) == 10
    assert float(found.group(4)) == pytest.approx(0.0291, rel=0.02)
    assert float(found.group(5)) == pytest.approx(58.2, abs=0.5)
    assert "Declare a [[pair]] between them" in named[0]
    assert named[0] in outcome.summary["warnings"]


def test_bodies_joined_by_pairs_or_far_apart_are_not_named(tmp_path):
    scene = load_scene(SCENE)
    outcome = run_scene(scene, tmp_path / "run", pictures=False)
    assert outcome.path.converged
    # the two supports: no contact joins them, and they lie far apart
    assert [(a.name, b.name) for a, b in unpaired_bodies(outcome.problem)] == [("left", "right")]
    with warnings.catch_warnings():
        warnings.simplefilter("error", SceneWarning)
        assert warn_unpaired_overlap(scene, outcome.problem) == 0.0
