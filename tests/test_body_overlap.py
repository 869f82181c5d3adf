"""After a run, each two-body pair's bodies are checked both ways for nodes inside the partner.

A node-to-segment pair holds its striker nodes out of the target surface,
one way: on ``scenes/bridge.toml`` each support's top corner, a target node,
slides out under the bridge and lies 5.8e-4 (1.2 % of the striker's h)
inside it, and the run says so. Blocks stacked with their faces meeting whole
(``scenes/stack_3_blocks.toml``) overlap by round-off: no warning.
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import pytest

from mpi4py import MPI

from fenics_contact import load_scene, run_scene
from fenics_contact.scene.body_overlap import WARN_DEPTH, warn_body_overlap
from fenics_contact.scene.checks import SceneWarning

ROOT = Path(__file__).parents[1]


def _shared_dir(factory) -> Path:
    comm = MPI.COMM_WORLD
    return Path(comm.bcast(str(factory.mktemp("overlap")) if comm.rank == 0 else None, root=0))


@pytest.mark.mpi
def test_a_target_corner_inside_the_striker_is_named(tmp_path_factory):
    out = _shared_dir(tmp_path_factory)
    scene = load_scene(ROOT / "scenes" / "bridge.toml")
    with pytest.warns(SceneWarning) as seen:
        outcome = run_scene(scene, out / "bridge", pictures=False)
    messages = [str(w.message) for w in seen if "inside body" in str(w.message)]
    assert len(messages) == 2  # one per pair
    for side, x in (("left", 1.002), ("right", 1.998)):
        found = [m for m in messages if f"body '{side}' lies" in m]
        assert len(found) == 1
        depth = float(re.search(r"lies ([0-9.e-]+) \(", found[0]).group(1))
        assert depth == pytest.approx(5.8e-4, rel=0.02)
        assert f"near ({x}, 0.4967)" in found[0]
        assert "inside body 'bridge'" in found[0]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        deepest = warn_body_overlap(scene, outcome.problem)
    assert deepest == pytest.approx(0.0116, rel=0.02)  # of h
    assert deepest > WARN_DEPTH


def test_blocks_whose_faces_meet_whole_overlap_by_round_off_only(tmp_path):
    scene = load_scene(ROOT / "scenes" / "stack_3_blocks.toml")
    outcome = run_scene(scene, tmp_path / "stack", pictures=False)
    assert outcome.path.converged
    with warnings.catch_warnings():
        warnings.simplefilter("error", SceneWarning)
        assert warn_body_overlap(scene, outcome.problem) < 1e-12


def test_an_automatic_contact_is_named_as_such_with_a_fix_that_applies(tmp_path):
    """Automatic pairing of the bridge: the support's corner again; the advice is to declare
    the pair (the automatic contact's striker and target are not the user's to retag)."""
    text = (ROOT / "scenes" / "bridge.toml").read_text().replace(
        '"../meshes/', f'"{ROOT}/meshes/')
    text = text[:text.index("[[pair]]")] + "[pairing]\nautomatic = true\n\n" + \
        text[text.index("[[dirichlet]]"):]
    (tmp_path / "auto.toml").write_text(text)
    with pytest.warns(SceneWarning) as seen:
        run_scene(load_scene(tmp_path / "auto.toml"), tmp_path / "run", pictures=False)
    named = [str(w.message) for w in seen if "inside body" in str(w.message)]
    assert len(named) == 2
    assert all("[pairing] automatic contact '" in m and "declare these two bodies as a [[pair]]"
               in m for m in named)


def test_an_overlap_at_an_earlier_step_is_named_with_its_step(tmp_path):
    """Node-to-segment blocks slid off each other: the lower corner passes inside, then out.

    The upper (coarser, striking) block is pressed 0.02 and slid 1.2 to the
    right, past the lower block's end. At load step 26 the lower block's
    corner lies 4.2 % of h inside the upper one; at the end the blocks have
    parted. Before, only the last state was checked: nothing was said.
    """
    import json

    text = (ROOT / "scenes" / "block_on_block_node_to_segment.toml").read_text()
    text = text.replace('"../meshes/block_on_block.geo"',
                        f'"{ROOT / "meshes" / "block_on_block.geo"}"')
    text = text.replace('[[dirichlet]]\ntag = "symmetry"\nvalue = [0.0, "free"]\n', "")
    text = text.replace('tag = "bottom"\nvalue = ["free", 0.0]',
                        'tag = "bottom"\nvalue = [0.0, 0.0]')
    text = text.replace('tag = "top"\nvalue = ["free", -0.01]',
                        'tag = "top"\npath = [[0.0, 0.0, 0.0], [0.2, 0.0, -0.02], '
                        "[1.0, 1.2, -0.02]]")
    text = re.sub(r"steps = \d+", "steps = 40", text)
    path = tmp_path / "slide.toml"
    path.write_text(text + "\n[output]\npictures = false\n")
    outcome = run_scene(load_scene(path), tmp_path / "out", comm=MPI.COMM_SELF)
    assert outcome.path.converged
    assert outcome.path.steps[-1].contact_force == 0.0  # parted
    said = [w for w in json.loads((tmp_path / "out" / "summary.json").read_text())["warnings"]
            if "inside body" in w]
    assert len(said) == 1
    found = re.search(r"at load step (\d+) \(load factor [\d.]+; the last step is clear of it\) "
                      r"a boundary node of body 'lower' lies ([\d.e-]+) \(([\d.]+)% of h\) "
                      r"inside body 'upper'", said[0])
    assert found, said[0]
    assert 20 < int(found.group(1)) < 36 and float(found.group(3)) > 100 * WARN_DEPTH


def test_an_overlap_between_bodies_of_several_pairs_goes_to_the_nearest_pair():
    """Two bodies joined by two pairs: the overlap is laid to the pair nearest it.

    A user's indenter pressed a block's top through a mortar pair, and a
    node-to-segment pair joined the block's side to the indenter (never
    touching): a node at the mortar interface 2.4 % of h inside was named
    under the side pair, with node-to-segment's 1 % allowance and advice.
    """
    from types import SimpleNamespace

    import numpy as np

    from fenics_contact.scene.body_overlap import _nearest_pair

    top = SimpleNamespace(name="top", nodal_coordinates=lambda: np.array(
        [[x, 1.0, 0.0] for x in np.linspace(0.0, 1.0, 11)]))
    side = SimpleNamespace(name="side", nodal_coordinates=lambda: np.array(
        [[0.0, y, 0.0] for y in np.linspace(0.0, 0.9, 10)]))
    problem = SimpleNamespace(comm=MPI.COMM_SELF,
                              domain=SimpleNamespace(geometry=SimpleNamespace(dim=2)))
    assert _nearest_pair(problem, [side, top], np.array([0.52, 0.998])).name == "top"
    assert _nearest_pair(problem, [side, top], np.array([0.01, 0.4])).name == "side"
    assert _nearest_pair(problem, [side], np.array([0.52, 0.998])).name == "side"


def test_an_overlap_under_the_penalty_method_is_laid_to_it(tmp_path):
    """The penalty method's own penetration is named as such, with the fix that applies.

    The three stacked blocks under penalty at r = 1e-2 E/h: the middle block
    sinks into the bottom one by about the pressure over r. The advice used
    to be to retag or refine the surfaces, which does nothing here.
    """
    from fenics_contact.scene.variants import with_contact_settings, with_solver

    scene = load_scene(ROOT / "scenes" / "stack_3_blocks.toml")
    scene = with_solver(with_contact_settings(scene, r=1e-2, relative=True), method="penalty")
    with pytest.warns(SceneWarning) as seen:
        outcome = run_scene(scene, tmp_path / "stack", pictures=False)
    assert outcome.path.converged
    named = [str(w.message) for w in seen if "inside body" in str(w.message)]
    assert named
    assert all("The penalty method lets a pair's surfaces overlap" in m for m in named)
    assert not any("tag the striker" in m for m in named)
